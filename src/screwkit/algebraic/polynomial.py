"""Sparse polynomial systems F(x; p) with parameters, evaluated batched over points.

A system is built with :class:`Poly`, a small exact-coefficient polynomial algebra over the
unknowns x and the parameters p (``Poly.variable``), and compiled into a
:class:`PolynomialSystem`: one table of terms, each term a coefficient times a product of at most
``max_factors`` powers of unknowns and parameters. Evaluation (values and both Jacobians) is
vectorised over a batch of points and parameter values: a gather of the needed powers, a product
over factors and a segmented sum per equation (``numpy.add.reduceat``), so its cost is
O(batch × terms × factors) with no Python loop over the batch.

Unknowns and parameters are complex. A parameter homotopy moves p along a path p(s) and tracks
x(s) (Sommese & Wampler, *The Numerical Solution of Systems of Polynomials*, 2005, ch. 7); it
needs F, ∂F/∂x and ∂F/∂p, which :meth:`PolynomialSystem.evaluate` returns together.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from numbers import Number

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError

Complex = NDArray[np.complex128]
Monomial = tuple[tuple[int, int], ...]  # ((symbol index, power > 0), ...) sorted by index


class Poly:
    """A polynomial in named symbols with complex coefficients: {monomial: coefficient}.

    Symbols are indices into one shared namespace: the builder of a system decides which are
    unknowns and which are parameters (:func:`compile_system`)."""

    __slots__ = ("terms",)

    def __init__(self, terms: Mapping[Monomial, complex] | None = None) -> None:
        self.terms: dict[Monomial, complex] = {k: v for k, v in (terms or {}).items() if v != 0}

    @staticmethod
    def variable(index: int) -> Poly:
        return Poly({((index, 1),): 1.0})

    @staticmethod
    def constant(value: complex) -> Poly:
        return Poly({(): value})

    @staticmethod
    def _lift(other: Poly | complex) -> Poly:
        return other if isinstance(other, Poly) else Poly.constant(complex(other))

    def __add__(self, other: Poly | complex) -> Poly:
        out = dict(self.terms)
        for k, v in Poly._lift(other).terms.items():
            out[k] = out.get(k, 0.0) + v
        return Poly(out)

    __radd__ = __add__

    def __neg__(self) -> Poly:
        return Poly({k: -v for k, v in self.terms.items()})

    def __sub__(self, other: Poly | complex) -> Poly:
        return self + (-Poly._lift(other))

    def __rsub__(self, other: Poly | complex) -> Poly:
        return Poly._lift(other) - self

    def __mul__(self, other: Poly | complex) -> Poly:
        if not isinstance(other, Poly):
            if not isinstance(other, Number):
                return NotImplemented
            return Poly({k: v * complex(other) for k, v in self.terms.items()})  # type: ignore[arg-type]
        out: dict[Monomial, complex] = {}
        for ka, va in self.terms.items():
            for kb, vb in other.terms.items():
                k = _multiply(ka, kb)
                out[k] = out.get(k, 0.0) + va * vb
        return Poly(out)

    __rmul__ = __mul__

    def __pow__(self, n: int) -> Poly:
        out = Poly.constant(1.0)
        for _ in range(n):
            out = out * self
        return out

    def degree(self, symbols: Sequence[int] | None = None) -> int:
        """Total degree, counting only ``symbols`` (all when None)."""
        keep = None if symbols is None else set(symbols)
        return max((sum(p for i, p in m if keep is None or i in keep) for m in self.terms),
                   default=0)


def _multiply(a: Monomial, b: Monomial) -> Monomial:
    powers = dict(a)
    for i, p in b:
        powers[i] = powers.get(i, 0) + p
    return tuple(sorted(powers.items()))


@dataclass(frozen=True)
class PolynomialSystem:
    """N polynomial equations in n unknowns x with k parameters p, as one table of terms.

    Term t belongs to equation ``eq[t]`` (sorted), has coefficient ``coef[t]`` and the factors
    ``sym[t, f] ** pw[t, f]`` (f < max_factors; padding has power 0). Symbols 0..n-1 are the
    unknowns, n..n+k-1 the parameters."""

    variables: tuple[str, ...]
    parameters: tuple[str, ...]
    eq: NDArray[np.intp]
    coef: Complex
    sym: NDArray[np.intp]
    pw: NDArray[np.intp]
    starts: NDArray[np.intp]  # first term of each equation (for reduceat)
    degrees: tuple[int, ...]  # total degree of each equation in the unknowns

    @property
    def n(self) -> int:
        return len(self.variables)

    @property
    def k(self) -> int:
        return len(self.parameters)

    @property
    def size(self) -> int:
        return len(self.degrees)

    def evaluate(self, x: Complex, p: Complex,
                 want_jp: bool = True) -> tuple[Complex, Complex, Complex | None]:
        """F (B, N), ∂F/∂x (B, N, n) and ∂F/∂p (B, N, k) (None unless ``want_jp``) at the
        points x (B, n) with parameters p (B, k) or (k,)."""
        x = np.asarray(x, dtype=complex)
        p = np.broadcast_to(np.asarray(p, dtype=complex), (x.shape[0], self.k))
        z = np.concatenate([x, p], axis=1)
        F = self._reduce(self._terms(z))
        dims = self.n + self.k if want_jp else self.n
        J = np.empty((x.shape[0], self.size, dims), dtype=complex)
        for i in range(dims):
            J[:, :, i] = self._reduce(self._derivative_terms(z, i))
        return F, J[:, :, : self.n], (J[:, :, self.n:] if want_jp else None)

    def _terms(self, z: Complex) -> Complex:
        factors = z[:, self.sym] ** self.pw  # (B, T, f); power 0 gives 1
        return self.coef * np.prod(factors, axis=2)

    def _derivative_terms(self, z: Complex, i: int) -> Complex:
        hit = self.sym == i
        power = np.where(hit, self.pw, 0).sum(axis=1)  # (T,)
        pw = self.pw - hit.astype(np.intp)
        factors = z[:, self.sym] ** np.maximum(pw, 0)
        return (self.coef * power) * np.prod(factors, axis=2)

    def _reduce(self, values: Complex) -> Complex:
        out = np.add.reduceat(values, self.starts, axis=1) if values.shape[1] else values
        empty = np.diff(np.append(self.starts, values.shape[1])) == 0
        if empty.any():
            out[:, empty] = 0.0
        return out


def compile_system(equations: Sequence[Poly], variables: Sequence[str],
                   parameters: Sequence[str] = ()) -> PolynomialSystem:
    """Compile ``equations`` (Polys over symbols 0..n+k-1: the unknowns named ``variables``
    first, then ``parameters``) into a :class:`PolynomialSystem`."""
    n, k = len(variables), len(parameters)
    if len(equations) != n:
        raise InputError(f"a square system is needed: {len(equations)} equations in {n} unknowns")
    rows: list[tuple[int, complex, Monomial]] = []
    for e, poly in enumerate(equations):
        for mono, c in poly.terms.items():
            if any(i >= n + k for i, _ in mono):
                raise InputError(f"equation {e} uses symbol {max(i for i, _ in mono)}, beyond "
                                 f"the {n} unknowns and {k} parameters")
            rows.append((e, complex(c), mono))
    width = max((len(m) for _, _, m in rows), default=1) or 1
    T = len(rows)
    sym = np.zeros((T, width), dtype=np.intp)
    pw = np.zeros((T, width), dtype=np.intp)
    for t, (_, _, mono) in enumerate(rows):
        for f, (i, power) in enumerate(mono):
            sym[t, f], pw[t, f] = i, power
    eq = np.array([r[0] for r in rows], dtype=np.intp)
    starts = np.searchsorted(eq, np.arange(n)).astype(np.intp)
    starts = np.minimum(starts, max(T - 1, 0))
    degrees = tuple(equations[e].degree(range(n)) for e in range(n))
    return PolynomialSystem(tuple(variables), tuple(parameters), eq,
                            np.array([r[1] for r in rows], dtype=complex), sym, pw, starts,
                            degrees)

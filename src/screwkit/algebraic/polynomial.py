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
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError

Complex = NDArray[np.complex128]
#: points evaluated together (see PolynomialSystem._blocks)
BLOCK = 64
Monomial = tuple[tuple[int, int], ...]  # ((symbol index, power > 0), ...) sorted by index


def _compiled_terms() -> bool:
    """Whether :meth:`PolynomialSystem.evaluate` (F and ∂F/∂x) runs compiled: numba is
    installed and not turned off (:data:`.compiled.AVAILABLE`)."""
    from screwkit.algebraic import compiled

    return compiled.AVAILABLE


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
        if not want_jp and _compiled_terms():
            from screwkit.algebraic.compiled import evaluate_terms

            F, J = evaluate_terms(self.coef, self.sym, self.pw, self.eq, self.size,
                                  np.asarray(x, dtype=complex), np.asarray(p, dtype=complex))
            return F, J, None
        dims = self.n + self.k if want_jp else self.n
        F, J, _ = self._blocks(self._columns(x, p), dims, None)
        return F.T, J[:, :, : self.n], (J[:, :, self.n:] if want_jp else None)

    def evaluate_directional(self, x: Complex, p: Complex,
                             dp: Complex | None) -> tuple[Complex, Complex, Complex | None]:
        """F (B, N), ∂F/∂x (B, N, n) and, when ``dp`` (B, k) is given, the derivative of F
        along the parameter direction dp, (∂F/∂p)·dp (B, N), without forming ∂F/∂p: what a
        parameter homotopy needs at each step."""
        F, J, Fdp = self._blocks(self._columns(x, p), self.n, dp)
        return F.T, J, (None if Fdp is None else Fdp.T)

    def _blocks(self, z: Complex, dims: int, dp: Complex | None
                ) -> tuple[Complex, Complex, Complex | None]:
        """:meth:`_evaluate_columns` over blocks of BLOCK points: the temporaries of a block
        stay small enough to live in cache and to skip the page faults that fresh large
        allocations cost (measured: 6× faster per point at 64 than at 128 and more)."""
        B = z.shape[1]
        if B <= BLOCK:
            return self._evaluate_columns(z, dims, dp)
        dpB = None if dp is None else np.broadcast_to(np.asarray(dp, dtype=complex),
                                                      (B, self.k))
        F = np.empty((self.size, B), dtype=complex)
        J = np.empty((B, self.size, dims), dtype=complex)
        Fdp = None if dp is None else np.empty((self.size, B), dtype=complex)
        for start in range(0, B, BLOCK):
            cut = slice(start, start + BLOCK)
            f, j, fdp = self._evaluate_columns(z[:, cut], dims, None if dpB is None
                                               else dpB[cut])
            F[:, cut], J[cut] = f, j
            if Fdp is not None and fdp is not None:
                Fdp[:, cut] = fdp
        return F, J, Fdp

    def _columns(self, x: Complex, p: Complex) -> Complex:
        """The symbols as rows, the batch along the rows: z (n + k, B)."""
        x = np.asarray(x, dtype=complex)
        B = x.shape[0]
        z = np.empty((self.n + self.k, B), dtype=complex)
        z[: self.n] = x.T
        z[self.n:] = np.broadcast_to(np.asarray(p, dtype=complex), (B, self.k)).T
        return z

    def _evaluate_columns(self, z: Complex, dims: int, dp: Complex | None
                          ) -> tuple[Complex, Complex, Complex | None]:
        """The core, laid out symbol-major so that every gather moves whole rows of B
        values: a table of powers z^0..z^D (D+1, S, B); the factors of each term (T, f, B)
        and their prefix and suffix products; F as a sparse sum of the terms; each Jacobian
        entry (the derivative of a term by the symbol of factor f is
        coef·pw_f·z_f^(pw_f−1) times the prefix before f and the suffix after it) as a sparse
        sum of those (term, factor) entries into their cells (scipy.sparse CSR products, which
        beat numpy's segmented sums several times over)."""
        B = z.shape[1]
        table = self._power_table(z)
        powers = table[self.pw, self.sym]  # (T, f, B)
        width = self.sym.shape[1]
        prefix = np.empty((width + 1, len(self.eq), B), dtype=complex)
        suffix = np.empty_like(prefix)
        prefix[0] = 1.0
        suffix[width] = 1.0
        for f in range(width):
            prefix[f + 1] = prefix[f] * powers[:, f]
            suffix[width - 1 - f] = suffix[width - f] * powers[:, width - 1 - f]
        plan = self._plan(dims)
        F = np.asarray(plan["F"] @ (self.coef[:, None] * prefix[width]))

        def entries(term: NDArray[np.intp], slot: NDArray[np.intp]) -> Complex:
            lower = np.maximum(self.pw[term, slot] - 1, 0)
            scale = (self.coef[term] * self.pw[term, slot])[:, None]
            return (table[lower, self.sym[term, slot]] * prefix[slot, term]
                    * suffix[slot + 1, term] * scale)

        J = np.asarray(plan["J"] @ entries(plan["term"], plan["slot"]))
        J3 = J.reshape(self.size, dims, B).transpose(2, 0, 1)
        if dp is None:
            return F, J3, None
        dpT = np.broadcast_to(np.asarray(dp, dtype=complex), (B, self.k)).T
        term_p, slot_p = plan["term_p"], plan["slot_p"]
        weighted = entries(term_p, slot_p) * dpT[self.sym[term_p, slot_p] - self.n]
        return F, J3, np.asarray(plan["P"] @ weighted)

    def homogenized(self) -> PolynomialSystem:
        """The system in n+1 homogeneous unknowns (h, x·h): each term of equation i times
        h^(d_i − its degree), so F_i^h(h, y) = h^(d_i)·F_i(y/h) (Sommese & Wampler 2005,
        §3.2). The new unknown ``h`` comes first; parameters are unchanged and N = n
        equations remain (a patch equation closes the system). Built once and kept on the
        system, so that the plans cached on it (evaluation, monomials) serve every call."""
        kept = self.__dict__.get("_homogenized")
        if kept is None:
            kept = self._homogenize()
            object.__setattr__(self, "_homogenized", kept)
        return kept  # type: ignore[no-any-return]

    def _homogenize(self) -> PolynomialSystem:
        unknown = self.sym < self.n
        term_degree = np.where(unknown, self.pw, 0).sum(axis=1)
        lift = np.asarray(self.degrees, dtype=np.intp)[self.eq] - term_degree
        sym = np.concatenate([self.sym + 1, np.zeros((len(self.eq), 1), dtype=np.intp)], axis=1)
        pw = np.concatenate([self.pw, lift[:, None]], axis=1)
        name = "h"
        while name in self.variables or name in self.parameters:
            name += "_"
        return PolynomialSystem((name, *self.variables), self.parameters, self.eq, self.coef,
                                sym, pw, self.starts, self.degrees)

    def coefficients_at(self, p: Complex) -> tuple[NDArray[np.intp], NDArray[np.intp], Complex]:
        """The system as polynomials in x alone at the parameters p (B, k) or (k,): the
        equation (G,) and exponent vector (G, n) of each distinct monomial in x, and its
        coefficient (B, G), the sum over the terms with that monomial of coef·Π p^pw."""
        p = np.atleast_2d(np.asarray(p, dtype=complex))
        keys, order, heads = self.monomial_plan()
        z = self._columns(np.ones((len(p), self.n), dtype=complex), p)
        values = (self.coef[:, None] * np.prod(self._power_table(z)[self.pw, self.sym],
                                               axis=1)).T
        out = np.add.reduceat(values[:, order], heads, axis=1)
        return keys[:, 0].astype(np.intp), keys[:, 1:].astype(np.intp), out

    def monomial_plan(self) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.intp]]:
        """The (equation, exponents in x) of each distinct monomial in x, the terms in the
        order of their monomials and the first of each (for reduceat): fixed by the system,
        so kept on it."""
        plan = self.__dict__.get("_monomial_plan")
        if plan is None:
            exps = np.zeros((len(self.eq), self.n), dtype=np.intp)
            rows = np.nonzero(self.sym < self.n)
            np.add.at(exps, (rows[0], self.sym[rows]), self.pw[rows])
            keys, group = np.unique(np.column_stack([self.eq, exps]), axis=0,
                                    return_inverse=True)
            order = np.argsort(group.reshape(-1), kind="stable")
            heads = np.flatnonzero(np.r_[True, np.diff(group.reshape(-1)[order]) != 0])
            plan = (keys, order, heads)
            object.__setattr__(self, "_monomial_plan", plan)
        return plan  # type: ignore[no-any-return]

    def _power_table(self, z: Complex) -> Complex:
        """z^0..z^D (D+1, S, B) for z (S, B)."""
        top = int(self.pw.max(initial=0))
        table = np.empty((top + 1, *z.shape), dtype=complex)
        table[0] = 1.0
        for d in range(1, top + 1):
            table[d] = table[d - 1] * z
        return table

    def _plan(self, dims: int) -> dict[str, Any]:
        """The sparse sums of one evaluation (cached per ``dims``): terms into equations
        ("F", N×T); the nonzero (term, factor) entries with symbol < dims into the Jacobian
        cells eq·dims + symbol ("J", N·dims×M, with their "term" and "slot"); and the entries
        with a parameter symbol into equations ("P", with "term_p", "slot_p")."""
        from scipy import sparse

        cache = self.__dict__.setdefault("_plans", {})
        if dims not in cache:
            T, N = len(self.eq), self.size
            term, slot = np.nonzero((self.pw > 0) & (self.sym < dims))
            cell = self.eq[term] * dims + self.sym[term, slot]
            term_p, slot_p = np.nonzero((self.pw > 0) & (self.sym >= self.n))

            def matrix(rows: NDArray[np.intp], cols: int, shape0: int) -> Any:
                ones = np.ones(len(rows), dtype=complex)
                return sparse.csr_matrix((ones, (rows, np.arange(cols))), shape=(shape0, cols))

            cache[dims] = {"F": matrix(self.eq, T, N), "J": matrix(cell, len(term), N * dims),
                           "term": term, "slot": slot,
                           "P": matrix(self.eq[term_p], len(term_p), N),
                           "term_p": term_p, "slot_p": slot_p}
        return cache[dims]  # type: ignore[no-any-return]


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

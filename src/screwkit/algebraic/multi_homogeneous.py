"""The multi-homogeneous homotopy: a linear-product start system for a grouping of the unknowns.

Split the unknowns u into groups u_1, …, u_m of sizes n_1, …, n_m, and let d_ij be the degree
of equation i in the unknowns of group j. The m-homogeneous Bézout number

    B_m = the coefficient of α_1^(n_1)·…·α_m^(n_m) in Π_i (d_i1·α_1 + … + d_im·α_m)

bounds the isolated solutions of F = 0 (Sommese & Wampler, *The Numerical Solution of Systems
of Polynomials*, 2005, §8.4.2, Theorem 8.4.7), and may be far below the total degree Π_i d_i:
a bilinear system of n equations in (λ, v) groups of sizes 1 and n−1 — the generalised
eigenvalue problem — has B_m = n against 2^n. The linear-product start system

    G_i(u) = Π_j Π_{l < d_ij} (c_ijl · u_j + c0_ijl),    random complex c, c0,

has exactly B_m nonsingular solutions, one per choice, for each equation i, of a group j(i)
with #{i: j(i) = j} = n_j and a factor l < d_{i,j(i)}: the chosen factors of group j are n_j
linear equations in u_j (§8.4.3). The homotopy b_i·F_i + a_i·G_i runs from (a = γ, b = 0),
γ random complex (the gamma trick), to (a = 0, b = 1), as the total-degree homotopy does
(:mod:`.total_degree`), and every isolated solution of F is the end of a path.

The grouping may be of a linear change of unknowns x = T·u (``basis``) and of a linear mix of
the equations E·F (``mix``), both invertible: neither changes the solutions, and a planar
mechanism's Cartesian coordinates become its isotropic ones (z = x + iy, z̄ = x − iy) in which a
distance equation is bilinear (Wampler 2001). The solutions are returned in x.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic.path import TrackOptions
from screwkit.algebraic.polynomial import Complex, Poly, PolynomialSystem, compile_system
from screwkit.algebraic.track import TrackResult, track_parameter_homotopy
from screwkit.errors import InputError

#: the largest m-homogeneous Bézout number :func:`solve_multi_homogeneous` tracks
MAX_PATHS = 5000


@dataclass(frozen=True)
class Grouping:
    """A grouping of the unknowns u (``groups``: index lists covering 0..n−1 once each), in
    the coordinates x = ``basis``·u (None: u = x) and for the equations ``mix``·F (None: F)."""

    groups: tuple[tuple[int, ...], ...]
    basis: Complex | None = None
    mix: Complex | None = None

    def check(self, n: int) -> None:
        flat = sorted(i for g in self.groups for i in g)
        if flat != list(range(n)) or any(not g for g in self.groups):
            raise InputError(f"a grouping must split the {n} unknowns into non-empty groups, "
                             f"each unknown in one; got {self.groups}")
        for name, m in (("basis", self.basis), ("mix", self.mix)):
            if m is not None and (np.shape(m) != (n, n) or np.linalg.cond(m) > 1e12):
                raise InputError(f"the grouping's {name} must be an invertible {n}×{n} "
                                 f"matrix; got shape {np.shape(m)}")


def system_polys(system: PolynomialSystem) -> list[Poly]:
    """The equations of ``system`` as :class:`Poly` over its symbols (unknowns, parameters)."""
    polys = [Poly() for _ in range(system.size)]
    for t in range(len(system.eq)):
        mono = tuple(sorted((int(s), int(w)) for s, w in zip(system.sym[t], system.pw[t],
                                                               strict=True) if w > 0))
        polys[system.eq[t]] = polys[system.eq[t]] + Poly({mono: complex(system.coef[t])})
    return polys


def transformed(system: PolynomialSystem, grouping: Grouping) -> list[Poly]:
    """``mix``·F(``basis``·u; p) as Polys over (u, p): the system in the grouping's unknowns."""
    n = system.n
    T = np.eye(n, dtype=complex) if grouping.basis is None else np.asarray(grouping.basis)
    E = np.eye(n, dtype=complex) if grouping.mix is None else np.asarray(grouping.mix)
    linear = [sum((Poly.variable(j) * complex(T[i, j]) for j in range(n) if T[i, j] != 0),
                  Poly()) for i in range(n)]
    out = []
    for poly in system_polys(system):
        total = Poly()
        for mono, c in poly.terms.items():
            term = Poly.constant(c)
            for s, w in mono:
                term = term * (linear[s] ** w if s < n else Poly.variable(s) ** w)
            total = total + term
        out.append(total)
    return [sum((p * complex(E[i, j]) for j, p in enumerate(out) if E[i, j] != 0), Poly())
            for i in range(n)]


def group_degrees(polys: Sequence[Poly], groups: Sequence[Sequence[int]]) -> NDArray[np.intp]:
    """d_ij (N, m): the degree of equation i in the unknowns of group j."""
    return np.array([[p.degree(g) for g in groups] for p in polys], dtype=np.intp)


def multi_homogeneous_bezout(degrees: NDArray[np.intp], sizes: Sequence[int]) -> int:
    """B_m, the coefficient of Π α_j^(n_j) in Π_i Σ_j d_ij·α_j (module docstring), by a
    sum over the equations one at a time of the counts each group still needs."""
    counts: dict[tuple[int, ...], int] = {tuple(sizes): 1}
    for row in np.asarray(degrees):
        nxt: dict[tuple[int, ...], int] = {}
        for need, c in counts.items():
            for j, d in enumerate(row):
                if d > 0 and need[j] > 0:
                    k = need[:j] + (need[j] - 1,) + need[j + 1:]
                    nxt[k] = nxt.get(k, 0) + c * int(d)
        counts = nxt
    return counts.get(tuple(0 for _ in sizes), 0)


@dataclass(frozen=True)
class LinearProduct:
    """A linear-product start system: factor (i, j, l) is ``coef[i][j][l]``·u_j + ``const``
    (module docstring); ``groups`` and ``degrees`` d_ij."""

    groups: tuple[tuple[int, ...], ...]
    degrees: NDArray[np.intp]
    coef: list[list[Complex]]   # [i][j]: (d_ij, n_j)
    const: list[list[Complex]]  # [i][j]: (d_ij,)

    @staticmethod
    def random(groups: Sequence[Sequence[int]], degrees: NDArray[np.intp],
               rng: np.random.Generator) -> LinearProduct:
        def cn(*shape: int) -> Complex:
            return (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) / np.sqrt(2)

        coef = [[cn(int(d), len(g)) for d, g in zip(row, groups, strict=True)] for row in degrees]
        const = [[cn(int(d)) for d in row] for row in degrees]
        return LinearProduct(tuple(tuple(g) for g in groups), np.asarray(degrees), coef, const)

    def polys(self) -> list[Poly]:
        """G_i as Polys over the unknowns u."""
        out = []
        for i, row in enumerate(self.degrees):
            g = Poly.constant(1.0)
            for j, group in enumerate(self.groups):
                for l in range(int(row[j])):
                    g = g * (sum((Poly.variable(v) * complex(self.coef[i][j][l, a])
                                  for a, v in enumerate(group)), Poly())
                             + complex(self.const[i][j][l]))
            out.append(g)
        return out

    def solutions(self) -> Complex:
        """Every solution (B_m, n) of G = 0: per assignment of equations to groups, each
        group's chosen factors solved as one batch of linear systems."""
        m = self.degrees.shape[1]
        n = sum(len(g) for g in self.groups)
        sizes = [len(g) for g in self.groups]
        out = []
        for assign in _assignments(self.degrees, sizes):
            rows = [np.flatnonzero(assign == j) for j in range(m)]
            choices = [list(itertools.product(*(range(int(self.degrees[i, j])) for i in r)))
                       for j, r in enumerate(rows)]
            parts = []
            for j, r in enumerate(rows):
                pick = np.array(choices[j], dtype=np.intp).reshape(len(choices[j]), len(r))
                A = np.stack([self.coef[i][j][pick[:, a]] for a, i in enumerate(r)], axis=1)
                b = -np.stack([self.const[i][j][pick[:, a]] for a, i in enumerate(r)], axis=1)
                parts.append(np.linalg.solve(A, b[..., None])[..., 0])  # (choices_j, n_j)
            for combo in itertools.product(*(range(len(p)) for p in parts)):
                u = np.empty(n, dtype=complex)
                for j, c in enumerate(combo):
                    u[list(self.groups[j])] = parts[j][c]
                out.append(u)
        return np.array(out, dtype=complex).reshape(-1, n)


def _assignments(degrees: NDArray[np.intp], sizes: Sequence[int]) -> list[NDArray[np.intp]]:
    """Every map i ↦ j(i) with d_{i,j(i)} > 0 and #{i: j(i) = j} = n_j (depth-first)."""
    N, m = degrees.shape
    found: list[NDArray[np.intp]] = []

    def walk(i: int, need: list[int], chosen: list[int]) -> None:
        if i == N:
            if not any(need):
                found.append(np.array(chosen, dtype=np.intp))
            return
        for j in range(m):
            if degrees[i, j] > 0 and need[j] > 0:
                need[j] -= 1
                walk(i + 1, need, [*chosen, j])
                need[j] += 1

    walk(0, list(sizes), [])
    return found


def mhom_bezout_of(system: PolynomialSystem, grouping: Grouping) -> int:
    """B_m of ``system`` under ``grouping`` (after its basis and mix)."""
    grouping.check(system.n)
    polys = transformed(system, grouping)
    return multi_homogeneous_bezout(group_degrees(polys, grouping.groups),
                                    [len(g) for g in grouping.groups])


@dataclass(frozen=True)
class MultiHomogeneousResult:
    """The paths' :class:`TrackResult` (its ``x`` in the original unknowns, mapped back by
    the basis; its patch points ``y`` stay in the grouping's unknowns u) and the m-homogeneous Bézout number (the paths tracked)."""

    result: TrackResult
    bezout: int


def solve_multi_homogeneous(system: PolynomialSystem, p: Complex, grouping: Grouping,
                            options: TrackOptions | None = None,
                            seed: int = 0) -> MultiHomogeneousResult:
    """Track B_m paths from the linear-product start system to F(x; p) = 0 for one parameter
    vector p (k,) (module docstring); the regular ends are the nonsingular isolated
    solutions."""
    grouping.check(system.n)
    p = np.asarray(p, dtype=complex)
    if p.shape != (system.k,):
        raise InputError(f"p must have shape ({system.k},); got {p.shape}")
    n, k = system.n, system.k
    polys = transformed(system, grouping)
    degrees = group_degrees(polys, grouping.groups)
    sizes = [len(g) for g in grouping.groups]
    count = multi_homogeneous_bezout(degrees, sizes)
    if count == 0:
        raise InputError("the grouping leaves no solutions to track (an m-homogeneous Bézout "
                         "number of 0): some group's unknowns appear in fewer equations than "
                         "there are of them")
    if count > MAX_PATHS:
        raise InputError(f"the multi-homogeneous homotopy would track {count} paths, more than "
                         f"{MAX_PATHS}; use monodromy_solve from one known solution instead")
    rng = np.random.default_rng(seed)
    product = LinearProduct.random(grouping.groups, degrees, rng)
    a = [Poly.variable(n + k + i) for i in range(n)]
    b = [Poly.variable(2 * n + k + i) for i in range(n)]
    equations = [f * bi + g * ai for f, g, ai, bi in zip(polys, product.polys(), a, b,
                                                         strict=True)]
    names = tuple(f"start_a{i}" for i in range(n)) + tuple(f"start_b{i}" for i in range(n))
    extended = compile_system(equations, [f"u{i}" for i in range(n)], system.parameters + names)
    gamma = np.exp(2j * np.pi * rng.random(n))
    u0 = product.solutions()
    p_start = np.concatenate([p, gamma, np.zeros(n)])
    p_target = np.concatenate([p, np.zeros(n), np.ones(n)])
    res = track_parameter_homotopy(extended, p_start, np.tile(p_target, (len(u0), 1)), u0,
                                   options)
    T = np.eye(n, dtype=complex) if grouping.basis is None else np.asarray(grouping.basis)
    return MultiHomogeneousResult(replace(res, x=res.x @ T.T), count)

"""Is the balancing optimum unique, and if not, how far does the optimal set reach?
(docs/balancing.md, "Solve, and a non-unique optimum").

For the convex QP  min zᵀQz + 2qᵀz  s.t.  A_eq z = b_eq, A_le z ≤ b_le  with a solution z* and
multipliers μ (stationarity 2Qz* + 2q + A_eqᵀy + A_leᵀμ = 0, μ ≥ 0), every optimal z satisfies
Q(z − z*) = 0, A_eq(z − z*) = 0 and a_i(z − z*) = 0 for each *strongly* active inequality
(μ_i > 0): the objective changes by gᵀΔ = −Σ μ_i a_iΔ along a feasible Δ in null(Q), and each
term is ≥ 0. So the optimal set is

    { z* + N c  :  A_le (z* + N c) ≤ b_le },     N = null(Q) ∩ null(A_eq) ∩ null(A_strong),

the null space of the reduced Hessian over the variables the equalities and the strongly
active bounds leave free (Nocedal & Wright, *Numerical Optimization*, 2nd ed., §16.1–16.2:
second-order sufficiency on the critical cone). If N = {0} the optimum is unique (no linear
program is needed: the usual case of an optimum at a vertex). Otherwise the extent along each
direction of a canonical basis of N comes from two linear programs over c that are always
feasible (c = 0 is a member; z*'s round-off infeasibility is clipped), so they end in an optimum
(a finite end), in "unbounded" (the set has no end that way), or — on a numerical failure of the
solver — in "could not determine"; never in ±inf.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.balancing.qp import QPSolution, solve_qp

Array = NDArray[np.float64]

#: eigenvalues of the reduced Hessian below this fraction of Q's largest count as zero
NULL_RTOL = 1e-9
#: an inequality with slack below this (relative to max(1, |z*|)) is active
ACTIVE_TOL = 1e-7
#: an active inequality whose multiplier term exceeds this fraction of the gradient's size is
#: strongly active (a bound the optimum presses on)
STRONG_RTOL = 1e-6
#: ranges shorter than this (relative variable changes) count as a point
EXTENT_TOL = 1e-6


@dataclass(frozen=True)
class NonUniqueDirection:
    """A direction (unit, in relative variable changes) along which the optimum may move
    without changing any load, and how far about the returned member: ``low ≤ t ≤ high``.
    ``low``/``high`` are None where ``extent`` says the set has no end that way
    ("unbounded …") or the linear program failed ("could not determine …")."""

    direction: dict[str, float]
    low: float | None
    high: float | None
    extent: str = "bounded"


@dataclass(frozen=True)
class OptimalSet:
    """The member returned (scaled variables), the directions of the optimal set and the
    verdict: True (unique), False (a set of optima), None (could not be determined)."""

    z: Array
    directions: list[NonUniqueDirection]
    unique: bool | None
    failures: list[str]


def canonical_basis(basis: Array, tol: float = 1e-9) -> Array:
    """A basis of the column space of ``basis`` (n, k) that depends only on the space: the reduced
    row-echelon form of ``basisᵀ`` against the variable order (pivots chosen in column order),
    each direction scaled to unit length with its leading (pivot) entry positive. Any orthonormal
    basis an eigen-solver returns (which differs between machines) gives the same answer."""
    A = np.array(basis, dtype=float).T  # (k, n) rows span the space
    k, n = A.shape
    row = 0
    for j in range(n):
        if row == k:
            break
        p = row + int(np.argmax(np.abs(A[row:, j])))
        if abs(A[p, j]) <= tol:
            continue
        A[[row, p]] = A[[p, row]]
        A[row] /= A[row, j]
        others = np.arange(k) != row
        A[others] -= np.outer(A[others, j], A[row])
        row += 1
    A = A[:row]
    A[np.abs(A) <= tol * np.abs(A).max(initial=1.0)] = 0.0
    return (A / np.linalg.norm(A, axis=1, keepdims=True)).T


def null_space(A: Array, n: int, rtol: float = 1e-10) -> Array:
    """Orthonormal basis (n, k) of null(A) by SVD; ``A`` may have no rows."""
    if A.size == 0:
        return np.eye(n)
    _, s, vt = np.linalg.svd(A)
    top = float(s.max()) if s.size else 0.0
    rank = int(np.sum(s > rtol * max(top, 1e-300)))
    return np.asarray(vt[rank:].T)


def strongly_active(z: Array, Q: Array, q: Array, Al: Array, bl: Array,
                    mu: Array) -> NDArray[np.bool_]:
    """Active inequalities (slack ≤ ACTIVE_TOL) with a multiplier term ≥ STRONG_RTOL of the
    gradient's size (module docstring)."""
    if not len(bl):
        return np.zeros(0, dtype=bool)
    norms = np.linalg.norm(Al, axis=1).clip(1e-300)
    slack = (bl - Al @ z) / norms
    active = slack <= ACTIVE_TOL * max(1.0, float(np.max(np.abs(z))))
    gscale = max(float(np.max(np.abs(2 * Q @ z))), float(np.max(np.abs(2 * q))), 1e-300)
    return np.asarray(active & (mu * norms > STRONG_RTOL * gscale))


def optimal_set(Q: Array, q: Array, first: QPSolution, Ae: Array, be: Array, Al: Array,
                bl: Array, z0: Array, names: list[str]) -> OptimalSet:
    """The optimal set of the scaled QP around ``first.x`` (module docstring); the member
    returned is the one nearest to ``z0`` (least squares in scaled variables)."""
    n = Q.shape[0]
    z_star = first.x
    H = 0.5 * (Q + Q.T)
    # rows of unit length: the LP solver drops coefficients below ~1e-9 as zeros, and a
    # variable scaled by a tiny original value (1e-12 kg) would give such rows
    norms = np.linalg.norm(Al, axis=1).clip(1e-300) if len(bl) else np.ones(0)
    Al, bl = Al / norms[:, None], bl / norms
    mu = first.multipliers_le * norms
    enorms = np.linalg.norm(Ae, axis=1).clip(1e-300) if len(be) else np.ones(0)
    Ae = Ae / enorms[:, None]
    strong = strongly_active(z_star, H, q, Al, bl, mu)
    Z = null_space(np.vstack([Ae, Al[strong]]).reshape(-1, n), n)
    if Z.shape[1] == 0:
        return OptimalSet(z_star, [], True, [])
    top = max(float(np.linalg.eigvalsh(H)[-1]), 1e-300)
    lam, vec = np.linalg.eigh(Z.T @ H @ Z)
    N = Z @ vec[:, lam <= NULL_RTOL * top]  # orthonormal: Z and vec are
    if N.shape[1] == 0:
        return OptimalSet(z_star, [], True, [])
    # the set in coordinates c: Al N c ≤ r; r ≥ 0 keeps c = 0 (z*) a member despite round-off
    AN = Al @ N
    r = np.maximum(bl - Al @ z_star, 0.0)
    moving = np.linalg.norm(AN, axis=1) > 1e-12 if len(r) else np.zeros(0, dtype=bool)
    AN, r = AN[moving], r[moving]  # rows N cannot move along hold for every c (r ≥ 0)
    z = _nearest_member(z_star, N, AN, r, z0)
    directions: list[NonUniqueDirection] = []
    failures: list[str] = []
    moves = undetermined = False
    basis = canonical_basis(N)
    for k in range(basis.shape[1]):
        d = basis[:, k]
        (lo, hi), why = _extent(N.T @ d, AN, r, float(d @ (z - z_star)))
        failures += why
        if lo is not None and hi is not None and hi - lo <= EXTENT_TOL:
            continue  # the bounds hold this direction: no movement
        sides = [f"could not determine {side}" if any(side in m for m in why)
                 else f"unbounded {side}" for end, side in ((lo, "below"), (hi, "above"))
                 if end is None]
        directions.append(NonUniqueDirection(
            {nm: float(v) for nm, v in zip(names, d, strict=True) if abs(v) > 1e-9},
            lo, hi, ", ".join(sides) or "bounded"))
        known = [e for e in (lo, hi) if e is not None]
        if any("unbounded" in s for s in sides) or any(abs(e) > EXTENT_TOL for e in known):
            moves = True
        else:
            undetermined = True
    unique: bool | None = False if moves else (None if undetermined else True)
    return OptimalSet(z, directions, unique, failures)


def _nearest_member(z_star: Array, N: Array, AN: Array, r: Array, z0: Array) -> Array:
    """The member of the optimal set nearest to ``z0``: min |z* + Nc − z0|² over Al N c ≤ r (a
    QP that c = 0 satisfies); z* itself if the solver fails."""
    from screwkit.balancing.errors import BalancingError

    k = N.shape[1]
    try:
        sol = solve_qp(np.eye(k), N.T @ (z_star - z0), np.zeros((0, k)), np.zeros(0), AN, r)
    except BalancingError:
        return z_star
    c = sol.x
    if np.any(AN @ c - r > 1e-9 * max(1.0, float(np.max(np.abs(c))))):
        c = c * 0.0  # keep z*: the solver's answer left the set
    return np.asarray(z_star + N @ c)


def _extent(w: Array, AN: Array, r: Array, offset: float
            ) -> tuple[tuple[float | None, float | None], list[str]]:
    """min and max of wᵀc over {AN c ≤ r}, minus ``offset`` (the returned member's
    coordinate): ((low, high) with None for an unbounded or undetermined end, failure notes)."""
    from scipy.optimize import linprog

    ends: list[float | None] = []
    notes: list[str] = []
    for sign, side in ((1.0, "below"), (-1.0, "above")):
        res = linprog(sign * w, A_ub=AN if len(r) else None, b_ub=r if len(r) else None,
                      bounds=[(None, None)] * len(w), method="highs")
        if res.status == 0:
            ends.append(sign * float(res.fun) - offset)
        elif res.status == 3:  # unbounded: the optimal set has no end this way
            ends.append(None)
        else:
            ends.append(None)
            notes.append(f"the linear program for the end {side} stopped: {res.message}")
    return (ends[0], ends[1]), notes

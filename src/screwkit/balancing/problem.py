"""The balancing problem: weighted load measures as a quadratic in the design variables, the
QP solve, and the analysis of a non-unique optimum (Rahman 1996 ch. 4, corrected).

G(x) = Σ_k W_k·measure_k(π(x)),  π(x) = π_fixed + B·x, so G = xᵀQx + 2qᵀx + c with
Q = Σ_k W_k/N · Y_kᵀY_k (Y_k = load rows·B). The Hessian 2Q is often singular: in the seed's
example the crank turns at constant speed about a principal axis, so its three pair masses act
only through their sum (SPEC §4.4). Every optimum then has the same loads, and the optimal set
is {x feasible : Q x = Q x*}; screwkit reports its directions and extent (by linear programs)
and returns its member nearest to the original design (relative changes, least squares).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.balancing.errors import BalancingError
from screwkit.balancing.measures import MEASURES, LoadRows
from screwkit.balancing.qp import QPSolution, solve_qp
from screwkit.balancing.variables import DesignVariables, LinearConstraint
from screwkit.dynamics import Regressor

Array = NDArray[np.float64]

#: eigenvalues of the scaled Hessian below this fraction of the largest count as zero
NULL_RTOL = 1e-9


def check_weights(weights: Mapping[str, float]) -> dict[str, float]:
    """W1…W5 by measure name; missing ones are 0; all ≥ 0 and not all zero."""
    unknown = sorted(set(weights) - set(MEASURES))
    if unknown:
        raise BalancingError(f"unknown weight(s) {unknown}; the measures are {list(MEASURES)} "
                             "(F shaking force, T shaking moment, R bearing forces, "
                             "M bearing moments, T0 input torque)")
    w = {k: float(weights.get(k, 0.0)) for k in MEASURES}
    bad = {k: v for k, v in w.items() if not (np.isfinite(v) and v >= 0)}
    if bad:
        raise BalancingError(f"weights must be finite and >= 0; got {bad}")
    if not any(w.values()):
        raise BalancingError("all weights are zero: the objective would be constant. Give at "
                             "least one of F, T, R, M, T0 a positive weight")
    return w


@dataclass(frozen=True)
class NonUniqueDirection:
    """A direction (unit, in relative variable changes) along which the optimum may move
    without changing any load, and how far: ``low ≤ t ≤ high`` about the returned member."""

    direction: dict[str, float]
    low: float
    high: float


@dataclass(frozen=True)
class QuadraticObjective:
    """G(x) = xᵀQx + 2qᵀx + c per measure (``parts``) and weighted (Q, q, c)."""

    parts: dict[str, tuple[Array, Array, float]]
    weights: dict[str, float]

    @property
    def Q(self) -> Array:
        return sum((w * self.parts[k][0] for k, w in self.weights.items()),
                   start=np.zeros_like(self.parts["F"][0]))

    @property
    def q(self) -> Array:
        return sum((w * self.parts[k][1] for k, w in self.weights.items()),
                   start=np.zeros_like(self.parts["F"][1]))

    @property
    def c(self) -> float:
        return float(sum(w * self.parts[k][2] for k, w in self.weights.items()))

    def measures(self, x: Array) -> dict[str, float]:
        out = {k: float(x @ Q @ x + 2 * q @ x + c) for k, (Q, q, c) in self.parts.items()}
        out["G"] = sum(self.weights[k] * out[k] for k in MEASURES)
        return out


def quadratic_objective(rows: LoadRows, variables: DesignVariables,
                        weights: Mapping[str, float]) -> QuadraticObjective:
    """Per-measure quadratic forms in x (module docstring)."""
    w = check_weights(weights)
    parts = {}
    N = rows.samples
    for k in MEASURES:
        Y = rows.rows[k] @ variables.basis  # (N, r, n)
        y = rows.rows[k] @ variables.pi_fixed + rows.offset[k]  # (N, r)
        Yf = Y.reshape(-1, Y.shape[-1])
        yf = y.reshape(-1)
        parts[k] = (Yf.T @ Yf / N, Yf.T @ yf / N, float(yf @ yf / N))
    return QuadraticObjective(parts, w)


def consistency_constraints(reg: Regressor, variables: DesignVariables) -> list[LinearConstraint]:
    """Equalities that keep the idle-freedom residual zero (docs/dynamics.md): an S–S rod whose
    axial spin is idle must stay axisymmetric about the line of its ball centres, otherwise its
    joints would have to carry a moment they cannot. For Rahman's rod this ties the two
    transverse pair masses, x6 = x7 (SPEC §8.3)."""
    R = reg.residual  # (N, m_p, P)
    if R.size == 0 or reg.indeterminacy.idle_freedoms == 0:
        return []
    Rx = (R @ variables.basis).reshape(-1, variables.basis.shape[1]) * variables.scale
    r0 = (R @ variables.pi_fixed + reg.constant["residual"][..., 0]).reshape(-1)
    # round-off is relative to the joint loads, not to the residual itself
    loads = np.concatenate([r["force"] for r in reg.reactions.values()], axis=1)
    scale = max(float(np.max(np.abs(loads @ variables.basis * variables.scale))), 1e-300)
    U, s, Vt = np.linalg.svd(Rx, full_matrices=False)
    keep = s > 1e-9 * scale
    out: list[LinearConstraint] = []
    for k in np.flatnonzero(keep):
        row = np.where(np.abs(Vt[k]) > 1e-12, Vt[k], 0.0)  # drop round-off entries
        a = row / variables.scale  # row in unscaled x
        bnd = float(-(U[:, k] @ r0) / s[k])
        out.append(LinearConstraint(f"idle-spin residual zero #{len(out) + 1} "
                                    "(axisymmetric S-S link)", a, "eq", bnd))
    return out


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


def _rows(cons: list[LinearConstraint], kind: str, n: int) -> tuple[Array, Array, list[str]]:
    sel = [c for c in cons if c.kind == kind]
    A = np.array([c.coefficients for c in sel]).reshape(-1, n)
    b = np.array([c.bound for c in sel], dtype=float)
    return A, b, [c.name for c in sel]


def _snap_to_active(z: Array, Ae: Array, be: Array, Al: Array, bl: Array) -> Array:
    """Project an interior-point answer onto its active constraints (least change), so that
    bounds the optimum reaches hold exactly rather than to the solver's 1e-9."""
    norms = np.linalg.norm(Al, axis=1).clip(1e-300) if len(bl) else np.zeros(0)
    act = (bl - Al @ z) / norms <= 1e-7 * max(1.0, float(np.max(np.abs(z)))) if len(bl) else (
        np.zeros(0, dtype=bool))
    A = np.vstack([Ae, Al[act]])
    b = np.concatenate([be, bl[act]])
    if not len(b):
        return z
    snapped = z - np.linalg.lstsq(A, A @ z - b, rcond=1e-10)[0]
    # keep the snap only if it is a small move (it is, unless the active set was misjudged)
    if np.max(np.abs(snapped - z)) > 1e-6 * max(1.0, float(np.max(np.abs(z)))):
        return z
    return np.asarray(snapped)


@dataclass(frozen=True)
class Optimum:
    """The solve of one balancing QP: the member returned, whether it is unique, and the
    multipliers of every constraint (for the KKT conditions)."""

    x: Array
    unique: bool
    directions: list[NonUniqueDirection]
    constraints: list[LinearConstraint]
    multipliers: Array  # one per constraint, stationarity 2Qx + 2q + Σ μ_i a_i = 0
    active: list[str]
    first_solve: QPSolution


def solve_balancing(objective: QuadraticObjective, variables: DesignVariables,
                    extra: list[LinearConstraint] | None = None) -> Optimum:
    """Minimise G over the design variables (scaled by their typical sizes); detect a singular
    Hessian and return the optimal member nearest to the original design."""
    from scipy.optimize import linprog

    cons = list(variables.constraints) + list(extra or [])
    n = len(variables.names)
    S = variables.scale
    scaled = [LinearConstraint(c.name, c.coefficients * S, c.kind, c.bound) for c in cons]
    Ae, be, ne = _rows(scaled, "eq", n)
    Al, bl, nl = _rows(scaled, "le", n)
    Q = S[:, None] * objective.Q * S[None, :]
    q = S * objective.q
    first = solve_qp(Q, q, Ae, be, Al, bl, ne, nl)
    z = first.x
    lam, vec = np.linalg.eigh(0.5 * (Q + Q.T))
    top = max(float(lam[-1]), 1e-300)
    null = vec[:, lam <= NULL_RTOL * top]
    rng = vec[:, lam > NULL_RTOL * top]
    directions: list[NonUniqueDirection] = []
    sol = first
    if null.shape[1]:
        band = 1e-9 * max(1.0, float(np.max(np.abs(z))))
        Rz = rng.T @ z
        A_opt = np.vstack([Al, rng.T, -rng.T])
        b_opt = np.concatenate([bl, Rz + band, -Rz + band])
        z0 = variables.original / S
        # nearest optimal member to the original design (relative changes)
        sol = solve_qp(np.eye(n), -z0, Ae, be, A_opt, b_opt, ne,
                       [*nl, *(["optimal set"] * 2 * rng.shape[1])])
        z = sol.x
        # directions of the optimal set: a canonical basis of null(Q) within the equalities
        basis = null
        if len(be):
            sub = Ae @ null
            _, s, Vt = np.linalg.svd(sub) if sub.size else (None, np.zeros(0), np.eye(null.shape[1]))
            rank = int(np.sum(s > 1e-9 * max(float(s.max()) if s.size else 0.0, 1e-300)))
            basis = null @ Vt[rank:].T
        basis = canonical_basis(basis)
        for k in range(basis.shape[1]):
            d = basis[:, k]
            ends = []
            for sign in (1.0, -1.0):
                res = linprog(-sign * d, A_ub=A_opt if len(b_opt) else None,
                              b_ub=b_opt if len(b_opt) else None,
                              A_eq=Ae if len(be) else None, b_eq=be if len(be) else None,
                              bounds=[(None, None)] * n, method="highs")
                ends.append(sign * (-res.fun) - d @ z if res.status == 0 else sign * np.inf)
            hi, lo = ends[0], ends[1]
            if hi - lo > 1e-6:
                dx = d * S
                dx /= np.linalg.norm(d)
                directions.append(NonUniqueDirection(
                    {nm: float(v) for nm, v in zip(variables.names, d, strict=True)
                     if abs(v) > 1e-9}, float(lo), float(hi)))
    z = _snap_to_active(z, Ae, be, Al, bl)
    x = z * S
    # multipliers of the original problem at x: stationarity of G (polished KKT, least squares)
    grad = 2 * objective.Q @ x + 2 * objective.q
    A_all = np.array([c.coefficients for c in cons]).reshape(-1, n)
    viol = np.array([c.coefficients @ x - c.bound for c in cons])  # a·x = (a·S)·z
    norms = np.linalg.norm(A_all * S[None, :], axis=1).clip(1e-300)
    active = np.array([c.kind == "eq" for c in cons]) | (
        viol / norms >= -1e-7 * max(1.0, float(np.max(np.abs(z)))))
    mu = np.zeros(len(cons))
    if active.any():
        mu[active] = np.linalg.lstsq(A_all[active].T, -grad, rcond=None)[0]
    return Optimum(x, not directions, directions, cons, mu,
                   [c.name for c, a in zip(cons, active, strict=True) if a], first)

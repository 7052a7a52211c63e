"""The balancing problem: weighted load measures as a quadratic in the design variables, the
QP solve, and the analysis of a non-unique optimum (Rahman 1996 ch. 4, corrected).

G(x) = Σ_k W_k·measure_k(π(x)),  π(x) = π_fixed + B·x, so G = xᵀQx + 2qᵀx + c with
Q = Σ_k W_k/N · Y_kᵀY_k (Y_k = load rows·B). The Hessian 2Q is often singular: in the seed's
example the crank turns at constant speed about a principal axis, so its three pair masses act
only through their sum (SPEC §4.4). Every optimum then has the same loads, and the optimal set
is {x feasible : Q x = Q x*, gradient·(x − x*) = 0}; screwkit reports its directions and extent
(screwkit.balancing.optimal_set: reduced-Hessian null space, then linear programs that are
feasible whenever the optimum is) and returns its member nearest to the original design
(relative changes, least squares).
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.balancing.errors import BalancingError
from screwkit.balancing.measures import MEASURES, LoadRows
from screwkit.balancing.optimal_set import NonUniqueDirection, optimal_set
from screwkit.balancing.optimal_set import canonical_basis as canonical_basis  # re-exported
from screwkit.balancing.qp import QPSolution, solve_qp
from screwkit.balancing.variables import DesignVariables, LinearConstraint
from screwkit.dynamics import Regressor
from screwkit.dynamics.graph_regressor import GraphRegressor
from screwkit.messages import listing, number

Array = NDArray[np.float64]


def check_weights(weights: Mapping[str, float]) -> dict[str, float]:
    """W1…W5 by measure name; missing ones are 0; all ≥ 0 and not all zero."""
    unknown = sorted(set(weights) - set(MEASURES))
    if unknown:
        raise BalancingError(f"unknown weight(s) {listing(unknown)}; the measures are "
                             f"{listing(MEASURES)} "
                             "(F shaking force, T shaking moment, R bearing forces, "
                             "M bearing moments, T0 input torque)")
    text = {k: v for k, v in weights.items() if isinstance(v, str | bytes | bool)
            or not isinstance(v, numbers.Real)}
    if text:
        raise BalancingError(f"weights must be numbers; got {text}")
    w = {k: float(weights.get(k, 0.0)) for k in MEASURES}
    bad = {k: v for k, v in w.items() if not (np.isfinite(v) and v >= 0)}
    if bad:
        raise BalancingError("weights must be finite and >= 0; got "
                             f"{listing(f'{k} = {number(v)}' for k, v in bad.items())}")
    if not any(w.values()):
        raise BalancingError("all weights are zero: the objective would be constant. Give at "
                             "least one of F, T, R, M, T0 a positive weight")
    return w


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


def consistency_constraints(reg: Regressor | GraphRegressor, variables: DesignVariables
                            ) -> list[LinearConstraint]:
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
    unique: bool | None  # None: could not be determined (a linear program failed)
    directions: list[NonUniqueDirection]
    constraints: list[LinearConstraint]
    multipliers: Array  # one per constraint, stationarity 2Qx + 2q + Σ μ_i a_i = 0
    active: list[str]
    first_solve: QPSolution


def solve_balancing(objective: QuadraticObjective, variables: DesignVariables,
                    extra: list[LinearConstraint] | None = None) -> Optimum:
    """Minimise G over the design variables (scaled by their typical sizes); detect a singular
    Hessian and return the optimal member nearest to the original design."""
    cons = list(variables.constraints) + list(extra or [])
    n = len(variables.names)
    S = variables.scale
    scaled = [LinearConstraint(c.name, c.coefficients * S, c.kind, c.bound) for c in cons]
    Ae, be, ne = _rows(scaled, "eq", n)
    Al, bl, nl = _rows(scaled, "le", n)
    Q = S[:, None] * objective.Q * S[None, :]
    q = S * objective.q
    first = solve_qp(Q, q, Ae, be, Al, bl, ne, nl)
    # uniqueness and the extent of the optimal set: reduced-Hessian null space over the
    # variables the equalities and the strongly active bounds leave free, then LPs that are
    # feasible whenever the optimum is (screwkit.balancing.optimal_set)
    found = optimal_set(Q, q, first, Ae, be, Al, bl, variables.original / S,
                        list(variables.names))
    z = found.z
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
    return Optimum(x, found.unique, found.directions, cons, mu,
                   [c.name for c, a in zip(cons, active, strict=True) if a], first)

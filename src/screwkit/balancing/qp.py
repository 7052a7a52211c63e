"""Convex quadratic programs with a maintained conic solver (Clarabel, interior point; accepts
positive semidefinite Hessians — the seed's IMSL QPROG had to add a ridge, SPEC §4.4).

Problem form (all arrays dense, variables already scaled by the caller)::

    minimise   xᵀQx + 2qᵀx          subject to   A_eq x = b_eq,   A_le x ≤ b_le

The interior-point answer is then *polished*: the active constraints are solved as equalities
(the KKT system, by least squares) and kept if that point is feasible, optimal and dual feasible,
which puts vertices exactly on their bounds. An infeasible problem raises
:class:`InfeasibleConstraintsError` naming the constraints in the support of the solver's Farkas
certificate (a set of constraints that cannot hold together).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import lstsq as scipy_lstsq

from screwkit.balancing.errors import InfeasibleConstraintsError, MissingSolverError, SolverError

Array = NDArray[np.float64]

#: feasibility tolerance of the polished point (scaled variables, rows of unit size)
FEASIBILITY_TOL = 1e-9


@dataclass(frozen=True)
class QPSolution:
    """Optimum x, objective xᵀQx + 2qᵀx, multipliers (stationarity:
    2Qx + 2q + A_eqᵀ·y_eq + A_leᵀ·y_le = 0, y_le ≥ 0) and the solver's status."""

    x: Array
    objective: float
    multipliers_eq: Array
    multipliers_le: Array
    status: str
    polished: bool


def load_clarabel():  # type: ignore[no-untyped-def]
    """The ``clarabel`` module (interior-point QP/conic solver, Apache-2.0) used by the QP and
    SDP balancing solves; MissingSolverError with the install command if it is missing."""
    try:
        import clarabel
    except ImportError as exc:  # pragma: no cover - clarabel is a hard dependency
        raise MissingSolverError(
            "balancing needs the 'clarabel' QP solver (Apache-2.0): pip install clarabel"
        ) from exc
    return clarabel


def _normalise_rows(A: Array, b: Array) -> tuple[Array, Array]:
    norms = np.linalg.norm(A, axis=1) if A.size else np.zeros(0)
    norms = np.where(norms > 0, norms, 1.0)
    return A / norms[:, None], b / norms


def solve_qp(
    Q: Array,
    q: Array,
    A_eq: Array,
    b_eq: Array,
    A_le: Array,
    b_le: Array,
    names_eq: Sequence[str] = (),
    names_le: Sequence[str] = (),
) -> QPSolution:
    """Minimise xᵀQx + 2qᵀx under the linear constraints (module docstring)."""
    from scipy import sparse

    clarabel = load_clarabel()
    n = Q.shape[0]
    Ae, be = _normalise_rows(np.asarray(A_eq, float).reshape(-1, n), np.asarray(b_eq, float))
    Al, bl = _normalise_rows(np.asarray(A_le, float).reshape(-1, n), np.asarray(b_le, float))
    zero_rows = np.flatnonzero(~Ae.any(axis=1) & (np.abs(be) > 0)).tolist()
    zero_rows += (len(be) + np.flatnonzero(~Al.any(axis=1) & (bl < 0))).tolist()
    if zero_rows:
        names = [*names_eq, *names_le]
        raise InfeasibleConstraintsError(
            "constraints without variables that cannot hold: "
            + ", ".join(names[i] if i < len(names) else f"#{i}" for i in zero_rows),
            [names[i] for i in zero_rows if i < len(names)],
        )
    H = 0.5 * (Q + Q.T)
    # the objective is scaled to O(1) for the solver; the multipliers are scaled back
    kappa = max(float(np.max(np.abs(H))), float(np.max(np.abs(q))) if q.size else 0.0, 1e-300)
    P = sparse.csc_matrix(np.triu(2.0 * H / kappa))
    A = sparse.csc_matrix(np.vstack([Ae, Al]) if len(be) + len(bl) else np.zeros((0, n)))
    b = np.concatenate([be, bl])
    cones = []
    if len(be):
        cones.append(clarabel.ZeroConeT(len(be)))
    if len(bl):
        cones.append(clarabel.NonnegativeConeT(len(bl)))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = 1e-11
    settings.tol_gap_rel = 1e-11
    settings.tol_feas = 1e-11
    settings.tol_ktratio = 1e-9
    settings.max_iter = 200
    solver = clarabel.DefaultSolver(P, 2.0 * q / kappa, A, b, cones, settings)
    sol = solver.solve()
    status = str(sol.status)
    if "PrimalInfeasible" in status:
        z = np.asarray(sol.z)
        names = [*names_eq, *names_le]
        support = np.flatnonzero(np.abs(z) > 1e-6 * max(float(np.max(np.abs(z))), 1e-300))
        conflict = [names[i] if i < len(names) else f"#{i}" for i in support]
        raise InfeasibleConstraintsError(
            "the constraints cannot all hold; these conflict (a Farkas certificate of the "
            "solver): " + "; ".join(conflict) + ". Relax one of them (e.g. a larger "
            "max_decrease, 'at_most' instead of 'equal', or wider counterweight bounds).",
            conflict,
        )
    if "Solved" not in status:
        raise SolverError(f"the QP solver stopped with status {status} after "
                          f"{sol.iterations} iterations")
    x = np.asarray(sol.x, dtype=float)
    z = np.asarray(sol.z, dtype=float)
    y_eq = z[: len(be)] * kappa / np.linalg.norm(
        np.asarray(A_eq, float).reshape(-1, n), axis=1).clip(1e-300) if len(be) else np.zeros(0)
    y_le = z[len(be):] * kappa / np.linalg.norm(
        np.asarray(A_le, float).reshape(-1, n), axis=1).clip(1e-300) if len(bl) else np.zeros(0)
    out = QPSolution(x, float(x @ H @ x + 2 * q @ x), y_eq, y_le, status, False)
    return _polish(H, q, np.asarray(A_eq, float).reshape(-1, n), np.asarray(b_eq, float),
                   np.asarray(A_le, float).reshape(-1, n), np.asarray(b_le, float), out)


def _polish(H: Array, q: Array, A_eq: Array, b_eq: Array, A_le: Array, b_le: Array,
            sol: QPSolution) -> QPSolution:
    """Solve the KKT system on the active set; keep it if it is at least as good."""
    n = H.shape[0]
    scale_le = np.linalg.norm(A_le, axis=1).clip(1e-300) if len(b_le) else np.zeros(0)
    slack = (b_le - A_le @ sol.x) / scale_le if len(b_le) else np.zeros(0)
    active = slack <= 1e-7 * max(1.0, float(np.max(np.abs(sol.x))))
    Aa = np.vstack([A_eq, A_le[active]])
    ba = np.concatenate([b_eq, b_le[active]])
    m = Aa.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n] = 2 * H
    K[:n, n:] = Aa.T
    K[n:, :n] = Aa
    rhs = np.concatenate([-2 * q, ba])
    # complete orthogonal factorisation (gelsy): the minimum-norm solution like SVD-based lstsq
    # but several times faster on these small dense KKT systems
    sol_k = scipy_lstsq(K, rhs, lapack_driver="gelsy", check_finite=False)[0]
    x = sol_k[:n]
    lam = sol_k[n:]
    y_eq = lam[: len(b_eq)]
    y_le = np.zeros(len(b_le))
    y_le[active] = lam[len(b_eq):]
    x_scale = max(1.0, float(np.max(np.abs(x))))
    feasible = (
        np.all(np.abs(A_eq @ x - b_eq) <= FEASIBILITY_TOL * x_scale)
        and np.all((A_le @ x - b_le) / np.where(scale_le > 0, scale_le, 1.0)
                   <= FEASIBILITY_TOL * x_scale)
    )
    obj = float(x @ H @ x + 2 * q @ x)
    grad_scale = max(float(np.max(np.abs(2 * H @ x + 2 * q))), float(np.max(np.abs(q))), 1e-300)
    dual_ok = np.all(y_le >= -1e-7 * grad_scale)
    kkt = np.max(np.abs(2 * H @ x + 2 * q + A_eq.T @ y_eq + A_le.T @ y_le)) if n else 0.0
    if (feasible and dual_ok and kkt <= 1e-9 * grad_scale
            and obj <= sol.objective + 1e-9 * max(abs(sol.objective), 1e-300)):
        return QPSolution(x, obj, y_eq, y_le, sol.status, True)
    return sol

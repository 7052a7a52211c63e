"""Equality-constrained least squares for dwells and exact ranges (Bagci 1969, §4, eqs. 5.9, 5.11).

The second route to Program C's designs: keep every dimension as an unknown and impose
the constraints as equations with Lagrange multipliers (eq. 5.11), here by scipy's SLSQP with
exact gradients:

* instantaneous rotation dwell at theta_j (eq. 5.9): d phi0/d theta0 = -d1 Q4/Q5 = 0, imposed as
  Q4 = W2 L1 + cos^2 d0 W1 L2 = 0 (scaled by 1/L^2), d/dx = Q4_x + Q4_phi d phi/dx;
* exact output range between theta_1 and theta_2: phi_g(theta_2) - phi_g(theta_1) = dphi12.

Unlike the parameters of constraint (eqs. 5.13-5.21) this route is not restricted to delta0 = 0.
Where both apply they give the same mechanism
(tests/synthesis/test_bagci_examples.py, Example 4).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize

from screwkit.errors import InputError
from screwkit.messages import shown
from screwkit.synthesis.problem import LENGTH_NAMES, RSRCSynthesisProblem
from screwkit.synthesis.residuals import (
    NotAssembled,
    ResidualModel,
    dimensions_of,
    rotation_rate_numerator,
)
from screwkit.synthesis.solve import SynthesisError, SynthesisResult, result_from_evaluation

__all__ = ["RangeConstraint", "synthesize_equality_constrained"]

FloatArray = NDArray[np.float64]
_STEP = 1e-30


@dataclass(frozen=True)
class RangeConstraint:
    """phi_g(theta_second) - phi_g(theta_first) = rotation (rad), both design points."""

    theta_first: float
    theta_second: float
    rotation: float


Pieces = tuple[float, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]


class _ConstraintEvaluator:
    """At one unknown vector x: E, its gradient, the dwell constraints Q4 / L^2 = 0 (eq. 5.9,
    total derivative through phi by complex steps) and the range constraints with their exact
    Jacobians.  The last x is cached: SLSQP asks for each piece separately."""

    def __init__(self, problem: RSRCSynthesisProblem, model: ResidualModel,
                 index: dict[float, int], dwell_idx: NDArray[np.int64],
                 ranges: tuple[RangeConstraint, ...]) -> None:
        self.problem, self.model, self.index = problem, model, index
        self.dwell_idx, self.ranges = dwell_idx, ranges
        self.cache: dict[bytes, Pieces] = {}
        self.deadline = time.perf_counter() + problem.time_limit
        self.evaluations = 0

    def __call__(self, x: FloatArray) -> Pieces:
        key = x.tobytes()
        if key not in self.cache:
            if time.perf_counter() > self.deadline:
                raise SynthesisError(f"time limit of {self.problem.time_limit:g} s reached")
            self.evaluations += 1
            pieces = self._pieces(x)
            self.cache.clear()
            self.cache[key] = pieces
        return self.cache[key]

    def _pieces(self, x: FloatArray) -> Pieces:
        problem, model, index, dwell_idx, ranges = (self.problem, self.model, self.index,
                                                    self.dwell_idx, self.ranges)
        scale = problem.length_scale
        ev = model.evaluate(x)
        assert ev.jacobian is not None and ev.phi_jacobian is not None
        r = ev.residuals
        e = float(r @ r)
        grad = 2.0 * ev.jacobian.T @ r
        # dwell constraints Q4 = 0 at theta_j (total derivative through phi)
        p = problem.parameters(x[None, :])
        th0 = ev.theta0[dwell_idx]
        ph = ev.phi[dwell_idx]
        q4 = np.real(rotation_rate_numerator(p, th0[None, :], ph[None, :]))[0] / scale**2
        n = x.size
        pc = problem.parameters(x[None, :] + 1j * _STEP * np.eye(n))
        th0c = pc["theta01"][:, None] + problem.input_direction * model.theta[dwell_idx][None, :]
        q4_x = np.imag(rotation_rate_numerator(pc, th0c, ph[None, :])) / _STEP
        q4_phi = np.imag(rotation_rate_numerator(p, th0[None, :], ph[None, :] + 1j * _STEP))[
            0] / _STEP
        dq4 = (q4_x.T + q4_phi[:, None] * ev.phi_jacobian[dwell_idx]) / scale**2
        rng = np.array([math.remainder(ev.phi[index[c.theta_second]]
                                       - ev.phi[index[c.theta_first]] - c.rotation,
                                       2 * math.pi) for c in ranges])
        drng = np.array([ev.phi_jacobian[index[c.theta_second]]
                         - ev.phi_jacobian[index[c.theta_first]] for c in ranges])
        model.phi_ref = ev.phi
        return (e, grad, q4, dq4, rng, drng.reshape(len(ranges), n))


def synthesize_equality_constrained(
    problem: RSRCSynthesisProblem,
    *,
    dwells: tuple[float, ...] = (),
    ranges: tuple[RangeConstraint, ...] = (),
    inversion: int | None = None,
    tol: float = 1e-14,
) -> SynthesisResult:
    """Minimise E subject to rotation dwells and exact ranges (SLSQP, exact gradients).

    ``problem`` must be unconstrained (no parameters of constraint); the dwell and range input
    positions must be design points of the target (theta = 0 always is).
    """
    if problem.construction is not None:
        raise InputError("use an unconstrained problem (no parameters of constraint) with "
                         "equality constraints")
    if not dwells and not ranges:
        raise InputError("give at least one dwell or range constraint")
    try:
        model = ResidualModel(problem, inversion)
    except NotAssembled as exc:
        raise SynthesisError(f"cannot start: {exc}") from None
    def find(th: float) -> int:
        k = int(np.argmin(np.abs(model.theta - th)))
        if abs(model.theta[k] - th) > 1e-9:
            raise InputError(f"constraint at theta = {shown(th, 'angle')} is not a design "
                             "point; add it to the target's design points")
        return k

    index = {float(t): find(float(t)) for t in
             (*dwells, *(r.theta_first for r in ranges), *(r.theta_second for r in ranges))}
    dwell_idx = np.array([index[float(t)] for t in dwells], dtype=np.int64)
    scale = problem.length_scale
    x0 = problem.start_vector()
    lo, hi = problem.bound_vectors()
    evaluate = _ConstraintEvaluator(problem, model, index, dwell_idx, ranges)

    # SLSQP starts from an identity Hessian: solve in lengths / L so that a unit step is sane
    unit = np.array([scale if n in LENGTH_NAMES else 1.0 for n in problem.unknowns])

    def on_z(k: int) -> Any:
        if k in (1, 3, 5):
            return lambda z: evaluate(z * unit)[k] * unit
        return lambda z: evaluate(z * unit)[k]

    constraints = []
    if dwells:
        constraints.append({"type": "eq", "fun": on_z(2), "jac": on_z(3)})
    if ranges:
        constraints.append({"type": "eq", "fun": on_z(4), "jac": on_z(5)})
    t0 = time.perf_counter()
    try:
        evaluate(x0)
    except NotAssembled as exc:
        raise SynthesisError(f"cannot start: {exc}") from None
    bounds = list(zip(np.where(np.isfinite(lo), lo / unit, None),
                      np.where(np.isfinite(hi), hi / unit, None), strict=True))
    status = "converged"
    try:
        sol = minimize(on_z(0), x0 / unit, jac=on_z(1), method="SLSQP", bounds=bounds,
                       constraints=constraints,
                       options={"maxiter": problem.max_iterations, "ftol": tol})
        x = sol.x * unit
        message = str(sol.message)
        if not sol.success:
            status = "iteration limit" if sol.status == 9 else "not solved"
            if status == "not solved":
                raise SynthesisError(f"the equality-constrained solve failed: {sol.message}")
        iterations = int(sol.nit)
    except NotAssembled as exc:
        raise SynthesisError(f"the solve left the assembly mode: {exc}") from None
    final = model.evaluate(x)
    dimensions_of(problem.parameters(x[None, :]))
    return result_from_evaluation(
        problem, model, final, inversion or problem.inversion or 1, iterations,
        evaluate.evaluations, time.perf_counter() - t0, status, message)  # type: ignore[arg-type]

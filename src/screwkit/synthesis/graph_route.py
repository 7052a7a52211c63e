"""Dimensional synthesis of a mechanism graph: hardpoints and axes of the drawing fitted so that
points, named outputs or joint variables pass through target values at given inputs.

A design is *re-drawn*: its values replace the drawing's (a moved hardpoint moves the joint in
both its bodies), so every design closes as drawn and its drawn mode is the one through the
drawing. The motion at the target inputs is :func:`~screwkit.kinematics.graph.solve_mechanism`'s
drawn mode (closed-form sub-chains, or continuation from the drawing): the mode is never
switched; a design whose drawn mode does not assemble (or is singular) at a target input is
infeasible (a large residual in the solve, an error at the start).

Residuals (Bagci 1969 eq. 5.4 with the graph's outputs): r_i = w_i (v_d,i − v_g,i) with
w = 1/L for a length (L the length scale, 1 spec length unit by default) and 1 for an angle
(wrapped to (−π, π]); E = Σ r_i². Solved by ``scipy.optimize.least_squares`` (trust-region
reflective, bounds) with the Jacobian dr/dx by central differences, h_j = 10⁻⁵ · s_j
(s_j the mechanism's size for a coordinate, the raw axis' length for an axis component; 10⁻⁵ ≈
ε^(1/3) balances truncation O(h²) against rounding O(ε/h)), checked in tests against a
five-point stencil. A zero-residual problem converges to its exact solution
whatever the Jacobian's small error (the fixed point r = 0 does not depend on it).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.kinematics.motion import AssemblyError, format_inputs
from screwkit.model.mechanism import Mechanism
from screwkit.synthesis.solve import ON_BOUND_RTOL, SynthesisError

__all__ = ["GraphSynthesisProblem", "GraphSynthesisResult", "GraphTarget", "GraphVariable",
           "graph_residuals", "graph_jacobian", "graph_target_values", "synthesize_graph",
           "synthesize_graph_multistart"]

FloatArray = NDArray[np.float64]
_H = 1e-5  # central-difference step, in units of each variable's size (≈ eps^(1/3))


class _Infeasible(Exception):
    """The drawn mode does not assemble (or is singular) at a target input."""


class _TimeUp(Exception):
    pass


@dataclass(frozen=True)
class GraphVariable:
    """One design variable: ``table`` "joints" or "points", item ``index``, ``field`` "at",
    "axis" or "axis2", ``component`` 0–2; ``kind`` "length" (SI) or "number" (an axis
    component, as written); ``label`` the key's canonical name (``joints.C.at[0]``)."""

    label: str
    table: str
    index: int
    field: str
    component: int
    kind: str


@dataclass(frozen=True)
class GraphTarget:
    """Target values of one quantity at input rows: ``what`` "point", "output" or "variable",
    ``name`` the point/output/joint variable, ``components`` (point: coordinate indices 0–2;
    else (0,)), ``inputs`` (M, n_in) SI from the drawing, ``values`` (M, len(components)) SI,
    ``kind`` "length" or "angle" (angles are compared wrapped)."""

    label: str
    what: str
    name: str
    components: tuple[int, ...]
    inputs: FloatArray
    values: FloatArray
    kind: str


@dataclass(frozen=True)
class GraphSynthesisProblem:
    """The drawing ``mechanism`` (its values are the start), ``axes`` the raw (unnormalised)
    axis vectors as written per joint index (``(axis, axis2)``), the variables, the targets,
    ``bounds`` (per variable, SI; ±inf when free), the length scale L (m) and the limits;
    ``range_inputs`` the spec's motion rows (the whole-range check of the result)."""

    mechanism: Mechanism
    axes: dict[int, tuple[FloatArray | None, FloatArray | None]]
    variables: tuple[GraphVariable, ...]
    targets: tuple[GraphTarget, ...]
    lower: FloatArray
    upper: FloatArray
    range_inputs: FloatArray
    length_scale: float = 1e-3
    max_iterations: int = 200
    time_limit: float = 30.0
    starts: int = 1
    seed: int = 0
    keep: int = 3
    spread: float = 0.1
    rates: Any = field(default=1.0)

    def start_vector(self) -> FloatArray:
        m = self.mechanism
        out = np.empty(len(self.variables))
        for k, v in enumerate(self.variables):
            if v.field == "at":
                item = m.joints[v.index] if v.table == "joints" else m.points[v.index]
                out[k] = float(item.at[v.component])
            else:
                raw = self.axes[v.index][0 if v.field == "axis" else 1]
                assert raw is not None
                out[k] = float(raw[v.component])
        return out

    def scales(self) -> FloatArray:
        """The size of a unit step of each variable: L for a coordinate, the length of the raw
        axis for an axis component."""
        out = np.empty(len(self.variables))
        for k, v in enumerate(self.variables):
            if v.kind == "length":
                out[k] = self.length_scale
            else:
                raw = self.axes[v.index][0 if v.field == "axis" else 1]
                out[k] = float(np.linalg.norm(raw)) if raw is not None else 1.0
        return out

    def sizes(self) -> FloatArray:
        """The size of each variable: the mechanism's size for a coordinate, the raw axis'
        length for an axis component (the finite-difference steps and the multistart's
        spread are fractions of it)."""
        return np.array([self.mechanism.length_scale if v.kind == "length" else s
                         for v, s in zip(self.variables, self.scales(), strict=True)])

    def design(self, x: FloatArray) -> Mechanism:
        """The drawing with the variables at ``x`` (re-drawn: every joint at its new point)."""
        m = self.mechanism
        joints, points = list(m.joints), list(m.points)
        axes = {j: [None if a is None else np.array(a, dtype=float) for a in pair]
                for j, pair in self.axes.items()}
        ats: dict[tuple[str, int], FloatArray] = {}
        for v, value in zip(self.variables, x, strict=True):
            if v.field == "at":
                base = (joints if v.table == "joints" else points)[v.index].at
                at = ats.setdefault((v.table, v.index), np.array(base, dtype=float))
                at[v.component] = value
            else:
                raw = axes[v.index][0 if v.field == "axis" else 1]
                assert raw is not None
                raw[v.component] = value
        for (table, k), at in ats.items():
            if table == "joints":
                joints[k] = replace(joints[k], at=at)
            else:
                points[k] = replace(points[k], at=at)
        for j, (a1, a2) in axes.items():
            if any(v.table == "joints" and v.index == j and v.field != "at"
                   for v in self.variables):
                joints[j] = replace(joints[j], axis=a1 if a1 is not None else joints[j].axis,
                                    axis2=a2 if a2 is not None else joints[j].axis2)
        return replace(m, joints=tuple(joints), points=tuple(points))


def _rows(problem: GraphSynthesisProblem) -> tuple[FloatArray, list[NDArray[np.intp]]]:
    """The distinct input rows of every target and, per target, the index of each of its rows."""
    stacked = np.vstack([t.inputs for t in problem.targets])
    rows, inverse = np.unique(np.round(stacked, 15), axis=0, return_inverse=True)
    inverse = np.asarray(inverse).reshape(-1)
    out: list[NDArray[np.intp]] = []
    at = 0
    for t in problem.targets:
        out.append(inverse[at:at + t.inputs.shape[0]].astype(np.intp))
        at += t.inputs.shape[0]
    return rows, out


def _quantity(mode: Any, target: GraphTarget, idx: NDArray[np.intp]) -> FloatArray:
    if target.what == "point":
        return np.asarray(mode.points[target.name])[idx][:, list(target.components)]
    if target.what == "output":
        return np.asarray(mode.outputs[target.name])[idx][:, None]
    return np.asarray(mode.variables[target.name])[idx][:, None]


def generated(problem: GraphSynthesisProblem, x: FloatArray) -> list[FloatArray]:
    """Per target, the values the design ``x`` generates at its inputs (M, c), SI; raises
    _Infeasible when its drawn mode does not assemble (or is singular) at a target input."""
    from screwkit.kinematics.graph import solve_mechanism

    rows, where = _rows(problem)
    try:
        mech = problem.design(x)
        motion = solve_mechanism(mech, rows, rates=problem.rates)
    except (AssemblyError, ValueError, InputError) as exc:
        raise _Infeasible(str(exc)) from None
    md = motion.modes[0]
    ok = np.asarray(md.assembles) & ~np.asarray(md.singular)
    if not ok.all():
        bad = rows[~ok][0]
        raise _Infeasible(f"the drawn mode does not assemble (or is singular) at the target "
                          f"input {format_inputs(mech, bad)}")
    return [_quantity(md, t, idx) for t, idx in zip(problem.targets, where, strict=True)]


def graph_target_values(problem: GraphSynthesisProblem
                        ) -> tuple[list[FloatArray] | None, str]:
    """Per target, what the drawing itself generates (SI), or (None, why) where its drawn mode
    does not reach a target input."""
    try:
        return generated(problem, problem.start_vector()), ""
    except _Infeasible as exc:
        return None, str(exc)


def _residual_parts(problem: GraphSynthesisProblem, values: list[FloatArray]) -> FloatArray:
    parts = []
    for t, v in zip(problem.targets, values, strict=True):
        d = t.values - v
        if t.kind == "angle":
            d = np.remainder(d + math.pi, 2 * math.pi) - math.pi
        else:
            d = d / problem.length_scale
        parts.append(d.reshape(-1))
    return np.concatenate(parts)


def graph_residuals(problem: GraphSynthesisProblem, x: FloatArray) -> FloatArray:
    """r(x) (module docstring); raises SynthesisError where the drawn mode does not assemble."""
    try:
        return _residual_parts(problem, generated(problem, x))
    except _Infeasible as exc:
        raise SynthesisError(f"infeasible design: {exc}") from None


def graph_jacobian(problem: GraphSynthesisProblem, x: FloatArray, step: float = _H,
                   stencil: int = 3) -> FloatArray:
    """dr/dx by central differences (``stencil`` 3) or the five-point stencil (5), steps
    ``step`` · size; raises _Infeasible when a shifted design does not assemble."""
    h = step * problem.sizes()
    cols = []
    for j in range(x.size):
        def at(k: float, j: int = j) -> FloatArray:
            y = x.copy()
            y[j] += k * h[j]
            return _residual_parts(problem, generated(problem, y))
        if stencil == 5:
            cols.append((-at(2) + 8 * at(1) - 8 * at(-1) + at(-2)) / (12 * h[j]))
        else:
            cols.append((at(1) - at(-1)) / (2 * h[j]))
    return np.stack(cols, axis=1)


@dataclass(frozen=True)
class GraphSynthesisResult:
    """A solve: ``start`` and ``x`` (SI, per variable), the residuals r at x, E = Σ r², RMSE
    (√(E / number of residuals)), ``at_bounds`` (label → ("lower"/"upper", bound SI)),
    ``status`` ("converged", "iteration limit", "time limit"), ``message``, the generated
    values per target, ``range_ok`` and ``range_message`` (the drawn mode over the spec's
    motion rows), ``gradient_norm`` (|∂E/∂x| in scaled variables, free ones), counts, time."""

    start: FloatArray
    x: FloatArray
    residuals: FloatArray
    objective: float
    rmse: float
    at_bounds: dict[str, tuple[str, float]]
    status: str
    message: str
    generated: list[FloatArray]
    range_ok: bool
    range_message: str
    gradient_norm: float
    iterations: int
    evaluations: int
    time: float
    mechanism: Mechanism


def _range_check(problem: GraphSynthesisProblem, mech: Mechanism) -> tuple[bool, str]:
    """Does the drawn mode of the result assemble, regular, at every motion row of the spec?"""
    from screwkit.kinematics.graph import solve_mechanism

    X = problem.range_inputs
    try:
        md = solve_mechanism(mech, X, rates=problem.rates).modes[0]
    except (AssemblyError, ValueError, InputError) as exc:
        return False, f"the drawn mode cannot be followed over the motion: {exc}"
    ok = np.asarray(md.assembles) & ~np.asarray(md.singular)
    if ok.all():
        return True, f"the drawn mode runs over all {X.shape[0]} motion rows of the spec"
    bad = X[~ok]
    return False, (f"the drawn mode does not assemble (or is singular) at {int((~ok).sum())} of "
                   f"{X.shape[0]} motion rows, first at input {format_inputs(mech, bad[0])}")


def synthesize_graph(problem: GraphSynthesisProblem, start: FloatArray | None = None, *,
                     gtol: float = 1e-15, xtol: float = 1e-15) -> GraphSynthesisResult:
    """Minimise E from ``start`` (default the drawing) within the bounds (module docstring)."""
    from scipy.optimize import least_squares

    x0 = problem.start_vector() if start is None else np.asarray(start, dtype=float)
    lo, hi = problem.lower, problem.upper
    outside = np.flatnonzero((x0 < lo) | (x0 > hi))
    if outside.size:
        k = int(outside[0])
        raise SynthesisError(f"the start of {problem.variables[k].label} = {x0[k]:.6g} (SI) is "
                             f"outside its bounds [{lo[k]:.6g}, {hi[k]:.6g}]; move the drawing "
                             "or the bounds")
    try:
        r0 = _residual_parts(problem, generated(problem, x0))
    except _Infeasible as exc:
        raise SynthesisError(f"cannot start from the drawing: {exc}") from None
    big = 1e3 * (1.0 + float(np.max(np.abs(r0))))
    t0 = time.perf_counter()
    deadline = t0 + problem.time_limit
    counts = {"fun": 0, "jac": 0}
    best_x, best_e = [x0], [float(r0 @ r0)]

    def fun(x: FloatArray) -> FloatArray:
        if time.perf_counter() > deadline:
            raise _TimeUp
        counts["fun"] += 1
        try:
            r = _residual_parts(problem, generated(problem, x))
        except _Infeasible:
            return np.full(r0.size, big)
        if float(r @ r) <= best_e[0]:
            best_x[0], best_e[0] = x.copy(), float(r @ r)
        return r

    def jac(x: FloatArray, *_: object) -> FloatArray:
        counts["jac"] += 1
        try:
            return graph_jacobian(problem, x)
        except _Infeasible:  # on the edge of the drawn mode: one-sided steps would switch it
            return np.zeros((r0.size, x.size))

    status, message = "converged", ""
    scales = problem.scales()
    try:
        sol = least_squares(fun, x0, jac=jac, bounds=(lo, hi), method="trf", x_scale=scales,
                            max_nfev=problem.max_iterations, gtol=gtol, xtol=xtol, ftol=1e-15)
        x = sol.x
        message = str(sol.message)
        if sol.status == 0:
            status = "iteration limit"
    except _TimeUp:
        x, status = best_x[0], "time limit"
        message = f"stopped after the time limit of {problem.time_limit:g} s"
    elapsed = time.perf_counter() - t0
    try:
        values = generated(problem, x)
    except _Infeasible:
        x = best_x[0]
        values = generated(problem, x)
    r = _residual_parts(problem, values)
    try:
        grad = 2.0 * (graph_jacobian(problem, x).T @ r) * scales
    except _Infeasible:  # on the edge of the drawn mode: no two-sided derivative
        grad = np.full(x.size, np.nan)
    on: dict[str, tuple[str, float]] = {}
    free = np.ones(x.size, dtype=bool)
    for k, v in enumerate(problem.variables):
        tol = ON_BOUND_RTOL * max(float(scales[k]), abs(float(x[k])))
        if np.isfinite(lo[k]) and x[k] - lo[k] <= tol:
            on[v.label] = ("lower", float(lo[k]))
            free[k] = grad[k] < 0
        elif np.isfinite(hi[k]) and hi[k] - x[k] <= tol:
            on[v.label] = ("upper", float(hi[k]))
            free[k] = grad[k] > 0
    mech = problem.design(x)
    range_ok, range_message = _range_check(problem, mech)
    notes = [message.rstrip(".")] + [
        f"{name} ended on its {side} bound: the best design may lie beyond it; widen the "
        "bound to look" for name, (side, _) in on.items()]
    if not np.isfinite(grad).all():
        notes.append("the result lies at the edge of its drawn mode (a target input at a limit "
                     "position of the design): no two-sided derivative there, so its optimality "
                     "is not checked")
    if not range_ok:
        notes.append(range_message)
    E = float(r @ r)
    return GraphSynthesisResult(
        start=x0, x=np.asarray(x, dtype=float), residuals=r, objective=E,
        rmse=math.sqrt(E / max(r.size, 1)), at_bounds=on, status=status,
        message="; ".join(n for n in notes if n), generated=values, range_ok=range_ok,
        range_message=range_message, gradient_norm=float(np.linalg.norm(grad[free])),  # nan at the edge
        iterations=counts["jac"], evaluations=counts["fun"], time=elapsed, mechanism=mech)


def synthesize_graph_multistart(problem: GraphSynthesisProblem, starts: int | None = None,
                                progress: Callable[[int, int], None] | None = None
                                ) -> list[GraphSynthesisResult]:
    """The drawing, then random starts (each variable + U(−spread, spread) × its size: the
    mechanism's size for a coordinate, the raw axis' length for an axis component), clipped to
    the bounds; the best ``keep`` distinct results, those whose drawn mode runs over the whole
    motion first. Starts whose drawn mode does not assemble at every target input are skipped
    (the error lists why when none is left)."""
    n = problem.starts if starts is None else starts
    rng = np.random.default_rng(problem.seed)
    x0 = problem.start_vector()
    size = problem.sizes()
    results: list[GraphSynthesisResult] = []
    reasons: dict[str, int] = {}
    for k in range(n):
        x = x0 if k == 0 else np.clip(x0 + rng.uniform(-problem.spread, problem.spread,
                                                         x0.size) * size,
                                      problem.lower, problem.upper)
        try:
            results.append(synthesize_graph(problem, x))
        except SynthesisError as exc:
            reasons[str(exc)] = reasons.get(str(exc), 0) + 1
        if progress is not None:
            progress(k + 1, n)
    if not results:
        shown = "; ".join(f"{r} ({c}x)" if c > 1 else r for r, c in list(reasons.items())[:5])
        raise SynthesisError(f"no start gave a solution ({n} start(s) tried): {shown}")
    results.sort(key=lambda r: (not r.range_ok, r.objective))
    scales = problem.scales()
    best: list[GraphSynthesisResult] = []
    for r in results:
        if all(np.any(np.abs(r.x - b.x) > 1e-4 * scales) for b in best):
            best.append(r)
        if len(best) == problem.keep:
            break
    return best

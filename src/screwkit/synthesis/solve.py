"""Least-squares synthesis with exact derivatives, limits, checks and multi-start.

Bagci's Program B solves the equations of condition (5.5) by Newton's method with the exact
Hessian (5.6); Program C by cyclic relaxation.  Here both problem forms are solved by scipy's
maintained trust-region least squares (`scipy.optimize.least_squares`, method "trf") with the exact
Jacobian of `ResidualModel` (no finite differences), under an iteration and a wall-time limit.
A trial step where the mechanism does not assemble on its mode is answered with a large residual,
so the trust region shrinks (Program B instead reset the offending dimension).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from screwkit.dual.spatial import wrap_angle
from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_motion, rsrc_positions
from screwkit.messages import shown, shown_range
from screwkit.synthesis.problem import LENGTH_NAMES, RSRCSynthesisProblem
from screwkit.synthesis.residuals import Evaluation, NotAssembled, ResidualModel, dimensions_of

__all__ = ["RangeCheck", "evaluate_design", "SynthesisError", "SynthesisResult", "best_distinct",
           "check_range", "fit_notes", "multistart_starts", "result_from_evaluation",
           "solve_start", "synthesize", "synthesize_multistart"]

FloatArray = NDArray[np.float64]
Status = Literal["converged", "iteration limit", "time limit", "not solved"]


class SynthesisError(InputError):
    """A synthesis that cannot start or has no solution; the message says why."""


class _TimeUp(Exception):
    pass


@dataclass(frozen=True)
class RangeCheck:
    """Does the mechanism run over the whole design range on one branch (no dead centre)?

    Attributes
    ----------
    ok : assembles at every sampled theta on the branch through the theta = 0 configuration,
        passes every design point on it, and never locks.
    gaps : (theta_start, theta_end) intervals (radians, input positions from theta01) where the
        branch does not assemble.
    branch_mismatch : design points theta_i whose synthesised configuration is not on that branch.
    min_transmission : min |sin chi0| over the range (1 = coupler normal to the output crank in
        projection, 0 = dead centre of the output): Bagci's coupler angle as transmission quality.
    """

    ok: bool
    gaps: tuple[tuple[float, float], ...]
    branch_mismatch: tuple[float, ...]
    min_transmission: float
    message: str


@dataclass(frozen=True)
class SynthesisResult:
    """Optimised mechanism and its errors (SI units, radians).

    ``inversion`` is the program label (1..4, Bagci's root ordering) of the result's
    configuration at theta = 0; ``mode_sign`` the sign of Q5 that identifies its branch.

    E_phi [rad^2], E_S [m^2]; objective = E_phi + E_S / length_scale^2 (eq. 5.4); rmse =
    sqrt(objective / N) with N the number of distinct design points (theta = 0 excluded unless it
    is a design point); rmse_phi = sqrt(E_phi / N_phi), rmse_S = sqrt(E_S / N_S) [m].
    gradient_norm : |dE/dx| with lengths measured in length_scale and angles in radians,
        components at an active bound left out (0 at a local optimum).
    relative_gradient : gradient_norm / (2 |J| |r|): the cosine-like first-order optimality
        measure, independent of the size of E (<= 1e-6 is a local optimum to rounding).
    at_bounds : the unknowns that ended on one of their bounds, by name: ``("lower" or
        "upper", the bound)`` (SI, radians); the message says so too — the best design may lie
        beyond the bound (:func:`bounds_reached`).
    """

    dimensions: dict[str, float]
    inversion: int
    mode_sign: float
    objective: float
    E_phi: float
    E_S: float
    rmse: float
    rmse_phi: float
    rmse_S: float
    max_dev_phi: float
    max_dev_S: float
    gradient_norm: float
    relative_gradient: float
    iterations: int
    evaluations: int
    time: float
    status: Status
    message: str
    length_scale: float
    rows: list[dict[str, float | None]]
    range_check: RangeCheck
    evaluation: Evaluation = field(repr=False)
    at_bounds: dict[str, tuple[str, float]] = field(default_factory=dict)


#: an unknown within this fraction of its scale (L for lengths, 1 rad for angles) of a bound
#: is on the bound
ON_BOUND_RTOL = 1e-7


def bounds_reached(unknowns: Sequence[str], x: FloatArray, lower: Sequence[float] | FloatArray,
                   upper: Sequence[float] | FloatArray, scales: Sequence[float] | FloatArray
                   ) -> dict[str, tuple[str, float]]:
    """The unknowns whose final value ``x`` lies on a finite bound (within
    :data:`ON_BOUND_RTOL` of its scale): name → ("lower" or "upper", the bound)."""
    out: dict[str, tuple[str, float]] = {}
    for name, v, lo, hi, s in zip(unknowns, x, lower, upper, scales, strict=True):
        tol = ON_BOUND_RTOL * max(float(s), abs(float(v)))
        if np.isfinite(lo) and float(v) - lo <= tol:
            out[name] = ("lower", float(lo))
        elif np.isfinite(hi) and hi - float(v) <= tol:
            out[name] = ("upper", float(hi))
    return out


def bound_notes(at_bounds: Mapping[str, tuple[str, float]], kinds: Mapping[str, str]
                ) -> list[str]:
    """One sentence per unknown on a bound, the bound in the message units."""
    return [f"{name} ended on its {side} bound ({shown(b, kinds.get(name, 'length'))}): the best "
            f"design may lie beyond it; widen the bound to look" for name, (side, b) in
            at_bounds.items()]


def _n_points(problem: RSRCSynthesisProblem) -> int:
    t = problem.target
    return int(np.unique(np.concatenate([t.theta_rotation, t.theta_translation])).size)


def check_range(problem: RSRCSynthesisProblem, ev: Evaluation, n_samples: int = 721) -> RangeCheck:
    """Sweep theta over [min, max] of the design points on the theta = 0 branch (`rsrc_motion`)."""
    p = {k: np.array([v]) for k, v in ev.params.items()}
    dims = dimensions_of(p)
    lo, hi = float(ev.theta.min()), float(ev.theta.max())
    sweep = np.linspace(lo, hi, n_samples)
    sweep = np.union1d(sweep, ev.theta)
    theta0 = ev.params["theta01"] + problem.input_direction * sweep
    order = np.argsort(theta0)
    motion = rsrc_motion(dims, theta0[order])
    inv = np.empty_like(order)
    inv[order] = np.arange(order.size)
    k0 = int(inv[int(np.flatnonzero(sweep == 0.0)[0])])
    diff = np.abs(wrap_angle(motion.phi0[k0] - ev.phi[0]))
    diff = np.where(motion.assembles[k0], diff, np.inf)
    branch = int(np.argmin(diff))
    ok_mask = motion.assembles[:, branch][inv]
    phi_b = motion.phi0[:, branch][inv]
    chi_b = motion.chi0[:, branch][inv]
    gaps: list[tuple[float, float]] = []
    bad = ~ok_mask
    if bad.any():
        idx = np.flatnonzero(bad)
        starts = idx[np.r_[True, np.diff(idx) > 1]]
        ends = idx[np.r_[np.diff(idx) > 1, True]]
        gaps = [(float(sweep[s]), float(sweep[e])) for s, e in zip(starts, ends, strict=True)]
    mismatch = []
    for i, th in enumerate(ev.theta):
        j = int(np.flatnonzero(sweep == th)[0])
        d = abs(math.remainder(float(phi_b[j]) - float(ev.phi[i]), 2 * math.pi)) if ok_mask[j] \
            else math.inf
        if d > 1e-6:
            mismatch.append(float(th))
    trans = float(np.nanmin(np.abs(np.sin(chi_b)))) if ok_mask.any() else 0.0
    ok = not gaps and not mismatch and trans > 1e-6
    parts = []
    for a, b in gaps:
        t01, sense = ev.params["theta01"], problem.input_direction
        parts.append(f"does not assemble on its branch for theta in "
                     f"{shown_range(a, b, 'angle', digits=5)} (theta0 in "
                     f"{shown_range(t01 + sense * a, t01 + sense * b, 'angle', digits=5)})")
    if mismatch:
        parts.append("design point(s) theta = " + ", ".join(shown(t, "angle", digits=5)
                                                            for t in mismatch)
                     + " lie on another branch (the mechanism would have to be reassembled)")
    if trans <= 1e-6:
        parts.append("passes a dead centre of the output (sin chi0 = 0)")
    msg = "; ".join(parts) if parts else (
        f"runs over the whole range on one branch; min |sin chi0| = {trans:.3f}")
    return RangeCheck(ok, tuple(gaps), tuple(mismatch), trans, msg)


def fit_notes(problem: Any, psi_d: FloatArray, s_d: FloatArray,
               r_phi: FloatArray, r_s: FloatArray, check: RangeCheck, status: Status) -> list[str]:
    """Plain-language notes for the result message: a limit that was hit, a target the result
    does not follow (a maximum deviation above 10 % of the desired range of that component),
    a result that does not run the whole range."""
    notes = []
    if status == "iteration limit":
        notes.append(f"stopped at the iteration limit (max_iterations = {problem.max_iterations}): "
                     "the result is the best point reached, not a converged optimum")
    elif status == "time limit":
        notes.append(f"stopped at the time limit ({problem.time_limit:g} s): the result is the best "
                     "point reached, not a converged optimum")
    # a component is "not followed" when the worst deviation exceeds 10 % of its desired range,
    # or, for a component meant to stay constant, a floor: 1° for rotation, 1 % of the length
    # scale for translation
    floors = {"rotation": math.radians(1.0), "translation": 0.01 * problem.length_scale}
    for name, desired, res, unit, scale in (("rotation", psi_d, r_phi, "deg", math.degrees(1.0)),
                                            ("translation", s_d, r_s, "m", 1.0)):
        finite = desired[np.isfinite(desired)]
        if res.size == 0 or finite.size == 0:
            continue
        span = float(np.ptp(np.append(finite, 0.0)))
        worst = float(np.max(np.abs(res)))
        if worst > max(0.1 * span, floors[name]):
            notes.append(
                f"the target {name} is not followed: the generated {name} deviates by up to "
                f"{worst * scale:.4g} {unit} over a desired range of {span * scale:.4g} {unit}; "
                "this family may not generate it from this start: try a multistart, other design "
                "constants, other bounds or another assembly mode")
    if not check.ok:
        notes.append(f"the result does not run the whole range: {check.message}")
    return notes


def result_from_evaluation(
    problem: RSRCSynthesisProblem, model: ResidualModel, ev: Evaluation, label: int,
    iterations: int, evaluations: int, elapsed: float, status: Status, message: str,
) -> SynthesisResult:
    """The `SynthesisResult` of a solve ending at evaluation ``ev``: objective E = E_phi + E_S
    (Bagci 1969, §5.1) and RMS and largest deviations, the gradient projected on the free unknowns
    (an active bound is not a defect), dimensions with wrapped angles, a row per design point,
    the whole-range check and the program label (root ordering at theta = 0) of the result."""
    n_rot = model.rot_idx.size
    r = ev.residuals
    r_phi, r_s = r[:n_rot], r[n_rot:] * problem.length_scale
    e_phi = float(np.sum(r_phi**2))
    e_s = float(np.sum(r_s**2))
    objective = float(np.sum(r**2))
    grad = 2.0 * ev.jacobian.T @ r if ev.jacobian is not None else np.zeros(0)
    # per unit of L for lengths and per radian for angles: E's gradient in the problem's scale
    unit = np.array([problem.length_scale if n in LENGTH_NAMES else 1.0
                     for n in problem.unknowns])
    grad = grad * unit if grad.size else grad
    jac_scaled = ev.jacobian * unit if ev.jacobian is not None else np.zeros((0, 0))
    free = np.ones(grad.size, dtype=bool)
    for k, name in enumerate(problem.unknowns):  # a gradient at an active bound is not a defect
        lo, hi = problem.bounds.get(name, (-np.inf, np.inf))
        x = ev.x[k]
        tol = 1e-9 * max(1.0, abs(x))
        if (x - lo <= tol and grad[k] > 0) or (hi - x <= tol and grad[k] < 0):
            free[k] = False
    dims = {k: ev.params[k] for k in ("e", "d1", "d2", "d3", "a", "b", "delta0", "lambda0",
                                      "theta01")}
    if problem.construction is not None:
        dims["q1"] = ev.params["q1"]
        dims["q2"] = ev.params["q2"]
    for name in dims:  # report angles wrapped: the solver works on the unwrapped values
        if name in ("delta0", "lambda0"):
            dims[name] = math.remainder(dims[name], 2 * math.pi)
        elif name in ("theta01", "q1", "q2"):
            dims[name] = dims[name] % (2 * math.pi)
    rows: list[dict[str, float | None]] = []
    psi_all = problem.target.desired_rotation(ev.theta)
    s_all = problem.target.desired_translation(ev.theta)
    for i, th in enumerate(ev.theta):
        rows.append({
            "theta": float(th), "theta0": float(ev.theta0[i]), "phi_g": float(ev.phi[i]),
            "psi_g0": float(problem.output_direction * math.remainder(ev.phi[i] - ev.phi[0],
                                                                      2 * math.pi)),
            "psi_d0": float(psi_all[i]), "S": float(ev.S[i]), "S_g": float(ev.S[i] - ev.S[0]),
            "S_d": float(s_all[i]),
        })
    check = check_range(problem, ev)
    on_bounds = bounds_reached(
        problem.unknowns, ev.x, [problem.bounds.get(n, (-np.inf, np.inf))[0]
                                 for n in problem.unknowns],
        [problem.bounds.get(n, (-np.inf, np.inf))[1] for n in problem.unknowns], unit)
    kinds = {n: "length" if n in LENGTH_NAMES else "angle" for n in problem.unknowns}
    notes = (*fit_notes(problem, psi_all, s_all, r_phi, r_s, check, status),
             *bound_notes(on_bounds, kinds))
    message = "; ".join(m for m in (message.rstrip("."), *notes) if m)
    # the program label (root ordering, Bagci's I8/I9) of the result's configuration at theta = 0
    pos = rsrc_positions(dimensions_of({k: np.array([v]) for k, v in ev.params.items()}),
                         ev.theta0[:1])
    gap = np.where(pos.assembles[0], np.abs(wrap_angle(pos.phi0[0] - ev.phi[0])), np.inf)
    label = int(np.argmin(gap)) + 1 if np.isfinite(gap).any() else label
    return SynthesisResult(
        dimensions=dims, inversion=label, mode_sign=model.sigma, objective=objective,
        E_phi=e_phi, E_S=e_s,
        rmse=math.sqrt(objective / max(_n_points(problem), 1)),
        rmse_phi=math.sqrt(e_phi / n_rot) if n_rot else 0.0,
        rmse_S=math.sqrt(e_s / r_s.size) if r_s.size else 0.0,
        max_dev_phi=float(r_phi[np.argmax(np.abs(r_phi))]) if n_rot else 0.0,
        max_dev_S=float(r_s[np.argmax(np.abs(r_s))]) if r_s.size else 0.0,
        gradient_norm=float(np.linalg.norm(grad[free])) if grad.size else 0.0,
        relative_gradient=(float(np.linalg.norm(grad[free])) / max(
            2.0 * float(np.linalg.norm(jac_scaled[:, free])) * float(np.linalg.norm(r)), 1e-300)
            if grad.size else 0.0),
        iterations=iterations, evaluations=evaluations, time=elapsed, status=status,
        message=message, length_scale=problem.length_scale, rows=rows, range_check=check,
        evaluation=ev, at_bounds=on_bounds,
    )


def _show(name: str, value: float) -> str:
    """A value of unknown ``name`` in the message units (:mod:`screwkit.messages`)."""
    return shown(value, "length" if name in LENGTH_NAMES else "angle")


def _check_start(problem: RSRCSynthesisProblem, x0: FloatArray, lo: FloatArray,
                 hi: FloatArray) -> None:
    """The start must lie within the bounds (a crank or coupler length strictly above 0)."""
    outside = (x0 < lo) | (x0 > hi) | ((x0 == lo) & np.isfinite(lo) & (lo == 0.0))
    if outside.any():
        k = int(np.flatnonzero(outside)[0])
        name = problem.unknowns[k]
        if name not in problem.bounds:
            raise SynthesisError(f"start value of {name} = {_show(name, x0[k])} must be > 0 (a "
                                 "crank or coupler length); give it a positive start")
        raise SynthesisError(f"start value of {name} = {_show(name, x0[k])} is outside its "
                             f"bounds [{_show(name, lo[k])}, {_show(name, hi[k])}]; move the "
                             "start inside them or widen the bounds")


def synthesize(problem: RSRCSynthesisProblem, *, inversion: int | None = None,
               gtol: float = 1e-14, xtol: float = 1e-15) -> SynthesisResult:
    """Minimise E = E_phi + E_S / L^2 from the problem's start on one assembly mode.

    Program B (unknown dimensions) or Program C with parameters of constraint (q1, q2), Bagci
    1969 §5.1-5.3.  The solve stops at convergence, after ``problem.max_iterations`` Jacobian
    evaluations or after ``problem.time_limit`` seconds, whichever comes first (``status``).

    Raises
    ------
    SynthesisError
        If the start does not assemble on the mode, or violates the bounds.
    """
    label = inversion if inversion is not None else problem.inversion
    try:
        model = ResidualModel(problem, label)
    except ValueError as exc:
        raise SynthesisError(f"cannot start: {exc}") from None
    label = label or 1
    x0 = problem.start_vector()
    lo, hi = problem.bound_vectors()
    _check_start(problem, x0, lo, hi)
    t_start = time.perf_counter()
    deadline = t_start + problem.time_limit
    try:
        first = model.evaluate(x0)
    except NotAssembled as exc:
        raise SynthesisError(f"cannot start: the start does not assemble on its mode at every "
                             f"design point ({exc})") from None
    best: dict[str, Evaluation] = {"ev": first}
    cache: dict[bytes, Evaluation] = {}
    counts = {"fun": 0, "jac": 0}
    big = 1e3 * (1.0 + float(np.max(np.abs(first.residuals))))

    def fun(x: FloatArray) -> FloatArray:
        if time.perf_counter() > deadline:
            raise _TimeUp
        counts["fun"] += 1
        try:
            ev = model.evaluate(x, remember=False)
        except (NotAssembled, ValueError):
            return np.full(model.n_residuals, big)
        cache.clear()
        cache[x.tobytes()] = ev
        if np.sum(ev.residuals**2) <= np.sum(best["ev"].residuals**2):
            best["ev"] = ev
        return ev.residuals

    def jac(x: FloatArray, *_args: object) -> FloatArray:
        counts["jac"] += 1
        ev = cache.get(x.tobytes())
        if ev is None:
            ev = model.evaluate(x)
        else:
            model.phi_ref = ev.phi  # accepted step: follow the branch from here
        assert ev.jacobian is not None
        return ev.jacobian

    status: Status = "converged"
    message = ""
    try:
        sol = least_squares(fun, x0, jac=jac, bounds=(lo, hi), method="trf", x_scale="jac",
                            max_nfev=problem.max_iterations, gtol=gtol, xtol=xtol, ftol=1e-15)
        x_final = sol.x
        message = str(sol.message)
        if sol.status == 0:
            status = "iteration limit"
    except _TimeUp:
        x_final = best["ev"].x
        status = "time limit"
        message = f"stopped after the time limit of {problem.time_limit:g} s"
    elapsed = time.perf_counter() - t_start
    try:
        model.phi_ref = best["ev"].phi
        final = model.evaluate(x_final)
    except NotAssembled:
        final = model.evaluate(best["ev"].x)
    return result_from_evaluation(problem, model, final, label, counts["jac"], counts["fun"], elapsed, status,
                   message)


def evaluate_design(problem: RSRCSynthesisProblem, *,
                    inversion: int | None = None) -> SynthesisResult:
    """The errors and checks of the problem's start without solving (e.g. a seed's printed
    mechanism): the same measures as `synthesize`, with status "not solved"."""
    label = inversion if inversion is not None else problem.inversion
    try:
        model = ResidualModel(problem, label)
        ev = model.evaluate(problem.start_vector())
    except NotAssembled as exc:
        raise SynthesisError(f"the design does not assemble: {exc}") from None
    return result_from_evaluation(problem, model, ev, label or 1, 0, 1, 0.0, "not solved", "")


def _distinct(a: SynthesisResult, b: SynthesisResult, scale: float) -> bool:
    for name, value in a.dimensions.items():
        other = b.dimensions[name]
        tol = 1e-4 * scale if name in LENGTH_NAMES or name == "d3" else 1e-4
        if name in LENGTH_NAMES:
            if abs(value - other) > tol:
                return True
        elif abs(math.remainder(value - other, 2 * math.pi)) > tol:
            return True
    return False


def multistart_starts(problem: RSRCSynthesisProblem, n_starts: int, seed: int,
                      spread: float) -> tuple[list[dict[str, float]], float]:
    """The starts of a multistart, in order, and its length scale (see
    `synthesize_multistart`): the problem's own start, then ``n_starts - 1`` random ones drawn
    from ``numpy.random.default_rng(seed)``. The same seed gives the same starts, so the starts
    can be solved anywhere (one process or a cluster) with the same results."""
    if n_starts < 1:
        raise InputError("n_starts and keep must be >= 1")
    rng = np.random.default_rng(seed)
    x0 = problem.start_vector()
    scale = max(abs(problem.start.get(n, 0.0)) for n in ("d1", "d2", "d3", "a", "b", "e")
                if n in problem.start) or problem.length_scale
    lo, hi = problem.bound_vectors()
    _check_start(problem, x0, lo, hi)
    starts = []
    for k in range(n_starts):
        x = x0.copy()
        if k > 0:
            for j, name in enumerate(problem.unknowns):
                u = rng.uniform(-spread, spread)
                if name in ("d1", "d2", "d3"):
                    x[j] = x0[j] * math.exp(u) if x0[j] > 0 else abs(u) * scale
                elif name in LENGTH_NAMES:
                    x[j] = x0[j] * math.exp(u) + rng.uniform(-spread, spread) * scale
                else:
                    x[j] = x0[j] + u
            x = np.clip(x, np.where(np.isfinite(lo), lo + 1e-9 * scale, lo),
                        np.where(np.isfinite(hi), hi - 1e-9 * scale, hi))
        start = dict(problem.start)
        start.update({n: float(v) for n, v in zip(problem.unknowns, x, strict=True)})
        starts.append(start)
    return starts, scale


def solve_start(problem: RSRCSynthesisProblem, start: dict[str, float],
                time_limit: float | None = None) -> tuple[list[SynthesisResult], list[str]]:
    """One start of a multistart solved on every assembly mode that assembles there (the
    problem's ``inversion`` when set): its results and the reasons a mode gave none."""
    sub = replace(problem, start=start, time_limit=min(problem.time_limit, time_limit)
                  if time_limit is not None else problem.time_limit)
    reasons: list[str] = []
    labels = [problem.inversion] if problem.inversion is not None else [1, 2, 3, 4]
    if problem.construction is not None:
        labels = [1]
    else:
        try:
            dims = dimensions_of({n: np.array([v]) for n, v in start.items()})
            pos = rsrc_positions(dims, np.array([start["theta01"]]))
            wanted = labels
            labels = [lb for lb in labels if lb is not None and pos.assembles[0, lb - 1]]
            if not labels:
                reasons.append("the start does not assemble at theta01 (theta = 0) on "
                               + ("any mode" if len(wanted) > 1 else f"mode {wanted[0]}"))
        except ValueError as exc:
            labels = []
            reasons.append(f"the start is not a valid mechanism: {exc}")
    results = []
    for lb in labels:
        try:
            res = synthesize(sub, inversion=lb)
        except (SynthesisError, ValueError) as exc:
            reasons.append(str(exc))
            continue
        if not math.isfinite(res.objective):
            reasons.append("the solve ended with a non-finite error measure")
            continue
        results.append(res)
    return results, reasons


def best_distinct(results: list[SynthesisResult], reasons: list[str], tried: int, keep: int,
                  scale: float) -> list[SynthesisResult]:
    """The best ``keep`` distinct results of a multistart (whole-range check first, then E),
    or a `SynthesisError` naming why no start gave one (``reasons`` in start order)."""
    if not results:
        counts: dict[str, int] = {}
        for why in reasons:
            counts[why] = counts.get(why, 0) + 1
        shown = "; ".join(f"{w} ({n}x)" if n > 1 else w for w, n in list(counts.items())[:5])
        more = f"; and {len(counts) - 5} other reason(s)" if len(counts) > 5 else ""
        advice = ("widen the spread ([synthesis.multistart] spread), use more starts or change "
                  "the start" if tried > 1 else "change the start ([dimensions] or "
                  "[synthesis.start]) or the assembly mode")
        raise SynthesisError(f"no start gave a solution ({tried} start(s) tried): "
                             f"{shown or 'the time limit ran out'}{more}. {advice.capitalize()}")
    ranked = sorted(results, key=lambda r: (not r.range_check.ok, r.objective))
    best: list[SynthesisResult] = []
    for r in ranked:
        if all(_distinct(r, b, scale) for b in best):
            best.append(r)
        if len(best) == keep:
            break
    return best


def synthesize_multistart(problem: RSRCSynthesisProblem, *, n_starts: int = 20, seed: int = 0,
                          keep: int = 3, spread: float = 0.5,
                          time_limit: float | None = None,
                          progress: Callable[[int, int], None] | None = None
                          ) -> list[SynthesisResult]:
    """Multi-start over random starts and every assembly mode; the best ``keep`` distinct results.

    Starts: the problem's own start, then random ones: each unknown length multiplied by
    exp(U(-spread, spread)) (plus a shift of spread * L for signed lengths), each angle shifted by
    U(-spread, spread) rad.  For every start each inversion label 1..4 that assembles at
    theta = 0 is solved (the problem's ``inversion`` when it is set).  Results that fail the
    whole-range check are kept but ranked after those that pass.  ``time_limit`` bounds the whole
    run (seconds; default n_starts * problem.time_limit). ``progress(done, n_starts)`` is called
    after each start.  `multistart_starts`, `solve_start` and `best_distinct` are its parts,
    for running the starts elsewhere (screwkit.sweep).
    """
    if n_starts < 1 or keep < 1:
        raise InputError("n_starts and keep must be >= 1")
    total_limit = time_limit if time_limit is not None else n_starts * problem.time_limit
    t0 = time.perf_counter()
    starts, scale = multistart_starts(problem, n_starts, seed, spread)
    results: list[SynthesisResult] = []
    reasons: list[str] = []
    tried = 0
    for start in starts:
        remaining = total_limit - (time.perf_counter() - t0)
        if remaining <= 0:
            break
        tried += 1
        found, why = solve_start(problem, start, remaining)
        results += found
        reasons += why
        if progress is not None:
            progress(tried, n_starts)
    return best_distinct(results, reasons, tried, keep, scale)


def dimensions_as_mechanism(result: SynthesisResult) -> RSRCDimensions:
    """The synthesised mechanism as `RSRCDimensions` (theta01 is kept in ``result.dimensions``)."""
    d = result.dimensions
    return RSRCDimensions(d["d1"], d["d2"], d["d3"], d["a"], d["b"], d["e"], d["delta0"],
                          d["lambda0"])

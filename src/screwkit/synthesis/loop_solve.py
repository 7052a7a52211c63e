"""The generic synthesis route solved: least squares with the exact Jacobian of
:class:`~screwkit.synthesis.loop_route.LoopResidualModel`, the whole-range check of the result
(its motion re-solved independently by :func:`~screwkit.kinematics.solve_motion.solve_motion`),
and a multistart over random starts and assembly modes.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.analysis.transmission import transmission
from screwkit.kinematics.tracker.loop import forward
from screwkit.messages import shown, shown_range
from screwkit.synthesis.loop_route import LoopResidualModel, LoopSynthesisProblem
from screwkit.synthesis.residuals import Evaluation, NotAssembled
from screwkit.synthesis.solve import (
    RangeCheck,
    Status,
    SynthesisError,
    SynthesisResult,
    bound_notes,
    bounds_reached,
    fit_notes,
)

__all__ = ["loop_range_check", "synthesize_loop", "synthesize_loop_multistart"]

FloatArray = NDArray[np.float64]


class _TimeUp(Exception):
    pass


def _bounds(problem: LoopSynthesisProblem) -> tuple[FloatArray, FloatArray]:
    """Bounds of the unknowns: as given; link lengths named d1, d2, d3 (RSRC/RSSR/4R names) and
    a1, a2 of a CSSP are positive by default (the constructors refuse others)."""
    lo = np.full(len(problem.unknowns), -np.inf)
    hi = np.full(len(problem.unknowns), np.inf)
    for k, name in enumerate(problem.unknowns):
        if name in problem.bounds:
            lo[k], hi[k] = problem.bounds[name]
        elif name in ("d1", "d2", "d3", "a1", "a2") and problem.kinds.get(name) == "length":
            lo[k] = 0.0
    return lo, hi


def loop_range_check(model: LoopResidualModel, ev: Evaluation, step: float = math.radians(1.0)
                     ) -> tuple[RangeCheck, int]:
    """Does the synthesised loop run over the whole design range on the branch through its θ = 0
    configuration? Its motion over [min θ, max θ] (``step`` apart, plus the design points) is
    solved anew; the
    branch through the synthesised θ = 0 configuration must assemble everywhere, stay regular,
    and pass every synthesised design configuration. ``min_transmission`` is the smallest
    transmission index of the outputs over the range (1 ideal, 0 a dead centre). Returns the
    check and that branch's mode number in the new analysis (over the design range)."""
    from screwkit.kinematics.solve_motion import solve_motion

    pr = model.problem
    linkage = model.linkage
    lo, hi = float(ev.theta.min()), float(ev.theta.max())
    sweep = np.union1d(np.linspace(lo, hi, int(math.ceil((hi - lo) / step)) + 1), ev.theta)
    x = ev.params["theta01"] + pr.input_direction * sweep
    order = np.argsort(x)
    motion = solve_motion(linkage, x[order])
    L = linkage.length_scale
    mine = forward(linkage, model.conf, model.layout).centres  # (N_design, n, 3), ground frame
    base_R, base_p = linkage.base.real, linkage.base.translation
    mine = np.einsum("ij,dkj->dki", base_R, mine) + base_p
    at = {float(t): int(np.flatnonzero(sweep[order] == t)[0]) for t in ev.theta}
    k0 = at[0.0]
    best, branch = np.inf, 0
    for md in motion.modes:
        gap = np.max(np.abs(md.joint_centres[k0] - mine[0])) if md.assembles[k0] else np.inf
        if gap < best:
            best, branch = gap, md.index
    md = motion.modes[branch]
    ok_mask = (md.assembles & ~md.singular)[np.argsort(order)]
    gaps: list[tuple[float, float]] = []
    if (~ok_mask).any():
        idx = np.flatnonzero(~ok_mask)
        starts = idx[np.r_[True, np.diff(idx) > 1]]
        ends = idx[np.r_[np.diff(idx) > 1, True]]
        gaps = [(float(sweep[s]), float(sweep[e])) for s, e in zip(starts, ends, strict=True)]
    mismatch = [float(t) for i, t in enumerate(ev.theta)
                if not md.assembles[at[float(t)]]
                or np.max(np.abs(md.joint_centres[at[float(t)]] - mine[i])) > 1e-6 * L]
    try:
        tr = transmission(motion).modes[branch]
        values = [v[md.assembles] for v in tr.index.values()]
        trans = float(min(np.nanmin(v) for v in values)) if values else float("nan")
    except ValueError:
        trans = float("nan")
    parts = [f"does not assemble (or is singular) on its branch for theta in "
             f"{shown_range(a, b, 'angle', digits=5)}" for a, b in gaps]
    if mismatch:
        parts.append("design point(s) theta = " + ", ".join(shown(t, "angle", digits=5)
                                                            for t in mismatch)
                     + " lie on another branch (the mechanism would have to be reassembled)")
    if math.isfinite(trans) and trans <= 1e-6:
        parts.append("passes a dead centre of the output (transmission index 0)")
    ok = not parts
    msg = "; ".join(parts) if parts else (
        f"runs over the whole range on one branch; min transmission index = {trans:.3f}")
    return RangeCheck(ok, tuple(gaps), tuple(mismatch), trans, msg), branch


def _result(model: LoopResidualModel, ev: Evaluation, iterations: int, evaluations: int,
            elapsed: float, status: Status, message: str) -> SynthesisResult:
    pr = model.problem
    n_rot = model.rot_idx.size
    r = ev.residuals
    r_phi, r_s = r[:n_rot], r[n_rot:] * pr.length_scale
    e_phi, e_s, objective = float(np.sum(r_phi**2)), float(np.sum(r_s**2)), float(np.sum(r**2))
    unit = np.array([pr.scale(n) for n in pr.unknowns])
    grad = 2.0 * ev.jacobian.T @ r * unit if ev.jacobian is not None else np.zeros(0)
    lo, hi = _bounds(pr)
    free = np.array([not ((x - a <= 1e-9 * max(1.0, abs(x)) and g > 0)
                          or (b - x <= 1e-9 * max(1.0, abs(x)) and g < 0))
                     for x, a, b, g in zip(ev.x, lo, hi, grad, strict=True)], dtype=bool)
    jac_scaled = ev.jacobian * unit if ev.jacobian is not None else np.zeros((0, 0))
    dims = {k: float(ev.params[k]) for k in (*pr.kinds, "theta01")}
    for name, kind in pr.kinds.items():
        if kind == "angle":
            dims[name] = math.remainder(dims[name], 2 * math.pi)
    dims["theta01"] = dims["theta01"] % (2 * math.pi)
    psi_all = pr.target.desired_rotation(ev.theta)
    s_all = pr.target.desired_translation(ev.theta)
    has_s = pr.translation_output is not None
    rows = [{"theta": float(th), "theta0": float(ev.theta0[i]), "phi_g": math.remainder(float(ev.phi[i]), 2 * math.pi),
             "psi_g0": float(pr.output_direction * math.remainder(ev.phi[i] - ev.phi[0],
                                                                 2 * math.pi)),
             "psi_d0": float(psi_all[i]), "S": float(ev.S[i]) if has_s else None,
             "S_g": float(ev.S[i] - ev.S[0]) if has_s else None, "S_d": float(s_all[i])}
            for i, th in enumerate(ev.theta)]
    check, branch = loop_range_check(model, ev)
    on_bounds = bounds_reached(pr.unknowns, ev.x, lo, hi, unit)
    notes = (*fit_notes(pr, psi_all, s_all, r_phi, r_s, check, status),
             *bound_notes(on_bounds, pr.kinds))
    message = "; ".join(m for m in (message.rstrip("."), *notes) if m)
    n_points = int(np.unique(np.concatenate([pr.target.theta_rotation,
                                             pr.target.theta_translation])).size)
    g_free = float(np.linalg.norm(grad[free])) if grad.size else 0.0
    return SynthesisResult(
        dimensions=dims, inversion=branch, mode_sign=0.0, objective=objective,
        E_phi=e_phi, E_S=e_s, rmse=math.sqrt(objective / max(n_points, 1)),
        rmse_phi=math.sqrt(e_phi / n_rot) if n_rot else 0.0,
        rmse_S=math.sqrt(e_s / r_s.size) if r_s.size else 0.0,
        max_dev_phi=float(r_phi[np.argmax(np.abs(r_phi))]) if n_rot else 0.0,
        max_dev_S=float(r_s[np.argmax(np.abs(r_s))]) if r_s.size else 0.0,
        gradient_norm=g_free,
        relative_gradient=(g_free / max(2.0 * float(np.linalg.norm(jac_scaled[:, free]))
                                        * float(np.linalg.norm(r)), 1e-300) if grad.size else 0.0),
        iterations=iterations, evaluations=evaluations, time=elapsed, status=status,
        message=message, length_scale=pr.length_scale, rows=rows, range_check=check,
        evaluation=ev, at_bounds=on_bounds)


def synthesize_loop(problem: LoopSynthesisProblem, *, mode: int | None = None,
                    gtol: float = 1e-14, xtol: float = 1e-15) -> SynthesisResult:
    """Minimise E = E_φ + E_S/L² (Bagci 1969 eq. 5.4) over the unknowns from the problem's start
    on one assembly mode, with scipy's trust-region least squares and the exact Jacobian; stops
    at convergence, ``max_iterations`` residual evaluations or ``time_limit`` seconds."""
    try:
        model = LoopResidualModel(problem, mode)
    except NotAssembled as exc:
        raise SynthesisError(f"cannot start: {exc}") from None
    x0 = problem.start_vector()
    lo, hi = _bounds(problem)
    if np.any((x0 < lo) | (x0 > hi)):
        k = int(np.flatnonzero((x0 < lo) | (x0 > hi))[0])
        raise SynthesisError(f"start value of {problem.unknowns[k]} = {x0[k]:.6g} is outside its "
                             f"bounds [{lo[k]:.6g}, {hi[k]:.6g}]; move the start or the bounds")
    t0 = time.perf_counter()
    deadline = t0 + problem.time_limit
    try:
        first = model.evaluate(x0)
    except NotAssembled as exc:
        raise SynthesisError(f"cannot start: {exc}") from None
    best = {"ev": first}
    cache: dict[bytes, Evaluation] = {}
    counts = {"fun": 0, "jac": 0}
    big = 1e3 * (1.0 + float(np.max(np.abs(first.residuals))))

    def fun(x: FloatArray) -> FloatArray:
        if time.perf_counter() > deadline:
            raise _TimeUp
        counts["fun"] += 1
        try:
            ev = model.evaluate(x, remember=False)
        except NotAssembled:
            return np.full(model.n_residuals, big)
        cache.clear()
        cache[x.tobytes()] = ev
        if np.sum(ev.residuals**2) <= np.sum(best["ev"].residuals**2):
            best["ev"] = ev
        return ev.residuals

    def jac(x: FloatArray, *_: object) -> FloatArray:
        counts["jac"] += 1
        ev = cache.get(x.tobytes())
        if ev is None or not model.accept(x):  # accepted step: follow the branch from here
            ev = model.evaluate(x)
        assert ev.jacobian is not None
        return ev.jacobian

    from scipy.optimize import least_squares  # on first use: start-up stays light

    status: Status = "converged"
    message = ""
    try:
        sol = least_squares(fun, x0, jac=jac, bounds=(lo, hi), method="trf", x_scale="jac",
                            max_nfev=problem.max_iterations, gtol=gtol, xtol=xtol, ftol=1e-15)
        x_final, message = sol.x, str(sol.message)
        if sol.status == 0:
            status = "iteration limit"
    except _TimeUp:
        x_final, status = best["ev"].x, "time limit"
        message = f"stopped after the time limit of {problem.time_limit:g} s"
    elapsed = time.perf_counter() - t0
    try:
        final = model.evaluate(x_final)
    except NotAssembled:
        final = model.evaluate(best["ev"].x)
    return _result(model, final, counts["jac"], counts["fun"], elapsed, status, message)


def _modes(problem: LoopSynthesisProblem) -> list[int]:
    """The assembly modes of the start that assemble at every design point (or the one asked)."""
    if problem.mode is not None:
        return [problem.mode]
    from screwkit.kinematics.solve_motion import solve_motion

    dims = problem.dimensions(problem.start_vector())
    x = dims["theta01"] + problem.input_direction * problem.target.theta_all
    try:
        motion = solve_motion(problem.build(dims), np.sort(x))
    except ValueError:
        return []
    return [md.index for md in motion.modes if (md.assembles & ~md.singular).all()]


def synthesize_loop_multistart(problem: LoopSynthesisProblem, *, n_starts: int = 20,
                               seed: int = 0, keep: int = 3, spread: float = 0.5,
                               progress: Callable[[int, int], None] | None = None
                               ) -> list[SynthesisResult]:
    """Random starts (lengths × e^U(−spread, spread), angles + U(−spread, spread) rad) × every
    assembly mode that assembles at every design point; the best ``keep`` distinct results,
    those that run the whole range first. ``progress(done, n_starts)`` after each start."""
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    x0 = problem.start_vector()
    lo, hi = _bounds(problem)
    results: list[SynthesisResult] = []
    reasons: dict[str, int] = {}
    for k in range(n_starts):
        remaining = n_starts * problem.time_limit - (time.perf_counter() - t0)
        if remaining <= 0:
            break
        x = x0.copy()
        if k:
            for j, name in enumerate(problem.unknowns):
                u = rng.uniform(-spread, spread)
                x[j] = x0[j] * math.exp(u) if problem.kinds.get(name) == "length" else x0[j] + u
            x = np.clip(x, lo, hi)
        start = {**problem.start, **dict(zip(problem.unknowns, map(float, x), strict=True))}
        sub = replace(problem, start=start, time_limit=min(problem.time_limit, remaining))
        modes = _modes(sub)
        if not modes:
            reasons["the start does not assemble on any mode at every design point"] = \
                reasons.get("the start does not assemble on any mode at every design point", 0) + 1
        for m in modes:
            try:
                results.append(synthesize_loop(replace(sub, mode=m)))
            except (SynthesisError, ValueError) as exc:
                reasons[str(exc)] = reasons.get(str(exc), 0) + 1
        if progress is not None:
            progress(k + 1, n_starts)
    if not results:
        shown = "; ".join(f"{r} ({n}x)" if n > 1 else r for r, n in list(reasons.items())[:5])
        raise SynthesisError(f"no start gave a solution ({n_starts} start(s) tried): {shown}. "
                             "Change the start ([dimensions] or [synthesis.start]), the mode or "
                             "the spread")
    results.sort(key=lambda r: (not r.range_check.ok, r.objective))
    best: list[SynthesisResult] = []
    for r in results:
        if all(any(abs(r.dimensions[n] - b.dimensions[n]) > 1e-4 * problem.scale(n)
                   for n in problem.unknowns) for b in best):
            best.append(r)
        if len(best) == keep:
            break
    return best

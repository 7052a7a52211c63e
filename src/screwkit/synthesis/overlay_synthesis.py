"""The overlay technique as a synthesis route (Bagci 1969, §5.4, Examples 8 and 9).

`synthesize_overlay` runs the overlay fit (`overlay.fit_overlay_circles`) for each requested
output sense, turns every distinct overlay circle into an RSRC (delta0 = 0) and re-analyses it
with the closed form on one branch (`solve.evaluate_design`: the same errors, rows and
whole-range check as the least-squares route).  The overlay minimises the circle misses
|C_i - P_i| - d2, not E, so the reported E, RMSE and gradient are those of the analysed
mechanism: the honest measure of how well the overlay mechanism generates the target.

Results are ranked: mechanisms that run the whole range on one branch without a dead centre
first, then by E; mechanisms that do not reach every design point on one branch are dropped
(the reason is kept for the error message when none is left).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import wrap_angle
from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_positions
from screwkit.messages import given, shown
from screwkit.synthesis.overlay import (
    OverlayCircle,
    OverlayDwell,
    ellipse_curvature_radius,
    fit_overlay_circles,
    mechanism_from_circle,
)
from screwkit.synthesis.problem import RSRCSynthesisProblem
from screwkit.synthesis.solve import SynthesisError, SynthesisResult, evaluate_design
from screwkit.synthesis.targets import ScrewTarget

__all__ = ["OverlayOutcome", "OverlayProblem", "synthesize_overlay"]

FloatArray = NDArray[np.float64]
Status = Literal["converged", "iteration limit", "time limit"]


@dataclass(frozen=True)
class OverlayProblem:
    """Everything an overlay run needs (SI units, radians).

    target : the desired screw; its rotation is fitted at its design points, its translation
        (optional) is only evaluated (the overlay fits the rotation; d1, lambda0, theta01 are
        chosen for the translation beforehand, §5.4 step 1).
    d1, d2, lambda0, theta01, e : the chosen dimensions (d2 is the start when refine_d2).
    input_direction : +1 (theta0 = theta01 + theta) or -1.
    output_directions : the output senses to try, +1 counter-clockwise, -1 clockwise.
    dwells : at most two `OverlayDwell` (at rotation design points).
    refine_d2 : fit d2 too (Bagci chooses it by hand).
    keep : number of distinct mechanisms returned.  n_starts : grid starts refined per sense.
    d3_range : output-crank radii scanned for the starts (default 0.05 d1 .. 20 d1).
    length_scale : L of E = E_phi + E_S / L^2 (only matters with a translation target).
    max_iterations : residual evaluations per local circle fit; time_limit : seconds in all.
    """

    target: ScrewTarget
    d1: float
    d2: float
    lambda0: float
    theta01: float
    e: float = 0.0
    input_direction: int = 1
    output_directions: tuple[int, ...] = (1,)
    dwells: tuple[OverlayDwell, ...] = ()
    refine_d2: bool = False
    keep: int = 3
    n_starts: int = 12
    d3_range: tuple[float, float] | None = None
    length_scale: float = 0.0254
    max_iterations: int = 500
    time_limit: float = 10.0

    def __post_init__(self) -> None:
        if self.target.rotation is None:
            raise InputError("the overlay technique fits the output rotation: give a rotation "
                             "target (the translation is set by d1, lambda0, theta01 beforehand)")
        for name in ("d1", "d2"):
            value = getattr(self, name)
            if not (value > 0.0 and math.isfinite(value)):
                raise InputError(f"{name} must be a positive length, got {given(value)}")
        for name in ("lambda0", "theta01", "e"):
            if not math.isfinite(getattr(self, name)):
                raise InputError(f"{name} must be finite")
        if self.input_direction not in (1, -1):
            raise InputError("input_direction must be +1 or -1")
        if not self.output_directions or any(s not in (1, -1) for s in self.output_directions):
            raise InputError("output_directions must be a non-empty tuple of +1 / -1")
        if self.keep < 1 or self.n_starts < 1:
            raise InputError("keep and n_starts must be >= 1")
        if self.max_iterations < 1 or not self.time_limit > 0.0:
            raise InputError("max_iterations must be >= 1 and time_limit > 0")
        if not (self.length_scale > 0.0 and math.isfinite(self.length_scale)):
            raise InputError(f"length_scale must be a positive length, got {given(self.length_scale)}")


@dataclass(frozen=True)
class OverlayOutcome:
    """One overlay mechanism and its closed-form re-analysis.

    result : the `SynthesisResult` of the analysed mechanism (dimensions, E, RMSEs, rows,
        range_check) with the overlay fit's iterations, time and status.
    output_direction : the output sense of this mechanism (+1 ccw, -1 cw).
    circle : the overlay circle (centre = (a, b sin lambda0) before any plane re-reference,
        d3, phi01, d2, circle misses).
    d2_chosen : d2 as given (circle.d2 differs when it was refined).
    dwell_curvature_radii : radius of curvature of the input-crank ellipse at each dwell
        (Bagci's guide for d2 at a higher-order dwell).
    """

    result: SynthesisResult
    output_direction: int
    circle: OverlayCircle
    d2_chosen: float
    dwell_curvature_radii: tuple[float, ...] = field(default=())

    @property
    def max_circle_miss(self) -> float:
        return float(np.max(np.abs(self.circle.circle_residual)))


def _label_at_start(dims: RSRCDimensions, theta01: float, phi01: float) -> int | None:
    """Program label (1..4) of the root at theta = 0 nearest the overlay's output angle."""
    pos = rsrc_positions(dims, np.array([theta01]))
    gap = np.where(pos.assembles[0], np.abs(wrap_angle(pos.phi0[0] - phi01)), np.inf)
    return int(np.argmin(gap)) + 1 if np.isfinite(gap).any() else None


def _distinct(a: SynthesisResult, b: SynthesisResult, scale: float) -> bool:
    return any(abs(a.dimensions[n] - b.dimensions[n]) > 1e-6 * scale
               for n in ("d2", "d3", "a", "b")) or abs(
        math.remainder(a.dimensions["theta01"] - b.dimensions["theta01"], 2 * math.pi)) > 1e-6


def synthesize_overlay(problem: OverlayProblem) -> list[OverlayOutcome]:
    """The overlay technique (§5.4) for each output sense; the best ``keep`` distinct mechanisms.

    Raises
    ------
    SynthesisError
        When no overlay circle gives a mechanism that reaches every design point on one branch
        (a target this family cannot follow with the chosen d1, d2, lambda0, theta01), or the
        dwells contradict each other; the message says what to change.
    """
    pr = problem
    t_start = time.perf_counter()
    deadline = t_start + pr.time_limit
    tgt = pr.target
    theta = tgt.theta_rotation
    psi = tgt.desired_rotation(theta)
    evaluations = 0
    status: Status = "converged"
    outcomes: list[OverlayOutcome] = []
    failures: list[str] = []
    unknowns = ("d2", "d3", "a", "b") if pr.refine_d2 else ("d3", "a", "b")
    radii = tuple(float(ellipse_curvature_radius(
        pr.d1, pr.lambda0, pr.theta01 + pr.input_direction * dw.theta)) for dw in pr.dwells)
    for sense in pr.output_directions:
        try:
            circles = fit_overlay_circles(
                d1=pr.d1, d2=pr.d2, lambda0=pr.lambda0, theta01=pr.theta01, theta=theta, psi=psi,
                input_direction=pr.input_direction, output_direction=sense, dwells=pr.dwells,
                refine_d2=pr.refine_d2, d3_range=pr.d3_range, n_starts=pr.n_starts,
                max_evaluations=pr.max_iterations, deadline=deadline)
        except ValueError as exc:
            raise SynthesisError(f"overlay: {exc}") from None
        for circle in circles:
            evaluations += circle.evaluations
            if circle.status == "time limit":
                status = "time limit"
            elif circle.status == "iteration limit" and status == "converged":
                status = "iteration limit"
            dims, theta01, phi01 = mechanism_from_circle(circle, d1=pr.d1, lambda0=pr.lambda0,
                                                         theta01=pr.theta01, e=pr.e)
            label = _label_at_start(dims, theta01, phi01)
            sense_name = "ccw" if sense > 0 else "cw"
            if label is None:
                failures.append(f"{sense_name} circle d3 = {shown(circle.d3, 'length', digits=4)}: does not assemble "
                                "at theta = 0")
                continue
            start = {"e": dims.e, "d1": dims.d1, "d2": dims.d2, "d3": dims.d3, "a": dims.a,
                     "b": dims.b, "delta0": 0.0, "lambda0": dims.lambda0, "theta01": theta01}
            analysis = RSRCSynthesisProblem(
                tgt, start, unknowns, inversion=label, input_direction=pr.input_direction,
                output_direction=sense, length_scale=pr.length_scale)
            try:
                result = evaluate_design(analysis)
            except SynthesisError as exc:
                failures.append(f"{sense_name} circle d3 = {shown(circle.d3, 'length', digits=4)}: {exc}")
                continue
            outcomes.append(OverlayOutcome(result, sense, circle, pr.d2, radii))
    elapsed = time.perf_counter() - t_start
    if not outcomes:
        detail = "; ".join(failures[:4]) + (" ..." if len(failures) > 4 else "")
        raise SynthesisError(
            "overlay: no overlay circle gives a mechanism that reaches every design point on one "
            "branch, so no RSRC with these d1, d2, lambda0, theta01 follows the target (" + detail
            + "); change d2 or theta01, refine d2, or try the other output direction")
    outcomes.sort(key=lambda o: (not o.result.range_check.ok, o.result.objective))
    message = {
        "converged": "overlay circles fitted; errors are those of the analysed mechanism",
        "iteration limit": f"a circle fit stopped at max_iterations = {pr.max_iterations}",
        "time limit": f"stopped after the time limit of {pr.time_limit:g} s: the remaining "
                      "overlay starts were analysed unrefined",
    }[status]
    kept: list[OverlayOutcome] = []
    for o in outcomes:
        if all(_distinct(o.result, k.result, pr.d1) or o.output_direction != k.output_direction
               for k in kept):
            notes = f"{message}; {o.result.message}" if o.result.message else message
            res = dataclasses.replace(o.result, iterations=evaluations, evaluations=evaluations,
                                      time=elapsed, status=status, message=notes)
            kept.append(dataclasses.replace(o, result=res))
        if len(kept) == pr.keep:
            break
    return kept

"""The synthesised mechanism of a report: the loop built from the best result of the spec's
``[synthesis]`` (the ``screwkit synthesize`` document's ``dimensions``), its motion over the
design range θ01 + θ, and the assembly mode that generates the document's output.

The report animates this mechanism, not the spec's ``[dimensions]`` (which are only the
synthesis start). The mode is not taken on trust: it is the mode of the solved motion whose
output, measured from its value at θ01 (Bagci 1969 eq. 5.1), equals the document's generated
output ψ_g0 (and S_g) at every design point to round-off; when no mode does, there is no
synthesised motion to show and the report says why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import wrap_angle
from screwkit.errors import ScrewkitError
from screwkit.kinematics.motion import Motion
from screwkit.kinematics.registry import family
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.linkage import Linkage
from screwkit.synthesis.config import SynthesisConfig
from screwkit.synthesis.loop_route import LoopSynthesisProblem

Array = NDArray[np.float64]
#: the largest input step of the synthesised motion between design points (rad)
MAX_STEP = math.radians(1.0)
#: agreement asked of the solved output with the document's (rad, and m per metre of length scale)
TOLERANCE = 1e-6


@dataclass(frozen=True)
class SynthesisedMotion:
    """The synthesised loop, its motion over the design range, the matching mode.

    ``theta``: (N,) the design parameter θ of each sample (from θ01); ``inputs`` = θ01 +
    ``direction``·θ, sorted ascending (the motion's inputs); ``design``: index of each design
    point's sample; ``output`` (N,) the rotation output from θ01 (rad, sign ``output_sign``),
    ``translation`` (N,) the translation output from θ01 (m) or None; ``deviation`` the largest
    difference from the document's ψ_g0 / S_g at the design points (rad or m)."""

    linkage: Linkage
    motion: Motion
    mode: int
    theta: Array
    design: NDArray[np.int64]
    direction: int
    output: Array | None
    translation: Array | None
    deviation: float


def synthesised_linkage(config: SynthesisConfig, dimensions: dict[str, float],
                        spec_family: str) -> Linkage:
    """The loop of a synthesis result's ``dimensions`` (SI; ``theta01`` ignored): the generic
    route's ``problem.build`` (every dimension not solved for kept from its start), else the
    spec family's constructor (Bagci's closed route reports every dimension of the family)."""
    dims = {k: float(v) for k, v in dimensions.items() if k != "theta01"}
    problem = config.problem
    if isinstance(problem, LoopSynthesisProblem):
        start = {k: float(v) for k, v in problem.start.items() if k != "theta01"}
        return problem.build({**start, **dims})
    fam = family(spec_family)
    # the closed route also reports its parameters of constraint (q1, q2), which are no
    # dimensions of the loop
    return fam.linkage(**{k: v for k, v in dims.items() if k in fam.dimensions})


def _design_grid(theta_design: Array) -> tuple[Array, NDArray[np.int64]]:
    """θ from the first to the last design point in steps of at most ``MAX_STEP``, every design
    point a sample; and the index of each design point."""
    pts = np.unique(theta_design)
    grid = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        n = max(1, math.ceil((b - a) / MAX_STEP - 1e-9))
        grid.append(a + (b - a) * np.arange(1, n + 1) / n)
    theta = np.concatenate(grid)
    design = np.array([int(np.argmin(np.abs(theta - t))) for t in theta_design], dtype=np.int64)
    return theta, design


def _column(rows: list[dict[str, Any]], key: str) -> Array:
    return np.array([np.nan if r.get(key) is None else float(r[key]) for r in rows])


def _direction(rows: list[dict[str, Any]], theta01: float) -> int:
    """+1 when the document's inputs θ0 run as θ01 + θ, −1 as θ01 − θ."""
    th, x = _column(rows, "theta"), _column(rows, "theta0")
    ok = np.isfinite(x)
    miss = [float(np.nanmax(np.abs(wrap_angle(theta01 + d * th[ok] - x[ok])))) for d in (1, -1)]
    return 1 if miss[0] <= miss[1] else -1


def _relative(values: Array, ref: int, angle: bool) -> Array:
    d = values - values[ref]
    return np.asarray(wrap_angle(d) if angle else d, dtype=float)


def synthesised_motion(config: SynthesisConfig, doc: dict[str, Any],
                       spec_family: str) -> SynthesisedMotion:
    """The synthesised mechanism of a synthesis document and the mode generating its output
    (module docstring); raises :class:`ScrewkitError` when no mode of the solved motion does."""
    rows = sorted(doc["rows"], key=lambda r: r["theta"])
    theta01 = float(doc["dimensions"]["theta01"])
    linkage = synthesised_linkage(config, doc["dimensions"], spec_family)
    theta_design = _column(rows, "theta")
    theta, design = _design_grid(theta_design)
    direction = _direction(rows, theta01)
    order = np.argsort(direction * theta)  # ascending inputs
    theta, design = theta[order], np.argsort(order)[design]
    motion = solve_motion(linkage, theta01 + direction * theta)
    ref = int(np.argmin(np.abs(theta)))
    rot_name, tr_name = config.outputs
    want_rot, want_tr = _column(rows, "psi_g0"), _column(rows, "S_g")
    scale = max(float(getattr(config.problem, "length_scale", 1.0) or 1.0), 1e-12)
    best: tuple[float, int, Array | None, Array | None] | None = None
    for k, md in enumerate(motion.modes):
        if not np.asarray(md.assembles, dtype=bool)[design].all():
            continue
        rot = tr = None
        dev = 0.0
        if rot_name is not None and rot_name in md.variables:
            y = _relative(np.asarray(md.variables[rot_name], dtype=float), ref, True)
            ok = np.isfinite(want_rot)
            sign = 1.0 if np.nanmax(np.abs(wrap_angle(y[design][ok] - want_rot[ok]))) <= \
                np.nanmax(np.abs(wrap_angle(-y[design][ok] - want_rot[ok]))) else -1.0
            rot = sign * y
            if ok.any():
                dev = max(dev, float(np.max(np.abs(wrap_angle(rot[design][ok] - want_rot[ok])))))
        if tr_name is not None and tr_name in md.variables:
            tr = _relative(np.asarray(md.variables[tr_name], dtype=float), ref, False)
            ok = np.isfinite(want_tr)
            if ok.any():
                dev = max(dev, float(np.max(np.abs(tr[design][ok] - want_tr[ok]))) / scale)
        if best is None or dev < best[0]:
            best = (dev, k, rot, tr)
    if best is None or not best[0] <= TOLERANCE:
        found = "no mode assembles at every design point" if best is None else (
            f"the closest mode misses the synthesis's output by {best[0]:.3g}")
        raise ScrewkitError(f"the synthesised {linkage.name} could not be followed over the "
                            f"design range ({found})")
    dev, k, rot, tr = best
    return SynthesisedMotion(linkage, motion, k, theta, design, direction, rot, tr, dev)


def _target(fn: Any, theta: Array) -> Array | None:
    if fn is None:
        return None
    return np.asarray(fn(np.asarray(theta, dtype=float)), dtype=float)


def add_synthesised_plots(scene: dict[str, Any], shown: SynthesisedMotion,
                          config: SynthesisConfig) -> None:
    """Put first in the scene's synthesis group the linked plots of the animated synthesised
    mechanism: its output from θ01 (rotation, and translation when the target has one) frame by
    frame, with the target ψ_d(θ) (S_d(θ)) over the same design parameter θ."""
    from screwkit.io.results import jsonable
    from screwkit.report.scene_plots import DEG

    units = scene["display_units"]
    x_label = f"{scene['input']['name']} (deg)"
    target = config.problem.target
    plots = []
    for key, out, fn, unit, scale, name in (
            ("rot", shown.output, target.rotation, "deg", DEG, "ψ0"),
            ("tr", shown.translation, target.translation, units["length"], units["factor"], "S")):
        want = _target(fn, shown.theta)
        if out is None or want is None:
            continue
        series = [{"name": f"synthesised mechanism, mode {shown.mode}", "mode": shown.mode,
                   "style": "line", "y": out},
                  {"name": f"target {name}_d", "mode": None, "style": "line", "y": want}]
        plots.append({"id": f"syn-follow-{key}", "group": "synthesis",
                      "title": f"output {name} from θ01: synthesised mechanism vs target",
                      "kind": "line", "x_label": x_label, "y_label": f"{name} ({unit})",
                      "x_scale": DEG, "y_scale": scale, "linked": True, "series": series})
    first = next((i for i, p in enumerate(scene["plots"]) if p["group"] == "synthesis"),
                 len(scene["plots"]))
    scene["plots"][first:first] = jsonable(plots)


def start_ghost(linkage: Linkage, motion: Motion, preferred_mode: int, theta01: float
                ) -> dict[str, Any] | None:
    """The synthesis start (the spec's own loop and motion) as a still ghost for the 3-D view:
    every link's polyline (:func:`screwkit.report.scene.link_polylines`) at the sample whose
    input is nearest the synthesised θ01, in ``preferred_mode`` when it assembles there (else
    the first mode that does); None when no mode assembles."""
    from screwkit.report.scene import link_polylines

    x = np.asarray(motion.inputs, dtype=float).reshape(len(motion.modes[0].assembles), -1)[:, 0]
    gap = np.abs(wrap_angle(x - theta01))
    order = [preferred_mode] + [k for k in range(len(motion.modes)) if k != preferred_mode]
    for k in order:
        if not 0 <= k < len(motion.modes):
            continue
        ok = np.asarray(motion.modes[k].assembles, dtype=bool)
        if ok.any():
            i = int(np.argmin(np.where(ok, gap, np.inf)))
            return {"label": f"the synthesis start (the spec's [dimensions]), mode {k}, at "
                             f"input {math.degrees(float(x[i])):.4g}°",
                    "link_points": link_polylines(linkage, motion.modes[k])[i]}
    return None

"""JSON documents of every job's result (SI units; docs/cli.md): the analysis of a
:class:`~screwkit.kinematics.motion.Motion`, the dynamics of one mode, the synthesis results.
Built here, in the io layer, from typed results — the CLI and the reports only format them."""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.dynamics import Dynamics
from screwkit.kinematics.analysis.coupler_curves import CouplerPoint, coupler_point_path
from screwkit.kinematics.analysis.transmission import Transmission
from screwkit.kinematics.motion import Motion
from screwkit.synthesis.config import SynthesisRun

TRANSMISSION_DEFINITION = (
    "index: Sutherland-Roth transmission index of each output, |$T o $O| / max, 0 (dead "
    "centre) ... 1 (ideal); angle: planar transmission angle mu at the coupler-output joint, "
    "0 ... pi (worst: smallest min(mu, pi - mu)); cone_angle: angle of each ball joint's stem "
    "from its socket axis (the centre of the smallest cone holding every stem direction), whose "
    "maximum cone_limit a ball joint must allow (docs/kinematics.md)")

ANALYSIS_UNITS = {"length": "m", "angle": "rad", "time": "s",
                  "velocities": "d/dt of each variable (rad/s or m/s)",
                  "accelerations": "d2/dt2 of each variable (rad/s^2 or m/s^2)"}


def _constant_or_list(values: np.ndarray) -> float | list[float]:
    v = np.asarray(values, dtype=float)
    return float(v[0]) if np.all(v == v[0]) else v.tolist()


def _xyz(p: np.ndarray) -> dict[str, Any]:
    return {"x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}


def transmission_entries(tr: Transmission, x: np.ndarray) -> list[dict[str, Any]]:
    """Per mode, the ``transmission`` entry of the analysis document: the index of every
    output, the transmission angle (planar loops), every ball joint's cone angle, all over the
    sweep, and ``summary`` (minimum index and worst angle with the input where they occur, the
    cone limits with the socket axes)."""
    out = []
    for m, summary in zip(tr.modes, tr.summary(x), strict=True):
        entry: dict[str, Any] = {"index": m.index, "cone_angle": m.cone_angle,
                                 "summary": summary}
        if m.angle is not None:
            entry["angle"] = m.angle
        out.append(entry)
    return out


def analysis_document(motion: Motion, *, name: str | None = None,
                      coupler_point: tuple[float, float, float] | None = None,
                      coupler_link: int = 1,
                      coupler_points: list[CouplerPoint] | None = None,
                      transmission: Transmission | None = None,
                      transmission_note: str | None = None) -> dict[str, Any]:
    """The analysis document of ``screwkit analyze`` (docs/cli.md): every mode with every
    variable (joint freedoms and the seed's names), rates, accelerations, events, the closure
    residual, the path of every coupler point (``coupler_points``; a bare ``coupler_point`` on
    link ``coupler_link`` too) and the transmission quality (``transmission``)."""
    lk = motion.linkage
    points = list(coupler_points or [])
    x = motion.input_values
    trans = transmission_entries(transmission, x) if transmission is not None else None
    modes: list[dict[str, Any]] = []
    for k, md in enumerate(motion.modes):
        entry: dict[str, Any] = {
            "mode": md.index,
            "label": md.label,
            "assembles": md.assembles,
            "singular": md.singular,
            "events": list(md.events),
            "variables": md.variables,
            "velocities": md.velocities,
            "accelerations": md.accelerations,
            "closure_residual": md.closure_residual,
        }
        if points:
            entry["coupler_points"] = {
                cp.name: {"link": cp.link_name, **_xyz(coupler_point_path(md, cp.point, cp.link))}
                for cp in points}
            entry["coupler_point"] = dict(entry["coupler_points"][points[0].name])
            del entry["coupler_point"]["link"]
        elif coupler_point is not None:
            entry["coupler_point"] = _xyz(coupler_point_path(md, coupler_point, coupler_link))
        if trans is not None:
            entry["transmission"] = trans[k]
        modes.append(entry)
    doc: dict[str, Any] = {
        "method": motion.method,
        "solver": motion.solver,
        "mechanism": name or lk.name,
        "family": lk.family or "LOOP",
        "units": ANALYSIS_UNITS,
        "input_name": lk.inputs[0],
        "input": motion.inputs[:, 0] if motion.inputs.shape[1] == 1 else motion.inputs,
        "input_speed": _constant_or_list(motion.input_rates[:, 0]),
        "input_acceleration": _constant_or_list(motion.input_accelerations[:, 0]),
        "parameters": dict(lk.parameters),
        "modes": modes,
    }
    if points:
        doc["coupler_points"] = [{"name": cp.name, "link": cp.link_name, "point": list(cp.point)}
                                 for cp in points]
    if transmission is not None:
        doc["transmission"] = {"outputs": list(transmission.outputs),
                               "output_joint": transmission.output_joint,
                               "driving_joint": transmission.driving_joint,
                               "planar": transmission.planar,
                               "definition": TRANSMISSION_DEFINITION}
    elif transmission_note is not None:
        doc["transmission"] = {"note": transmission_note}
    if motion.notes:
        doc["method_note"] = "; ".join(motion.notes)
    return doc


def dynamics_document(dyn: Dynamics, *, mode: int, note: str | None = None) -> dict[str, Any]:
    """The document of ``screwkit dynamics``: the loads (:meth:`Dynamics.as_dict`), the mode,
    the RMS/peak summary, what is indeterminate, and a note on non-assembling samples. The
    per-sample loads stay arrays (``as_dict(arrays=True)``), written column by column by the
    JSON writer."""
    doc = dyn.as_dict(arrays=True)
    if note is not None:
        doc["note"] = note
    doc["mode"] = mode
    doc["gravity_on"] = bool(np.any(dyn.gravity != 0))
    doc["summary"] = dyn.summary()
    doc["indeterminacy"] = dyn.indeterminacy.describe()
    return doc


def result_document(result: Any) -> dict[str, Any]:
    """A `SynthesisResult` as a JSON-able dict (SI units, radians)."""
    rc = result.range_check
    return {
        "dimensions": dict(result.dimensions),
        "mode": result.inversion,
        "mode_sign": result.mode_sign,
        "objective": result.objective,
        "E_phi": result.E_phi,
        "E_S": result.E_S,
        "length_scale": result.length_scale,
        "rmse": result.rmse,
        "rmse_phi": result.rmse_phi,
        "rmse_S": result.rmse_S,
        "max_dev_phi": result.max_dev_phi,
        "max_dev_S": result.max_dev_S,
        "gradient_norm": result.gradient_norm,
        "relative_gradient": result.relative_gradient,
        "iterations": result.iterations,
        "evaluations": result.evaluations,
        "time": result.time,
        "status": result.status,
        "message": result.message,
        "at_bounds": {name: {"side": side, "bound": b}
                      for name, (side, b) in result.at_bounds.items()},
        "range_check": {"ok": rc.ok, "gaps": [list(g) for g in rc.gaps],
                        "branch_mismatch": list(rc.branch_mismatch),
                        "min_transmission": rc.min_transmission, "message": rc.message},
        "rows": result.rows,
    }


def overlay_document(outcome: Any) -> dict[str, Any]:
    """An `OverlayOutcome` as a JSON-able dict: the least-squares document shape (the analysed
    mechanism's errors and rows) plus ``method`` and the ``overlay`` keys."""
    doc = result_document(outcome.result)
    c = outcome.circle
    doc["method"] = "overlay"
    doc["overlay"] = {
        "output_direction": "ccw" if outcome.output_direction > 0 else "cw",
        "centre": list(c.centre),
        "d3": c.d3,
        "phi01": c.phi01,
        "d2_chosen": outcome.d2_chosen,
        "d2": c.d2,
        "d2_refined": c.d2 != outcome.d2_chosen,
        "circle_residual": [float(v) for v in c.circle_residual],
        "max_circle_miss": outcome.max_circle_miss,
        "fit_status": c.status,
        "dwell_curvature_radii": list(outcome.dwell_curvature_radii),
    }
    return doc


def synthesis_document(run: SynthesisRun, spec_path: Any) -> dict[str, Any]:
    """The document of ``screwkit synthesize``: the best result with the alternatives."""
    if run.overlay is not None:
        docs = [overlay_document(o) for o in run.overlay]
    else:
        docs = [result_document(r) for r in run.results]
        for d in docs:
            d["method"] = "least_squares"
    doc = dict(docs[0])
    doc["alternatives"] = docs[1:]
    doc["spec"] = str(spec_path)
    return doc


#: each balancing measure's physical RMS: (kind, scale of the measure as a power of F0, ℓ, b)
MEASURE_RMS = {"F": ("force", "F0"), "T": ("moment", "F0*l"), "R": ("force", "F0"),
               "M": ("moment", "F0*b"), "T0": ("moment", "F0*l")}


def measures_rms(result: Any) -> dict[str, Any]:
    """Each normalised mean-square measure of a :class:`BalanceResult` as the RMS load it
    stands for, in N or N·m (Rahman 1996 eqs. 4.1/4.2 undone: F = mean|F_sh|²/F0², so the RMS
    shaking force is F0·√F; T and T0 scale by F0·ℓ, M by F0·b; R is the RMS over the samples of
    the root-sum-square of the joint forces), before and after, with the change in percent.
    A driven slide's T0 is a force (F0 scale)."""
    norm = result.normalisation
    slide = result.dynamics_before.input_names[0].rsplit(".", 1)[-1] == "s"
    scale = {"F0": norm.force, "F0*l": norm.force * norm.length,
             "F0*b": norm.force * norm.bearing_length}
    out: dict[str, Any] = {"before": {}, "after": {}, "change_percent": {}, "kinds": {}}
    for key, (kind, s) in MEASURE_RMS.items():
        if key == "T0" and slide:
            kind, s = "force", "F0"
        b = scale[s] * float(np.sqrt(max(result.measures_before[key], 0.0)))
        a = scale[s] * float(np.sqrt(max(result.measures_after[key], 0.0)))
        out["before"][key], out["after"][key] = b, a
        out["change_percent"][key] = None if b == 0 else 100.0 * (a - b) / b
        out["kinds"][key] = kind
    out["units"] = {k: "N" if v == "force" else "N*m" for k, v in out["kinds"].items()}
    return out


def active_bounds(result: Any) -> list[dict[str, str]]:
    """The design variables at one of their bounds at the optimum (a point mass at its allowed
    decrease, a counterweight at its mass limit): variable, which bound, the constraint."""
    out = []
    for c in result.active_constraints:
        for name in result.names:
            for op, side in ((" >= ", "lower"), (" <= ", "upper")):
                if c.startswith(name + op):
                    out.append({"variable": name, "bound": side, "constraint": c})
    return out


def balance_document(result: Any) -> dict[str, Any]:
    """The document of ``screwkit balance``: :meth:`BalanceResult.as_dict` (docs/balancing.md)
    with ``measures_rms`` (:func:`measures_rms`, N and N·m) and ``active_bounds``
    (:func:`active_bounds`)."""
    doc: dict[str, Any] = result.as_dict()
    doc["measures_rms"] = measures_rms(result)
    doc["active_bounds"] = active_bounds(result)
    return doc

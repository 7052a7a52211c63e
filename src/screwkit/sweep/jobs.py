"""The jobs a sweep runs on each design, each through a :class:`~screwkit.pipeline.Pipeline`
(the same computation as the single-spec command) and summarised into scalar columns
(docs/sweeps.md, "Columns"; SI units, radians).

Every job's row starts with where the design assembles (:func:`assembly_columns`); then
``analyze``: the range of every output variable per mode, the transmission measure where the
kinematics gives one, and the number of limit positions; ``limits``: every limit position;
``mobility``: formula and Jacobian mobility; ``dynamics``: RMS and peak of the shaking force and
moment, every joint reaction and the input efforts; ``balance``: the measures (G …) before and
after and the link-mass change; ``synthesize``: the best result's errors (E, RMSE) and
dimensions.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.kinematics.motion import Motion
from screwkit.kinematics.registry import family_of
from screwkit.pipeline import Pipeline

Row = dict[str, Any]

JOBS = ("analyze", "limits", "mobility", "dynamics", "balance", "synthesize")


@dataclass(frozen=True)
class JobOptions:
    """Options of a sweep's job (as the single-spec commands take them): ``method`` of the
    kinematics, ``gravity`` for dynamics, ``dwell_tolerance`` for limits, ``starts`` for
    synthesis (``None``: the spec's ``[synthesis.multistart]``)."""

    method: str = "auto"
    gravity: bool = False
    dwell_tolerance: float = 1e-6
    starts: int | None = None

    def as_dict(self) -> dict[str, Any]:
        return {"method": self.method, "gravity": self.gravity,
                "dwell_tolerance": self.dwell_tolerance, "starts": self.starts}


def where_text(inputs: np.ndarray, ok: np.ndarray, angle: bool) -> str:
    """The input intervals where ``ok`` holds, in degrees (or metres): ``"0–120 deg,
    250–350 deg"``, ``"everywhere"`` or ``"nowhere"`` (ends are sample values)."""
    if ok.all():
        return "everywhere"
    if not ok.any():
        return "nowhere"
    x = np.degrees(inputs) if angle else inputs
    idx = np.flatnonzero(ok)
    starts = idx[np.r_[True, np.diff(idx) > 1]]
    ends = idx[np.r_[np.diff(idx) > 1, True]]
    unit = "deg" if angle else "m"
    return ", ".join(f"{x[s]:.6g}–{x[e]:.6g} {unit}" for s, e in zip(starts, ends, strict=True))


def assembly_columns(pipe: Pipeline) -> Row:
    """Whether and where the spec's ``[motion] mode`` assembles (and is not singular) over the
    input sweep, and how many assembly modes the design has."""
    s = pipe.spec
    motion = pipe.motion
    inputs = np.asarray(s.inputs, dtype=float).reshape(motion.samples, -1)[:, 0]
    row: Row = {"modes": len(motion.modes)}
    if s.mode >= len(motion.modes):
        return {**row, "assembles": False, "assembling_samples": 0,
                "where": f"no mode {s.mode} (the design has {len(motion.modes)})"}
    md = motion.modes[s.mode]
    ok = np.asarray(md.assembles) & ~np.asarray(md.singular)
    return {**row, "assembles": bool(ok.all()), "assembling_samples": int(ok.sum()),
            "where": where_text(inputs, ok, s.input_is_angle)}


def output_variables(motion: Motion) -> list[str]:
    """The output variables of a motion: the seed's names (θ0 … for a family that has them),
    else every scalar joint freedom; the inputs left out."""
    md = motion.modes[0]
    inputs = set(motion.linkage.inputs)
    x = motion.input_values
    seed = [n for n in md.variables if "." not in n]
    if seed:
        return [n for n in seed if not np.array_equal(md.variables[n], x, equal_nan=True)]
    spherical = {j.name for j in motion.linkage.joints if j.kind == "S"}
    return [n for n in md.variables if n not in inputs and n.split(".")[0] not in spherical]


def _range(values: np.ndarray) -> tuple[float, float]:
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    return (float(v.min()), float(v.max())) if v.size else (float("nan"), float("nan"))


def transmission_columns(motion: Motion) -> Row:
    """Transmission quality per mode. The hook for the kinematics' transmission measures: a
    mode that carries ``transmission_angle`` ((N,) rad) gives its minimum; otherwise, where the
    seed's coupler angle χ0 exists (RSRC, 4R: Bagci's transmission angle), min |sin χ0| over
    the assembling samples (1: coupler square to the output crank, 0: dead centre)."""
    row: Row = {}
    for md in motion.modes:
        angle = getattr(md, "transmission_angle", None)
        if angle is not None:
            row[f"mode{md.index}.transmission_angle.min"] = _range(np.asarray(angle))[0]
        elif "chi0" in md.variables:
            row[f"mode{md.index}.min_abs_sin_chi0"] = _range(
                np.abs(np.sin(np.asarray(md.variables["chi0"]))))[0]
    return row


def analyze_row(pipe: Pipeline, options: JobOptions) -> Row:
    """Output ranges per mode, transmission, limit-position counts (``analyze``)."""
    motion = pipe.motion
    row: Row = {}
    names = output_variables(motion)
    for md in motion.modes:
        k = md.index
        row[f"mode{k}.assembling_samples"] = int(np.sum(md.assembles))
        for name in names:
            lo, hi = _range(md.variables[name])
            row[f"mode{k}.{name}.min"] = lo
            row[f"mode{k}.{name}.max"] = hi
    row.update(transmission_columns(motion))
    if "limits" in family_of(pipe.spec.linkage).capabilities:
        lims = pipe.limits(options.dwell_tolerance).limits
        row["limits.rotation"] = sum(1 for x in lims if x.kind == "rotation")
        row["limits.translation"] = sum(1 for x in lims if x.kind == "translation")
    return row


def limits_row(pipe: Pipeline, options: JobOptions) -> Row:
    """Every limit position with its dwell order (``limits``, Bagci App. D)."""
    doc = pipe.limits(options.dwell_tolerance).as_dict()
    row: Row = {"limits": len(doc["limits"])}
    for k, lim in enumerate(doc["limits"]):
        for field in ("kind", "branch", "theta0", "phi0", "S", "second_derivative", "dwell_order"):
            value = lim.get(field)
            row[f"limit{k}.{field}"] = float("nan") if value is None and field == "S" else value
    return row


def mobility_row(pipe: Pipeline, options: JobOptions) -> Row:
    """Formula and Jacobian mobility (``mobility``, Bagci App. B)."""
    doc = pipe.mobility().as_dict()
    f, n = doc["formula"], doc["numeric"]
    return {"formula.mobility": f["mobility"], "formula.malytcheff": f["malytcheff"],
            "formula.kutzbach": f["kutzbach"], "numeric.mobility": n["mobility"],
            "numeric.rank": n["rank"], "numeric.redundant_constraints": n["redundant_constraints"],
            "numeric.undetermined_motions": n["undetermined_motions"],
            "agree": bool(doc["comparison"]["agree"])}


def dynamics_row(pipe: Pipeline, options: JobOptions) -> Row:
    """RMS and peak of every load over the cycle (``dynamics``): the summary of
    :meth:`~screwkit.dynamics.Dynamics.summary`; ``effort <input>`` becomes ``effort.<input>``."""
    summary = pipe.dynamics(options.gravity).summary()
    row: Row = {}
    for name, stats in summary.items():
        col = name.replace("effort ", "effort.")
        row[f"{col}.rms"] = stats["rms"]
        row[f"{col}.peak"] = stats["peak"]
    return row


def balance_row(pipe: Pipeline, options: JobOptions) -> Row:
    """The balancing measures before and after, their change, and the link masses
    (``balance``, docs/balancing.md)."""
    doc = pipe.balance().as_dict()
    m = doc["measures"]
    row: Row = {}
    for name in m["before"]:
        row[f"{name}.before"] = m["before"][name]
        row[f"{name}.after"] = m["after"][name]
        row[f"{name}.change_percent"] = m["change_percent"][name]
    mass = doc["link_mass"]
    before, after = sum(mass["before"].values()), sum(mass["after"].values())
    row["mass.before"] = before
    row["mass.after"] = after
    row["mass.change"] = after - before
    for link in mass["before"]:
        row[f"mass.{link}.before"] = mass["before"][link]
        row[f"mass.{link}.after"] = mass["after"][link]
    row["unique"] = bool(doc["unique"])
    return row


def synthesize_row(pipe: Pipeline, options: JobOptions) -> Row:
    """The best synthesis result (``synthesize``, Bagci ch. V): E, its parts, RMSE, the whole-
    range check and the optimised dimensions."""
    best = pipe.synthesize(options.starts).results[0]
    row: Row = {"E": best.objective, "E_phi": best.E_phi, "E_S": best.E_S, "rmse": best.rmse,
                "rmse_phi": best.rmse_phi, "rmse_S": best.rmse_S,
                "max_dev_phi": best.max_dev_phi, "max_dev_S": best.max_dev_S,
                "synthesis.mode": best.inversion, "synthesis.status": best.status,
                "range_ok": bool(best.range_check.ok),
                "min_transmission": best.range_check.min_transmission}
    for name, value in best.dimensions.items():
        row[f"result.{name}"] = value
    return row


JOB_ROWS: dict[str, Callable[[Pipeline, JobOptions], Row]] = {
    "analyze": analyze_row, "limits": limits_row, "mobility": mobility_row,
    "dynamics": dynamics_row, "balance": balance_row, "synthesize": synthesize_row,
}


def check_job(job: str) -> str:
    """``job`` if it is one of :data:`JOBS`; a ValueError naming them otherwise."""
    if job not in JOB_ROWS:
        raise InputError(f"--job {job!r}: choose one of {', '.join(JOBS)}")
    return job

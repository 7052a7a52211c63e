"""What the studio page draws for one design: the spec's :class:`~screwkit.pipeline.Pipeline`
(the closed form or the tracker, as ``screwkit analyze`` chooses) turned into curves in the
spec's display units — the output against the input in every mode, the coupler-point (or
joint-centre) paths, the transmission index and angle, the loads of ``[motion] mode`` when the
spec gives masses (input effort, shaking force and moment, the largest joint reaction), the
numbers the CLI prints (limit positions, minimum transmission, load peaks), where each mode
assembles, and the report's 3-D scene (:mod:`screwkit.report.scene`).

Every number comes from the same functions as the CLI's; nothing here recomputes kinematics.
"""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np

from screwkit.errors import ScrewkitError
from screwkit.io.spec import Spec
from screwkit.kinematics.registry import default_outputs
from screwkit.pipeline import Pipeline


def json_series(values: Any) -> list[float | None]:
    """An array as a JSON list, ``None`` where a value is missing (NaN or infinite)."""
    a = np.asarray(values, dtype=float).ravel()
    out = a.astype(object)  # one vectorised step, not a Python test per sample
    out[~np.isfinite(a)] = None
    return list(out.tolist())


def _floats(values: Any, width: int | None = None) -> np.ndarray:
    """A document's series (a list with ``None`` where a mode does not assemble, or an
    array) as floats, NaN for the ``None`` (rows of ``width`` NaN for a list of vectors)."""
    if isinstance(values, np.ndarray):
        return values.astype(float)
    gap = np.nan if width is None else [np.nan] * width
    return np.asarray([gap if v is None else v for v in values], dtype=float)


def _kind_of(name: str) -> str:
    """``"length"`` for a slide (``<joint>.s``, Rahman's ``s4``), else ``"angle"``."""
    from screwkit.kinematics.motion_table import variable_kind

    return variable_kind(name)


def assembly_runs(x_shown: np.ndarray, ok: np.ndarray, unit: str) -> str:
    """The input intervals where ``ok`` holds, in words: ``"0 … 120 deg, 250 … 360 deg"``."""
    runs, start = [], None
    for i, flag in enumerate(ok):
        if flag and start is None:
            start = i
        if start is not None and (not flag or i == len(ok) - 1):
            end = i if flag else i - 1
            runs.append(f"{x_shown[start]:.6g} … {x_shown[end]:.6g} {unit}")
            start = None
    return ", ".join(runs) if runs else "nowhere in the sweep"


def assembly_notes(pipe: Pipeline, x_shown: np.ndarray, unit: str) -> list[str]:
    """One sentence per mode that does not assemble over the whole sweep, naming the input
    ranges where it still does."""
    out = []
    for md in pipe.motion.modes:
        ok = np.asarray(md.assembles, dtype=bool) & ~np.asarray(md.singular, dtype=bool)
        if not ok.all():
            out.append(f"{md.label} assembles only at input {assembly_runs(x_shown, ok, unit)}")
    return out


def _paths(pipe: Pipeline, factor: float) -> dict[str, Any]:
    """Per mode, the path (N, 3) of each coupler point of the spec in display lengths; a spec
    without coupler points gets the paths of its moving joint centres."""
    if pipe.spec.coupler_points:
        curves = pipe.coupler_curves()
        return {"title": "coupler-point paths",
                "modes": [{name: [json_series(c[:, j] / factor) for j in range(3)]
                           for name, c in per.items()} for per in curves]}
    out = []
    names = [j.name for j in pipe.spec.linkage.joints]
    for md in pipe.motion.modes:
        c = np.asarray(md.joint_centres, dtype=float)
        moving = [k for k in range(c.shape[1])
                  if np.nanmax(np.nanstd(c[:, k, :], axis=0), initial=0.0) > 1e-12]
        out.append({names[k]: [json_series(c[:, k, j] / factor) for j in range(3)] for k in moving})
    return {"title": "joint-centre paths", "modes": out}


#: the transmission without cone angles of each pipeline still in use (the curves and the
#: numbers table share it)
_TRANSMISSION: weakref.WeakKeyDictionary[Pipeline, Any] = weakref.WeakKeyDictionary()


def shown_transmission(pipe: Pipeline) -> Any:
    """The pipeline's transmission index and angle (:func:`~screwkit.kinematics.analysis.
    transmission.transmission` with ``cones=False``: the same numbers as ``screwkit analyze``,
    without the ball joints' cone angles, which the page does not show), once per pipeline;
    a :class:`~screwkit.errors.ScrewkitError` says why a loop has none."""
    from screwkit.kinematics.analysis.transmission import transmission
    from screwkit.messages import message_units

    if pipe not in _TRANSMISSION:
        try:
            with message_units(pipe.units):
                _TRANSMISSION[pipe] = transmission(pipe.motion, cones=False)
        except ScrewkitError as exc:
            _TRANSMISSION[pipe] = exc
    tr = _TRANSMISSION[pipe]
    if isinstance(tr, ScrewkitError):
        raise tr
    return tr


def _transmission(pipe: Pipeline, units: Any) -> tuple[list[dict[str, Any]] | None, str | None]:
    try:
        tr = shown_transmission(pipe)
    except ScrewkitError as exc:
        return None, str(exc)
    out = []
    for m in tr.modes:
        entry: dict[str, Any] = {"index": {k: json_series(v) for k, v in m.index.items()}}
        if m.angle is not None:
            entry["angle"] = json_series(units.show("angle", np.asarray(m.angle, dtype=float)))
        out.append(entry)
    return out, None


#: the dynamics document of each pipeline still in use: the ``state`` answer and the ``scene``
#: after it both draw it, solved once
_DYNAMICS: weakref.WeakKeyDictionary[Pipeline, tuple[dict[str, Any] | None, str | None]] = \
    weakref.WeakKeyDictionary()


def dynamics_document(pipe: Pipeline) -> tuple[dict[str, Any] | None, str | None]:
    """The dynamics document of ``[motion] mode`` (no gravity, as ``screwkit dynamics``
    without ``--gravity``), or why there is none (once per pipeline)."""
    if pipe not in _DYNAMICS:
        _DYNAMICS[pipe] = _dynamics_document(pipe)
    return _DYNAMICS[pipe]


def _dynamics_document(pipe: Pipeline) -> tuple[dict[str, Any] | None, str | None]:
    if any(link.mass is None for link in pipe.spec.linkage.links):
        return None, "no loads: the spec gives no mass properties ([links.<name>] mass)"
    try:
        return pipe.dynamics().as_dict(arrays=True), None
    except ScrewkitError as exc:
        return None, str(exc)


def _loads(doc: dict[str, Any], mode: int, units: Any) -> dict[str, Any]:
    """The load curves and the peak and RMS of every load (``screwkit dynamics``'s table) in
    display units."""
    reactions = np.stack([np.linalg.norm(_floats(r["force"], 3), axis=1)
                          for r in doc["reactions"].values()])
    with np.errstate(invalid="ignore"):
        largest = np.where(np.isnan(reactions).all(axis=0), np.nan,
                           np.nanmax(np.where(np.isnan(reactions), -1.0, reactions), axis=0))
    name = next(iter(doc["efforts"]))
    effort_kind = "moment" if _kind_of(name) == "angle" else "force"
    f, m = units.label("force"), units.label("moment")
    curves = {
        f"input effort {name} [{units.label(effort_kind)}]":
            json_series(units.show(effort_kind, _floats(doc["efforts"][name]))),
        f"shaking force [{f}]": json_series(units.show(
            "force", np.linalg.norm(_floats(doc["shaking_force"], 3), axis=1))),
        f"shaking moment [{m}]": json_series(units.show(
            "moment", np.linalg.norm(_floats(doc["shaking_moment"], 3), axis=1))),
        f"largest joint reaction force [{f}]": json_series(units.show("force", largest)),
    }
    summary = []
    for key, stats in doc["summary"].items():
        if key == "relative_residual":
            continue
        kind = _summary_kind(key)
        summary.append([f"{key} [{units.label(kind)}]", units.show(kind, stats["peak"]),
                        units.show(kind, stats["rms"])])
    return {"mode": mode, "curves": curves, "summary": summary}


def _summary_kind(key: str) -> str:
    """The quantity kind of a dynamics summary entry (as ``screwkit dynamics`` shows it)."""
    if key.endswith("moment"):
        return "moment"
    if key.startswith("effort"):
        return "moment" if _kind_of(key.split()[-1]) == "angle" else "force"
    return "force"


def numbers_table(pipe: Pipeline) -> list[list[str]]:
    """The table of numbers ``screwkit limits`` and ``screwkit analyze`` print: every limit
    position of the outputs (input, value, dwell order) and each mode's minimum transmission
    index and worst transmission angle."""
    units = pipe.spec.display_units()
    x_kind = _kind_of(pipe.motion.input_names[0])
    rows: list[list[str]] = []
    xl = units.label(x_kind)
    try:
        lim = pipe.limits()
        for p in lim.limits:
            kind = "angle" if p.kind == "rotation" else "length"
            where = "" if p.mode is None else f", mode {p.mode}"
            rows.append([f"limit of {p.output}{where}",
                         f"{units.show(kind, p.value):.6g} {units.label(kind)} at input "
                         f"{units.show(x_kind, p.input):.6g} {xl} (dwell order {p.dwell_order})"])
        if not lim.limits:
            rows.append(["limit positions", "none: the outputs turn fully"])
    except ScrewkitError as exc:
        rows.append(["limit positions", str(exc)])
    x = np.asarray(pipe.spec.inputs, dtype=float).reshape(len(pipe.spec.inputs), -1)[:, 0]
    try:
        summary = shown_transmission(pipe).summary(x)
    except ScrewkitError:
        summary = []
    for entry in summary:
        for name, st in entry["index"].items():
            if st["value"] is not None:
                rows.append([f"min transmission index of {name}, mode {entry['mode']}",
                             f"{st['value']:.4f} at input "
                             f"{units.show(x_kind, st['at']):.6g} {xl}"])
        if "angle" in entry and entry["angle"]["value"] is not None:
            st = entry["angle"]
            rows.append([f"worst transmission angle, mode {entry['mode']}",
                         f"{units.show('angle', st['value']):.6g} {units.label('angle')} "
                         f"at input {units.show(x_kind, st['at']):.6g} {xl}"])
    return rows


def design_scene(pipe: Pipeline, dyn_doc: dict[str, Any] | None, *, packed: bool = False,
                 plots: bool = True) -> dict[str, Any]:
    """The report's scene (:func:`~screwkit.report.scene.scene_from_motion`) of the pipeline's
    motion with the spec's coupler points as traces (their 3-D paths) and the loads of
    ``[motion] mode`` (``dyn_doc``, from :func:`dynamics_document`; None: no loads), as
    :func:`~screwkit.report.spec_report.spec_scene` builds it. No balancing or synthesis: they
    are not redone on every change. ``packed``: as the page gets it (report/viewer.py)."""
    from screwkit.report.scene import scene_from_motion
    from screwkit.report.spec_report import seed_tables

    mot = pipe.motion
    return scene_from_motion(pipe.spec, mot, dynamics_doc=dyn_doc,
                             dynamics_mode=None if dyn_doc is None else int(pipe.spec.mode),
                             seed_variables=[seed_tables(md) for md in mot.modes],
                             coupler_points={p.name: (p.link, p.point)
                                             for p in pipe.spec.coupler_points}, packed=packed,
                             plots=plots)


def packed_scene(pipe: Pipeline) -> dict[str, Any]:
    """The scene of :func:`design_scene` packed for the page's 3-D view (the report's plots
    and text left out: the page draws its own)."""
    return design_scene(pipe, dynamics_document(pipe)[0], packed=True, plots=False)


def solve_spec(spec: Spec | Pipeline, *, numbers: bool = True,
               scene: bool = True) -> dict[str, Any]:
    """Everything the page draws for ``spec`` (module docstring) as a JSON-able dictionary
    (display units; the scene stays SI). ``numbers=False`` leaves out the table of
    :func:`numbers_table` (the limit positions are the slowest part) and ``scene=False`` the 3-D
    scene (:func:`packed_scene`): the server sends the scene right after the curves, and the
    page asks for the numbers once they are drawn."""
    pipe = spec if isinstance(spec, Pipeline) else Pipeline(spec)
    spec = pipe.spec
    units = spec.display_units()
    mot = pipe.motion
    input_name = mot.input_names[0]
    x_kind = _kind_of(input_name)
    x_si = np.asarray(spec.inputs, dtype=float).reshape(len(spec.inputs), -1)[:, 0]
    x_shown = units.show(x_kind, x_si)
    outputs = list(default_outputs(spec.linkage)) or [n for n in mot.modes[0].variables
                                                     if n != input_name][:1]
    modes = []
    for md in mot.modes:
        modes.append({
            "index": int(md.index), "label": str(md.label),
            "assembles": [bool(v) for v in np.asarray(md.assembles)],
            "outputs": {f"{n} [{units.label(_kind_of(n))}]": json_series(units.show(
                _kind_of(n), np.asarray(md.variables[n], dtype=float))) for n in outputs},
        })
    trans, trans_note = _transmission(pipe, units)
    dyn_doc, loads_note = dynamics_document(pipe)
    loads = None if dyn_doc is None else _loads(dyn_doc, int(spec.mode), units)
    return {
        "ok": True, "method": mot.method, "mode": int(spec.mode),
        "input": {"name": input_name, "unit": units.label(x_kind), "values": json_series(x_shown)},
        "modes": modes, "paths": _paths(pipe, units.unit_of("length")[1]),
        "length_unit": units.label("length"),
        "transmission": trans, "transmission_note": trans_note,
        "loads": loads, "loads_note": loads_note,
        "numbers": numbers_table(pipe) if numbers else None,
        "assembly": assembly_notes(pipe, np.asarray(x_shown), units.label(x_kind)),
        "scene": packed_scene(pipe) if scene else None,
    }


#: values of a dimension tried by :func:`assembling_values`, and input samples per try
SCAN_VALUES = 21
SCAN_INPUTS = 36


def scan_grid(dimension: Any) -> np.ndarray:
    """The values :func:`assembling_values` tries: its slider's default range, evenly."""
    return np.linspace(dimension.low, dimension.high, SCAN_VALUES)


def assembling_values(design: Any, values: dict[str, float], mode: int, name: str) -> str:
    """Where the dimension ``name`` lets the loop close, the other values held: a scan of
    :data:`SCAN_VALUES` values over its slider's default range, each solved at
    :data:`SCAN_INPUTS` inputs of the spec's sweep with the same solver as the page; a sentence
    naming the intervals (to the scan's step) where some mode assembles somewhere."""
    from screwkit.kinematics.solve_motion import solve_motion

    d = design.by_name[name]
    lo, hi = d.low, d.high
    grid = scan_grid(d)
    ok = np.zeros(SCAN_VALUES, dtype=bool)
    for k, v in enumerate(grid):
        try:
            spec = design.spec_with({**values, name: float(v)}, mode)
            every = max(1, len(spec.inputs) // SCAN_INPUTS)
            if design.graph:
                from screwkit.studio.graph import graph_closes

                ok[k] = graph_closes(spec, every)
                continue
            mot = solve_motion(spec.linkage, spec.inputs[::every], rates=spec.speed)
            ok[k] = any(np.asarray(md.assembles).any() for md in mot.modes)
        except (ScrewkitError, FloatingPointError, np.linalg.LinAlgError):
            ok[k] = False
    short = name.removeprefix("dimensions.")
    unit = d.key.unit or ""
    if not ok.any():
        return (f"no value of {short} from {lo:.6g} to {hi:.6g} {unit} closes the loop with "
                "the other values as they are; change another dimension")
    return (f"{short} closes the loop (somewhere over the input sweep) at "
            f"{assembly_runs(grid, ok, unit)} (a scan of {SCAN_VALUES} values from {lo:.6g} to "
            f"{hi:.6g} {unit}, the other values held)")

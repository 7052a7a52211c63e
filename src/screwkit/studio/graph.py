"""The studio on a graph spec (``[[bodies]]`` and ``[[joints]]`` with ``between``;
docs/mechanisms.md): its editable values and what the page draws for one design.

A graph spec's dimensions are its hardpoints — every coordinate of a joint's ``at`` and of a
point's ``at`` — and each body's ``mass`` where the spec gives one, named as a sweep names
them (:mod:`screwkit.sweep.graph_keys`: ``joints.LB.at[0]``, ``points.wheel_centre.at[2]``,
``bodies.upright.mass``). A design is *re-drawn*, as a sweep's design is: a moved hardpoint
moves the joint in both its bodies, so the drawing still closes.

The page's answer has the same fields as a single loop's (:func:`screwkit.studio.solve.
solve_spec`): every assembly mode (``solve_mechanism(..., every_mode=True)``, what ``screwkit
analyze`` prints on a graph), the named outputs (``[[outputs]]``: camber, toe …; without any,
the scalar joint freedoms) against the first input, the point paths, and with mass properties
on every body the loads of the picked mode (``graph_inverse_dynamics`` without gravity, as
``screwkit dynamics`` without ``--gravity``). Nothing here recomputes kinematics.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from screwkit.errors import ScrewkitError
from screwkit.studio.solve import json_series
from screwkit.sweep.keys import SpecKey, spec_key

#: a hardpoint slider spans ± this fraction of the diagonal of the hardpoints' bounding box
HARDPOINT_HALF_RANGE = 0.2


def graph_keys(data: dict[str, Any], spec: Any) -> list[SpecKey]:
    """Every joint and point coordinate the file gives, then every body's mass it gives."""
    keys: list[SpecKey] = []
    for table in ("joints", "points"):
        for item in data.get(table) or []:
            if isinstance(item.get("at"), list):
                keys += [spec_key(data, spec, f"{table}.{item['name']}.at[{k}]", None)
                         for k in range(len(item["at"]))]
    for body in data.get("bodies") or []:
        if "mass" in body:
            keys.append(spec_key(data, spec, f"bodies.{body['name']}.mass", None))
    return keys


def graph_ranges(spec: Any, keys: list[SpecKey], values: list[float]
                 ) -> list[tuple[float, float]]:
    """A hardpoint coordinate ± a fifth of the hardpoints' bounding-box diagonal; a mass from
    a tenth of its value to twice it."""
    from screwkit.io.units import to_si

    mech = spec.mechanism
    pts = np.array([j.at for j in mech.joints] + [p.at for p in mech.points], dtype=float)
    diagonal = float(np.linalg.norm(np.ptp(pts, axis=0))) or 1.0
    out = []
    for k, v in zip(keys, values, strict=True):
        if k.kind == "mass":
            out.append((0.1 * v, 2.0 * v))
        else:
            half = HARDPOINT_HALF_RANGE * diagonal / to_si(1.0, "length", k.unit)
            out.append((v - half, v + half))
    return out


def solve_graph_spec(spec: Any) -> Any:
    """Every assembly mode of the spec over its inputs (``screwkit analyze``'s solve)."""
    from screwkit.kinematics.graph import solve_mechanism

    return solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                           accelerations=spec.acceleration, every_mode=True)


@dataclass
class GraphRun:
    """A graph spec with the page's values and the assembly mode picked (mode 0 is the drawn
    mode), solved once (every mode) on first use."""

    spec: Any
    mode: int
    _motion: Any = field(default=None, repr=False)

    @property
    def motion(self) -> Any:
        if self._motion is None:
            self._motion = solve_graph_spec(self.spec)
        return self._motion

    @property
    def shown_mode(self) -> int:
        """The picked mode, or the last one where the mechanism has fewer modes."""
        return min(self.mode, len(self.motion.modes) - 1)

    def dynamics(self) -> tuple[Any, str | None]:
        """The loads of the shown mode without gravity, or why there are none."""
        from screwkit.dynamics.graph_inverse import graph_inverse_dynamics

        if any(b.mass is None for b in self.spec.mechanism.bodies):
            return None, "no loads: the spec gives no mass properties ([[bodies]] mass)"
        try:
            return graph_inverse_dynamics(self.motion, self.shown_mode, None), None
        except ScrewkitError as exc:
            return None, str(exc)


def _outputs(run: GraphRun) -> list[tuple[str, str]]:
    """(name, kind) of what the page plots against the input: the named outputs, else the
    scalar joint freedoms that are not inputs (at most six)."""
    mech = run.spec.mechanism
    if mech.outputs:
        return [(o.name, o.kind) for o in mech.outputs]
    from screwkit.kinematics.motion_table import variable_kind

    md = run.motion.modes[0]
    return [(n, variable_kind(n)) for n in md.variables if n not in mech.driven_names][:6]


def _values(md: Any, name: str) -> Any:
    return md.outputs[name] if name in md.outputs else md.variables[name]


def _paths(run: GraphRun, factor: float) -> dict[str, Any]:
    """Per mode, each point's path (N, 3) in display lengths; without points, the moving
    joint centres' paths."""
    out = []
    names = [j.name for j in run.spec.mechanism.joints]
    for md in run.motion.modes:
        if md.points:
            out.append({n: [json_series(np.asarray(p)[:, j] / factor) for j in range(3)]
                        for n, p in md.points.items()})
            continue
        c = np.asarray(md.joint_centres, dtype=float)
        moving = [k for k in range(c.shape[1])
                  if np.nanmax(np.nanstd(c[:, k, :], axis=0), initial=0.0) > 1e-12]
        out.append({names[k]: [json_series(c[:, k, j] / factor) for j in range(3)] for k in moving})
    return {"title": "point paths" if run.spec.mechanism.points else "joint-centre paths",
            "modes": out}


def _loads(dyn: Any, mode: int, units: Any) -> dict[str, Any]:
    """The load curves and the peak and RMS of each (``screwkit dynamics``'s summary) in
    display units."""
    f, m = units.label("force"), units.label("moment")
    name = dyn.input_names[0]
    kind = "force" if name.endswith(".s") else "moment"
    reactions = np.linalg.norm(dyn.reaction_force, axis=2)
    with np.errstate(invalid="ignore"):
        largest = np.where(np.isnan(reactions).all(axis=1), np.nan,
                           np.nanmax(np.where(np.isnan(reactions), -1.0, reactions), axis=1))
    raw = {f"input effort {name} [{units.label(kind)}]": (kind, dyn.efforts[:, 0]),
           f"shaking force [{f}]": ("force", np.linalg.norm(dyn.shaking_force, axis=1)),
           f"shaking moment [{m}]": ("moment", np.linalg.norm(dyn.shaking_moment, axis=1)),
           f"largest joint reaction force [{f}]": ("force", largest)}
    curves, summary = {}, []
    for label, (k, v) in raw.items():
        shown = np.asarray(units.show(k, np.asarray(v, dtype=float)), dtype=float)
        curves[label] = json_series(shown)
        a = np.abs(shown[np.isfinite(shown)])
        summary.append([label, float(a.max()) if a.size else None,
                        float(np.sqrt(np.mean(a ** 2))) if a.size else None])
    return {"mode": mode, "curves": curves, "summary": summary}


def solve_graph(run: GraphRun, *, numbers: bool = True, scene: bool = True) -> dict[str, Any]:
    """Everything the page draws for a graph design, as :func:`~screwkit.studio.solve.
    solve_spec` gives it for a single loop (module docstring)."""
    spec, motion = run.spec, run.motion
    units = spec.display_units()
    x_kind = "angle" if spec.input_is_angle else "length"
    x_shown = np.asarray(units.show(x_kind, np.asarray(spec.inputs, dtype=float)[:, 0]))
    outputs = _outputs(run)
    modes = [{"index": int(md.index), "label": _label(md),
              "assembles": [bool(v) for v in np.asarray(md.assembles)],
              "outputs": {f"{n} [{units.label(k)}]": json_series(units.show(
                  k, np.asarray(_values(md, n), dtype=float))) for n, k in outputs}}
             for md in motion.modes]
    dyn, loads_note = run.dynamics()
    mode = run.shown_mode
    return {
        "ok": True, "method": motion.method, "mode": mode,
        "input": {"name": motion.input_names[0], "unit": units.label(x_kind),
                  "values": json_series(x_shown)},
        "modes": modes, "paths": _paths(run, units.unit_of("length")[1]),
        "length_unit": units.label("length"),
        "transmission": None,
        "transmission_note": "transmission indices are computed for single loops",
        "loads": None if dyn is None else _loads(dyn, mode, units), "loads_note": loads_note,
        "numbers": graph_numbers(run) if numbers else None,
        "assembly": [*_assembly(motion, x_shown, units.label(x_kind)),
                     *(str(n) for n in motion.notes)],
        "scene": graph_scene(run, dyn) if scene else None,
    }


def _assembly(motion: Any, x_shown: np.ndarray, unit: str) -> list[str]:
    """One sentence per mode that does not assemble (regularly) over the whole sweep, naming
    the input ranges where it still does."""
    from screwkit.studio.solve import assembly_runs

    out = []
    for md in motion.modes:
        ok = np.asarray(md.assembles, dtype=bool) & ~np.asarray(md.singular, dtype=bool)
        if not ok.all():
            out.append(f"{_label(md)} assembles only at input {assembly_runs(x_shown, ok, unit)}")
    return out


def _label(md: Any) -> str:
    if md.index == 0:
        return "mode 0 (drawn)"
    return f"mode {md.index}" + (f" ({md.label})" if getattr(md, "label", "") else "")


def graph_numbers(run: GraphRun) -> list[list[str]]:
    """The numbers of the shown mode: each plotted output's smallest and largest value with
    the input where it occurs, and the limit positions of the joint freedoms (``screwkit
    limits``)."""
    from screwkit.kinematics.graph.limits import graph_limit_positions

    spec, units = run.spec, run.spec.display_units()
    md = run.motion.modes[run.shown_mode]
    x_kind = "angle" if spec.input_is_angle else "length"
    x = np.asarray(units.show(x_kind, np.asarray(spec.inputs, dtype=float)[:, 0]))
    xl = units.label(x_kind)
    rows: list[list[str]] = []
    for name, kind in _outputs(run):
        v = np.asarray(units.show(kind, np.asarray(_values(md, name), dtype=float)))
        if not np.isfinite(v).any():
            continue
        lo, hi = int(np.nanargmin(v)), int(np.nanargmax(v))
        rows.append([f"{name}, mode {md.index}",
                     f"{v[lo]:.6g} … {v[hi]:.6g} {units.label(kind)} (at input {x[lo]:.6g} "
                     f"and {x[hi]:.6g} {xl})"])
    try:
        lim = graph_limit_positions(run.motion, None, 1e-6, run.shown_mode)
        at_kind = lim.input_kind or x_kind  # a body-driven graph says what its input is
        for p in lim.limits:
            kind = "angle" if p.kind == "rotation" else "length"
            where = (f"row {p.input:.6g} of the input path" if at_kind == "ratio" else
                     f"input {units.show(at_kind, p.input):.6g} {units.label(at_kind)}")
            rows.append([f"limit of {p.output}, mode {md.index}",
                         f"{units.show(kind, p.value):.6g} {units.label(kind)} at {where} "
                         f"(dwell order {p.dwell_order})"])
        if not lim.limits:
            what = "outputs" if spec.mechanism.drives else "joint freedoms"
            rows.append(["limit positions", f"none of the {what} over the sweep"])
    except ScrewkitError as exc:
        rows.append(["limit positions", str(exc)])
    return rows


def _scene(run: GraphRun, dyn: Any, packed: bool) -> dict[str, Any]:
    """The graph report's scene (:mod:`screwkit.report.graph_scene`) of every mode, showing
    the picked one, with the load arrows of ``dyn`` (its loads; None: none)."""
    from screwkit.report.graph_scene import scene_from_mechanism

    loads = None
    if dyn is not None:
        from screwkit.report.graph_loads import graph_dynamics_document, graph_load_arrows

        doc = graph_dynamics_document(dyn)
        loads = (doc, graph_load_arrows(run.motion, run.shown_mode, doc))
    scene = scene_from_mechanism(run.spec, run.motion, loads=loads, packed=packed)
    scene["initial_mode"] = run.shown_mode
    return scene


def graph_scene(run: GraphRun, dyn: Any = None) -> dict[str, Any]:
    """The scene of the design packed for the page's 3-D view (its plots left out: the page
    draws its own)."""
    packed = _scene(run, dyn, True)
    packed["plots"], packed["plot_groups"] = [], []
    return packed


def graph_notebook(run: GraphRun) -> tuple[dict[str, Any], list[list[str]], list[str]]:
    """What the notebook controls show of a graph design: the graph report's scene (every
    mode, the loads of the shown mode), the numbers table and the assembly notes."""
    units = run.spec.display_units()
    kind = "angle" if run.spec.input_is_angle else "length"
    x = np.asarray(units.show(kind, np.asarray(run.spec.inputs, dtype=float)[:, 0]))
    return (_scene(run, run.dynamics()[0], False), graph_numbers(run),
            [*_assembly(run.motion, x, units.label(kind)), *(str(n) for n in run.motion.notes)])


def graph_closes(spec: Any, every: int) -> bool:
    """Whether some mode of the spec assembles at one of every ``every``-th input."""
    from screwkit.kinematics.graph import solve_mechanism

    mot = solve_mechanism(spec.mechanism, spec.inputs[::every], rates=spec.speed)
    return any(np.asarray(md.assembles).any() for md in mot.modes)


def graph_csv(run: GraphRun) -> str:
    """The per-sample CSV ``screwkit analyze --csv`` writes on a graph spec (every mode)."""
    from screwkit.io.mechanism_documents import mechanism_table

    return mechanism_table(run.motion).csv_text(run.spec.display_units())


def graph_report(spec: Any, spec_text: str) -> str:
    """The HTML report ``screwkit report`` writes on a graph spec, showing ``spec_text``."""
    from screwkit.report.graph_scene import graph_spec_scene
    from screwkit.report.viewer import render_report_html

    scene = graph_spec_scene(spec)
    scene["text"]["spec"] = spec_text
    return render_report_html(scene)

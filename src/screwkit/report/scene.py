"""The **scene**: everything the HTML report draws, as one JSON-able dictionary (SI units), and
:func:`scene_from_motion`, the adapter from a solved motion to a scene.

The report front end (:func:`screwkit.report.viewer.render_report_html`), the matplotlib
animation (:mod:`screwkit.report.animation`) and the notebook view read nothing else, so any
solver that can fill this dictionary gets the same report. The keys (docs/report.md has the
same table):

``format``
    ``"screwkit-scene/1"``.
``name``, ``family``, ``source``, ``description``
    Text about the mechanism (``family`` and ``source`` may be ``None``).
``display_units``
    ``{"length": "mm", "factor": 1000.0, "angle": "deg", "force": "N", "force_factor": 1.0}``:
    how lengths are shown (metres × ``factor``) and forces (newtons × ``force_factor``, the
    spec's ``[units] force``; absent for a bare linkage: N); angles are shown in degrees. Data
    stay SI.
``input``
    ``{"name", "kind": "angle" | "length", "values": [N], "periodic": bool}``, the driven
    freedom over the N frames (rad or m); ``periodic`` closes traces over a full turn.
``joints``
    ``[{"name", "kind" (R P C H U S), "pitch" (m/rad), "input": bool}]`` in loop order.
``links``
    ``[{"name", "joints": [i, j], "ground": bool}]``: moving link i joins joints i and i+1,
    the ground (last) joins the last joint and joint 0.
``fixed_frame``
    ``{"origin": [3], "rotation": [3][3]}``: the ground frame of the loop in the world.
``modes``
    One entry per assembly mode: ``index``, ``label``, ``assembles`` [N] and ``singular`` [N]
    (bool), ``events`` [str], ``joint_centres`` [N][n][3] (m; ``None`` where the mode does not
    assemble), ``joint_axes`` [N][n][3] (unit), ``second_axes`` [N][n][3] (the second axis of
    each U joint; the distal frame's y axis for every joint), ``link_points`` [N][n][3][3]
    (each link as a polyline: where it leaves its first joint, the foot of the common normal
    on the next joint's axis, the next joint's centre), ``traces`` {name: [N][3]} (points
    carried by links, e.g. a coupler point), ``arrows`` {name: {"kind": "force" | "moment",
    "unit", "vectors": [N][3], "points": [N][3]}}, ``closure_residual`` [N] or ``None``.
``initial_mode``
    The mode shown first (the one with dynamics, if any).
``plots``
    ``[{"id", "group", "title", "kind": "line" | "xy", "x_label", "y_label", "x_scale",
    "y_scale", "linked", "series": [{"name", "mode", "style", "x", "y"}]}]``. Values are SI;
    the viewer multiplies by ``x_scale``/``y_scale`` for display. A ``linked`` plot has one
    value per frame (``x`` omitted means the input values) and follows the animation.
``plot_groups``
    ``[{"id", "title", "note"}]`` in the order the report shows them.
``text``
    ``{"spec": str | None, "units": [str], "solver": [str], "validation": [str]}``.
``ghost`` (optional)
    ``{"label", "link_points": [n][3][3]}``: another loop drawn still, as thin grey lines (the
    synthesis start behind a synthesised mechanism; :mod:`screwkit.report.spec_report`).

``None`` stands wherever a value does not exist (a mode that does not assemble, a singular
velocity). The adapter reads only these attributes of a motion: ``inputs`` and ``modes``, and of
each mode ``assembles``, ``singular``, ``joint_centres``, ``joint_axes``, ``link_rotation``,
``link_origin``, ``variables``, ``velocities``, ``accelerations``, ``events`` (and
``closure_residual`` when present).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.io.results import jsonable
from screwkit.report.scene_plots import (
    balancing_plots,
    dynamics_arrows,
    dynamics_plots,
    kinematic_plots,
    synthesis_plots,
)
from screwkit.report.scene_text import text_sections
from screwkit.report.viewer import pack_scene

Array = NDArray[np.float64]
SCENE_FORMAT = "screwkit-scene/1"
#: display units of length the report understands (name → metres per unit)
LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "um": 1e-6, "in": 0.0254, "ft": 0.3048}


def display_length(spec_unit: str | None, extent: float) -> dict[str, Any]:
    """The length unit of the report: the spec's ``[units] length`` when it is one of
    ``LENGTH_UNITS`` (pint spellings such as ``inch`` and ``millimeter`` too), else mm for a
    mechanism under a metre and m above."""
    aliases = {"inch": "in", "millimeter": "mm", "centimeter": "cm", "meter": "m", "foot": "ft",
               "feet": "ft", "micrometer": "um", "µm": "um", "metre": "m", "millimetre": "mm"}
    unit = aliases.get(spec_unit or "", spec_unit or "")
    if unit not in LENGTH_UNITS:
        unit = "mm" if extent < 1.0 else "m"
    return {"length": unit, "factor": 1.0 / LENGTH_UNITS[unit], "angle": "deg"}


def _display_units(spec: Any, extent: float) -> tuple[dict[str, Any], Any]:
    """The scene's ``display_units`` (:func:`display_length`, and the spec's force unit) and
    the spec's :class:`~screwkit.io.display_units.DisplayUnits` for forces and moments (the
    tables' units), None for a bare linkage (SI)."""
    units = display_length(getattr(spec, "units", {}).get("length") if spec else None, extent)
    du = spec.display_units() if spec is not None and hasattr(spec, "display_units") else None
    if du is not None:
        units["force"] = du.pretty("force")
        units["force_factor"] = 1.0 / du.unit_of("force")[1]
    return units, du


def _input_values(motion: Any, n: int) -> Array:
    x = np.asarray(motion.inputs, dtype=float).reshape(n, -1)
    return np.asarray(x[:, 0])


def _ground_frame(linkage: Any) -> tuple[Array, Array]:
    """Rotation and origin (world) of the frame after the last joint: the inverse of the last
    link transform, placed by the base (the loop closes: J_1 L_1 ··· J_n L_n = I)."""
    L = linkage.link_transforms[-1]
    RL = np.asarray(L.real, dtype=float)
    pL = np.asarray(L.translation, dtype=float)
    BR = np.asarray(linkage.base.real, dtype=float)
    Bp = np.asarray(linkage.base.translation, dtype=float)
    return BR @ RL.T, BR @ (-RL.T @ pL) + Bp


def link_polylines(linkage: Any, mode: Any) -> Array:
    """(N, n, 3, 3): for link k (moving links, then the ground) the point where it leaves joint
    k (the joint frame's origin after the joint motion), the foot of its common normal on the
    next joint's axis (the link transform's translation, Hartenberg–Denavit a_k along x) and
    the next joint's centre."""
    centres = np.asarray(mode.joint_centres, dtype=float)
    N, n, _ = centres.shape
    R = np.asarray(mode.link_rotation, dtype=float)  # (N, n-1, 3, 3)
    o = np.asarray(mode.link_origin, dtype=float)
    Rg, og = _ground_frame(linkage)
    R_all = np.concatenate([R, np.broadcast_to(Rg, (N, 1, 3, 3))], axis=1)
    o_all = np.concatenate([o, np.broadcast_to(og, (N, 1, 3))], axis=1)
    t = np.stack([np.asarray(L.translation, dtype=float) for L in linkage.link_transforms])
    elbow = o_all + np.einsum("nkij,kj->nki", R_all, t)
    end = np.roll(centres, -1, axis=1)
    pts = np.stack([o_all, elbow, end], axis=2)
    pts[~np.asarray(mode.assembles, dtype=bool)] = np.nan
    return pts


def second_axes(linkage: Any, mode: Any) -> Array:
    """(N, n, 3): the y axis of each joint's distal frame, which is a U joint's second axis
    (Rz(θ1)·Ry(θ2) leaves y where Rz(θ1) put it)."""
    R = np.asarray(mode.link_rotation, dtype=float)
    N = R.shape[0]
    Rg, _ = _ground_frame(linkage)
    R_all = np.concatenate([R, np.broadcast_to(Rg, (N, 1, 3, 3))], axis=1)
    out = np.array(R_all[..., :, 1])
    out[~np.asarray(mode.assembles, dtype=bool)] = np.nan
    return out


def point_trace(mode: Any, link: int, local: Array) -> Array:
    """World path (N, 3) of a point fixed in moving link ``link`` (link frame coordinates,
    Bagci App. C: P = O + f·e1 + g·e2 + h·e3)."""
    R = np.asarray(mode.link_rotation, dtype=float)[:, link]
    return np.asarray(mode.link_origin, dtype=float)[:, link] + np.einsum("nij,j->ni", R, local)


def is_full_turn(x: Array, kind: str) -> bool:
    """Whether angle samples ``x`` (evenly stepped) cover one full turn, so that traces close."""
    if kind != "angle" or len(x) < 3:
        return False
    step = x[1] - x[0]
    return bool(abs(x[-1] - x[0] + step - 2 * np.pi) < 1e-9)


def _mode_entry(linkage: Any, k: int, md: Any, traces: dict[str, Array]) -> dict[str, Any]:
    ok = np.asarray(md.assembles, dtype=bool)
    singular = np.asarray(md.singular, dtype=bool)
    label = f"mode {k}"
    if not ok.all():
        label += f" (assembles at {int(ok.sum())} of {ok.size})"
    residual = getattr(md, "closure_residual", None)
    return {
        "index": k,
        "label": label,
        "assembles": ok.tolist(),
        "singular": singular.tolist(),
        "events": [str(e) for e in md.events],
        "joint_centres": np.asarray(md.joint_centres, dtype=float),
        "joint_axes": np.asarray(md.joint_axes, dtype=float),
        "second_axes": second_axes(linkage, md),
        "link_points": link_polylines(linkage, md),
        "traces": traces,
        "arrows": {},
        "closure_residual": None if residual is None else np.asarray(residual, dtype=float),
    }


def scene_from_motion(
    spec_or_linkage: Any,
    motion: Any,
    *,
    dynamics_doc: dict[str, Any] | None = None,
    dynamics_mode: int | None = None,
    balance_doc: dict[str, Any] | None = None,
    synthesis_doc: dict[str, Any] | None = None,
    spec_text: str | None = None,
    coupler_points: dict[str, tuple[int, Any]] | None = None,
    seed_variables: list[tuple[dict[str, Array], dict[str, Array], dict[str, Array]]] | None = None,
    solver: list[str] | None = None,
    notes: list[str] | None = None,
    linkage: Any = None,
    initial_mode: int | None = None,
    packed: bool = False,
    plots: bool = True,
) -> dict[str, Any]:
    """Build the scene (module docstring) of a solved motion.

    ``spec_or_linkage``: a loaded spec (``screwkit.io.spec.load_spec``; gives the name, source
    and units) or a bare linkage. ``dynamics_doc``: ``Dynamics.as_dict()`` of the
    mode with index ``dynamics_mode`` in ``motion.modes`` (default: its ``"mode"`` key, else 0);
    ``balance_doc``: ``BalanceResult.as_dict()``; ``synthesis_doc``: the ``screwkit
    synthesize`` document. ``coupler_points``: extra traces {name: (moving link index, point
    in that link's frame, m)}. ``seed_variables``: per mode the (variables, velocities,
    accelerations) under the seed's names, plotted instead of the joint variables.
    ``linkage``: the loop the motion is of, when it is not the spec's (the synthesised one);
    ``initial_mode``: the mode shown first (default: the mode with dynamics, else 0).
    ``packed``: the scene as the page gets it (:func:`~screwkit.report.viewer.pack_scene`: the
    large arrays as base64 floats), packed from the arrays without the lists between.
    ``plots=False``: no plots and no text (empty, None), for a page drawing its own (studio).
    """
    spec_linkage = getattr(spec_or_linkage, "linkage", spec_or_linkage)
    spec = spec_or_linkage if spec_or_linkage is not spec_linkage else None
    linkage = spec_linkage if linkage is None else linkage
    modes = list(motion.modes)
    if not modes:
        raise InputError(f"{linkage.name}: the motion has no assembly mode to show")
    n_frames = int(np.asarray(modes[0].assembles).shape[0])
    x = _input_values(motion, n_frames)
    input_name = str(linkage.inputs[0])
    kind = "length" if input_name.endswith(".s") else "angle"
    all_c = np.concatenate([np.asarray(m.joint_centres, dtype=float).reshape(-1, 3) for m in modes])
    extent = float(np.nanmax(np.abs(all_c))) if np.isfinite(all_c).any() else 1.0
    units, du = _display_units(spec, extent)
    points = dict(coupler_points or {})
    mode_entries = []
    for k, md in enumerate(modes):
        traces = {name: point_trace(md, link, np.asarray(local, dtype=float))
                  for name, (link, local) in points.items()}
        mode_entries.append(_mode_entry(linkage, k, md, traces))
    charts, groups = kinematic_plots(modes, x, input_name, kind, units, linkage.inputs,
                                     seed_variables) if plots else ([], [])
    dyn_mode = None
    if dynamics_doc is not None:
        dyn_mode = dynamics_mode if dynamics_mode is not None else int(dynamics_doc.get("mode", 0))
        if not 0 <= dyn_mode < len(modes):
            raise InputError(f"dynamics of mode {dyn_mode} given, but the motion has "
                             f"{len(modes)} mode(s)")
        centres = np.asarray(modes[dyn_mode].joint_centres, dtype=float)
        mode_entries[dyn_mode]["arrows"] = dynamics_arrows(dynamics_doc, centres, linkage)
    for p, g in [] if not plots else [
            dynamics_plots(dynamics_doc, dyn_mode or 0, x, input_name, kind, du)
            if dynamics_doc is not None else ([], []),
            balancing_plots(balance_doc, dyn_mode, x, input_name, kind, du)
            if balance_doc is not None else ([], []),
            synthesis_plots(synthesis_doc, units, synthesised=linkage is not spec_linkage)
            if synthesis_doc is not None else ([], [])]:
        charts, groups = charts + p, groups + g
    base_R = np.asarray(linkage.base.real, dtype=float)
    scene = {
        "format": SCENE_FORMAT,
        "name": str(getattr(spec, "name", None) or linkage.name),
        "family": getattr(spec, "family", None) or linkage.family,
        "source": getattr(spec, "source", None),
        "description": spec.describe() if spec is not None else str(linkage.name),
        "display_units": units,
        "input": {"name": input_name, "kind": kind, "values": x,
                  "periodic": is_full_turn(x, kind)},
        "joints": [{"name": j.name, "kind": j.kind, "pitch": float(j.pitch),
                    "input": any(i.split(".")[0] == j.name for i in linkage.inputs)}
                   for j in linkage.joints],
        "links": [{"name": lk.name, "joints": [i, i + 1], "ground": False}
                  for i, lk in enumerate(linkage.links)]
                 + [{"name": "ground", "joints": [len(linkage.joints) - 1, 0], "ground": True}],
        "fixed_frame": {"origin": np.asarray(linkage.base.translation, dtype=float),
                        "rotation": base_R},
        "modes": mode_entries,
        "initial_mode": initial_mode if initial_mode is not None else dyn_mode or 0,
        "plots": charts,
        "plot_groups": groups,
        "text": text_sections(linkage, mode_entries, units, kind, spec_text=spec_text,
                              solver=solver, notes=notes, dynamics_doc=dynamics_doc,
                              dynamics_mode=dyn_mode, balance_doc=balance_doc,
                              synthesis_doc=synthesis_doc) if plots else None,
    }
    out: dict[str, Any] = jsonable(pack_scene(scene) if packed else scene)
    return out

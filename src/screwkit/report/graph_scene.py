"""The report scene (:mod:`screwkit.report.scene`) of any mechanism, a graph of bodies and joints
(issue 26, docs/mechanisms.md): :func:`scene_from_mechanism` and :func:`graph_spec_scene`.

The keys are those of a loop's scene, read for a graph:

``joints``
    every joint of ``mechanism.joints`` (name, kind, pitch, input), in that order; each mode's
    ``joint_centres`` and ``joint_axes`` are the motion's (the joint's point and axis carried by
    its first body), ``second_axes`` a U joint's second axis (carried by its second body) and
    ``rail_ends`` (N, J, 3) the joint's point carried by its second body: where a P, C or H
    joint's travel ends (for R, U and S the same point as the centre).
``links``
    one per body, the moving bodies in ``mechanism.bodies`` order and then the ground:
    ``{"name", "joints": [indices of its joints], "points": [names of its points], "ground"}``.
    ``link_points`` (N, B + 1, P, 3) draws each body as a polyline through its joints and
    points, each carried by the body's pose: two vertices as a bar, three or more round the
    polygon they span (ordered by angle in their plane; along the line when they are
    collinear), padded to the common length P by repeating the last vertex.
``loops``
    ``[{"name": "loop k", "joints": [joint indices], "joint_names", "links": [indices of the
    bodies the loop's joints join]}]``, the independent loops of ``mechanism.topology``; the
    viewer's loop selector draws every other joint and body faint.
``traces``
    every ``[[points]]`` path (``mode.points``).

The plots are every joint variable, rate and acceleration against the first input (a spherical
joint's rotation vector excepted, as for a loop); the text adds ``topology`` (the topology
summary). The validation lines are checks made here, from the body poses alone: every drawn
body keeps its shape, and the two bodies of every joint carry the joint's point to the same
place (off the joint's travel for P, C and H).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.io.results import jsonable
from screwkit.model.mechanism import GROUND, Mechanism
from screwkit.report.mode_marks import mode_chart, mode_marks
from screwkit.report.scene import SCENE_FORMAT, display_length, is_full_turn
from screwkit.report.scene_plots import kinematic_plots
from screwkit.report.scene_text import link_span_variation
from screwkit.report.viewer import pack_scene

Array = NDArray[np.float64]

#: vertices this close to a line (second singular value over the first) are drawn along it
COLLINEAR = 1e-9


def _poses(mech: Mechanism, mode: Any) -> tuple[Array, Array]:
    """Rotations (N, B + 1, 3, 3) and origins (N, B + 1, 3) of every body, the ground last
    (the identity: the drawing is the world); NaN where the mode does not assemble."""
    R = np.asarray(mode.link_rotation, dtype=float)
    p = np.asarray(mode.link_origin, dtype=float)
    N = R.shape[0]
    R_all = np.concatenate([R, np.broadcast_to(np.eye(3), (N, 1, 3, 3))], axis=1)
    p_all = np.concatenate([p, np.zeros((N, 1, 3))], axis=1)
    bad = ~np.asarray(mode.assembles, dtype=bool)
    R_all[bad], p_all[bad] = np.nan, np.nan
    return R_all, p_all


def _body_index(mech: Mechanism) -> dict[str, int]:
    out = {b.name: k for k, b in enumerate(mech.bodies)}
    out[GROUND] = len(mech.bodies)
    return out


def body_vertices(mech: Mechanism) -> list[tuple[list[int], list[str], Array]]:
    """Per body (moving bodies, then the ground): its joints, its points and the drawn
    positions of the polyline that pictures it (module docstring), in world = body frame."""
    out = []
    for name in [*mech.body_names, GROUND]:
        joints = [i for i, j in enumerate(mech.joints) if name in j.bodies]
        points = [pt.name for pt in mech.points if pt.body == name]
        drawn = [mech.joints[i].at for i in joints]
        drawn += [pt.at for pt in mech.points if pt.body == name]
        out.append((joints, points, _polyline(np.array(drawn, dtype=float).reshape(-1, 3))))
    return out


def _polyline(v: Array) -> Array:
    """The vertices ordered for drawing: as given up to two; round the polygon when they span
    a plane (by angle about their centroid); along their line when they are collinear."""
    if v.shape[0] <= 2:
        return v
    c = v.mean(axis=0)
    _, s, vt = np.linalg.svd(v - c)
    if s[1] <= COLLINEAR * max(s[0], 1e-300):
        return np.asarray(v[np.argsort((v - c) @ vt[0], kind="stable")])
    ang = np.arctan2((v - c) @ vt[1], (v - c) @ vt[0])
    ring = v[np.argsort(ang, kind="stable")]
    return np.vstack([ring, ring[:1]])


def body_polylines(mech: Mechanism, mode: Any) -> Array:
    """(N, B + 1, P, 3): every body's polyline carried by its pose at every sample."""
    R, p = _poses(mech, mode)
    shapes = [v for _, _, v in body_vertices(mech)]
    P = max(2, *(v.shape[0] for v in shapes))
    out = np.empty((R.shape[0], len(shapes), P, 3))
    for b, v in enumerate(shapes):
        padded = np.vstack([v, np.repeat(v[-1:], P - v.shape[0], axis=0)])
        out[:, b] = np.einsum("nij,qj->nqi", R[:, b], padded) + p[:, b, None, :]
    return out


def joint_ends(mech: Mechanism, mode: Any) -> tuple[Array, Array]:
    """Each joint's point (N, J, 3) and second axis (N, J, 3; a U joint's ``axis2``, else the
    y axis) carried by its second body."""
    R, p = _poses(mech, mode)
    index = _body_index(mech)
    N, J = R.shape[0], len(mech.joints)
    ends, second = np.empty((N, J, 3)), np.empty((N, J, 3))
    for i, j in enumerate(mech.joints):
        b = index[j.bodies[1]]
        ends[:, i] = R[:, b] @ j.at + p[:, b]
        second[:, i] = R[:, b] @ (j.axis2 if j.axis2 is not None else np.array([0.0, 1.0, 0.0]))
    return ends, second


def joint_gap(mech: Mechanism, mode: Any) -> float:
    """Largest distance (m), over the assembling samples, between the two bodies' copies of a
    joint's point, measured off the joint's axis for P, C and H (their travel): 0 when every
    joint holds. NaN when no sample assembles."""
    ok = np.asarray(mode.assembles, dtype=bool)
    if not ok.any():
        return float("nan")
    ends, _ = joint_ends(mech, mode)
    d = (ends - np.asarray(mode.joint_centres, dtype=float))[ok]
    u = np.asarray(mode.joint_axes, dtype=float)[ok]
    slides = np.array([j.kind in "PCH" for j in mech.joints])
    d[:, slides] -= np.einsum("nj,nji->nji", np.einsum("nji,nji->nj", d, u), u)[:, slides]
    return float(np.max(np.linalg.norm(d, axis=-1)))


def _mode_entry(mech: Mechanism, md: Any) -> dict[str, Any]:
    ok = np.asarray(md.assembles, dtype=bool)
    label = f"mode {md.index} (the drawn mode)" if md.index == 0 else f"mode {md.index}"
    if md.index != 0 and getattr(md, "label", ""):  # a closed-form mode: its branches
        label += f" ({md.label})"
    if not ok.all():
        label += f" (assembles at {int(ok.sum())} of {ok.size})"
    ends, second = joint_ends(mech, md)
    residual = getattr(md, "closure_residual", None)
    return {
        "index": int(md.index),
        "label": label,
        "assembles": ok.tolist(),
        "singular": np.asarray(md.singular, dtype=bool).tolist(),
        "events": [str(e) for e in md.events],
        "marks": mode_marks(ok, getattr(md, "singular_class", None)),
        "joint_centres": np.asarray(md.joint_centres, dtype=float),
        "joint_axes": np.asarray(md.joint_axes, dtype=float),
        "second_axes": second,
        "rail_ends": ends,
        "link_points": body_polylines(mech, md),
        "traces": {name: np.asarray(path, dtype=float) for name, path in md.points.items()},
        "arrows": {},
        "closure_residual": None if residual is None else np.asarray(residual, dtype=float),
    }


def loop_entries(mech: Mechanism) -> list[dict[str, Any]]:
    """The ``loops`` key: each independent loop's joints and the bodies they join."""
    index = _body_index(mech)
    out = []
    for k, loop in enumerate(mech.topology.loops):
        joints = [int(i) for i, _ in loop]
        links = sorted({index[b] for i in joints for b in mech.joints[i].bodies})
        out.append({"name": f"loop {k + 1}", "joints": joints,
                    "joint_names": [mech.joints[i].name for i in joints], "links": links})
    return out


def _text(mech: Mechanism, motion: Any, modes: list[dict[str, Any]], units: dict[str, Any],
          kind: str, spec_text: str | None, topology: list[str]) -> dict[str, Any]:
    lu = units["length"]
    unit_lines = [
        f"Lengths are shown in {lu}, angles in degrees; rates per second ({lu}/s, deg/s) and "
        f"accelerations per second squared ({lu}/s², deg/s²).",
        "The numbers inside this page are SI (m, rad, s); the first input is "
        + ("an angle." if kind == "angle" else "a translation.")
        + " Inputs are measured from the drawing (the drawn configuration is 0).",
    ]
    joints = ", ".join(f"{j.name} ({j.kind}: {j.bodies[0]}–{j.bodies[1]})" for j in mech.joints)
    solver = [f"{motion.solver} ({motion.method}; screwkit.kinematics.graph).",
              f"Joints: {joints}; inputs {', '.join(mech.driven_names)}."]
    validation = []
    for m, md in zip(modes, motion.modes, strict=True):
        ok = np.asarray(m["assembles"], dtype=bool)
        line = f"{m['label']}: assembles at {int(ok.sum())} of {ok.size} samples"
        res = m.get("closure_residual")
        if res is not None and ok.any():
            line += f"; largest scaled loop-closure residual {float(np.nanmax(res[ok])):.3g}"
        line += (f"; bodies rigid to {link_span_variation(m['link_points'], ok):.3g} m (largest "
                 "change of a distance between two drawn points of a body)")
        line += (f"; joints hold to {joint_gap(mech, md):.3g} m (largest gap between the two "
                 "bodies' copies of a joint's point, off a slide's travel)")
        sing = int(np.sum(m["singular"]))
        if sing:
            line += f"; singular at {sing} sample(s) (rates undefined there)"
        validation.append(line + ".")
        validation += [f"{m['label']}: {e}" for e in m["events"]]
    validation += [str(n) for n in getattr(motion, "notes", ())]
    validation.append("How screwkit is checked (seed tables, physical laws, second methods): "
                      "docs/validation.md.")
    return {"spec": spec_text, "units": unit_lines, "solver": solver, "topology": topology,
            "validation": validation}


def scene_from_mechanism(spec_or_mechanism: Any, motion: Any, *, spec_text: str | None = None,
                         topology: list[str] | None = None,
                         loads: tuple[dict[str, Any], dict[str, Any]] | None = None,
                         balance_doc: dict[str, Any] | None = None, packed: bool = False
                         ) -> dict[str, Any]:
    """The scene of a solved mechanism (``solve_mechanism``): ``spec_or_mechanism`` is a graph
    spec (``load_spec``; gives the name, source, units and topology) or a bare
    :class:`~screwkit.model.mechanism.Mechanism`. ``topology``: the summary lines (default:
    the spec's, else ``mechanism_topology`` at the drawing). ``loads``: the drawn mode's
    dynamics document and load arrows (report/graph_loads.py); ``balance_doc``: a balancing
    result's document (before/after plots)."""
    mech = getattr(spec_or_mechanism, "mechanism", spec_or_mechanism)
    spec = spec_or_mechanism if spec_or_mechanism is not mech else None
    if not isinstance(mech, Mechanism):
        raise InputError(f"scene_from_mechanism needs a Mechanism or a graph spec; got "
                         f"{type(mech).__name__}")
    modes = list(motion.modes)
    if not modes:
        raise InputError(f"{mech.name}: the motion has no assembly mode to show")
    x = np.asarray(motion.inputs, dtype=float)[:, 0]
    input_name = mech.driven_names[0]
    kind = "length" if mech.driven_is_translation()[0] else "angle"
    entries = [_mode_entry(mech, md) for md in modes]
    every = np.concatenate([e["link_points"].reshape(-1, 3) for e in entries])
    extent = float(np.nanmax(np.abs(every))) if np.isfinite(every).any() else 1.0
    units = display_length((getattr(spec, "units", None) or {}).get("length"), extent)
    plots, groups = kinematic_plots(modes, x, input_name, kind, units, (input_name,))
    if len(mech.driven_names) > 1:
        groups[0]["note"] += (f" Every variable is plotted against the first input, "
                              f"{input_name}; the other inputs are plotted too.")
    if len(modes) > 1 or any(e["marks"] for e in entries):  # births, deaths, crossings
        chart, group = mode_chart(entries, plots[0]["x_label"] if plots else input_name,
                                  plots[0]["x_scale"] if plots else 1.0)
        plots.insert(0, chart)
        groups.insert(0, group)
    if loads is not None or balance_doc is not None:
        _add_load_plots(spec, entries, plots, groups, (x, input_name, kind), loads, balance_doc)
    if getattr(spec, "synthesis", None) is not None:
        from screwkit.report.graph_synthesis_plots import graph_synthesis_plots

        p, g = graph_synthesis_plots(spec, units)
        plots += p
        groups += g
    if topology is None:
        if spec is not None and getattr(spec, "topology", None) is not None:
            topology = list(spec.topology.summary())
        else:
            from screwkit.kinematics.graph.topology import mechanism_topology

            topology = mechanism_topology(mech).summary()
    index = {name: k for k, name in enumerate([*mech.body_names, GROUND])}
    links = [{"name": name, "joints": joints, "points": points, "ground": name == GROUND}
             for name, (joints, points, _) in zip(index, body_vertices(mech), strict=True)]
    scene = {
        "format": SCENE_FORMAT,
        "name": str(getattr(spec, "name", None) or mech.name),
        "family": "graph",
        "source": getattr(spec, "source", None),
        "description": spec.describe() if spec is not None else
        f"{mech.name}: {len(mech.bodies)} moving bodies, {len(mech.joints)} joints",
        "display_units": units,
        "input": {"name": input_name, "kind": kind, "values": x,
                  "periodic": is_full_turn(x, kind)},
        "joints": [{"name": j.name, "kind": j.kind, "pitch": float(j.pitch),
                    "input": any(i.split(".")[0] == j.name
                                 for i in (*mech.inputs, *mech.actuated))}
                   for j in mech.joints],
        "links": links,
        "loops": loop_entries(mech),
        "fixed_frame": {"origin": np.zeros(3), "rotation": np.eye(3)},
        "modes": entries,
        "initial_mode": 0,
        "plots": plots,
        "plot_groups": groups,
        "text": _text(mech, motion, entries, units, kind, spec_text, topology),
    }
    out: dict[str, Any] = jsonable(pack_scene(scene) if packed else scene)
    return out


def _add_load_plots(spec: Any, entries: list[dict[str, Any]], plots: list[dict[str, Any]],
                    groups: list[dict[str, Any]], axis: tuple[Any, str, str],
                    loads: tuple[dict[str, Any], dict[str, Any]] | None,
                    balance_doc: dict[str, Any] | None) -> None:
    """The drawn mode's load arrows, the dynamics plots (every input's effort among them) and
    the balancing plots, in the spec's display units."""
    from screwkit.report.scene_plots import balancing_plots, dynamics_plots

    x, input_name, kind = axis
    du = spec.display_units() if spec is not None else None
    if loads is not None:
        doc, arrows = loads
        entries[0]["arrows"] = arrows
        p, g = dynamics_plots(doc, 0, x, input_name, kind, du)
        g[0]["note"] = g[0]["note"].replace(
            "A reaction is the force on the distal link by the proximal link; the shaking "
            "force is what the moving links exert on the ground.",
            "A reaction is the force by the joint's first body on its second (between = "
            "[first, second]); the shaking force is what the moving bodies exert on the ground, "
            "its moment about the world origin; a body's inertia force (with its weight when "
            "gravity is on) is drawn at its centre of mass.")
        plots += p
        groups += g
    if balance_doc is not None:
        p, g = balancing_plots(balance_doc, 0, x, input_name, kind, du)
        plots += p
        groups += g


def graph_spec_scene(spec: Any, motion: Any = None, *, gravity: bool = False) -> dict[str, Any]:
    """The scene of a graph spec (``load_spec`` of a ``[[joints]]`` spec): its drawn mode over
    its inputs (solved here unless ``motion`` is given) and the text of the spec file; with
    mass properties on every body, the loads of the drawn mode (gravity along the spec's
    direction if ``gravity``), and the spec's ``[balancing]`` run when it has one."""
    if motion is None:
        from screwkit.kinematics.graph import solve_mechanism

        motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                                 accelerations=spec.acceleration)
    text = Path(spec.path).read_text(encoding="utf-8") if Path(spec.path).is_file() else None
    loads = balance_doc = None
    if all(b.mass is not None for b in spec.mechanism.bodies):
        from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
        from screwkit.report.graph_loads import graph_dynamics_document, graph_load_arrows

        dyn = graph_inverse_dynamics(motion, 0, spec.gravity_vector if gravity else None)
        doc = graph_dynamics_document(dyn)
        loads = (doc, graph_load_arrows(motion, 0, doc))
    if getattr(spec, "balancing", None) is not None:
        from screwkit.balancing.graph import balance_mechanism

        balance_doc = balance_mechanism(motion, 0, spec.balancing, speed=float(spec.speed[0]),
                                        gravity=spec.gravity_vector).as_dict()
    return scene_from_mechanism(spec, motion, spec_text=text, loads=loads,
                                balance_doc=balance_doc)

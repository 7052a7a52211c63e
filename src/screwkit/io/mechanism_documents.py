"""Documents and tables of a mechanism graph's motion (``screwkit analyze`` on a graph spec):
the JSON document (SI) with every mode's variables, rates, accelerations, events, closure
residual, body poses and the paths of the ``[[points]]`` under ``coupler_points.<name>``, and
the per-sample column table (CSV, Parquet, NPZ) in the same shape as a single loop's."""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.kinematics.graph.motion import MechanismMotion
from screwkit.kinematics.graph.topology import MechanismTopology
from screwkit.kinematics.motion_table import mode_columns
from screwkit.tables import Column, ResultTable, stack_tables


def _xyz(p: np.ndarray) -> dict[str, Any]:
    return {"x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}


def mechanism_document(motion: MechanismMotion, topology: MechanismTopology | None = None
                       ) -> dict[str, Any]:
    """The analysis document of a graph spec (docs/mechanisms.md)."""
    mech = motion.mechanism
    modes = []
    for md in motion.modes:
        modes.append({
            "mode": md.index,
            "label": md.label or "drawn",
            "assembles": md.assembles,
            "singular": md.singular,
            "singular_class": [str(c) for c in md.singular_class],
            "jacobian_condition": dict(md.jacobian_condition),
            "events": list(md.events),
            "variables": md.variables,
            "velocities": md.velocities,
            "accelerations": md.accelerations,
            "closure_residual": md.closure_residual,
            "coupler_points": {name: {"body": _body_of(motion, name), **_xyz(p)}
                               for name, p in md.points.items()},
            "outputs": {o.name: {"kind": o.kind, "value": md.outputs[o.name],
                                 "rate": md.output_rates[o.name],
                                 "acceleration": md.output_accelerations[o.name]}
                        for o in mech.outputs},
            "bodies": {b.name: {"origin": md.link_origin[:, k],
                                "rotation": md.link_rotation[:, k]}
                       for k, b in enumerate(mech.bodies)},
        })
    doc: dict[str, Any] = {
        "method": motion.method,
        "solver": motion.solver,
        "notes": list(motion.notes),
        "mechanism": mech.name,
        "family": "graph",
        "units": {"length": "m", "angle": "rad", "time": "s"},
        "input_names": list(motion.input_names),
        "input_name": motion.input_names[0],
        "input": motion.inputs[:, 0] if motion.inputs.shape[1] == 1 else motion.inputs,
        "input_speed": motion.input_rates[0].tolist(),
        "input_acceleration": motion.input_accelerations[0].tolist(),
        "bodies": ["ground", *mech.body_names],
        "joints": [{"name": j.name, "kind": j.kind, "between": list(j.bodies)}
                   for j in mech.joints],
        "loops": mech.loop_joint_names(),
        "modes": modes,
    }
    if mech.drives:
        doc["drives"] = [{"name": d.name, "body": d.body, "freedom": d.freedom,
                          "at": d.at.tolist()} for d in mech.drives]
        doc["actuated"] = list(mech.actuated)
    if topology is not None:
        doc["topology"] = topology.as_dict()
    return doc


def _body_of(motion: MechanismMotion, point: str) -> str:
    return next(p.body for p in motion.mechanism.points if p.name == point)


def mechanism_table(motion: MechanismMotion) -> ResultTable:
    """One row per sample and mode: the inputs, every freedom with its rates, every driven body
    freedom (``<body>.<freedom>``) with its rates, the closure residual and every point's path
    (``<point>_x|y|z``)."""
    mech = motion.mechanism
    tables = []
    for md in motion.modes:
        kinds = ["length" if t else "angle" for t in mech.driven_is_translation()]
        cols = mode_columns(md, motion.inputs[:, 0], kinds[0])
        for k in range(1, len(kinds)):
            cols.insert(2 + k - 1, Column(f"input_{k + 1}", kinds[k], motion.inputs[:, k]))
        for k, d in enumerate(mech.drives, start=len(mech.inputs)):
            # a driven body freedom by its name, with its (given) rate and acceleration
            rate = "angular_velocity" if d.kind == "angle" else "velocity"
            acc = "angular_acceleration" if d.kind == "angle" else "acceleration"
            bad = ~np.asarray(md.assembles)
            cols += [Column(d.name, d.kind, np.where(bad, np.nan, motion.inputs[:, k])),
                     Column(f"{d.name}_dot", rate, np.where(bad, np.nan,
                                                           motion.input_rates[:, k])),
                     Column(f"{d.name}_ddot", acc, np.where(bad, np.nan,
                                                           motion.input_accelerations[:, k]))]
        for o in mech.outputs:
            rate = "angular_velocity" if o.kind == "angle" else "velocity"
            acc = "angular_acceleration" if o.kind == "angle" else "acceleration"
            cols += [Column(o.name, o.kind, md.outputs[o.name]),
                     Column(f"{o.name}_dot", rate, md.output_rates[o.name]),
                     Column(f"{o.name}_ddot", acc, md.output_accelerations[o.name])]
        for name, p in md.points.items():
            cols += [Column(f"{name}_{a}", "length", p[:, j]) for j, a in enumerate("xyz")]
        tables.append(ResultTable(tuple(cols)))
    return stack_tables(tables, f"{mech.name}: graph analysis, one row per input and mode")

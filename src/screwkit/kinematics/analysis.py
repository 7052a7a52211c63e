"""One call from a spec to an analysis document: every mode, every variable (general and under
the seed's names), rates, coupler point, events. Used by the CLI and reports."""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.kinematics.motion import Motion, motion
from screwkit.kinematics.named import seed_variables
from screwkit.model.linkage import Linkage


def analyze(linkage: Linkage, inputs: np.ndarray, speed: float = 1.0, acceleration: float = 0.0,
            coupler_point: tuple[float, float, float] | None = None) -> tuple[Motion, dict[str, Any]]:
    """Motion of every assembly mode over ``inputs`` and its JSON-able document (SI)."""
    m = motion(linkage, inputs, speed, acceleration)
    modes = []
    for k, md in enumerate(m.modes):
        v, vd, vdd = seed_variables(linkage, md)
        entry: dict[str, Any] = {
            "mode": k,
            "assembles": md.assembles,
            "singular": md.singular,
            "events": md.events,
            "variables": {**v, **md.variables},
            "velocities": {**vd, **md.velocities},
            "accelerations": {**vdd, **md.accelerations},
            "closure_residual": md.closure_residual,
        }
        if coupler_point is not None:
            # Bagci App. C: P = O1 + f B e1 + g B e2 + h B e3 (coupler frame B at the sphere)
            R = md.link_rotation[:, 1]
            p = md.link_origin[:, 1] + np.einsum("nij,j->ni", R, np.asarray(coupler_point))
            entry["coupler_point"] = {"x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}
        modes.append(entry)
    doc = {
        "mechanism": linkage.name,
        "family": linkage.family,
        "units": {"length": "m", "angle": "rad", "time": "s",
                  "velocities": "d/dt of each variable (rad/s or m/s)",
                  "accelerations": "d2/dt2 of each variable (rad/s^2 or m/s^2)"},
        "input_name": linkage.inputs[0],
        "input": inputs,
        "input_speed": speed,
        "input_acceleration": acceleration,
        "parameters": dict(linkage.parameters),
        "modes": modes,
    }
    return m, doc

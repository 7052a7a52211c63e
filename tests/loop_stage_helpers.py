"""A family loop hung on a driven body, shared by the loop-stage tests
(tests/graphs/test_loop_stage.py, test_quartic_folds.py)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from screwkit.model.mechanism import Body, Mechanism, MechanismJoint


def knee(loop: Mechanism) -> Mechanism:
    """The loop hung on a thigh that a hip joint turns (about an axis across the four-bar's
    normal, so the thigh moves out of its plane): the loop's ground is the thigh, its crank
    driven from the thigh by a second input (a knee inside a serial chain)."""
    on_thigh = tuple(replace(j, bodies=tuple("thigh" if b == "ground" else b for b in j.bodies))
                     for j in loop.joints)
    hip = MechanismJoint("hip", "R", ("ground", "thigh"), np.array([0.5, -2.0, 1.0]),
                         np.array([0.2, 0.3, 1.0]))
    return Mechanism("knee", (Body("thigh"), *loop.bodies), (hip, *on_thigh),
                     ("hip.theta", f"{loop.joints[0].name}.theta"))

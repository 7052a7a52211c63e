"""The CSSP's optional per-sample joint fields, computed when first read (issue 30).

:func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_mode_motion` with ``lazy=True`` leaves
out of its blocked pass the ball joints' relative rotations (``conf.spherical``), their rates
(``pin.w*``, ``ball.w*``), their rotation vectors (``pin.r*``, ``ball.r*``) and Rahman's angles
(``theta2`` … with their rates): they are nearly two thirds of the pass and of the bytes it
writes, and neither the inverse dynamics nor the kinematic tables of most jobs read them.
:func:`joint_fields` computes them in a second blocked pass over the same block rows
(:func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_block_rows`), with the same
functions (:mod:`screwkit.kinematics.closed_forms.cssp_joint_rows`) and the same masking, so the
values are those of the eager pass bit for bit; :func:`joint_names` gives the tables' key
order, which the lazy tables keep.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from screwkit.kinematics.closed_forms.cssp_joint_rows import (
    SEED_ANGLES,
    ball_joint_block,
    rotation_vector_block,
    seed_angle_block,
)
from screwkit.kinematics.tracker.loop import Array
from screwkit.model.linkage import Linkage

if TYPE_CHECKING:
    from screwkit.kinematics.closed_forms.cssp_motion import CSSPSweep


def joint_names(linkage: Linkage, driven_offset: bool, ball_joints: bool, vectors: bool,
                seed: bool) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """Keys of the variables, velocities and accelerations tables of a CSSP mode, in the order
    of :func:`~screwkit.kinematics.closed_forms.cssp_motion._joint_tables`."""
    first = linkage.joints[0].name
    pin, ball, slider = (j.name for j in linkage.joints[1:])
    head = [f"{first}.theta"] + ([f"{first}.s"] if driven_offset else [])
    variables, rates = list(head), list(head)
    if ball_joints:
        for name in (pin, ball):
            if vectors:
                variables += [f"{name}.r{ax}" for ax in "xyz"]
            rates += [f"{name}.w{ax}" for ax in "xyz"]
    tail = [f"{slider}.s"] + (list(SEED_ANGLES) if seed else [])
    return tuple(variables + tail), tuple(rates + tail), tuple(rates + tail)


def joint_fields(linkage: Linkage, sw: CSSPSweep, block: int, vectors: bool,
                 seed: bool) -> dict[str, Any]:
    """The ball joints' relative rotations ``"spherical"`` (N, 2, 3, 3) and the lazy entries
    of the three tables by name (``"variables"``, ``"velocities"``, ``"accelerations"``), NaN
    where the mode does not assemble (module docstring)."""
    from screwkit.kinematics.closed_forms.cssp_motion import component_major, cssp_block_rows

    n, ok = sw.n, sw.assembles
    REL_st, relative = component_major(n, 2, 3, 3)
    RATE_st, _ = component_major(n, 4, 3)
    RV_st = np.empty((2, 3, n)) if vectors else None
    SEED_st = np.empty((12, n)) if seed else None
    base_R, base_p = linkage.base.real, linkage.base.translation
    for start in range(0, n, block):
        sl = slice(start, min(start + block, n))
        rows = cssp_block_rows(sw, sl, base_R, base_p)
        ball_joint_block(rows.loop, REL_st, RATE_st, sl)
        if RV_st is not None:
            rotation_vector_block(REL_st, RV_st, ok[sl], sl)
        if SEED_st is not None:
            seed_angle_block(sw.dims, sw.theta1[sl], rows.loop, ok[sl], SEED_st, sl)
    variables: dict[str, Array] = {}
    velocities: dict[str, Array] = {}
    accelerations: dict[str, Array] = {}
    for name, r in ((linkage.joints[1].name, 0), (linkage.joints[2].name, 2)):
        for a, ax in enumerate("xyz"):
            if RV_st is not None:
                variables[f"{name}.r{ax}"] = RV_st[r // 2, a]
            velocities[f"{name}.w{ax}"] = RATE_st[r, a]
            accelerations[f"{name}.w{ax}"] = RATE_st[r + 1, a]
    for r, key in enumerate(SEED_ANGLES if SEED_st is not None else ()):
        assert SEED_st is not None
        variables[key], velocities[key] = SEED_st[r], SEED_st[4 + r]
        accelerations[key] = SEED_st[8 + r]
    bad = ~ok
    if bad.any():  # as _mask_unassembled does for the eager fields
        relative[bad] = np.nan
        for table in (variables, velocities, accelerations):
            for values in table.values():
                values[bad] = np.nan
    return {"spherical": relative, "variables": variables, "velocities": velocities,
            "accelerations": accelerations}

"""Why a sample of a mechanism graph is singular: the motion the inputs no longer fix.

At a singular sample the passive block J_p of the stacked screw Jacobian loses rank: a passive
motion q̇_p ≠ 0 keeps every loop closed with the inputs held. Its direction (the right singular
vector of J_p's smallest singular value) names the joints that move. If they all lie in one loop
and move no freedom of another loop, it is that loop's **dead centre** (a four-bar's crank and
coupler in line); otherwise the whole mechanism **gains a freedom** (a platform or constraint
singularity: several loops move together).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.graph.newton import linearise
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]


def singular_reasons(mech: Mechanism, lay: GraphLayout, conf: Configuration, rank: int
                     ) -> list[str]:
    """One reason per sample of ``conf`` (each singular), in words."""
    lin = linearise(mech, lay, conf)
    passive = list(lay.passive)
    Jp = lin.J[:, :, passive]
    _, _, Vt = np.linalg.svd(Jp)
    null = Vt[:, max(rank - 1, 0)]  # the direction that the singular sample frees
    loops = [{k for k, _ in loop} for loop in mech.topology.loops]
    out = []
    for v in np.abs(null):
        moving = {lay.joint_of[passive[k]] for k in np.nonzero(v > 0.05 * v.max())[0]}
        names = ", ".join(mech.joints[j].name for j in sorted(moving))
        inside = [l for l, joints in enumerate(loops) if moving <= joints]
        if len(inside) == 1 and not any(moving & joints for l, joints in enumerate(loops)
                                        if l != inside[0] and not moving <= joints):
            out.append(f"a dead centre of loop {inside[0] + 1} (joints {names} move with the "
                       "inputs held)")
        else:
            out.append(f"the mechanism gains a freedom (joints {names} move with the inputs "
                       "held)")
    return out


def singular_events(mech: Mechanism, lay: GraphLayout, conf: Configuration, rank: int,
                    idx: NDArray[np.intp], shown_input: dict[int, str]) -> list[str]:
    """Events for the singular samples ``idx``: consecutive samples with one reason together,
    each with the inputs where it holds (``shown_input`` formats sample k's inputs)."""
    reasons = singular_reasons(mech, lay, conf.take(idx), rank)
    events: list[str] = []
    start = 0
    for k in range(1, len(idx) + 1):
        if k == len(idx) or reasons[k] != reasons[start] or idx[k] != idx[k - 1] + 1:
            a, b = int(idx[start]), int(idx[k - 1])
            where = shown_input[a] if a == b else f"{shown_input[a]} … {shown_input[b]}"
            events.append(f"singular at {where}: {reasons[start]}")
            start = k
        if len(events) >= 20:
            events.append(f"… and more singular samples ({len(idx)} in all)")
            break
    return events

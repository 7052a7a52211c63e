"""A single loop as a mechanism graph: the loop's joints placed where one solved sample puts them
(a drawing of that configuration), so a loop given as a family or a joint list and the same loop
given as a graph can be compared sample by sample (docs/mechanisms.md)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from screwkit.errors import CapabilityError
from screwkit.kinematics.motion import Motion
from screwkit.model.linkage import Linkage
from screwkit.model.mechanism import GROUND, Body, Mechanism, MechanismJoint


def mechanism_from_loop(motion: Motion, mode: int = 0, sample: int = 0) -> Mechanism:
    """The loop of ``motion`` drawn in its configuration at ``sample`` of ``mode``: link k is a
    body between joints k and k+1, joint i joins link i−1 (the ground for the first) to link i
    (the ground for the last), on the line the sample puts it. Inputs are measured from that
    sample. U joints need their second axis, which a Motion does not keep: not offered."""
    lk = motion.linkage
    md = motion.mode(mode)
    if not md.assembles[sample]:
        raise CapabilityError(f"{lk.name}: mode {mode} does not assemble at sample {sample}")
    return mechanism_drawn(lk, md.joint_centres[sample], md.joint_axes[sample])


def mechanism_drawn(lk: Linkage, centres: ArrayLike, axes: ArrayLike) -> Mechanism:
    """The loop ``lk`` drawn with its joints on the lines through ``centres`` (n, 3) along
    ``axes`` (n, 3) (one closed configuration; :func:`mechanism_from_loop`)."""
    centres, axes = np.asarray(centres, dtype=float), np.asarray(axes, dtype=float)
    names = [link.name for link in lk.links]
    n = len(lk.joints)
    joints = []
    for i, j in enumerate(lk.joints):
        if j.kind == "U":
            raise CapabilityError(f"{lk.name}: joint {j.name!r} is a U joint; its second axis "
                                  "is not kept by a Motion, so the loop cannot be redrawn")
        first = GROUND if i == 0 else names[i - 1]
        second = GROUND if i == n - 1 else names[i]
        joints.append(MechanismJoint(j.name, j.kind, (first, second), np.array(centres[i]),
                                     np.array(axes[i]), None, j.pitch))
    bodies = tuple(Body(link.name, None) for link in lk.links)
    return Mechanism(lk.name, bodies, tuple(joints), tuple(lk.inputs))

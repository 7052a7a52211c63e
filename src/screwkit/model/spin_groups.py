"""Rods that spin idly: bodies held between two ball joints, alone or slid together.

A body held by exactly two ball (S) joints can spin about the line through their centres
without moving any other body (a rod). So can a telescopic leg: bodies joined to one another
only by prismatic (P) joints, and to the rest of the mechanism only by two ball joints (the
S–P–S leg of a 6-SPS platform, a strut of cylinder and piston). The P joints lock the bodies'
turns relative to one another, so the leg turns as one body about the line through its balls
at any slide (its slides along that line, or at a slant to it: the spin moves no joint either
way), one idle spin shared by its bodies. Such a spin is an idle freedom (Hunt 1978, §2.5: a passive
freedom that moves no joint): the mobility counts it apart, and the kinematics holds it at
zero (kinematics/graph/idle.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from screwkit.model.mechanism import Mechanism

@dataclass(frozen=True)
class SpinGroup:
    """Bodies that spin together about the line through two ball joints' centres, and
    nothing else moves: ``bodies`` (one for a rod; a leg's slid by P joints),
    the two ball joints (indices into ``mech.joints``) and the P joints among the bodies."""

    bodies: tuple[str, ...]
    balls: tuple[int, int]
    slides: tuple[int, ...]

    @property
    def label(self) -> str:
        """The group in words: its body, or its bodies joined by '+'."""
        return "+".join(self.bodies)


def spin_groups(mech: Mechanism) -> list[SpinGroup]:
    """Every :class:`SpinGroup` of ``mech``, in the order of their first bodies: the sets of
    moving bodies joined to one another by P joints only (none for a rod) whose other joints
    are exactly two S joints with distinct centres (as drawn)."""
    moving = list(mech.body_names)  # (the ground is not among them)
    slid: dict[str, set[str]] = {b: {b} for b in moving}
    for j in mech.joints:  # the P-connected sets of moving bodies
        a, b = j.bodies
        if j.kind == "P" and a in slid and b in slid and slid[a] is not slid[b]:
            merged = slid[a] | slid[b]
            for body in merged:
                slid[body] = merged
    out: list[SpinGroup] = []
    seen: set[int] = set()
    for first in moving:
        group = slid[first]
        if id(group) in seen:
            continue
        seen.add(id(group))
        inner = [k for k, j in enumerate(mech.joints) if set(j.bodies) <= group]
        outer = [k for k, j in enumerate(mech.joints) if len(set(j.bodies) & group) == 1]
        if len(outer) != 2 or any(mech.joints[k].kind != "S" for k in outer):
            continue
        if any(mech.joints[k].kind != "P" for k in inner):
            continue
        start, end = (np.asarray(mech.joints[k].at, float) for k in outer)
        if float(np.linalg.norm(end - start)) == 0.0:
            continue
        bodies = tuple(b for b in moving if b in group)
        out.append(SpinGroup(bodies, (outer[0], outer[1]), tuple(inner)))
    return out

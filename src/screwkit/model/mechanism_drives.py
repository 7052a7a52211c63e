"""Driven body freedoms of a mechanism (the model side; kinematics/graph/drives.py solves them):
one coordinate of a body's pose relative to the ground, measured from the drawing.

======  =================================================================================
x y z   the travel of the body point ``at`` (where it is drawn) along world x, y or z
roll    the body's rotation from the drawing R = Rz(yaw)·Ry(pitch)·Rx(roll): rotations about
pitch   the fixed world axes x (roll), then y (pitch), then z (yaw) — the Tait–Bryan angles
yaw     of aeronautics (ISO 1151-2 / DIN 9300); defined for |pitch| < 90°
======  =================================================================================

Every value is 0 in the drawing. The joints whose efforts hold a body-driven mechanism on its
path are named separately (``Mechanism.actuated``): the motion does not depend on them, the loads
do.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

#: the driven pose coordinates and whether each is a length
DRIVE_FREEDOMS = {"x": True, "y": True, "z": True, "roll": False, "pitch": False, "yaw": False}


@dataclass(frozen=True)
class BodyDrive:
    """Drive ``freedom`` (a key of :data:`DRIVE_FREEDOMS`) of ``body``; ``at`` is the body point
    whose travel a translation measures (drawn position, world; any point for a rotation)."""

    name: str
    body: str
    freedom: str
    at: Array = field(default_factory=lambda: np.zeros(3))

    @property
    def is_translation(self) -> bool:
        return DRIVE_FREEDOMS[self.freedom]

    @property
    def kind(self) -> str:
        return "length" if self.is_translation else "angle"

"""Joints of a closed loop and their freedoms.

Every joint acts about the z axis of its own joint frame (Hartenberg–Denavit form, Rahman
1996 eq. 2.2: the joint contributes Z(θ̂) with θ̂ = θ + εs):

====  =================================  =========================================
kind  freedoms (names)                   joint motion J(q)
====  =================================  =========================================
R     theta                              Z(θ + ε·offset)
P     s                                  Z(angle + ε·s)
C     theta, s                           Z(θ + ε·s)
H     theta                              Z(θ + ε·(offset + pitch·θ))
U     theta1, theta2                     Z(ε·offset) · Rz(θ1) · Ry(θ2)
S     wx, wy, wz (body increments)        Z(ε·offset) · R, R any rotation
====  =================================  =========================================

The second axis of a U joint is the y axis after the first rotation, so the link that follows
(along x, Hartenberg–Denavit) is perpendicular to both axes at zero. An S joint's orientation
is held as a rotation matrix (no Euler-angle singularity); its three
freedoms are small rotations about the joint's own moving axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from screwkit.errors import InputError, InputTypeError

JointKind = Literal["R", "P", "C", "H", "U", "S"]

JOINT_FREEDOMS: dict[str, tuple[str, ...]] = {
    "R": ("theta",),
    "P": ("s",),
    "C": ("theta", "s"),
    "H": ("theta",),
    "U": ("theta1", "theta2"),
    "S": ("wx", "wy", "wz"),
}

JOINT_DESCRIPTIONS: dict[str, str] = {
    "R": "revolute (rotation about the joint axis)",
    "P": "prismatic (translation along the joint axis)",
    "C": "cylindrical (rotation about and translation along the joint axis)",
    "H": "helical (rotation about the axis with translation pitch·angle along it)",
    "U": "universal (rotation about z, then about the new y axis; the next link leaves along x)",
    "S": "spherical (any rotation about the joint centre)",
}


@dataclass(frozen=True)
class Joint:
    """One joint of the loop.

    Parameters
    ----------
    name:
        Unique name, used to label variables (``"<name>.theta"``) and reactions.
    kind:
        One of ``R P C H U S`` (see the module table).
    offset:
        Constant translation along the joint axis for R, H, U and S joints (metres); the
        constant rotation angle about the axis for a P joint (radians). Ignored for C.
    pitch:
        Lead per radian of an H joint (metres per radian); must be non-zero for H.
    """

    name: str
    kind: str
    offset: float = 0.0
    pitch: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not isinstance(self.kind, str):
            raise InputTypeError(f"Joint(name, kind): both are strings, e.g. Joint('crank', 'R'); "
                                 f"got {type(self.name).__name__}, {type(self.kind).__name__}")
        if self.kind not in JOINT_FREEDOMS:
            raise InputError(
                f"joint {self.name!r}: unknown kind {self.kind!r}; use one of "
                + ", ".join(f"{k} ({v})" for k, v in JOINT_DESCRIPTIONS.items())
            )
        if not self.name or "." in self.name:
            raise InputError(
                f"joint name {self.name!r} must be non-empty and contain no '.' "
                "(it labels variables as '<joint>.<freedom>')"
            )
        if self.kind == "H" and self.pitch == 0.0:
            raise InputError(
                f"joint {self.name!r}: a helical (H) joint needs a non-zero pitch; "
                "use an R joint for pitch 0"
            )

    @property
    def freedoms(self) -> tuple[str, ...]:
        """Names of this joint's freedoms, e.g. ``("theta", "s")`` for a C joint."""
        return JOINT_FREEDOMS[self.kind]

    @property
    def dof(self) -> int:
        return len(self.freedoms)

    def freedom_names(self) -> list[str]:
        """Qualified freedom names ``"<joint>.<freedom>"``."""
        return [f"{self.name}.{f}" for f in self.freedoms]

"""Driven body translations in the spatial point formulation (modes/spatial_points.py).

A mechanism driven at body freedoms (model/mechanism_drives.py) is solved as its augmented
mechanism (kinematics/graph/drives.py): one virtual chain per driven body, slides along world
x, y, z then turns about z, y, x through the body's drive point a, the driven freedoms its
inputs. Written as points, that chain would add five bodies of points; instead the real
mechanism is written and each driven translation of a body is one linear equation on the
drive point a, carried by the body as one more point:

    e · P_a = e · a + v      (e the world axis x, y or z; v the driven travel)

(scaled coordinates), with e·a + v a parameter that follows the input. A driven turn (roll,
pitch, yaw) is not polynomial in the points without its cosine and sine as unknowns: such a
mechanism is refused. The virtual chain's joint values are read back off the body's solved
pose: the travel of a, R a + p − a, and the Tait–Bryan angles of R = Rz(yaw) Ry(pitch) Rx(roll).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.drives import PREFIX
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]
Pose = tuple[Array, Array]
#: the virtual chain's freedoms in order (graph/drives.py ``_CHAIN``), translations first
CHAIN = ("x", "y", "z", "yaw", "pitch", "roll")
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


@dataclass(frozen=True)
class PointDrive:
    """A driven translation of ``body``'s drive point ``at`` (drawn, world) along world
    ``freedom`` (x, y or z), its input column ``column`` of the augmented mechanism."""

    body: str
    freedom: str
    at: Array
    column: int

    @property
    def axis(self) -> Array:
        return np.asarray(AXES[self.freedom])


def real_mechanism(mech: Mechanism) -> tuple[Mechanism, tuple[PointDrive, ...]]:
    """The real mechanism of an augmented one (its virtual chains and their inputs left out)
    and its driven translations; ``mech`` itself and none when it has no virtual chain. A
    CapabilityError for a driven turn."""
    virtual = [j for j in mech.joints if j.name.startswith(PREFIX)]
    if not virtual:
        return mech, ()
    drives = []
    for c, name in enumerate(mech.inputs):
        joint = name.split(".")[0]
        if not joint.startswith(PREFIX):
            continue
        body, freedom = joint[len(PREFIX):].rsplit("_", 1)
        if freedom not in AXES:
            raise CapabilityError(
                f"{mech.name}: the spatial point formulation does not take this mechanism: "
                f"it is driven at {body}'s {freedom}, a turn, which is not polynomial in its "
                "points (driven translations x, y, z are); follow the drawn mode with the "
                "graph tracker (--modes drawn)")
        at = next(j.at for j in virtual if j.name == joint)
        drives.append(PointDrive(body, freedom, np.asarray(at, float), c))
    chain = {b for j in virtual for b in j.bodies if b.startswith(PREFIX)}
    real = Mechanism(mech.name, tuple(b for b in mech.bodies if b.name not in chain),
                     tuple(j for j in mech.joints if not j.name.startswith(PREFIX)),
                     tuple(x for x in mech.inputs if not x.startswith(PREFIX)), mech.points,
                     mech.length_scale, mech.outputs)
    return real, tuple(drives)


def chain_poses(mech: Mechanism, poses: dict[str, Pose]) -> dict[str, Pose]:
    """The virtual chains' bodies' poses (augmented ``mech``) from their driven bodies' poses
    (module docstring): after the slides x, y, z, then the turns yaw and pitch about the drive
    point."""
    out: dict[str, Pose] = {}
    for j in mech.joints:
        if not (j.name.startswith(PREFIX) and j.name.endswith("_x")):
            continue
        body = j.name[len(PREFIX):-2]
        R, p = poses[body]
        a = np.asarray(j.at, float)
        t = np.einsum("nij,j->ni", R, a) + p - a
        yaw = np.arctan2(R[:, 1, 0], R[:, 0, 0])
        pitch = np.arcsin(np.clip(-R[:, 2, 0], -1.0, 1.0))
        N = len(t)
        eye = np.broadcast_to(np.eye(3), (N, 3, 3))
        Rz, Ry = _turn(2, yaw), _turn(1, pitch)
        mask = np.array([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]])
        for k in range(3):
            out[f"{PREFIX}{body}_{k + 1}"] = (eye, t * mask[k])
        for k, Rk in ((4, Rz), (5, Rz @ Ry)):
            out[f"{PREFIX}{body}_{k}"] = (Rk, t + a - np.einsum("nij,j->ni", Rk, a))
    return out


def _turn(axis: int, angle: Array) -> Array:
    """Rotations (N, 3, 3) by ``angle`` about world axis 0 (x), 1 (y) or 2 (z)."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R = np.zeros((len(angle), 3, 3))
    R[:, axis, axis] = 1.0
    R[:, i, i], R[:, j, j], R[:, i, j], R[:, j, i] = c, c, -s, s
    return R

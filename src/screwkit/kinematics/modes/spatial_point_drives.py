"""Driven body freedoms in the spatial point formulation (modes/spatial_points.py).

A mechanism driven at body freedoms (model/mechanism_drives.py) is solved as its augmented
mechanism (kinematics/graph/drives.py): one virtual chain per driven body, slides along world
x, y, z then turns about z, y, x through the body's drive point a, the driven freedoms its
inputs. Written as points, that chain would add five bodies of points; instead the real
mechanism is written and each drive is one equation on the body's points.

A driven translation is linear in the drive point a, carried by the body as one more point:

    e · P_a = e · a + v      (e the world axis x, y or z; v the driven travel)

(scaled coordinates), with e·a + v a parameter that follows the input.

A driven turn is one equation in the body's rotation from its drawing, R = U U0⁻¹, where
U = [u, v, u × v] is built on the body's base (u = b2 − b1, v = b3 − b1) and U0 is the same
in the drawing. The chain's R = Rz(ψ) Ry(φ) Rx(ρ) has its roll equal to ρ exactly when
(R Rx(−ρ))₃₂ = 0, since then R Rx(−ρ) = Rz(ψ) Ry(φ) for some ψ and φ; likewise
(Rz(−ψ) R)₂₁ = 0 for a yaw ψ and R₃₁ = −sin φ for a pitch φ:

    roll ρ:   e3ᵀ R (cos ρ e2 − sin ρ e3) = 0
    yaw ψ:    (cos ψ e2 − sin ψ e1)ᵀ R e1 = 0
    pitch φ:  e3ᵀ R e1 = −sin φ

Each is  Σ W_ik U_ik = h  with W = r (U0⁻¹ m)ᵀ for the row and column vectors r, m above. The
equation is quadratic in the points, since u × v is. One driven turn has no spurious root:
every solution is a pose of the chain with that drive value. Two or three turns of one body
also hold at rotations that take each turn from the other Tait–Bryan triple (below); those
are not poses of the chain, and every_mode drops them (their turns read back are not the
inputs). W (nine numbers) and h are parameters; the generic
family takes them all free.

The virtual chain's joint values are read back off the body's solved pose. The travel is that
of a, R a + p − a. The angles are the Tait–Bryan ones of R: of the two triples (ψ, φ, ρ) with
cos φ ≥ 0 and (ψ + π, π − φ, ρ + π), the one that agrees with the driven turns.
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
TURNS = ("yaw", "pitch", "roll")


@dataclass(frozen=True)
class PointDrive:
    """A driven freedom of ``body``: a translation of its drive point ``at`` (drawn, world)
    along world ``freedom`` (x, y or z), or its turn (yaw, pitch or roll), at input column
    ``column`` of the augmented mechanism."""

    body: str
    freedom: str
    at: Array
    column: int

    @property
    def is_turn(self) -> bool:
        return self.freedom in TURNS

    @property
    def axis(self) -> Array:
        return np.asarray(AXES[self.freedom])


def turn_parameters(drive: PointDrive, angle: Array, drawn_frame: Array) -> Array:
    """The parameters (N, 10) of a driven turn's equation Σ W_ik U_ik = h (module
    docstring): W (row-major) then h, at the driven angles (N,), for a body whose drawn base
    frame is U0 = ``drawn_frame`` (3, 3: u0, v0, u0 × v0 as columns)."""
    c, s = np.cos(angle), np.sin(angle)
    zero, one = np.zeros_like(c), np.ones_like(c)
    e1, e3 = np.stack([one, zero, zero], 1), np.stack([zero, zero, one], 1)
    if drive.freedom == "roll":
        r, m, h = e3, np.stack([zero, c, -s], 1), zero
    elif drive.freedom == "yaw":
        r, m, h = np.stack([-s, c, zero], 1), e1, zero
    else:
        r, m, h = e3, e1, -s
    m = np.linalg.solve(drawn_frame, m.T).T  # rᵀ R m = rᵀ U (U0⁻¹ m)
    W = np.einsum("ni,nk->nik", r, m).reshape(len(angle), 9)
    return np.hstack([W, h[:, None]])


def check_turns(mech: Mechanism, drives: tuple[PointDrive, ...], rotated: set[str]) -> None:
    """Refuse a driven turn of a body the formulation writes no base triangle for (not in
    ``rotated``: one the inputs place, or whose points lie on one line)."""
    for d in drives:
        if d.is_turn and d.body not in rotated:
            raise CapabilityError(
                f"{mech.name}: the spatial point formulation does not take this mechanism: it "
                f"is driven at {d.body}'s {d.freedom}, a turn, but the formulation writes no "
                f"rotation for {d.body} (the inputs place it, or its points lie on one line); "
                "follow the drawn mode with the graph tracker (--modes drawn)")


def real_mechanism(mech: Mechanism) -> tuple[Mechanism, tuple[PointDrive, ...]]:
    """The real mechanism of an augmented one (its virtual chains and their inputs left out)
    and its drives; ``mech`` itself and none when it has no virtual chain."""
    virtual = [j for j in mech.joints if j.name.startswith(PREFIX)]
    if not virtual:
        return mech, ()
    drives = []
    for c, name in enumerate(mech.inputs):
        joint = name.split(".")[0]
        if not joint.startswith(PREFIX):
            continue
        body, freedom = joint[len(PREFIX):].rsplit("_", 1)
        at = next(j.at for j in virtual if j.name == joint)
        drives.append(PointDrive(body, freedom, np.asarray(at, float), c))
    chain = {b for j in virtual for b in j.bodies if b.startswith(PREFIX)}
    real = Mechanism(mech.name, tuple(b for b in mech.bodies if b.name not in chain),
                     tuple(j for j in mech.joints if not j.name.startswith(PREFIX)),
                     tuple(x for x in mech.inputs if not x.startswith(PREFIX)), mech.points,
                     mech.length_scale, mech.outputs)
    return real, tuple(drives)


def chain_poses(mech: Mechanism, poses: dict[str, Pose], X: Array) -> dict[str, Pose]:
    """The virtual chains' bodies' poses (augmented ``mech``, inputs X (N, n_inputs)) from
    their driven bodies' poses (module docstring): after the slides x, y, z, then the turns yaw
    and pitch about the drive point, on the Tait–Bryan triple that agrees with the driven
    turns."""
    out: dict[str, Pose] = {}
    for j in mech.joints:
        if not (j.name.startswith(PREFIX) and j.name.endswith("_x")):
            continue
        body = j.name[len(PREFIX):-2]
        R, p = poses[body]
        a = np.asarray(j.at, float)
        t = np.einsum("nij,j->ni", R, a) + p - a
        yaw, pitch = _tait_bryan(mech, body, R, X)
        N = len(t)
        eye = np.broadcast_to(np.eye(3), (N, 3, 3))
        Rz, Ry = _turn(2, yaw), _turn(1, pitch)
        mask = np.array([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]])
        for k in range(3):
            out[f"{PREFIX}{body}_{k + 1}"] = (eye, t * mask[k])
        for k, Rk in ((4, Rz), (5, Rz @ Ry)):
            out[f"{PREFIX}{body}_{k}"] = (Rk, t + a - np.einsum("nij,j->ni", Rk, a))
    return out


def _tait_bryan(mech: Mechanism, body: str, R: Array, X: Array) -> tuple[Array, Array]:
    """The yaw and pitch (N,) of R = Rz(yaw) Ry(pitch) Rx(roll): the triple with
    cos(pitch) ≥ 0, or its twin (yaw + π, π − pitch, roll + π) where that one is nearer the
    driven turns of ``body`` (inputs X)."""
    yaw = np.arctan2(R[:, 1, 0], R[:, 0, 0])
    pitch = np.arcsin(np.clip(-R[:, 2, 0], -1.0, 1.0))
    roll = np.arctan2(R[:, 2, 1], R[:, 2, 2])
    first = {"yaw": yaw, "pitch": pitch, "roll": roll}
    twin = {"yaw": yaw + np.pi, "pitch": np.pi - pitch, "roll": roll + np.pi}
    miss = np.zeros((2, len(R)))
    for c, name in enumerate(mech.inputs):
        joint = name.split(".")[0]
        if joint.startswith(f"{PREFIX}{body}_") and joint.rsplit("_", 1)[1] in TURNS:
            turn = joint.rsplit("_", 1)[1]
            for k, triple in enumerate((first, twin)):
                miss[k] += 1.0 - np.cos(triple[turn] - X[:, c])
    flip = miss[1] < miss[0]
    return np.where(flip, yaw + np.pi, yaw), np.where(flip, np.pi - pitch, pitch)


def _turn(axis: int, angle: Array) -> Array:
    """Rotations (N, 3, 3) by ``angle`` about world axis 0 (x), 1 (y) or 2 (z)."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R = np.zeros((len(angle), 3, 3))
    R[:, axis, axis] = 1.0
    R[:, i, i], R[:, j, j], R[:, i, j], R[:, j, i] = c, c, -s, s
    return R

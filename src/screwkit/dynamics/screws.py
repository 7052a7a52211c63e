"""Freedom screws of every joint in the world frame, from a :class:`ModeMotion`.

The reaction of a joint does no work along the joint's freedoms except the actuator effort, so
the statics of the loop needs one unit screw per freedom (Bagci 1969 eqs. 3.19–3.26, the skew
operators of the joints carried to the base). :func:`screwkit.kinematics.tracker.loop.forward` computes
them in the ground frame; here they are rebuilt in the world frame from the joint centres and
axes already stored on the mode (no second pass round the loop):

====  ==================================================================
kind  screws (ω; v), v = velocity of the point at the reference point r
====  ==================================================================
R     (u; (c − r) × u)
P     (0; u)
C     (u; (c − r) × u), (0; u)
H     (u; (c − r) × u + h u)
U     (u; (c − r) × u), (u₂; (c − r) × u₂), u₂ = x axis after the first turn
S     (e_k; (c − r) × e_k) for the world axes e_x, e_y, e_z
====  ==================================================================

For a spherical joint any three independent rotations about its centre span the same freedoms,
so the world axes are used: the constraint "no moment about the centre" does not depend on the
joint's (possibly minimum-norm, Rahman 1996 §1.4) spin.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import cross, rot_z
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.linkage import Linkage

Array = NDArray[np.float64]


@dataclass(frozen=True)
class FreedomScrews:
    """Unit freedom screws of a loop, world frame, batch-first.

    ``screws`` (N, m, 6): (ω; v) per freedom, v taken at ``reference`` (3,);
    ``names``: freedom names, loop order (S joints: ``"<joint>.world_x"`` …, the world-axis
    basis of the module docstring); ``joint_of``: joint index of each freedom;
    ``is_rotation``: True where ω ≠ 0 (the generalised force is a moment);
    ``driven``: True for the linkage's inputs.
    """

    screws: Array
    names: tuple[str, ...]
    joint_of: tuple[int, ...]
    is_rotation: tuple[bool, ...]
    driven: tuple[bool, ...]
    reference: Array


def _line(axis: Array, arm: Array) -> Array:
    return np.concatenate([axis, cross(arm, axis)], -1)


def freedom_screws(
    linkage: Linkage, mode: ModeMotion, reference: Array | None = None
) -> FreedomScrews:
    """Unit screws of every freedom in the world frame, taken about ``reference`` (default the
    world origin). Vectorised over samples; samples that do not assemble are NaN."""
    ref = np.zeros(3) if reference is None else np.asarray(reference, dtype=float)
    centres = mode.joint_centres - ref
    axes = mode.joint_axes
    N = centres.shape[0]
    cols: list[Array] = []
    names: list[str] = []
    joint_of: list[int] = []
    is_rot: list[bool] = []
    driven: list[bool] = []
    base_R = linkage.base.real
    for i, joint in enumerate(linkage.joints):
        c = centres[:, i]
        u = axes[:, i]
        kind = joint.kind
        if kind == "R":
            cols.append(_line(u, c))
            rot = [True]
        elif kind == "P":
            cols.append(np.concatenate([np.zeros_like(u), u], -1))
            rot = [False]
        elif kind == "C":
            cols.append(_line(u, c))
            cols.append(np.concatenate([np.zeros_like(u), u], -1))
            rot = [True, False]
        elif kind == "H":
            cols.append(_line(u, c) + np.concatenate([np.zeros_like(u), joint.pitch * u], -1))
            rot = [True]
        elif kind == "U":
            if i == 0:
                before = np.broadcast_to(base_R, (N, 3, 3))
            else:
                before = mode.link_rotation[:, i - 1] @ linkage.link_transforms[i - 1].real
            theta1 = mode.variables[f"{joint.name}.theta1"]
            u2 = (before @ rot_z(theta1))[..., :, 0]
            cols.append(_line(u, c))
            cols.append(_line(u2, c))
            rot = [True, True]
        else:  # S: world-axis basis
            for k in range(3):
                e = np.zeros((N, 3))
                e[:, k] = 1.0
                cols.append(_line(e, c))
            rot = [True, True, True]
        if kind == "S":
            fnames = [f"{joint.name}.world_{ax}" for ax in "xyz"]
        else:
            fnames = joint.freedom_names()
        names.extend(fnames)
        joint_of.extend([i] * len(fnames))
        is_rot.extend(rot)
        driven.extend(f in linkage.inputs for f in fnames)
    return FreedomScrews(
        screws=np.stack(cols, axis=1),
        names=tuple(names),
        joint_of=tuple(joint_of),
        is_rotation=tuple(is_rot),
        driven=tuple(driven),
        reference=ref,
    )

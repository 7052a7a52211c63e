"""The CSSP's closed-form kinematics as a :class:`~screwkit.kinematics.motion.ModeMotion`.

:func:`cssp_mode_motion` gives the same result type, with the same conventions, as
``motion(linkage, …).modes[k]`` for a linkage built by :func:`screwkit.model.families.cssp`,
from the exact closed form :func:`screwkit.kinematics.cssp.cssp_motion` (Rahman 1996 §2.1;
reference SPEC §1.2) instead of the generic Newton solver. Every array is computed in one
vectorised pass, so the inverse dynamics can run on 10⁶ samples.

Frames (those of :func:`screwkit.model.families.cssp` and :func:`screwkit.kinematics.loop.forward`):

* crank: rotation Z(θ1), origin on z1 at the crank offset s1 (joint 1's frame after its motion;
  x along the crank);
* rod: origin at the crank pin D1, x along the rod u = (P − D1)/a2 (the pin S joint's child
  frame). A two-ball rod's spin angle about u is not fixed by the loop; this adapter uses
  Rahman's frame {3}, R = Z(θ1 + θ2)·Y(η2) (SPEC §1.1, L2), so y lies in the plane of z1;
* slider: origin at the ball centre P, constant rotation X(−(α4 + π/2)) (the loop closes the
  slider's rotation with the ball joint).

Rates follow the generic solver's rule for an S–S link: zero absolute spin, ω_rod·u = 0, so
ω_rod = u × u̇ and α_rod = u × ü (Rahman 1996 §1.2). As in the generic solver, the rod's
rotation is therefore not the time integral of its angular velocity (the spin angle is a free
choice, the spin rate is zero); only quantities that do not depend on the spin angle are
physical — the CoM kinematics of a rod whose CoM is on its axis, ω, α, the joint centres and the
loads of an axisymmetric rod (docs/dynamics.md, "idle passive freedoms").

Spherical-joint rates use the generic solver's convention: the three freedoms ``<joint>.wx|wy|wz``
are the relative angular velocity in the child frame, and their "accelerations" the time
derivatives of those components, with the child frame turning at the link's ω.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from screwkit.kinematics.cssp import SEED_ASSEMBLY_MODE, CSSPDimensions, cssp_motion
from screwkit.kinematics.loop import Configuration, rot_x
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.linkage import Linkage

Array = NDArray[np.float64]

_JOINTS = (("R", "C"), ("S",), ("S",), ("P",))


class NotACSSPError(ValueError):
    """The linkage given to :func:`cssp_mode_motion` is not a CSSP of the family constructor."""


def cssp_dimensions(linkage: Linkage) -> CSSPDimensions:
    """The :class:`CSSPDimensions` of a linkage built by :func:`screwkit.model.families.cssp`
    (read from ``linkage.parameters``); raises :class:`NotACSSPError` for any other linkage."""
    kinds = tuple(j.kind for j in linkage.joints)
    ok = (
        linkage.family == "CSSP"
        and len(kinds) == 4
        and all(k in allowed for k, allowed in zip(kinds, _JOINTS, strict=True))
        and all(key in linkage.parameters for key in ("a1", "a2", "a4", "alpha4", "s1"))
    )
    if not ok:
        raise NotACSSPError(
            f"cssp_mode_motion needs a CSSP built by screwkit.model.families.cssp (joints "
            f"R|C, S, S, P and parameters a1, a2, a4, alpha4, s1); got {linkage.name!r} "
            f"(family {linkage.family!r}, joints {''.join(kinds)}). Use "
            "screwkit.kinematics.motion.motion for other loops."
        )
    p = linkage.parameters
    return CSSPDimensions(p["a1"], p["a2"], p["a4"], p["alpha4"], p["s1"])


def _cross(a: Array, b: Array) -> Array:
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        -1,
    )


def _rotate_back(R: Array, v: Array) -> Array:
    """Rᵀ v for (N, 3, 3) R and (N, 3) v."""
    return np.einsum("nji,nj->ni", R, v)


def cssp_mode_motion(
    linkage: Linkage,
    theta1: ArrayLike,
    theta1_dot: ArrayLike = 0.0,
    theta1_ddot: ArrayLike = 0.0,
    mode: int = SEED_ASSEMBLY_MODE,
    *,
    s1: ArrayLike | None = None,
    s1_dot: ArrayLike = 0.0,
    s1_ddot: ArrayLike = 0.0,
    allow_partial: bool = False,
    joint_rotations: bool = True,
) -> ModeMotion:
    """One assembly mode of a CSSP over N crank angles, from the closed form (no Newton).

    Same result as ``motion(linkage, theta1, theta1_dot, theta1_ddot).modes[k]`` for the mode
    whose slider position is s4 = −b + mode·√(b² − c) (SPEC §1.2; ``mode=+1`` is Rahman's
    branch), up to the rod's free spin angle (module docstring). ``theta1`` (N,) rad,
    ``theta1_dot``/``theta1_ddot`` rad/s, rad/s² (scalars or (N,)); ``s1``, ``s1_dot``,
    ``s1_ddot`` drive the crank offset of a CSSP built with ``s1_is_input=True`` (for a fixed
    offset they must be left out: the offset is ``linkage.parameters["s1"]``).

    Samples where the CSSP does not assemble raise ``CSSPAssemblyError`` unless
    ``allow_partial``, which marks them in ``assembles`` and fills them with NaN.
    ``joint_rotations=False`` skips the rotation vectors of the two ball joints in
    ``variables`` (``pin.rx`` …; a third of the cost on 10⁶ samples, unused by the dynamics).
    """
    dims = cssp_dimensions(linkage)
    driven_offset = linkage.joints[0].kind == "C"
    if not driven_offset and (
        s1 is not None or np.any(np.asarray(s1_dot) != 0) or np.any(np.asarray(s1_ddot) != 0)
    ):
        raise ValueError(
            f"{linkage.name}: the crank offset s1 is a constant of this CSSP "
            f"(s1 = {dims.s1!r} m); build it with cssp(..., s1_is_input=True) to drive s1"
        )
    cf = cssp_motion(
        dims, theta1, theta1_dot, theta1_ddot, mode,
        s1=s1, s1_dot=s1_dot, s1_ddot=s1_ddot, allow_partial=allow_partial,
    )
    n = cf.theta1.shape[0]
    ok = cf.assembles
    ct, st = np.cos(cf.theta1), np.sin(cf.theta1)

    # link l's rotation (crank Z(θ1), rod Rahman's {3}, slider X(−(α4 + π/2))), origin, and
    # their rates, written in place (np.stack of (N, 3) pieces costs as much as the closed form)
    link_rotation = np.zeros((n, 3, 3, 3))
    link_rotation[:, 0, 0, 0], link_rotation[:, 0, 0, 1] = ct, -st
    link_rotation[:, 0, 1, 0], link_rotation[:, 0, 1, 1] = st, ct
    link_rotation[:, 0, 2, 2] = 1.0
    link_rotation[:, 1] = cf.rod_frame
    link_rotation[:, 2] = rot_x(np.array(-(dims.alpha4 + np.pi / 2)))
    crank_R, rod_R, slider_R = link_rotation[:, 0], link_rotation[:, 1], link_rotation[:, 2]

    link_origin = np.zeros((n, 3, 3))
    link_origin[:, 0, 2] = cf.s1
    link_origin[:, 1] = cf.crank_pin
    link_origin[:, 2] = cf.slider_ball
    link_origin_velocity = np.zeros((n, 3, 3))
    link_origin_velocity[:, 0, 2] = cf.s1_dot
    link_origin_velocity[:, 1] = cf.crank_pin_velocity
    link_origin_velocity[:, 2] = cf.slider_ball_velocity
    link_origin_acceleration = np.zeros((n, 3, 3))
    link_origin_acceleration[:, 0, 2] = cf.s1_ddot
    link_origin_acceleration[:, 1] = cf.crank_pin_acceleration
    link_origin_acceleration[:, 2] = cf.slider_ball_acceleration
    link_angular_velocity = np.zeros((n, 3, 3))
    link_angular_velocity[:, 0, 2] = cf.theta1_dot
    link_angular_velocity[:, 1] = cf.rod_angular_velocity
    link_angular_acceleration = np.zeros((n, 3, 3))
    link_angular_acceleration[:, 0, 2] = cf.theta1_ddot
    link_angular_acceleration[:, 1] = cf.rod_angular_acceleration
    crank_w, rod_w = link_angular_velocity[:, 0], link_angular_velocity[:, 1]
    crank_al, rod_al = link_angular_acceleration[:, 0], link_angular_acceleration[:, 1]

    # joint centres and axes; a C joint's centre is its frame origin on z1, an R joint's sits at
    # its offset (loop.forward)
    joint_centres = np.zeros((n, 4, 3))
    if not driven_offset:
        joint_centres[:, 0, 2] = cf.s1
    joint_centres[:, 1] = cf.crank_pin
    joint_centres[:, 2] = cf.slider_ball
    joint_centres[:, 3] = cf.slider_ball
    joint_axes = np.zeros((n, 4, 3))
    joint_axes[:, 0, 2] = 1.0
    joint_axes[:, 1, 2] = 1.0
    joint_axes[:, 2] = rod_R[:, :, 2]
    joint_axes[:, 3] = dims.slider_axis

    # joint variables in the generic solver's layout
    pin_rel = crank_R.transpose(0, 2, 1) @ rod_R  # R_crankᵀ R_rod (matmul: 3× einsum's speed)
    ball_rel = rod_R.transpose(0, 2, 1) @ slider_R  # R_rodᵀ R_slider
    scalars = [cf.theta1] + ([cf.s1] if driven_offset else []) + [cf.s4]
    conf = Configuration(np.stack(scalars, -1), np.stack([pin_rel, ball_rel], 1))
    first = linkage.joints[0].name
    pin, ball, slider = (j.name for j in linkage.joints[1:])
    variables: dict[str, Array] = {f"{first}.theta": cf.theta1.copy()}
    velocities: dict[str, Array] = {f"{first}.theta": cf.theta1_dot.copy()}
    accelerations: dict[str, Array] = {f"{first}.theta": cf.theta1_ddot.copy()}
    if driven_offset:
        variables[f"{first}.s"] = cf.s1.copy()
        velocities[f"{first}.s"] = cf.s1_dot.copy()
        accelerations[f"{first}.s"] = cf.s1_ddot.copy()
    # ball-joint rates in the child frame: pin R_rod·ω_b = ω_rod − ω_crank and
    # R_rod·ω̇_b = α_rod − α_crank + ω_rod × ω_crank; ball (slider does not turn)
    # R_slider·ω_b = −ω_rod and R_slider·ω̇_b = −α_rod
    pin_rate = _rotate_back(rod_R, rod_w - crank_w)
    pin_acc = _rotate_back(rod_R, rod_al - crank_al + _cross(rod_w, crank_w))
    ball_rate = _rotate_back(slider_R, -rod_w)
    ball_acc = _rotate_back(slider_R, -rod_al)
    if joint_rotations:
        safe = np.where(ok[:, None, None], 1.0, 0.0)
        eye = np.where(ok[:, None, None], 0.0, 1.0) * np.eye(3)
        pin_rv = Rotation.from_matrix(np.nan_to_num(pin_rel) * safe + eye).as_rotvec()
        ball_rv = Rotation.from_matrix(np.nan_to_num(ball_rel) * safe + eye).as_rotvec()
    for name, rate, acc, rv in (
        (pin, pin_rate, pin_acc, pin_rv if joint_rotations else None),
        (ball, ball_rate, ball_acc, ball_rv if joint_rotations else None),
    ):
        for a, ax in enumerate("xyz"):
            if rv is not None:
                variables[f"{name}.r{ax}"] = np.where(ok, rv[:, a], np.nan)
            velocities[f"{name}.w{ax}"] = rate[:, a]
            accelerations[f"{name}.w{ax}"] = acc[:, a]
    variables[f"{slider}.s"] = cf.s4
    velocities[f"{slider}.s"] = cf.s4_dot
    accelerations[f"{slider}.s"] = cf.s4_ddot

    arrays = [link_rotation, link_origin, link_angular_velocity, link_origin_velocity,
              link_angular_acceleration, link_origin_acceleration, joint_centres, joint_axes]
    base_R, base_p = linkage.base.real, linkage.base.translation
    if not (np.array_equal(base_R, np.eye(3)) and not np.any(base_p)):
        # place the loop in the world: rotate every vector, translate the points
        arrays = [np.einsum("ij,n...jk->n...ik", base_R, arrays[0])] + [
            np.einsum("ij,n...j->n...i", base_R, a) for a in arrays[1:]
        ]
        arrays[1] = arrays[1] + base_p
        arrays[6] = arrays[6] + base_p
    bad = ~ok
    if bad.any():
        for arr in arrays:
            arr[bad] = np.nan
        for table in (variables, velocities, accelerations):
            for values in table.values():
                values[bad] = np.nan
    closure = cf.loop_closure_gap / linkage.length_scale
    events: list[str] = []
    if bad.any() and ok.any():
        events.append(f"does not assemble at {int(bad.sum())} of {n} sample(s)")
    return ModeMotion(
        assembles=ok.copy(),
        singular=np.zeros(n, dtype=bool),
        conf=conf,
        variables=variables,
        velocities=velocities,
        accelerations=accelerations,
        link_rotation=arrays[0],
        link_origin=arrays[1],
        link_angular_velocity=arrays[2],
        link_origin_velocity=arrays[3],
        link_angular_acceleration=arrays[4],
        link_origin_acceleration=arrays[5],
        joint_centres=arrays[6],
        joint_axes=arrays[7],
        closure_residual=closure,
        events=events,
    )


__all__ = ["NotACSSPError", "cssp_dimensions", "cssp_mode_motion"]

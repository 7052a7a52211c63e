"""The CSSP's closed-form kinematics as a :class:`~screwkit.kinematics.motion.ModeMotion`.

:func:`cssp_mode_motion` gives the same result type, with the same conventions, as
``motion(linkage, …).modes[k]`` for a linkage built by :func:`screwkit.model.families.cssp`,
from the exact closed form of :func:`screwkit.kinematics.closed_forms.cssp.cssp_motion` (Rahman 1996 §2.1;
reference SPEC §1.2) instead of the generic Newton solver. The samples are processed in blocks
in structure-of-arrays form (:func:`cssp_block_rows`, one (n,) array per component), and the
(N, …) arrays are views of component-major storage (each component contiguous over the
samples), so 10⁶ samples take well under a microsecond each; the fused CSSP inverse dynamics
(:func:`screwkit.dynamics.cssp_inverse_dynamics`) consumes the same block rows directly.

Frames (those of :func:`screwkit.model.families.cssp` and :func:`screwkit.kinematics.tracker.loop.forward`):

* crank: rotation Z(θ1), origin on z1 at the crank offset s1 (joint 1's frame after its motion;
  x along the crank);
* rod: origin at the crank pin D1, x along the rod u = (P − D1)/a2 (the pin S joint's child
  frame). A two-ball rod's spin angle about u is not fixed by the loop; it is the zero-spin
  frame along the branch, the generic solver's convention (:mod:`screwkit.kinematics.tracker.idle_spin`),
  so that its rotation differentiates to its ω: Rahman's frame {3}, R = Z(θ1 + θ2)·Y(η2)
  (SPEC §1.1, L2), turned about u by the sweep's ``rod_turn`` φ
  (:mod:`screwkit.kinematics.closed_forms.cssp_rod_pose`);
* slider: origin at the ball centre P, constant rotation X(−(α4 + π/2)) (the loop closes the
  slider's rotation with the ball joint).

Rates follow the generic solver's rule for an S–S link: zero absolute spin, ω_rod·u = 0, so
ω_rod = u × u̇ and α_rod = u × ü (Rahman 1996 §1.2), and the rod's pose is the frame that spin
rule carries along the branch (path dependent: after a full turn of the crank it comes back
turned about u by the holonomy). The fused inverse dynamics reads the same block rows.

The checked inputs, the crank angles' cosines and sines and where the loop assembles
(:class:`~screwkit.kinematics.closed_forms.cssp_inputs.CSSPSweep`) do not depend on the root of
the quadratic: ``solve_motion`` prepares them once for both modes (:func:`sweep_mode_motion`).
For a crank on an R joint the link origins are the first three joint centres and are stored
with them (one storage, ``link_origin`` a view of ``joint_centres``'s).

Spherical-joint rates use the generic solver's convention: the three freedoms ``<joint>.wx|wy|wz``
are the relative angular velocity in the child frame, and their "accelerations" the time
derivatives of those components, with the child frame turning at the link's ω.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import GIMBAL_TOL, rot_x
from screwkit.kinematics.closed_forms import cssp_compiled
from screwkit.kinematics.closed_forms.cssp import SEED_ROOT, CSSPDimensions
from screwkit.kinematics.closed_forms.cssp_inputs import (
    CSSPSweep,
    NotACSSPError,
    cssp_dimensions,
    cssp_sweep,
    sweep_for_root,
)
from screwkit.kinematics.closed_forms.cssp_joint_rows import (
    SEED_ANGLES,
    ball_joint_block,
    combine,
    rotation_vector_block,
    seed_angle_block,
)
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.linkage import Linkage

Array = NDArray[np.float64]

BLOCK_SAMPLES = 16384
"""Samples per block of :func:`cssp_mode_motion` (its temporaries stay in the CPU caches)."""


def component_major(n: int, *shape: int) -> tuple[Array, Array]:
    """Zeroed storage (shape…, n) and its (n, shape…) view: every component of every sample
    row is contiguous over the samples, which the closed form writes (and the blocked inverse
    dynamics reads) without transposing. Entries never written stay zero at no cost."""
    storage = np.zeros((*shape, n))
    return storage, np.moveaxis(storage, -1, 0)


def cssp_closed_form_block(
    dims: CSSPDimensions, root: int, ct: Array, st: Array, w: Any, wd: Any, s1: Any, s1d: Any,
    s1dd: Any, disc: Array,
) -> dict[str, Any]:
    """Crank pin, slider ball, s4, the rod direction u and their first two rates for one block,
    one (n,) array per component — :func:`screwkit.kinematics.closed_forms.cssp.cssp_motion`'s formulas
    (SPEC §1.2) in structure-of-arrays form. ``ct``, ``st``: cos θ1, sin θ1; the rates and s1
    are (n,) arrays or floats; ``disc`` = b² − c > 0 (placeholder 1 where the CSSP does not
    assemble, whose samples are overwritten with NaN afterwards)."""
    a1, a2, a4 = dims.a1, dims.a2, dims.a4
    sa, ca = np.sin(dims.alpha4), np.cos(dims.alpha4)
    a1c, a1s = a1 * ct, a1 * st
    b = sa * a1s + ca * s1
    c = (a4**2 + a1**2 - a2**2) + 2 * a4 * a1c + s1 * s1
    radical = np.sqrt(disc) if root > 0 else -np.sqrt(disc)  # = s4 + b
    # −b + root cancels when root·b > 0; there use the product of the roots, s4·s4' = c
    other = -b - radical
    cancels = (b > 0) if root > 0 else (b < 0)
    cancels &= other != 0
    s4 = np.where(cancels, c / np.where(cancels, other, 1.0), radical - b)
    w2 = w * w
    pin_v = (-a1s * w, a1c * w, s1d)
    pin_a = (-(a1c * w2 + a1s * wd), a1c * wd - a1s * w2, s1dd)
    b_dot = sa * pin_v[1] + ca * s1d
    b_ddot = sa * pin_a[1] + ca * s1dd
    c_dot = 2 * (a4 * pin_v[0] + s1 * s1d)
    c_ddot = 2 * (a4 * pin_a[0] + s1d * s1d + s1 * s1dd)
    inv_root = 1.0 / radical
    s4_dot = -(b_dot * s4 + 0.5 * c_dot) * inv_root
    s4_ddot = -(s4_dot * s4_dot + 2 * b_dot * s4_dot + b_ddot * s4 + 0.5 * c_ddot) * inv_root
    inv_a2 = 1.0 / a2
    ball = (-a4, -sa * s4, -ca * s4)
    u = ((-a4 - a1c) * inv_a2, (ball[1] - a1s) * inv_a2, (ball[2] - s1) * inv_a2)
    u_dot = (-pin_v[0] * inv_a2, (-sa * s4_dot - pin_v[1]) * inv_a2,
             (-ca * s4_dot - s1d) * inv_a2)
    u_ddot = (-pin_a[0] * inv_a2, (-sa * s4_ddot - pin_a[1]) * inv_a2,
              (-ca * s4_ddot - s1dd) * inv_a2)
    return {
        "s4": s4, "s4_dot": s4_dot, "s4_ddot": s4_ddot,
        "pin": (a1c, a1s, s1), "pin_v": pin_v, "pin_a": pin_a, "ball": ball,
        "u": u, "u_dot": u_dot, "u_ddot": u_ddot,
    }


def rahman_rod_axes(u: tuple[Any, Any, Any]) -> tuple[tuple[Any, Any, Any], tuple[Any, Any, Any]]:
    """y3 and z3 of Rahman's rod frame {3} = Z(θ1 + θ2)·Y(η2) with x3 = u:
    y3 = (−u_y, u_x, 0)/ρ, z3 = u × y3 (SPEC §1.1; y3 = (0, 1, 0) where u is vertical)."""
    rho2 = u[0] * u[0] + u[1] * u[1]
    defined = rho2 > GIMBAL_TOL**2
    inv_rho = 1.0 / np.sqrt(np.where(defined, rho2, 1.0))
    y3 = (np.where(defined, -u[1] * inv_rho, 0.0), np.where(defined, u[0] * inv_rho, 1.0),
          np.zeros_like(rho2))
    z3 = (-u[2] * y3[1], u[2] * y3[0], u[0] * y3[1] - u[1] * y3[0])
    return y3, z3


def _cross3(a: tuple[Any, Any, Any], b: tuple[Any, Any, Any]) -> tuple[Any, Any, Any]:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


Rows = list[Any]  # one entry per component: an (n,) array, or a float for a constant


@dataclass(frozen=True)
class CSSPBlockRows:
    """The link motion of one block of samples, component by component (structure of arrays),
    world frame; entries are (n,) arrays or floats (0.0 where a component is zero throughout).

    ``rotation`` 27 rows (link l, entry R[i, j] at 9l + 3i + j); ``origin``, ``velocity``,
    ``acceleration`` (of the link origins), ``angular_velocity``, ``angular_acceleration``
    9 rows (3l + i); ``centres``, ``axes`` 12 rows (joint j at 3j + i) — the layout of the
    ModeMotion arrays flattened behind the sample axis. ``loop`` holds loop-frame quantities
    of the ball joints' coordinates (crank angle cos/sin, rod frame, rod ω and α, crank rates),
    ``s4`` (s4, ṡ4, s̈4) and ``closure`` the translational loop-closure gap (m).
    """

    rotation: Rows
    origin: Rows
    velocity: Rows
    acceleration: Rows
    angular_velocity: Rows
    angular_acceleration: Rows
    centres: Rows
    axes: Rows
    s4: tuple[Array, Array, Array]
    closure: Array
    loop: dict[str, Any]


def _place(rows: Rows, R: Array, p: Array | None, rotations: bool = False) -> Rows:
    """world = R·loop (+ p for points) for every 3-vector of ``rows``; with ``rotations`` the
    rows are 3×3 matrices (9 per link) and each of their columns is rotated."""
    out: Rows = list(rows)
    if rotations:
        groups = [[b + 3 * i + col for i in range(3)]
                  for b in range(0, len(rows), 9) for col in range(3)]
    else:
        groups = [[b, b + 1, b + 2] for b in range(0, len(rows), 3)]
    for idx in groups:
        v = (rows[idx[0]], rows[idx[1]], rows[idx[2]])
        for i, k in enumerate(idx):
            value = combine(R[i], v)
            if p is not None and p[i] != 0.0:
                value = float(p[i]) if type(value) is float and value == 0.0 else value + p[i]
            out[k] = value
    return out


def cssp_block_rows(
    sw: CSSPSweep, sel: slice | NDArray[np.intp], base_R: Array, base_p: Array
) -> CSSPBlockRows:
    """Link frames, their rates, joint centres and axes of the samples ``sel`` of a sweep
    (:class:`CSSPBlockRows`) from the closed form (SPEC §1.2; frames of the module docstring),
    placed in the world by the linkage base (R, p). Shared by :func:`cssp_mode_motion`, which
    stores the rows, and the fused CSSP inverse dynamics, which consumes them block by block."""
    dims, driven_offset = sw.dims, sw.driven_offset
    ct, st = sw.cos[sel], sw.sin[sel]
    w, wd = sw.block("theta1_dot", sel), sw.block("theta1_ddot", sel)
    s1 = sw.block("s1", sel)
    s1d, s1dd = sw.block("s1_dot", sel), sw.block("s1_ddot", sel)
    k = cssp_closed_form_block(dims, sw.root, ct, st, w, wd, s1, s1d, s1dd,
                               sw.discriminant[sel])
    u, ud, udd = k["u"], k["u_dot"], k["u_ddot"]
    y3, z3 = rahman_rod_axes(u)
    # the zero-spin frame: {3} turned about u by the sweep's rod turn φ (module docstring)
    c, s = np.cos(sw.rod_turn[sel]), np.sin(sw.rod_turn[sel])
    y3, z3 = (tuple(c * y + s * z for y, z in zip(y3, z3, strict=True)),
              tuple(c * z - s * y for y, z in zip(y3, z3, strict=True)))
    rod = ((u[0], y3[0], z3[0]), (u[1], y3[1], z3[1]), (u[2], y3[2], z3[2]))
    w_rod = _cross3(u, ud)
    al_rod = _cross3(u, udd)
    slider_R = rot_x(np.array(-(dims.alpha4 + np.pi / 2)))
    k4 = dims.slider_axis
    s4, s4d, s4dd = k["s4"], k["s4_dot"], k["s4_ddot"]
    rotation: Rows = [ct, -st, 0.0, st, ct, 0.0, 0.0, 0.0, 1.0]
    rotation += [rod[i][j] for i in range(3) for j in range(3)]
    rotation += [float(x) for x in slider_R.ravel()]
    ball = [-dims.a4, k["ball"][1], k["ball"][2]]
    origin: Rows = [0.0, 0.0, s1, *k["pin"], *ball]
    velocity: Rows = [0.0, 0.0, s1d, *k["pin_v"], 0.0, -k4[1] * s4d, -k4[2] * s4d]
    acceleration: Rows = [0.0, 0.0, s1dd, *k["pin_a"], 0.0, -k4[1] * s4dd, -k4[2] * s4dd]
    angular_velocity: Rows = [0.0, 0.0, w, *w_rod, 0.0, 0.0, 0.0]
    angular_acceleration: Rows = [0.0, 0.0, wd, *al_rod, 0.0, 0.0, 0.0]
    # a C joint's centre is its frame origin on z1, an R joint's sits at its offset (loop.forward)
    centres: Rows = [0.0, 0.0, 0.0 if driven_offset else s1, *k["pin"], *ball, *ball]
    axes: Rows = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0, *z3, *(float(x) for x in k4)]
    if not (np.array_equal(base_R, np.eye(3)) and not np.any(base_p)):
        rotation = _place(rotation, base_R, None, rotations=True)
        origin = _place(origin, base_R, base_p)
        centres = _place(centres, base_R, base_p)
        velocity = _place(velocity, base_R, None)
        acceleration = _place(acceleration, base_R, None)
        angular_velocity = _place(angular_velocity, base_R, None)
        angular_acceleration = _place(angular_acceleration, base_R, None)
        axes = _place(axes, base_R, None)
    span = np.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
    return CSSPBlockRows(
        rotation=rotation, origin=origin, velocity=velocity, acceleration=acceleration,
        angular_velocity=angular_velocity, angular_acceleration=angular_acceleration,
        centres=centres, axes=axes, s4=(s4, s4d, s4dd),
        closure=dims.a2 * np.abs(span - 1.0),  # ||P − D1| − a2|
        loop={"ct": ct, "st": st, "rod": rod, "w_rod": w_rod, "al_rod": al_rod, "w": w,
              "wd": wd, "slider_R": slider_R, "u": u, "u_dot": ud, "u_ddot": udd},
    )


def _write_rows(stores: tuple[Array | None, ...], rows: CSSPBlockRows, sl: slice) -> None:
    """Store a block's link rows (rotation, origin, velocity, acceleration, angular velocity
    and acceleration, joint centres, axes) into their component-major storage (``None``:
    stored with another)."""
    for storage, component_rows in zip(stores, (
            rows.rotation, rows.origin, rows.velocity, rows.acceleration,
            rows.angular_velocity, rows.angular_acceleration, rows.centres, rows.axes),
            strict=True):
        if storage is not None:
            _write(storage, component_rows, sl)


def _write(storage: Array, rows: Rows, sl: slice) -> None:
    """Store a block's rows into component-major storage (zero rows are already zero)."""
    flat = storage.reshape(-1, storage.shape[-1])
    for r, value in enumerate(rows):
        if not (type(value) is float and value == 0.0):
            flat[r, sl] = value


def _joint_tables(linkage: Linkage, sw: CSSPSweep, s4_st: Array,
                  vectors: Array | None, rates: Array | None, seed: Array | None = None,
                  ) -> tuple[dict[str, Array], dict[str, Array], dict[str, Array]]:
    """The joint variables of a CSSP mode, their rates and accelerations by name: the crank's
    θ1 (and s1 when driven), the ball joints' rotation vectors (rows of ``vectors`` (2, 3, N),
    when given) and child-frame rates (when ``rates`` holds them), the slider's s4, and
    Rahman's angles with their rates (rows of ``seed`` (12, N), when given)."""
    first = linkage.joints[0].name
    pin, ball, slider = (j.name for j in linkage.joints[1:])
    # the sweep's θ1 is shared by both roots' modes: a mode that is masked (NaN where it does
    # not assemble, _mask_unassembled) gets its own
    theta1 = sw.theta1 if sw.assembles.all() else sw.theta1.copy()
    variables: dict[str, Array] = {f"{first}.theta": theta1}
    velocities: dict[str, Array] = {f"{first}.theta": sw.full("theta1_dot")}
    accelerations: dict[str, Array] = {f"{first}.theta": sw.full("theta1_ddot")}
    if sw.driven_offset:
        variables[f"{first}.s"] = sw.full("s1")
        velocities[f"{first}.s"] = sw.full("s1_dot")
        accelerations[f"{first}.s"] = sw.full("s1_ddot")
    for name, r in ((pin, 0), (ball, 2)):
        if rates is None:
            break
        for a, ax in enumerate("xyz"):
            if vectors is not None:  # NaN where it does not assemble: _mask_unassembled
                variables[f"{name}.r{ax}"] = vectors[r // 2, a]
            velocities[f"{name}.w{ax}"] = rates[r, a]
            accelerations[f"{name}.w{ax}"] = rates[r + 1, a]
    variables[f"{slider}.s"] = s4_st[0]
    velocities[f"{slider}.s"] = s4_st[1]
    accelerations[f"{slider}.s"] = s4_st[2]
    for r, key in enumerate(SEED_ANGLES if seed is not None else ()):
        assert seed is not None
        variables[key], velocities[key], accelerations[key] = seed[r], seed[4 + r], seed[8 + r]
    return variables, velocities, accelerations


def cssp_mode_motion(
    linkage: Linkage,
    theta1: ArrayLike,
    theta1_dot: ArrayLike = 0.0,
    theta1_ddot: ArrayLike = 0.0,
    root: int = SEED_ROOT,
    *,
    s1: ArrayLike | None = None,
    s1_dot: ArrayLike = 0.0,
    s1_ddot: ArrayLike = 0.0,
    allow_partial: bool = False,
    joint_rotations: bool = True,
    ball_joints: bool = True,
    seed_angles: bool = False,
    lazy: bool = False,
) -> ModeMotion:
    """One assembly mode of a CSSP over N crank angles, from the closed form (no Newton).

    Same result as ``motion(linkage, theta1, theta1_dot, theta1_ddot).modes[k]`` for the mode
    whose slider position is s4 = −b + root·√(b² − c) (SPEC §1.2; ``root=+1`` is Rahman's
    branch), up to the rod's free spin angle (module docstring). ``theta1`` (N,) rad,
    ``theta1_dot``/``theta1_ddot`` rad/s, rad/s² (scalars or (N,)); ``s1``, ``s1_dot``,
    ``s1_ddot`` drive the crank offset of a CSSP built with ``s1_is_input=True`` (for a fixed
    offset they must be left out: the offset is ``linkage.parameters["s1"]``).

    Samples where the CSSP does not assemble raise ``CSSPAssemblyError`` unless
    ``allow_partial``, which marks them in ``assembles`` and fills them with NaN.
    ``joint_rotations=False`` skips the rotation vectors of the two ball joints in
    ``variables`` (``pin.rx`` …; the costliest part on 10⁶ samples, unused by the dynamics).
    ``ball_joints=False`` also leaves out the ball joints' relative rotations (``conf.spherical``
    is then a read-only NaN view) and their rates (``pin.w*``, ``ball.w*`` in ``velocities`` and
    ``accelerations``): everything inverse dynamics reads — link frames and their rates, joint
    centres and axes, the scalar joint variables — is kept, at two thirds of the cost.
    ``seed_angles=True`` adds Rahman's θ2, η2, θ3, η3 and their rates (SPEC §1.1; θ2 wrapped
    into (−π, π]) to the tables, from the closed form's u, u̇, ü block by block.
    ``lazy=True`` computes the ball joints' fields and Rahman's angles (what ``ball_joints`` and
    ``seed_angles`` add) when they are first read, in a second blocked pass
    (:mod:`screwkit.kinematics.closed_forms.cssp_joint_fields`; the same values, the same keys
    in the same order): ``conf`` is then a
    :class:`~screwkit.kinematics.lazy_fields.LazyConfiguration` and the tables
    :class:`~screwkit.kinematics.lazy_fields.LazyTable` s.

    Computed in blocks of :data:`BLOCK_SAMPLES` samples in structure-of-arrays form (the lean
    pass — ``ball_joints=False`` or ``lazy=True`` — by the compiled loop of
    :mod:`~screwkit.kinematics.closed_forms.cssp_compiled` where it applies: the same rows). The (N, …)
    arrays are views of component-major storage (every component contiguous over the samples;
    not C-contiguous): the values are those of the (N, …) layout, and the blocked inverse
    dynamics reads them without a transposing copy.
    """
    sw = cssp_sweep(linkage, theta1, theta1_dot, theta1_ddot, root, s1=s1, s1_dot=s1_dot,
                    s1_ddot=s1_ddot, allow_partial=allow_partial)
    return sweep_mode_motion(linkage, sw, joint_rotations=joint_rotations,
                             ball_joints=ball_joints, seed_angles=seed_angles, lazy=lazy)


def sweep_mode_motion(linkage: Linkage, sw: CSSPSweep, *, joint_rotations: bool = True,
                      ball_joints: bool = True, seed_angles: bool = False,
                      lazy: bool = False) -> ModeMotion:
    """:func:`cssp_mode_motion` of a prepared sweep (:func:`cssp_sweep`, or
    :func:`~screwkit.kinematics.closed_forms.cssp_inputs.sweep_for_root` for the other root
    of the same inputs), with the same options."""
    joint_rotations = joint_rotations and ball_joints
    if lazy and (ball_joints or seed_angles):
        return _lazy_mode_motion(linkage, sw, joint_rotations, ball_joints, seed_angles)
    return _mode_motion(linkage, sw, joint_rotations, ball_joints, seed_angles)


def _mode_motion(linkage: Linkage, sw: CSSPSweep, joint_rotations: bool, ball_joints: bool,
                 seed_angles: bool) -> ModeMotion:
    """:func:`cssp_mode_motion` of a checked sweep, every field computed now."""
    driven_offset, n, ok = sw.driven_offset, sw.n, sw.assembles
    th = sw.theta1

    R_st, link_rotation = component_major(n, 3, 3, 3)
    C_st, joint_centres = component_major(n, 4, 3)
    O_st: Array | None = None
    if driven_offset:  # a C joint's centre is on z1 at 0, the crank frame's origin at s1
        O_st, link_origin = component_major(n, 3, 3)
    else:
        # the crank frame's origin is the R joint's centre, the rod's the pin's and the
        # slider's the ball's: the link origins are the first three joint centres, stored once
        link_origin = np.moveaxis(C_st[:3], -1, 0)
    V_st, link_origin_velocity = component_major(n, 3, 3)
    A_st, link_origin_acceleration = component_major(n, 3, 3)
    W_st, link_angular_velocity = component_major(n, 3, 3)
    AL_st, link_angular_acceleration = component_major(n, 3, 3)
    X_st, joint_axes = component_major(n, 4, 3)
    RV_st: Array | None = None
    if ball_joints:
        # pin: R_crankᵀR_rod, ball: R_rodᵀR_slider; pin, ball joint rates and "accelerations"
        REL_st, relative = component_major(n, 2, 3, 3)
        RATE_st, _ = component_major(n, 4, 3)
        if joint_rotations:  # the ball joints' rotation vectors
            RV_st = np.empty((2, 3, n))
    else:
        relative = np.broadcast_to(np.nan, (n, 2, 3, 3))
    SEED_st = np.empty((12, n)) if seed_angles else None
    s4_st = np.empty((3, n))  # s4, ṡ4, s̈4
    closure = np.empty(n)
    base_R, base_p = linkage.base.real, linkage.base.translation
    if (not ball_joints and SEED_st is None and cssp_compiled.use_compiled(n)
            and np.array_equal(base_R, np.eye(3)) and not np.any(base_p)):
        # the same rows, written by the compiled loop (cssp_compiled); the rows the numpy
        # route leaves unwritten (a constant zero) are those of one sample's block rows
        one = cssp_block_rows(sw, slice(0, 1), base_R, base_p)
        write = [not (type(v) is float and v == 0.0) for rows in (
            one.rotation, one.origin, one.velocity, one.acceleration, one.angular_velocity,
            one.angular_acceleration, one.centres, one.axes) for v in rows] + [True] * 4
        cssp_compiled.lean_rows(sw, [R_st, O_st, V_st, A_st, W_st, AL_st, C_st, X_st, s4_st,
                                     closure], write)
        n_blocks = 0
    else:
        n_blocks = n
    for start in range(0, n_blocks, BLOCK_SAMPLES):
        sl = slice(start, min(start + BLOCK_SAMPLES, n))
        rows = cssp_block_rows(sw, sl, base_R, base_p)
        _write_rows((R_st, O_st, V_st, A_st, W_st, AL_st, C_st, X_st), rows, sl)
        s4_st[0, sl], s4_st[1, sl], s4_st[2, sl] = rows.s4
        closure[sl] = rows.closure
        if ball_joints:
            ball_joint_block(rows.loop, REL_st, RATE_st, sl)
            if RV_st is not None:
                rotation_vector_block(REL_st, RV_st, ok[sl], sl)
        if SEED_st is not None:
            seed_angle_block(sw.dims, th[sl], rows.loop, ok[sl], SEED_st, sl)

    scalars = [th] + ([sw.full("s1")] if driven_offset else []) + [s4_st[0]]
    conf = Configuration(np.stack(scalars, -1), relative)
    variables, velocities, accelerations = _joint_tables(
        linkage, sw, s4_st, RV_st, RATE_st if ball_joints else None, SEED_st)

    arrays = [link_rotation, link_origin, link_angular_velocity, link_origin_velocity,
              link_angular_acceleration, link_origin_acceleration, joint_centres, joint_axes]
    if ball_joints:
        arrays.append(relative)
    _mask_unassembled(ok, arrays, conf, (variables, velocities, accelerations), closure)
    closure /= linkage.length_scale
    bad = ~ok
    events = ([f"does not assemble at {int(bad.sum())} of {n} sample(s)"]
              if bad.any() and ok.any() else [])
    return ModeMotion(
        assembles=ok, singular=np.zeros(n, dtype=bool), conf=conf, variables=variables,
        velocities=velocities, accelerations=accelerations, link_rotation=arrays[0],
        link_origin=arrays[1], link_angular_velocity=arrays[2], link_origin_velocity=arrays[3],
        link_angular_acceleration=arrays[4], link_origin_acceleration=arrays[5],
        joint_centres=arrays[6], joint_axes=arrays[7], closure_residual=closure, events=events)


def _lazy_mode_motion(linkage: Linkage, sw: CSSPSweep, vectors: bool, ball_joints: bool,
                      seed: bool) -> ModeMotion:
    """:func:`cssp_mode_motion` with ``lazy=True``: the lean pass now, the joint fields of
    :func:`~screwkit.kinematics.closed_forms.cssp_joint_fields.joint_fields` on first read."""
    from screwkit.kinematics.closed_forms.cssp_joint_fields import joint_fields, joint_names
    from screwkit.kinematics.lazy_fields import LazyConfiguration, LazyFields, LazyTable

    lean = _mode_motion(linkage, sw, False, False, False)
    fields = LazyFields(lambda: joint_fields(linkage, sw, BLOCK_SAMPLES, vectors, seed))
    orders = joint_names(linkage, sw.driven_offset, ball_joints, vectors, seed)
    tables = []
    for key, order, eager in zip(("variables", "velocities", "accelerations"), orders,
                                 (lean.variables, lean.velocities, lean.accelerations),
                                 strict=True):
        tables.append(LazyTable(order, eager, [k for k in order if k not in eager],
                                lambda key=key: fields.get()[key]))  # type: ignore[misc]
    conf = (LazyConfiguration(lean.conf.scalars, lambda: fields.get()["spherical"])
            if ball_joints else lean.conf)
    from dataclasses import replace

    return replace(lean, conf=conf, variables=tables[0], velocities=tables[1],
                   accelerations=tables[2])


def _mask_unassembled(ok: NDArray[np.bool_], arrays: list[Array], conf: Configuration,
                      tables: tuple[dict[str, Array], ...], closure: Array) -> None:
    """NaN (in place) wherever the CSSP does not assemble."""
    bad = ~ok
    if not bad.any():
        return
    for arr in arrays:
        arr[bad] = np.nan
    conf.scalars[bad, -1] = np.nan
    for table in tables:
        for values in table.values():
            values[bad] = np.nan
    closure[bad] = np.nan

__all__ = [
    "CSSPBlockRows",
    "CSSPSweep",
    "NotACSSPError",
    "cssp_block_rows",
    "cssp_dimensions",
    "cssp_mode_motion",
    "cssp_sweep",
    "sweep_for_root",
    "sweep_mode_motion",
]

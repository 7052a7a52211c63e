"""The CSSP's fast inverse dynamics: structure-of-arrays link wrenches and the closed-form
statics of :mod:`screwkit.dynamics.cssp_statics`, block by block.

Two entry points share one kernel (:func:`cssp_rows_block`):

* :func:`cssp_mode_block` — what :func:`screwkit.dynamics.inverse_dynamics` runs on each block
  of any CSSP ModeMotion (from the closed form or from the generic solver);
* :func:`cssp_inverse_dynamics` — kinematics and dynamics fused: each block's link motion comes
  straight from the closed form (:func:`screwkit.kinematics.closed_forms.cssp_motion.cssp_block_rows`),
  so the (N, …) ModeMotion arrays are never built. Same results as
  ``inverse_dynamics(linkage, cssp_mode_motion(linkage, …))`` to round-off.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dynamics import component_arrays as soa
from screwkit.dynamics.checks import (
    DynamicsInputError,
    ExternalLoad,
    check_external_loads,
    check_link_masses,
    check_vector3,
)
from screwkit.dynamics.cssp_statics import CSSPStatics, cssp_block_statics, cssp_statics_for
from screwkit.dynamics.inertia import inertia_wrenches_soa
from screwkit.dynamics.loop_statics import statics_structure
from screwkit.dynamics.result import Array, Dynamics
from screwkit.dynamics.sample_blocks import BLOCK_SAMPLES, Outputs, Setup, as_dynamics, blocks
from screwkit.dynamics.screws import freedom_screws
from screwkit.kinematics.closed_forms.cssp import SEED_ROOT
from screwkit.kinematics.closed_forms.cssp_motion import (
    cssp_block_rows,
    cssp_mode_motion,
    cssp_sweep,
)
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.linkage import Linkage
from screwkit.model.mass import MassProperties

ExternalByLink = dict[int, tuple[Array, Array, Array]]


def _vectors(rows: list[soa.Scalar]) -> list[soa.Vec]:
    return [soa.vec(rows, 3 * k) for k in range(len(rows) // 3)]


def cssp_rows_block(
    linkage: Linkage,
    plan: CSSPStatics,
    masses: list[MassProperties],
    s: Setup,
    motion: dict[str, list[soa.Scalar]],
    external: ExternalByLink,
    out: Outputs,
) -> None:
    """Loads of one block from its link motion as component rows (``motion``: ``rotation``,
    ``origin``, ``angular_velocity``, ``angular_acceleration``, ``acceleration`` of the link
    origins, ``centres`` of the four joints, ``axes`` of the crank and slider joints; world
    frame), written into ``out`` (a block of :class:`Outputs`)."""
    ref = soa.const(s.reference)
    rotation, origin = motion["rotation"], motion["origin"]
    wrenches = inertia_wrenches_soa(
        masses, rotation, origin, motion["angular_velocity"], motion["angular_acceleration"],
        motion["acceleration"], s.gravity, s.reference,
    )
    for l, (force, moment, point) in external.items():
        at = soa.sub(soa.add(soa.vec(origin, 3 * l),
                             soa.rotate(rotation[9 * l : 9 * l + 9], soa.const(point))), ref)
        fe = soa.const(force)
        F, M = wrenches[l]
        wrenches[l] = (soa.add(F, fe), soa.add(M, soa.add(soa.const(moment), soa.cross(at, fe))))
    centres = [soa.sub(c, ref) for c in _vectors(motion["centres"])]
    st = cssp_block_statics(plan, wrenches, centres, _vectors(motion["axes"]),
                            linkage.length_scale)
    total_f, total_m = soa.ZERO, soa.ZERO
    for F, M in wrenches:
        total_f, total_m = soa.add(total_f, F), soa.add(total_m, M)
    arm = soa.const(s.reference - s.moment_point)
    soa.store(out.shaking_force, total_f)
    soa.store(out.shaking_moment, soa.add(total_m, soa.cross(arm, total_f)))
    inv_ell2 = 1.0 / linkage.length_scale**2
    scale2 = 0.0
    for j, (f, m) in enumerate(zip(st.forces, st.moments, strict=True)):
        soa.store(out.reaction_force[:, j], f)
        soa.store(out.reaction_moment[:, j], m)
        size2 = soa.plus(soa.dot(f, f), soa.mul(inv_ell2, soa.dot(m, m)))
        scale2 = max(scale2, float(np.max(size2)))
    for k, v in st.efforts.items():
        out.efforts[k][...] = v
    out.residual[...] = st.residual
    out.scale = math.sqrt(scale2)


def cssp_mode_block(
    linkage: Linkage,
    plan: CSSPStatics,
    masses: list[MassProperties],
    s: Setup,
    part: ModeMotion,
    external: ExternalByLink,
    out: Outputs,
    check_finite: bool = False,
) -> bool:
    """:func:`cssp_rows_block` for a block of a ModeMotion (rows read by
    :func:`screwkit.dynamics.component_arrays.rows`: views of component-major arrays, zero rows as 0.0).
    With ``check_finite``, first checks that the block's motion is finite (while it is in the
    cache) and returns False, computing nothing, if it is not."""
    finite: list[bool] | None = [] if check_finite else None
    motion = {
        "rotation": soa.rows(part.link_rotation, finite),
        "origin": soa.rows(part.link_origin, finite),
        "angular_velocity": soa.rows(part.link_angular_velocity, finite),
        "angular_acceleration": soa.rows(part.link_angular_acceleration, finite),
        "acceleration": soa.rows(part.link_origin_acceleration, finite),
        "centres": soa.rows(part.joint_centres, finite),
    }
    axes = soa.rows(part.joint_axes, finite)
    motion["axes"] = axes[0:3] + axes[9:12]
    if finite is not None:
        soa.rows(part.link_origin_velocity, finite)  # read only to check it
        if not all(finite):
            return False
    cssp_rows_block(linkage, plan, masses, s, motion, external, out)
    return True


def cssp_inverse_dynamics(
    linkage: Linkage,
    theta1: ArrayLike,
    theta1_dot: ArrayLike = 0.0,
    theta1_ddot: ArrayLike = 0.0,
    gravity: ArrayLike | None = None,
    moment_point: ArrayLike | None = None,
    *,
    root: int = SEED_ROOT,
    s1: ArrayLike | None = None,
    s1_dot: ArrayLike = 0.0,
    s1_ddot: ArrayLike = 0.0,
    external_loads: Mapping[str, ExternalLoad] | None = None,
    allow_partial: bool = False,
    block_size: int = BLOCK_SAMPLES,
) -> Dynamics:
    """Kinematics and inverse dynamics of a CSSP in one blocked pass (Rahman 1996 §2.1–2.2):
    the same :class:`Dynamics` as ``inverse_dynamics(linkage, cssp_mode_motion(linkage,
    theta1, theta1_dot, theta1_ddot, mode, s1=…), gravity, moment_point, …)`` — to round-off
    (the moments are taken about another interior reference point) — without building the
    ModeMotion: memory is the loads, joint centres and inputs (≈ 400 bytes per sample) plus
    one block.

    Arguments as :func:`screwkit.kinematics.closed_forms.cssp_motion.cssp_mode_motion` (crank angle and its
    rates, assembly ``mode``, driven crank offset) and
    :func:`screwkit.dynamics.inverse_dynamics` (gravity, moment point, external loads).
    Samples where the CSSP does not assemble raise ``CSSPAssemblyError`` unless
    ``allow_partial`` (then their loads are NaN and ``valid`` is False).
    """
    masses = check_link_masses(linkage)
    if not isinstance(block_size, int | np.integer) or block_size < 1:
        raise DynamicsInputError(f"block_size must be a positive integer, got {block_size!r}")
    sw = cssp_sweep(linkage, theta1, theta1_dot, theta1_ddot, root, s1=s1, s1_dot=s1_dot,
                    s1_ddot=s1_ddot, allow_partial=allow_partial)
    if not sw.assembles.any():
        from screwkit.dynamics.checks import NonAssemblingMotionError

        raise NonAssemblingMotionError(
            f"{linkage.name}: the mode assembles at none of its {sw.n} samples; choose a mode "
            "or a sweep where it does"
        )
    offset_names = ("s1", "s1_dot", "s1_ddot") if sw.driven_offset else ()
    valid_idx = np.flatnonzero(sw.assembles)
    # the generic statics structure and the reference point from (up to) 32 samples spread
    # over the valid ones, through the ModeMotion route (cheap at this size)
    take = valid_idx[np.unique(np.linspace(0, valid_idx.size - 1,
                                           min(32, valid_idx.size)).astype(int))]
    spread = cssp_mode_motion(
        linkage, sw.theta1[take], sw.block("theta1_dot", take), sw.block("theta1_ddot", take),
        sw.root, **{k: sw.block(k, take) for k in offset_names},  # type: ignore[arg-type]
        ball_joints=False)
    reference = np.mean(spread.joint_centres, axis=(0, 1))
    structure = statics_structure(freedom_screws(linkage, spread, reference),
                                  linkage.length_scale)
    plan = cssp_statics_for(linkage)
    if plan is None or structure.rank != 6 or structure.passive_count != 7:
        from screwkit.dynamics.inverse import inverse_dynamics

        mm = cssp_mode_motion(linkage, theta1, theta1_dot, theta1_ddot, root, s1=s1,
                              s1_dot=s1_dot, s1_ddot=s1_ddot, allow_partial=allow_partial,
                              ball_joints=False)
        return inverse_dynamics(linkage, mm, gravity, moment_point,
                                external_loads=external_loads, allow_partial=allow_partial)
    inputs = np.stack([sw.theta1] + ([sw.full("s1")] if sw.driven_offset else []), -1)
    inputs[~sw.assembles] = np.nan  # as the ModeMotion's variables, which inverse_dynamics reads
    s = Setup(valid=sw.assembles, inputs=inputs, reference=reference, structure=structure,
              gravity=check_vector3(gravity, "gravity"),
              moment_point=check_vector3(moment_point, "moment_point"))
    external = check_external_loads(linkage, external_loads)
    partial = not sw.assembles.all()
    out = Outputs.allocate(linkage, sw.n, fill=partial)
    joint_centres = soa.component_major(sw.n, 4, 3)
    if partial:
        joint_centres.fill(np.nan)
    base_R, base_p = linkage.base.real, linkage.base.translation
    for sel in blocks(sw.assembles, int(block_size)):
        rows = cssp_block_rows(sw, sel, base_R, base_p)
        motion = {
            "rotation": rows.rotation, "origin": rows.origin,
            "angular_velocity": rows.angular_velocity,
            "angular_acceleration": rows.angular_acceleration,
            "acceleration": rows.acceleration, "centres": rows.centres,
            "axes": rows.axes[0:3] + rows.axes[9:12],
        }
        dest = out.block(sel)
        cssp_rows_block(linkage, plan, masses, s, motion, external, dest)
        out.scatter(sel, dest)
        for r, value in enumerate(rows.centres):
            joint_centres[sel, r // 3, r % 3] = value
    if not np.isfinite(out.scale):
        raise DynamicsInputError(
            f"{linkage.name}: the loads overflow (non-finite) at some samples; check the "
            "crank rates and the mass properties for absurd magnitudes"
        )
    return as_dynamics(linkage, joint_centres, s, out)

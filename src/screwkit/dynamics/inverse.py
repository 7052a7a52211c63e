"""Inverse dynamics of a single closed loop and its regressor (loads = Y·π).

``inverse_dynamics(linkage, mode_motion)`` runs three steps, each its own module:

1. the applied inertia + weight (+ external) wrench of every moving link
   (:mod:`screwkit.dynamics.inertia`, Newton–Euler in the world frame);
2. the unit freedom screws of every joint (:mod:`screwkit.dynamics.screws`);
3. the joint wrenches and driven efforts from the link balances and the joints' "no work along a
   passive freedom" conditions (:mod:`screwkit.dynamics.loop_statics`).

The samples go through these steps in blocks (:mod:`screwkit.dynamics.sample_blocks`), written into
preallocated outputs. For a family with a registered closed-form statics (the CSSP,
:mod:`screwkit.dynamics.cssp_statics`, run by :mod:`screwkit.dynamics.cssp_fused_dynamics`), steps 2–3
are replaced by the closed form and step 1 runs in structure-of-arrays form: same results to
round-off, several times faster.

Every load is linear in the link loads, and those are linear in the inertial parameters, so
``regressor`` runs the same solve with one load column per parameter (Atkeson, An & Hollerbach
1986 form of the Newton–Euler equations; the closed loop adds nothing non-linear).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual.spatial import cross
from screwkit.dynamics import cssp_compiled as compiled
from screwkit.dynamics.checks import (
    DynamicsInputError,
    ExternalLoad,
    check_external_loads,
    check_link_masses,
    check_vector3,
    finite_samples,
    valid_samples,
)
from screwkit.dynamics.cssp_fused_dynamics import cssp_mode_block
from screwkit.dynamics.cssp_statics import CSSPStatics, cssp_statics_for
from screwkit.dynamics.inertia import inertia_wrench_regressor, inertia_wrenches
from screwkit.dynamics.loop_statics import (
    solve_loop_statics,
    statics_structure,
)
from screwkit.dynamics.result import Array, Dynamics, Indeterminacy
from screwkit.dynamics.sample_blocks import (
    BLOCK_SAMPLES,
    Outputs,
    Selection,
    Setup,
    as_dynamics,
    blocks,
    indeterminacy,
    joint_scale,
)
from screwkit.dynamics.screws import freedom_screws
from screwkit.errors import expect_instance
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.messages import listing, shown_values
from screwkit.model.linkage import Linkage
from screwkit.model.mass import N_INERTIAL_PARAMETERS, MassProperties

INERTIAL_PARAMETER_NAMES = ("m", "mcx", "mcy", "mcz", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")


class _NonFiniteMotion(Exception):
    """Internal: a block found a non-finite sample the optimistic run did not check for."""


def _subset(mode: ModeMotion, sel: Selection) -> ModeMotion:
    """The mode restricted to some samples (only the fields dynamics reads; views for a
    slice)."""
    from dataclasses import replace

    from screwkit.kinematics.lazy_fields import mapped_table

    return replace(
        mode,
        link_rotation=mode.link_rotation[sel],
        link_origin=mode.link_origin[sel],
        link_angular_velocity=mode.link_angular_velocity[sel],
        link_origin_velocity=mode.link_origin_velocity[sel],
        link_angular_acceleration=mode.link_angular_acceleration[sel],
        link_origin_acceleration=mode.link_origin_acceleration[sel],
        joint_centres=mode.joint_centres[sel],
        joint_axes=mode.joint_axes[sel],
        variables=mapped_table(mode.variables, lambda v: v[sel]),  # lazy entries stay lazy
    )


def _setup(
    linkage: Linkage,
    mode: ModeMotion,
    gravity: ArrayLike | None,
    moment_point: ArrayLike | None,
    inputs: ArrayLike | None,
    allow_partial: bool,
    check_finite: bool = True,
) -> Setup:
    """What every block needs. ``check_finite=False``: the caller checks each block's
    finiteness (:class:`_NonFiniteMotion` if it fails); only the samples read here are."""
    N = mode.assembles.shape[0]
    if inputs is None:
        columns = [mode.variables.get(name, np.full(N, np.nan)) for name in linkage.inputs]
        # one input: a view of the mode's variable (no copy, as for given ``inputs``)
        input_arr = (np.asarray(columns[0], dtype=float)[:, None] if len(columns) == 1
                     else np.stack(columns, -1))
    else:
        try:
            input_arr = np.asarray(inputs, dtype=float).reshape(N, -1)
        except (TypeError, ValueError):
            input_arr = np.zeros((N, 0))  # not N rows of numbers: named below
        if input_arr.shape[1] != len(linkage.inputs):
            raise DynamicsInputError(
                f"inputs must have one column per input ({listing(linkage.inputs)}); "
                f"got shape {shown_values(np.shape(inputs))}"
            )
    valid = valid_samples(linkage, mode, input_arr, allow_partial, check_finite=check_finite)
    idx = np.flatnonzero(valid)
    centres = mode.joint_centres if idx.size == N else mode.joint_centres[idx]
    reference = np.mean(centres, axis=(0, 1))
    # the generic rank of the statics from (up to) 32 samples spread over the valid ones
    take = idx[np.unique(np.linspace(0, idx.size - 1, min(32, idx.size)).astype(int))]
    spread = _subset(mode, take)
    if not check_finite and not (np.all(np.isfinite(reference)) and finite_samples(spread).all()):
        raise _NonFiniteMotion
    fs = freedom_screws(linkage, spread, reference)
    return Setup(
        valid=valid,
        inputs=input_arr,
        reference=reference,
        structure=statics_structure(fs, linkage.length_scale),
        gravity=check_vector3(gravity, "gravity"),
        moment_point=check_vector3(moment_point, "moment_point"),
    )


def _external_wrenches(
    linkage: Linkage, sub: ModeMotion, loads: Mapping[str, ExternalLoad] | None, ref: Array
) -> Array | None:
    by_link = check_external_loads(linkage, loads)
    if not by_link:
        return None
    N = sub.link_rotation.shape[0]
    out = np.zeros((N, len(linkage.links), 6))
    for l, (force, moment, point) in by_link.items():
        at = sub.link_origin[:, l] + sub.link_rotation[:, l] @ point - ref
        out[:, l, :3] = force
        out[:, l, 3:] = moment + cross(at, np.broadcast_to(force, at.shape))
    return out


def _cross_columns(a: Array, b: Array) -> Array:
    """a × b for vectors along axis −2 (the trailing axis is the load case)."""
    return np.stack(
        [
            a[..., 1, :] * b[..., 2, :] - a[..., 2, :] * b[..., 1, :],
            a[..., 2, :] * b[..., 0, :] - a[..., 0, :] * b[..., 2, :],
            a[..., 0, :] * b[..., 1, :] - a[..., 1, :] * b[..., 0, :],
        ],
        -2,
    )


def _block_loads(
    linkage: Linkage, s: Setup, part: ModeMotion, link_wrenches: Array
) -> dict[str, Any]:
    """Every load of some samples with a trailing load-case axis K, by the generic statics.
    ``link_wrenches`` (n, L, 6, K) about the reference point."""
    fs = freedom_screws(linkage, part, s.reference)
    centres = part.joint_centres - s.reference
    st = solve_loop_statics(fs, centres, link_wrenches, linkage.length_scale, s.structure)
    n = len(linkage.joints)
    total = link_wrenches.sum(axis=1)  # (n, 6, K)
    arm = (s.reference - s.moment_point)[None, :, None]
    shaking_moment = total[:, 3:] + _cross_columns(arm, total[:, :3])
    W = st.wrenches  # (n, n_joints, 6, K) proximal on distal
    sign = np.ones(n)
    sign[-1] = -1.0  # the last joint's distal link is the ground: report the load on the link
    f = W[:, :, :3] * sign[None, :, None, None]
    m_ref = W[:, :, 3:] * sign[None, :, None, None]
    m_c = m_ref - _cross_columns(centres[..., None], f)
    driven_names = [nm for nm, dv in zip(fs.names, fs.driven, strict=True) if dv]
    return {
        "shaking_force": total[:, :3],
        "shaking_moment": shaking_moment,
        "reaction_force": f,
        "reaction_moment": m_c,
        "efforts": {
            name: st.efforts[:, driven_names.index(name)] for name in linkage.inputs
        },
        "residual": st.residual,
    }


def _loads(linkage: Linkage, s: Setup, part: ModeMotion, link_wrenches: Array) -> dict[str, Any]:
    """:func:`_block_loads` of all valid samples at once, scattered to all N samples (NaN where
    not valid); used by the regressor."""
    loads = _block_loads(linkage, s, part, link_wrenches)
    N = s.valid.shape[0]

    def full(a: Array) -> Array:
        out = np.full((N, *a.shape[1:]), np.nan)
        out[s.valid] = a
        return out

    return {
        key: {k: full(v) for k, v in value.items()} if key == "efforts" else full(value)
        for key, value in loads.items()
    }


def _generic_block(
    linkage: Linkage, masses: list[MassProperties], s: Setup, part: ModeMotion,
    external_loads: Mapping[str, ExternalLoad] | None, out: Outputs,
) -> None:
    """One block by the generic Newton–Euler + loop statics (any single loop)."""
    B = inertia_wrenches(masses, part, s.gravity, s.reference)
    ext = _external_wrenches(linkage, part, external_loads, s.reference)
    if ext is not None:
        B = B + ext
    loads = _block_loads(linkage, s, part, B[..., None])
    out.shaking_force[...] = loads["shaking_force"][..., 0]
    out.shaking_moment[...] = loads["shaking_moment"][..., 0]
    out.reaction_force[...] = loads["reaction_force"][..., 0]
    out.reaction_moment[...] = loads["reaction_moment"][..., 0]
    for k, v in loads["efforts"].items():
        out.efforts[k][...] = v[:, 0]
    out.residual[...] = np.linalg.norm(loads["residual"][..., 0], axis=-1)
    out.scale = joint_scale(out.reaction_force, out.reaction_moment, linkage.length_scale)


def resolve_mode(linkage: Linkage | Motion, mode: ModeMotion | int,
                 inputs: ArrayLike | None) -> tuple[Linkage, ModeMotion, ArrayLike | None]:
    """(linkage, mode_motion, inputs) from either calling form of :func:`inverse_dynamics`:
    a Motion and a mode index, or a linkage and one mode's ModeMotion."""
    expect_instance(linkage, Linkage | Motion, "linkage",
                    "a solved Motion (sk.solve_motion(...)) or a Linkage")
    if isinstance(linkage, Motion):
        if not isinstance(mode, int | np.integer) or isinstance(mode, bool):
            raise DynamicsInputError(f"with a Motion, give the assembly mode as an index "
                                     f"0…{len(linkage.modes) - 1}; got {mode!r}")
        return linkage.linkage, linkage.mode(int(mode)), (linkage.inputs if inputs is None
                                                           else inputs)
    if not isinstance(mode, ModeMotion):
        raise DynamicsInputError("with a linkage, give one mode's ModeMotion (motion.mode(k)); "
                                 "or pass the Motion itself: inverse_dynamics(motion, k)")
    return linkage, mode, inputs


def inverse_dynamics(
    linkage: Linkage | Motion,
    mode_motion: ModeMotion | int = 0,
    gravity: ArrayLike | None = None,
    moment_point: ArrayLike | None = None,
    *,
    external_loads: Mapping[str, ExternalLoad] | None = None,
    inputs: ArrayLike | None = None,
    allow_partial: bool = False,
    closed_form: bool = True,
    block_size: int = BLOCK_SAMPLES,
) -> Dynamics:
    """Shaking force and moment, joint reactions and driven efforts of one assembly mode, over
    the cycle, in SI units (N, N·m; world frame).

    ``inverse_dynamics(motion, mode=0, gravity=…)`` takes a solved
    :class:`~screwkit.kinematics.motion.Motion` (:func:`screwkit.solve_motion`) and one of its
    modes; ``inverse_dynamics(linkage, mode_motion, …)`` takes a linkage and one
    :class:`~screwkit.kinematics.motion.ModeMotion` — e.g. the same motion with other mass
    properties (``linkage.with_links(...)``).

    Parameters
    ----------
    linkage:
        a :class:`Motion`, or the loop; every moving link needs ``mass`` (a MassProperties in its
        body frame).
    mode_motion:
        the mode index (with a Motion), or one mode's :class:`ModeMotion` (with a linkage).
    gravity:
        gravitational acceleration, world frame (m/s²), e.g. ``(0, 0, -9.80665)``; none if
        omitted.
    moment_point:
        point (world, m) about which the shaking moment is taken; the world origin if omitted.
    external_loads:
        constant loads on moving links by link name (:class:`ExternalLoad`).
    inputs:
        (N, n_in) input values of the sweep (``Motion.inputs``), to label samples in messages
        and in the result; read from the mode where omitted.
    allow_partial:
        accept samples that do not assemble or are singular (their loads are NaN); otherwise
        they raise :class:`NonAssemblingMotionError` naming them.
    closed_form:
        use the family's closed-form statics where one is registered (the CSSP:
        :mod:`screwkit.dynamics.cssp_statics`; same results to round-off); ``False`` forces
        the generic solve.
    block_size:
        samples per block (module constant :data:`BLOCK_SAMPLES`); results are the same for
        any block size, only speed and peak memory change.

    Newton–Euler with the closed-loop statics of :mod:`screwkit.dynamics.loop_statics`, run
    block by block into preallocated outputs; see docs/dynamics.md for the conventions and how
    indeterminate components are reported.
    """
    linkage, mode_motion, inputs = resolve_mode(linkage, mode_motion, inputs)
    if not isinstance(block_size, int | np.integer) or block_size < 1:
        raise DynamicsInputError(f"block_size must be a positive integer, got {block_size!r}")
    check_vector3(gravity, "gravity")  # argument mistakes before the model's
    check_vector3(moment_point, "moment_point")
    masses = check_link_masses(linkage)
    args = (linkage, mode_motion, masses, gravity, moment_point, external_loads, inputs,
            allow_partial, closed_form, int(block_size))
    if mode_motion.assembles.all() and not mode_motion.singular.any():
        # the usual case: check finiteness block by block, while the block is in the cache
        try:
            return _run(*args, check_finite=False)
        except _NonFiniteMotion:
            pass  # start again with the full check, which names the bad samples
    return _run(*args, check_finite=True)


def _run(
    linkage: Linkage,
    mode_motion: ModeMotion,
    masses: list[MassProperties],
    gravity: ArrayLike | None,
    moment_point: ArrayLike | None,
    external_loads: Mapping[str, ExternalLoad] | None,
    inputs: ArrayLike | None,
    allow_partial: bool,
    closed_form: bool,
    block_size: int,
    check_finite: bool,
) -> Dynamics:
    s = _setup(linkage, mode_motion, gravity, moment_point, inputs, allow_partial, check_finite)
    external = check_external_loads(linkage, external_loads)
    plan = _closed_form_plan(linkage, s) if closed_form else None
    N = s.valid.shape[0]
    out = Outputs.allocate(linkage, N, fill=not s.valid.all())
    if plan is not None and not external and compiled.use_compiled(N):  # same loads, compiled
        if not compiled.mode_loads(linkage, plan, masses, s, mode_motion, out, block_size,
                                   check_finite=not check_finite):
            raise _NonFiniteMotion
        return as_dynamics(linkage, mode_motion.joint_centres, s, out)
    for sel in blocks(s.valid, block_size):
        part = _subset(mode_motion, sel)
        dest = out.block(sel)
        if plan is not None:
            if not cssp_mode_block(linkage, plan, masses, s, part, external, dest,
                                   check_finite=not check_finite):
                raise _NonFiniteMotion
        else:
            if not check_finite and not finite_samples(part).all():
                raise _NonFiniteMotion
            _generic_block(linkage, masses, s, part, external_loads, dest)
        out.scatter(sel, dest)
    return as_dynamics(linkage, mode_motion.joint_centres, s, out)


def _closed_form_plan(linkage: Linkage, s: Setup) -> CSSPStatics | None:
    """The closed-form statics registered for this linkage's family, if one applies (only the
    CSSP has one): it needs the generic rank of the statics (6, with one idle freedom, the
    rod spin) that the closed form assumes."""
    plan = cssp_statics_for(linkage)
    st = s.structure
    if plan is None or st.rank != 6 or st.passive_count != 7:
        return None
    return plan


@dataclass(frozen=True, eq=False)
class Regressor:
    """Loads linear in the inertial parameters: load = Y·π + constant.

    π (P = 10·L) stacks the parameters of the moving links in link order, each as
    :meth:`MassProperties.inertial_parameters` (about the link body-frame origin);
    ``parameter_names`` labels them ``"<link>.<m|mcx|…|Iyz>"``. Arrays carry P as their last
    axis: ``shaking_force`` (N, 3, P), ``shaking_moment`` (N, 3, P), ``reactions`` {joint:
    {"force", "moment"}: (N, 3, P)}, ``efforts`` {freedom: (N, P)}, ``residual`` (N, m_p, P)
    (the idle-freedom generalised force, a vector). ``constant`` holds the π-independent part
    (external loads) with the same keys and a last axis of length 1; zero without external loads.
    ``indeterminacy`` says which reaction components the joints leave undetermined and how many
    idle passive freedoms (an S–S rod's spin) the loads can act along (``residual``).
    """

    parameter_names: tuple[str, ...]
    shaking_force: Array
    shaking_moment: Array
    reactions: Mapping[str, Mapping[str, Array]]
    efforts: Mapping[str, Array]
    residual: Array
    constant: Mapping[str, Any]
    indeterminacy: Indeterminacy
    _linkage: Linkage
    _mode: ModeMotion
    _setup: Setup

    def parameters_of(self, linkage: Linkage | None = None) -> Array:
        """π of the links of ``linkage`` (default the one the regressor was built for)."""
        lk = self._linkage if linkage is None else linkage
        return np.concatenate([mp.inertial_parameters() for mp in check_link_masses(lk)])

    def apply(self, parameters: ArrayLike) -> Dynamics:
        """The loads for inertial parameters π (P,): a :class:`Dynamics` equal to
        ``inverse_dynamics`` of links with those parameters."""
        pi = np.asarray(parameters, dtype=float)
        P = len(self.parameter_names)
        if pi.shape != (P,) or not np.all(np.isfinite(pi)):
            raise DynamicsInputError(
                f"parameters must be a finite vector of length {P} (10 per moving link, "
                f"order {self.parameter_names[:10]}…); got shape {pi.shape}"
            )
        c = self.constant
        forces = np.stack([r["force"] @ pi for r in self.reactions.values()], 1)
        moments = np.stack([r["moment"] @ pi for r in self.reactions.values()], 1)
        out = Outputs(
            shaking_force=self.shaking_force @ pi + c["shaking_force"][..., 0],
            shaking_moment=self.shaking_moment @ pi + c["shaking_moment"][..., 0],
            reaction_force=forces + c["reaction_force"][..., 0],
            reaction_moment=moments + c["reaction_moment"][..., 0],
            efforts={k: v @ pi + c["efforts"][k][..., 0] for k, v in self.efforts.items()},
            residual=np.linalg.norm(self.residual @ pi + c["residual"][..., 0], axis=-1),
        )
        out.scale = joint_scale(out.reaction_force, out.reaction_moment,
                                 self._linkage.length_scale)
        return as_dynamics(self._linkage, self._mode.joint_centres, self._setup, out)


def regressor(
    linkage: Linkage | Motion,
    mode_motion: ModeMotion | int,
    gravity: ArrayLike | None = None,
    moment_point: ArrayLike | None = None,
    *,
    external_loads: Mapping[str, ExternalLoad] | None = None,
    inputs: ArrayLike | None = None,
    allow_partial: bool = False,
) -> Regressor:
    """The regressor Y of every load of :func:`inverse_dynamics` in the stacked inertial
    parameters π of the moving links (load = Y·π + constant). Mass properties on the links are
    not needed (they are what π describes). Same arguments as :func:`inverse_dynamics`."""
    linkage, mode_motion, inputs = resolve_mode(linkage, mode_motion, inputs)
    s = _setup(linkage, mode_motion, gravity, moment_point, inputs, allow_partial)
    sub = mode_motion if s.valid.all() else _subset(mode_motion, np.flatnonzero(s.valid))
    Y = inertia_wrench_regressor(sub, s.gravity, s.reference)  # (Nv, L, 6, 10)
    Nv, L = Y.shape[:2]
    P = N_INERTIAL_PARAMETERS * L
    B = np.zeros((Nv, L, 6, P))
    for l in range(L):
        B[:, l, :, N_INERTIAL_PARAMETERS * l : N_INERTIAL_PARAMETERS * (l + 1)] = Y[:, l]
    ext = _external_wrenches(linkage, sub, external_loads, s.reference)
    const = _loads(linkage, s, sub, (np.zeros((Nv, L, 6)) if ext is None else ext)[..., None])
    loads = _loads(linkage, s, sub, B)
    reactions = {
        j.name: {
            "force": loads["reaction_force"][:, k],
            "moment": loads["reaction_moment"][:, k],
        }
        for k, j in enumerate(linkage.joints)
    }
    names = tuple(f"{lk.name}.{p}" for lk in linkage.links for p in INERTIAL_PARAMETER_NAMES)
    return Regressor(
        parameter_names=names,
        shaking_force=loads["shaking_force"],
        shaking_moment=loads["shaking_moment"],
        reactions=reactions,
        efforts=loads["efforts"],
        residual=loads["residual"],
        constant=const,
        indeterminacy=indeterminacy(s),
        _linkage=linkage,
        _mode=mode_motion,
        _setup=s,
    )

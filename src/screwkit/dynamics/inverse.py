"""Inverse dynamics of a single closed loop and its regressor (loads = Y·π).

``inverse_dynamics(linkage, mode_motion)`` runs three steps, each its own module:

1. the applied inertia + weight (+ external) wrench of every moving link
   (:mod:`screwkit.dynamics.inertia`, Newton–Euler in the world frame);
2. the unit freedom screws of every joint (:mod:`screwkit.dynamics.screws`);
3. the joint wrenches and driven efforts from the link balances and the joints' "no work along a
   passive freedom" conditions (:mod:`screwkit.dynamics.loop_statics`).

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

from screwkit.dynamics.checks import (
    DynamicsInputError,
    ExternalLoad,
    check_external_loads,
    check_link_masses,
    check_vector3,
    valid_samples,
)
from screwkit.dynamics.inertia import inertia_wrench_regressor, inertia_wrenches
from screwkit.dynamics.loop_statics import (
    StaticsStructure,
    solve_loop_statics,
    statics_structure,
)
from screwkit.dynamics.result import Array, Dynamics, Indeterminacy
from screwkit.dynamics.screws import FreedomScrews, _cross, freedom_screws
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.linkage import Linkage
from screwkit.model.mass import N_INERTIAL_PARAMETERS

INERTIAL_PARAMETER_NAMES = ("m", "mcx", "mcy", "mcz", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")


@dataclass(frozen=True)
class _Setup:
    valid: Any
    inputs: Array
    reference: Array
    screws: FreedomScrews
    centres: Array  # (Nv, n, 3) relative to the reference
    structure: StaticsStructure
    gravity: Array
    moment_point: Array


def _take_valid(mode: ModeMotion, valid: Any) -> ModeMotion:
    """A view of the mode restricted to the valid samples (only the fields dynamics reads)."""
    from dataclasses import replace

    return replace(
        mode,
        link_rotation=mode.link_rotation[valid],
        link_origin=mode.link_origin[valid],
        link_angular_velocity=mode.link_angular_velocity[valid],
        link_origin_velocity=mode.link_origin_velocity[valid],
        link_angular_acceleration=mode.link_angular_acceleration[valid],
        link_origin_acceleration=mode.link_origin_acceleration[valid],
        joint_centres=mode.joint_centres[valid],
        joint_axes=mode.joint_axes[valid],
        variables={k: v[valid] for k, v in mode.variables.items()},
    )


def _setup(
    linkage: Linkage,
    mode: ModeMotion,
    gravity: ArrayLike | None,
    moment_point: ArrayLike | None,
    inputs: ArrayLike | None,
    allow_partial: bool,
) -> tuple[_Setup, ModeMotion]:
    N = mode.assembles.shape[0]
    if inputs is None:
        input_arr = np.stack(
            [mode.variables.get(name, np.full(N, np.nan)) for name in linkage.inputs], -1
        )
    else:
        input_arr = np.asarray(inputs, dtype=float).reshape(N, -1)
        if input_arr.shape[1] != len(linkage.inputs):
            raise DynamicsInputError(
                f"inputs must have one column per input {list(linkage.inputs)}; "
                f"got shape {np.shape(inputs)}"
            )
    valid = valid_samples(linkage, mode, input_arr, allow_partial)
    sub = mode if valid.all() else _take_valid(mode, valid)
    reference = np.mean(sub.joint_centres, axis=(0, 1))
    fs = freedom_screws(linkage, sub, reference)
    structure = statics_structure(fs, linkage.length_scale)
    setup = _Setup(
        valid=valid,
        inputs=input_arr,
        reference=reference,
        screws=fs,
        centres=sub.joint_centres - reference,
        structure=structure,
        gravity=check_vector3(gravity, "gravity"),
        moment_point=check_vector3(moment_point, "moment_point"),
    )
    return setup, sub


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
        out[:, l, 3:] = moment + _cross(at, np.broadcast_to(force, at.shape))
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


def _loads(linkage: Linkage, s: _Setup, link_wrenches: Array) -> dict[str, Any]:
    """Every load with a trailing load-case axis K, scattered to all N samples (NaN where not
    valid). ``link_wrenches`` (Nv, L, 6, K) about the reference point."""
    st = solve_loop_statics(
        s.screws, s.centres, link_wrenches, linkage.length_scale, s.structure
    )
    N = s.valid.shape[0]
    K = link_wrenches.shape[-1]
    n = len(linkage.joints)

    def full(a: Array) -> Array:
        out = np.full((N, *a.shape[1:]), np.nan)
        out[s.valid] = a
        return out

    total = link_wrenches.sum(axis=1)  # (Nv, 6, K)
    arm = (s.reference - s.moment_point)[None, :, None]
    shaking_moment = total[:, 3:] + _cross_columns(arm, total[:, :3])
    W = st.wrenches  # (Nv, n, 6, K) proximal on distal
    sign = np.ones(n)
    sign[-1] = -1.0  # the last joint's distal link is the ground: report the load on the link
    f = W[:, :, :3] * sign[None, :, None, None]
    m_ref = W[:, :, 3:] * sign[None, :, None, None]
    m_c = m_ref - _cross_columns(s.centres[..., None], f)
    driven_names = [nm for nm, dv in zip(s.screws.names, s.screws.driven, strict=True) if dv]
    efforts = {
        name: full(st.efforts[:, driven_names.index(name)]) for name in linkage.inputs
    }
    return {
        "shaking_force": full(total[:, :3]),
        "shaking_moment": full(shaking_moment),
        "reaction_force": full(f),
        "reaction_moment": full(m_c),
        "efforts": efforts,
        "residual": full(st.residual),
        "K": K,
    }


def _as_dynamics(linkage: Linkage, mode: ModeMotion, s: _Setup, loads: dict[str, Any]) -> Dynamics:
    """K = 1 loads → a :class:`Dynamics`."""
    reactions = {
        j.name: {
            "force": loads["reaction_force"][:, k, :, 0],
            "moment": loads["reaction_moment"][:, k, :, 0],
        }
        for k, j in enumerate(linkage.joints)
    }
    ell = linkage.length_scale
    joint_size = np.hypot(
        np.linalg.norm(loads["reaction_force"][..., 0], axis=-1),
        np.linalg.norm(loads["reaction_moment"][..., 0], axis=-1) / ell,
    )
    scale = float(np.nanmax(joint_size)) if np.any(s.valid) else 0.0
    directions = s.structure.indeterminate_directions.copy()
    # moment of each self-stress direction about the world origin
    directions[:, 3:] += _cross(np.broadcast_to(s.reference, directions[:, :3].shape),
                                directions[:, :3])
    return Dynamics(
        input_names=tuple(linkage.inputs),
        inputs=s.inputs,
        valid=s.valid,
        shaking_force=loads["shaking_force"][..., 0],
        shaking_moment=loads["shaking_moment"][..., 0],
        moment_point=s.moment_point,
        reactions=reactions,
        joint_centres=mode.joint_centres,
        efforts={k: v[:, 0] for k, v in loads["efforts"].items()},
        indeterminacy=Indeterminacy(
            count=s.structure.indeterminate_count,
            directions=directions,
            idle_freedoms=s.structure.idle_count,
        ),
        residual=np.linalg.norm(loads["residual"][..., 0], axis=-1),
        residual_scale=scale,
        gravity=s.gravity,
    )


def inverse_dynamics(
    linkage: Linkage,
    mode_motion: ModeMotion,
    gravity: ArrayLike | None = None,
    moment_point: ArrayLike | None = None,
    *,
    external_loads: Mapping[str, ExternalLoad] | None = None,
    inputs: ArrayLike | None = None,
    allow_partial: bool = False,
) -> Dynamics:
    """Shaking force and moment, joint reactions and driven efforts of one assembly mode.

    Parameters
    ----------
    linkage:
        the loop; every moving link needs ``mass`` (a MassProperties in its body frame).
    mode_motion:
        one mode of :func:`screwkit.kinematics.motion.motion` (``motion(...).modes[k]``).
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

    Newton–Euler with the closed-loop statics of :mod:`screwkit.dynamics.loop_statics`; see
    docs/dynamics.md for the conventions and how indeterminate components are reported.
    """
    masses = check_link_masses(linkage)
    s, sub = _setup(linkage, mode_motion, gravity, moment_point, inputs, allow_partial)
    B = inertia_wrenches(masses, sub, s.gravity, s.reference)
    ext = _external_wrenches(linkage, sub, external_loads, s.reference)
    if ext is not None:
        B = B + ext
    return _as_dynamics(linkage, mode_motion, s, _loads(linkage, s, B[..., None]))


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
    """

    parameter_names: tuple[str, ...]
    shaking_force: Array
    shaking_moment: Array
    reactions: Mapping[str, Mapping[str, Array]]
    efforts: Mapping[str, Array]
    residual: Array
    constant: Mapping[str, Any]
    _linkage: Linkage
    _mode: ModeMotion
    _setup: _Setup

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
        loads: dict[str, Any] = {
            "shaking_force": self.shaking_force @ pi + self.constant["shaking_force"][..., 0],
            "shaking_moment": self.shaking_moment @ pi + self.constant["shaking_moment"][..., 0],
            "reaction_force": np.stack(
                [r["force"] @ pi for r in self.reactions.values()], 1
            ) + self.constant["reaction_force"][..., 0],
            "reaction_moment": np.stack(
                [r["moment"] @ pi for r in self.reactions.values()], 1
            ) + self.constant["reaction_moment"][..., 0],
            "efforts": {
                k: v @ pi + self.constant["efforts"][k][..., 0] for k, v in self.efforts.items()
            },
            "residual": self.residual @ pi + self.constant["residual"][..., 0],
        }
        for key in ("shaking_force", "shaking_moment", "reaction_force", "reaction_moment",
                    "residual"):
            loads[key] = loads[key][..., None]
        loads["efforts"] = {k: v[..., None] for k, v in loads["efforts"].items()}
        return _as_dynamics(self._linkage, self._mode, self._setup, loads)


def regressor(
    linkage: Linkage,
    mode_motion: ModeMotion,
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
    s, sub = _setup(linkage, mode_motion, gravity, moment_point, inputs, allow_partial)
    Y = inertia_wrench_regressor(sub, s.gravity, s.reference)  # (Nv, L, 6, 10)
    Nv, L = Y.shape[:2]
    P = N_INERTIAL_PARAMETERS * L
    B = np.zeros((Nv, L, 6, P))
    for l in range(L):
        B[:, l, :, N_INERTIAL_PARAMETERS * l : N_INERTIAL_PARAMETERS * (l + 1)] = Y[:, l]
    ext = _external_wrenches(linkage, sub, external_loads, s.reference)
    const = _loads(linkage, s, (np.zeros((Nv, L, 6)) if ext is None else ext)[..., None])
    loads = _loads(linkage, s, B)
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
        _linkage=linkage,
        _mode=mode_motion,
        _setup=s,
    )

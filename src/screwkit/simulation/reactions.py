"""Every load of the loop over a simulated motion, from the existing inverse dynamics
(:func:`screwkit.dynamics.inverse_dynamics`) at the simulated speed and acceleration.

The motion at a simulated sample is the grid mode at its angle moved at the simulated θ̇, θ̈
(:meth:`~screwkit.simulation.reduced.ReducedModel.motion_at`: exact). The output load Q_out(t)
varies from sample to sample, and the inverse dynamics takes constant external loads, so the
loads are assembled by linearity (every load is linear in the applied wrenches):

    D = D_0 + Q_out · (D_1 − D_0),

D_0 the dynamics without the load and D_1 with a unit load on the output freedom: the wrench
whose power is Q_out q̇_out — a moment −u on the last moving link for a rotation about the
ground joint's axis u, a force −u on the axis for a translation (the last joint's freedom moves
the ground relative to the link). By virtual work its input effort is −r(θ) (tested).

Viscous joint friction (``[drive.friction]``) is a pair of opposite wrenches on the two links a
joint joins: on the distal link the moment −c_rot ω_rel and the force −c_slide ṡ u at the joint
centre. It enters the same way, by linearity, as a per-sample wrench on each moving link it
touches (unit forces and moments at the link's origin), and is then put where it belongs: into
the joint's reaction (the joint transmits it), and out of the shaking loads at the two ground
joints (it is a load between a link and the frame, not from outside: the shaking force and
moment stay −dḢ/dt + weight, whatever the friction — tested). The driven effort is the
actuator's torque, which now also overcomes the friction: its power exceeds the frictionless
one by B(θ) θ̇² (tested)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual.spatial import cross
from screwkit.dynamics import Dynamics, inverse_dynamics
from screwkit.dynamics.checks import ExternalLoad
from screwkit.dynamics.result import Reaction
from screwkit.kinematics.motion import ModeMotion
from screwkit.simulation.reduced import (
    Array,
    ReducedModel,
    joint_friction,
    relative_angular_velocity,
    sliding_rate,
)


def unit_output_load(model: ReducedModel, freedom: str) -> dict[str, ExternalLoad]:
    """The external load (on the last moving link) of a unit generalised force on ``freedom``,
    a freedom of the last joint (module docstring)."""
    md = model.grid_mode
    u = md.joint_axes[0, -1]
    link = model.linkage.links[-1].name
    if freedom.endswith(".s"):
        R, o = md.link_rotation[0, -1], md.link_origin[0, -1]
        point = R.T @ (md.joint_centres[0, -1] - o)
        return {link: ExternalLoad(force=-u, point=point)}
    return {link: ExternalLoad(moment=-u)}


def loop_loads(model: ReducedModel, indices: ArrayLike, speed: ArrayLike,
               acceleration: ArrayLike, *, gravity: ArrayLike | None = None,
               load_freedom: str | None = None, output_force: ArrayLike | None = None,
               inputs: ArrayLike | None = None, friction: Sequence[Any] = ()
               ) -> tuple[Dynamics, ModeMotion]:
    """The :class:`Dynamics` of the loop at grid samples ``indices`` moving at ``speed``,
    ``acceleration`` (M,), with ``gravity``, the generalised force ``output_force`` (M,) on
    ``load_freedom`` and the viscous joint ``friction`` (JointFriction items); and the motion it
    was computed on. ``inputs`` labels the samples (unwrapped input angles)."""
    mm = model.motion_at(indices, speed, acceleration)
    lk = model.linkage
    d0 = inverse_dynamics(lk, mm, gravity, inputs=inputs)
    terms: list[tuple[Dynamics, Array]] = []
    if load_freedom is not None and output_force is not None:
        unit = unit_output_load(model, load_freedom)
        terms.append((inverse_dynamics(lk, mm, gravity, inputs=inputs, external_loads=unit),
                      np.asarray(output_force, dtype=float)))
    wrenches = friction_wrenches(lk, mm, friction)
    for link, (F, M) in wrenches.links.items():
        for k in range(3):
            e = np.eye(3)[k]
            for load, w in ((ExternalLoad(force=e), F[:, k]), (ExternalLoad(moment=e), M[:, k])):
                if np.any(w):
                    terms.append((inverse_dynamics(lk, mm, gravity, inputs=inputs,
                                                   external_loads={link: load}), w))
    dyn = _superposed(d0, terms) if terms else d0
    return (_friction_in_joints(dyn, wrenches) if friction else dyn), mm


def _superposed(d0: Dynamics, terms: list[tuple[Dynamics, Array]]) -> Dynamics:
    """D_0 + Σ w_i (D_i − D_0): every load is linear in the applied wrenches (module docstring);
    the residual, a norm, bounded by the triangle inequality."""
    def total(get: Callable[[Dynamics], Array]) -> Array:
        base = get(d0)
        out = base.copy()
        for d, w in terms:
            out += w.reshape(-1, *([1] * (base.ndim - 1))) * (get(d) - base)
        return out

    weight = np.zeros_like(d0.residual)
    residual = np.zeros_like(d0.residual)
    for d, w in terms:
        weight = weight + w
        residual = residual + np.abs(w) * d.residual
    return replace(
        d0,
        shaking_force=total(lambda d: d.shaking_force),
        shaking_moment=total(lambda d: d.shaking_moment),
        reactions={name: Reaction(force=total(_reaction_field(name, "force")),
                                  moment=total(_reaction_field(name, "moment")),
                                  point=r0.point)
                   for name, r0 in d0.reactions.items()},
        efforts={k: total(_effort(k)) for k in d0.efforts},
        residual=np.abs(1.0 - weight) * d0.residual + residual,
    )


def _reaction_field(name: str, field: str) -> Callable[[Dynamics], Array]:
    return lambda d: np.asarray(getattr(d.reactions[name], field))


def _effort(name: str) -> Callable[[Dynamics], Array]:
    return lambda d: np.asarray(d.efforts[name])


@dataclass(frozen=True)
class FrictionWrenches:
    """The friction of every frictional joint over a motion (world frame, (M, 3) each):
    ``joints`` name -> (force, moment, joint index) on the joint's distal side (the moment is
    about the joint centre, where the force acts; for the last joint, index ``last``, the distal
    side is the ground); ``links`` moving-link name -> (force, moment about the link's origin)
    of all the friction it receives."""

    joints: dict[str, tuple[Array, Array, int]]
    links: dict[str, tuple[Array, Array]]
    last: int


def friction_wrenches(linkage: Any, mode: ModeMotion, friction: Sequence[Any]
                      ) -> FrictionWrenches:
    """Per-sample friction wrenches of ``friction`` on ``mode`` (module docstring); repeated
    entries for one joint add up."""
    friction = joint_friction(linkage, friction)
    index = {j.name: i for i, j in enumerate(linkage.joints)}
    names = [link.name for link in linkage.links]
    n = mode.link_origin.shape[0]
    joints: dict[str, tuple[Array, Array, int]] = {}
    links: dict[str, tuple[Array, Array]] = {}
    for fr in friction:
        j = index[fr.joint]
        moment = -fr.rotation * relative_angular_velocity(mode, j)
        force = np.zeros((n, 3))
        if fr.translation:
            u = mode.joint_axes[:, j]
            force = -fr.translation * sliding_rate(linkage, mode, j)[:, None] * u
        joints[fr.joint] = (force, moment, j)
        centre = mode.joint_centres[:, j]
        for link, sign in ((j, 1.0), (j - 1, -1.0)):  # distal gets +, proximal −
            if not 0 <= link < len(names):
                continue  # the ground
            arm = centre - mode.link_origin[:, link]
            F, M = links.get(names[link], (np.zeros((n, 3)), np.zeros((n, 3))))
            links[names[link]] = (F + sign * force, M + sign * (moment + cross(arm, force)))
    return FrictionWrenches(joints, links, len(linkage.joints) - 1)


def _friction_in_joints(dyn: Dynamics, wrenches: FrictionWrenches) -> Dynamics:
    """Move the friction, applied to the links as if from outside, to where it acts: into each
    joint's reaction, and out of the shaking loads for the two ground joints (module
    docstring)."""
    last = wrenches.last
    reactions = dict(dyn.reactions)
    sf, sm = dyn.shaking_force.copy(), dyn.shaking_moment.copy()
    for name, (force, moment, j) in wrenches.joints.items():
        r = reactions[name]
        # the reaction is on the distal link, or on the moving link for the last joint
        sign = -1.0 if j == last else 1.0
        reactions[name] = Reaction(force=r.force + sign * force,
                                   moment=r.moment + sign * moment, point=r.point)
        if j in (0, last):  # the moving link's share from the ground came in as external
            arm = r.point - dyn.moment_point
            sf -= sign * force
            sm -= sign * (moment + cross(arm, force))
    return replace(dyn, reactions=reactions, shaking_force=sf, shaking_moment=sm)

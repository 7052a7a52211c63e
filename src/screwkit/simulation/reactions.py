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
the ground relative to the link). By virtual work its input effort is −r(θ) (tested)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dynamics import Dynamics, inverse_dynamics
from screwkit.dynamics.checks import ExternalLoad
from screwkit.dynamics.result import Reaction
from screwkit.kinematics.motion import ModeMotion
from screwkit.simulation.reduced import Array, ReducedModel


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


def _combine(a: Array, b: Array, q: Array) -> Array:
    shape = (-1, *([1] * (a.ndim - 1)))
    return a + q.reshape(shape) * (b - a)


def loop_loads(model: ReducedModel, indices: ArrayLike, speed: ArrayLike,
               acceleration: ArrayLike, *, gravity: ArrayLike | None = None,
               load_freedom: str | None = None, output_force: ArrayLike | None = None,
               inputs: ArrayLike | None = None) -> tuple[Dynamics, ModeMotion]:
    """The :class:`Dynamics` of the loop at grid samples ``indices`` moving at ``speed``,
    ``acceleration`` (M,), with ``gravity`` and the generalised force ``output_force`` (M,) on
    ``load_freedom``; and the motion it was computed on. ``inputs`` labels the samples
    (unwrapped input angles)."""
    mm = model.motion_at(indices, speed, acceleration)
    lk = model.linkage
    d0 = inverse_dynamics(lk, mm, gravity, inputs=inputs)
    if load_freedom is None or output_force is None:
        return d0, mm
    q = np.asarray(output_force, dtype=float)
    d1 = inverse_dynamics(lk, mm, gravity, inputs=inputs,
                          external_loads=unit_output_load(model, load_freedom))
    reactions = {name: Reaction(force=_combine(r0.force, d1.reactions[name].force, q),
                                moment=_combine(r0.moment, d1.reactions[name].moment, q),
                                point=r0.point)
                 for name, r0 in d0.reactions.items()}
    return replace(
        d0,
        shaking_force=_combine(d0.shaking_force, d1.shaking_force, q),
        shaking_moment=_combine(d0.shaking_moment, d1.shaking_moment, q),
        reactions=reactions,
        efforts={k: _combine(v, d1.efforts[k], q) for k, v in d0.efforts.items()},
        # residual: a norm, so the triangle-inequality bound of (1 − q) r_0 + q r_1
        residual=np.abs(1.0 - q) * d0.residual + np.abs(q) * d1.residual,
    ), mm

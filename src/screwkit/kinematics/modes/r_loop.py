"""A single loop of R joints from a :class:`~screwkit.model.mechanism.Mechanism` as the 6R system
of :mod:`.loop6r`: six free joints, any number of them driven at given values (a 7R loop at one
input is a 6R loop: the two links at the driven joint move as one), and the way back from the
system's solutions to the graph tracker's :class:`Configuration` (joint values from the drawing).

The loop is walked from the ground; joint i's axis is oriented along the walk (the joint's axis,
reversed where the walk runs from its second body to its first), so that its value q turns the
next link about it by q either way (T_second = T_first · M_j(q), model/mechanism.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.graph.closure import GraphLayout, graph_layout
from screwkit.kinematics.modes.loop6r import (
    PlacedLink,
    loop6r_angles,
    loop6r_axes,
    loop6r_parameters,
)
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.messages import listing
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]


def _rotation(u: Array, q: float) -> Array:
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return np.eye(3) + np.sin(q) * K + (1.0 - np.cos(q)) * (K @ K)


@dataclass(frozen=True)
class RLoopInstance:
    """A loop of R joints at given input values as a 6R instance: the system's parameters, the
    mechanism joints that are its joints 1..6, and each joint's angle in the drawing (the
    offset between the system's joint angle and the mechanism's joint value)."""

    mechanism: Mechanism
    params: Array
    free_joints: tuple[int, ...]
    drawn_angles: Array
    fixed_values: dict[int, float]
    #: +1 where free joint i's axis in the system is the joint's own axis, −1 where reversed
    signs: Array

    def solution_from_axes(self, joint_axes: ArrayLike) -> Array:
        """The system's unknowns (N, 12) at configurations whose joint axes (N, J, 3, world, in
        mechanism joint order; e.g. GraphFrames.axes) are given: the independent way in."""
        z = np.asarray(joint_axes)[:, list(self.free_joints)] * self.signs[:, None]
        return z[:, 1:5].reshape(z.shape[0], 12)

    def joint_values(self, solutions: ArrayLike) -> Array:
        """The six free joints' values (N, 6) of real solutions (N, 12)."""
        axes = loop6r_axes(np.real(np.asarray(solutions)), self.params)
        q = loop6r_angles(axes) - self.drawn_angles
        return np.mod(q + np.pi, 2 * np.pi) - np.pi

    def configuration(self, solutions: ArrayLike) -> tuple[Configuration, GraphLayout]:
        """The graph tracker's configurations (N) of real solutions (N, 12)."""
        lay = graph_layout(self.mechanism)
        q = self.joint_values(solutions)
        scalars = np.zeros((q.shape[0], lay.n_scalar))
        for col, k in enumerate(self.free_joints):
            scalars[:, lay.scalar_col[lay.first_freedom[k]]] = q[:, col]
        for k, value in self.fixed_values.items():
            scalars[:, lay.scalar_col[lay.first_freedom[k]]] = value
        return Configuration(scalars, np.zeros((q.shape[0], 0, 3, 3))), lay


def _walk(mech: Mechanism) -> tuple[list[int], list[Array]]:
    """The loop's joints in order from the ground and their axes oriented along the walk."""
    if len(mech.topology.loops) != 1 or len(mech.topology.tree) + 1 != len(mech.joints):
        raise CapabilityError(f"{mech.name}: the 6R formulation takes a single loop and "
                              f"nothing else; this mechanism has {len(mech.topology.loops)} "
                              f"loops and {len(mech.joints)} joints")
    bad = [j.name for j in mech.joints if j.kind != "R"]
    if bad:
        raise CapabilityError(f"{mech.name}: joints {listing(bad)} are not R joints; the 6R "
                              "formulation takes loops of R joints only")
    steps = loop_walk(mech)
    return ([k for k, _ in steps],
            [mech.joints[k].axis if forward else -mech.joints[k].axis for k, forward in steps])


def loop_walk(mech: Mechanism) -> list[tuple[int, bool]]:
    """A single loop's joints in order from the ground, each with whether the walk runs from
    its first body to its second (``forward``); a CapabilityError where the loop does not pass
    through the ground."""
    steps: list[tuple[int, bool]] = []
    body, used = GROUND, set()
    while True:
        k = next((i for i, j in enumerate(mech.joints) if body in j.bodies and i not in used),
                 None)
        if k is None:
            raise CapabilityError(f"{mech.name}: the loop does not pass through the ground")
        j = mech.joints[k]
        forward = j.bodies[0] == body
        used.add(k)
        steps.append((k, forward))
        body = j.bodies[1] if forward else j.bodies[0]
        if body == GROUND:
            return steps


def r_loop_instance(mech: Mechanism, input_values: ArrayLike = ()) -> RLoopInstance:
    """The 6R instance of the single R loop ``mech`` with its inputs at ``input_values``
    (one per input, radians from the drawing); the loop must have six free joints."""
    order, axes = _walk(mech)
    values = np.atleast_1d(np.asarray(input_values, dtype=float))
    if values.shape != (len(mech.inputs),):
        raise InputError(f"{mech.name}: {len(mech.inputs)} input values are needed "
                         f"({listing(mech.inputs)}); got {values.shape[0]}")
    joint_index = {j.name: k for k, j in enumerate(mech.joints)}
    fixed = {joint_index[name.split(".")[0]]: float(v)
             for name, v in zip(mech.inputs, values, strict=True)}
    if order[-1] in fixed:  # walk the other way round, so the last joint is free
        order, axes = order[::-1], [-a for a in axes[::-1]]
        if order[-1] in fixed:
            raise CapabilityError(f"{mech.name}: both ground joints are driven; drive at most "
                                  "one of them")
    n = len(order)
    if n - len(fixed) != 6:
        raise CapabilityError(f"{mech.name}: the loop has {n} R joints and {len(fixed)} inputs; "
                              "the 6R formulation needs exactly six free joints")
    centre = [mech.joints[k].at for k in order]
    links: list[PlacedLink] = []
    ends: list[Array] = []  # rotation of each link's last body (its placement in the drawing)
    a, u, R, p = centre[-1], axes[-1], np.eye(3), np.zeros(3)
    for i, k in enumerate(order):
        ci, zi = R @ centre[i] + p, R @ axes[i]
        if k in fixed:  # the next body joins this link, turned by the input about joint i
            Rq = _rotation(axes[i], fixed[k])
            R, p = R @ Rq, R @ (centre[i] - Rq @ centre[i]) + p
            continue
        links.append(PlacedLink(a, u, ci, zi))
        ends.append(R)
        a, u, R, p = centre[i], axes[i], np.eye(3), np.zeros(3)
    params = loop6r_parameters(links)
    # the angle at free joint i in the drawing: from link i−1's normal (back in its last body's
    # drawn coordinates) to link i's, about the joint's drawn axis
    w = [np.cross(lk.u, lk.v) for lk in links]
    free = [k for k in order if k not in fixed]
    drawn = np.empty(6)
    for i in range(6):  # free joint i joins links[i] to links[i + 1]
        prev, nxt = ends[i].T @ w[i], w[(i + 1) % 6]
        z = axes[order.index(free[i])]
        drawn[i] = np.arctan2(np.cross(prev, nxt) @ z, prev @ nxt)
    # formulation joint 1 is the first free joint after the ground: links[0] is the ground
    signs = np.array([1.0 if axes[order.index(k)] @ mech.joints[k].axis > 0 else -1.0
                      for k in free])
    return RLoopInstance(mech, params, tuple(free), drawn, fixed, signs)

"""Inverse kinematics of a 6R arm as the 6R loop of :mod:`.loop6r`: every one of its 16 solutions.

The arm is given in its home configuration by its joint lines (points c_i, unit axes u_i, base
to tool) and the tool frame T_home; its forward kinematics is the product of exponentials
T(q) = Π exp(ξ_i q_i) · T_home (Brockett; Murray, Li & Sastry 1994 §3.2). Holding the tool at a
target pose T closes the chain into a loop whose ground is the base together with the last link,
placed at T·T_home⁻¹: the ground carries joint 1 as drawn and joint 6 moved by T·T_home⁻¹, and
links 1..5 keep their home geometry. The joint values then come from the axes: q_i is the change,
from home, of the angle about z_i from a direction fixed in the link before (the base's for
joint 1) to one fixed in the link after (the tool's for joint 6).

:func:`arm_inverse_kinematics` solves it: by elimination (a 24 × 24 eigenproblem, Raghavan &
Roth 1993), with the parameter homotopy where elimination cannot settle all 16
(modes/loop6r_solve.py). An arm with (nearly) parallel consecutive axes, where the loop's
k_i = a_i / sin α_i are infinite, is solved by a generic perturbation instead
(modes/arm6r_parallel.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.solve import Solutions
from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.modes.arm6r_parallel import (
    ArmContinuation,
    ground_parallel,
    parallel_links,
    solve_parallel_arm,
)
from screwkit.kinematics.modes.loop6r import PlacedLink, loop6r_axes, loop6r_parameters

Array = NDArray[np.float64]


def _rodrigues(u: Array, q: float) -> Array:
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return np.eye(3) + np.sin(q) * K + (1.0 - np.cos(q)) * (K @ K)


def arm_forward(centres: ArrayLike, axes: ArrayLike, tool_home: tuple[Array, Array],
                q: ArrayLike) -> tuple[Array, Array]:
    """The tool pose (R, p) at joint values q (6,): T = Π exp(ξ_i q_i) · T_home."""
    R, p = np.eye(3), np.zeros(3)
    for c, u, qi in zip(np.asarray(centres), np.asarray(axes), np.asarray(q), strict=True):
        Ri = _rodrigues(u / np.linalg.norm(u), float(qi))
        R, p = R @ Ri, R @ (c - Ri @ c) + p
    return R @ tool_home[0], R @ tool_home[1] + p


def _angle(before: Array, after: Array, z: Array) -> Array:
    """The signed angle about z from ``before`` to ``after`` (…, 3), both projected on z⊥."""
    b = before - np.einsum("...i,...i->...", before, z)[..., None] * z
    a = after - np.einsum("...i,...i->...", after, z)[..., None] * z
    return np.arctan2(np.einsum("...i,...i->...", np.cross(b, a), z),
                      np.einsum("...i,...i->...", b, a))


def _joint_angles(z: Array, base_ref: Array, tool_ref: Array) -> Array:
    """The angle about each axis z_i (…, 6, 3) from the link before to the link after: the
    common normals z_i × z_{i+1} of links 1..5, the base's and the tool's reference at the
    ends."""
    w = np.cross(z[..., :5, :], z[..., 1:, :])
    out = [_angle(np.broadcast_to(base_ref, w[..., 0, :].shape), w[..., 0, :], z[..., 0, :])]
    out += [_angle(w[..., i - 1, :], w[..., i, :], z[..., i, :]) for i in range(1, 5)]
    out.append(_angle(w[..., 4, :], np.broadcast_to(tool_ref, w[..., 4, :].shape),
                      z[..., 5, :]))
    return np.stack(out, -1)


@dataclass(frozen=True)
class Arm6RInstance:
    """The 6R loop of an arm holding its tool at a target: the system's parameters, the
    references fixed in the base and (at the target) in the last link, and the home angles."""

    params: Array
    base_ref: Array
    tool_ref: Array
    home_angles: Array

    def joint_values(self, solutions: ArrayLike) -> Array:
        """Joint values (N, 6) of real solutions (N, 12), from home."""
        z = np.real(loop6r_axes(np.real(np.asarray(solutions)), self.params))
        q = _joint_angles(z, self.base_ref, self.tool_ref) - self.home_angles
        return np.mod(q + np.pi, 2 * np.pi) - np.pi


def arm_lines(centres: ArrayLike, axes: ArrayLike) -> tuple[Array, Array]:
    """A 6R arm's joint points (6, 3) and unit axes (6, 3), checked."""
    C = np.asarray(centres, dtype=float)
    U = np.asarray(axes, dtype=float)
    if C.shape != (6, 3) or U.shape != (6, 3):
        raise InputError(f"a 6R arm needs 6 joint points and 6 axes (6 × 3 each); got "
                         f"{C.shape} and {U.shape}")
    return C, U / np.linalg.norm(U, axis=1)[:, None]


def arm6r_instance(centres: ArrayLike, axes: ArrayLike, tool_home: tuple[ArrayLike, ArrayLike],
                   target: tuple[ArrayLike, ArrayLike]) -> Arm6RInstance:
    """The 6R loop of the arm (joint lines at home, base to tool; the home tool pose) with its
    tool held at ``target`` (R, p)."""
    C, U = arm_lines(centres, axes)
    Rh, ph = (np.asarray(v, dtype=float) for v in tool_home)
    Rt, pt = (np.asarray(v, dtype=float) for v in target)
    move = Rt @ Rh.T  # the last link's motion from home: x ↦ move·x + shift
    lines = [(i + 1, i + 2, U[i], U[i + 1]) for i in range(5)] + [(6, 1, move @ U[5], U[0])]
    for i, j, u, v in lines:
        if 1.0 - float(u @ v) ** 2 < 1e-12:
            raise CapabilityError(
                f"joints {i} and {j} of the arm are parallel{' at this target' if i == 6 else ''}"
                f", where the 6R loop's k = a / sin α is infinite; arm_inverse_kinematics "
                f"solves such arms (by a generic perturbation, modes/arm6r_parallel.py)")
    shift = pt - move @ ph
    c6, u6 = move @ C[5] + shift, move @ U[5]
    links = [PlacedLink(c6, u6, C[0], U[0])]
    links += [PlacedLink(C[i], U[i], C[i + 1], U[i + 1]) for i in range(5)]
    params = loop6r_parameters(links)
    base_ref = np.cross(U[0], [1.0, 0.0, 0.0] if abs(U[0][0]) < 0.9 else [0.0, 1.0, 0.0])
    tool_home_ref = np.cross(U[5], [1.0, 0.0, 0.0] if abs(U[5][0]) < 0.9 else [0.0, 1.0, 0.0])
    home = _joint_angles(U, base_ref, tool_home_ref)
    return Arm6RInstance(params, base_ref, move @ tool_home_ref, home)


def arm_inverse_kinematics(centres: ArrayLike, axes: ArrayLike,
                           tool_home: tuple[ArrayLike, ArrayLike],
                           target: tuple[ArrayLike, ArrayLike]
                           ) -> tuple[Array, Solutions | ArmContinuation]:
    """Every real inverse-kinematics solution of the 6R arm (joint lines at home, base to
    tool; the home tool pose) at ``target`` (R, p): joint values from home (N, 6), and the
    loop's :class:`Solutions` (all 16 complex solutions, certificates, the route that ran).
    An arm with consecutive axes within :data:`.arm6r_parallel.PARALLEL_SIN` of parallel (a
    UR, PUMA, KUKA arm), or whose joint 6 at the target is that near parallel to joint 1, goes to :func:`.arm6r_parallel.solve_parallel_arm` and its
    :class:`.arm6r_parallel.ArmContinuation` instead."""
    from screwkit.kinematics.modes.loop6r_solve import solve_loop6r

    U = np.asarray(axes, dtype=float)
    if U.shape == (6, 3) and (parallel_links(U, np.asarray(centres, dtype=float))
                              or ground_parallel(U, tool_home, target)):
        return solve_parallel_arm(centres, axes, tool_home, target)

    inst = arm6r_instance(centres, axes, tool_home, target)
    sol = solve_loop6r(inst.params)
    return inst.joint_values(sol.x[sol.real]), sol

"""Independent check on the planar 4R: a hand-written Lagrangian (DESIGN validation level 3).

sympy (for sympy.physics.mechanics) is not installed in the project environment, so the second
engine is this self-contained Lagrangian: the 4R's own closed-form position (circle intersection,
no screwkit kinematics; the screwkit motion is used only to place the pivots and pick the branch
at the first sample), the kinetic energy T = ½ M(θ) θ̇² with
M = Σ m |∂p_c/∂θ|² + I_zz (∂ψ/∂θ)², the potential V = −Σ m g·p_c, and Lagrange's equation at
constant input rate, τ = ½ M'(θ) θ̇² + V'(θ). The shaking force is −Σ m θ̇² ∂²p_c/∂θ² + Σ m g.

θ-derivatives are 8th-order central differences (step 1e-3 rad, truncation ~1e-24); M' differences
M once more, so round-off is ~ε/h² ≈ 1e-10 of the load: the tolerance 1e-7 leaves room for that.
The inertia products I_xz, I_yz and the out-of-plane CoM offsets are random too: they must not
change the input torque (they only load the joints out of plane).
"""

from __future__ import annotations

import numpy as np
from mechanisms import full_cycle

from screwkit.dynamics import inverse_dynamics

GRAVITY = np.array([0.0, -9.81, 0.0])
FD8 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
H = 1e-3


def d_dtheta(f, theta):
    return sum(c * f(theta + (k - 4) * H) for k, c in enumerate(FD8) if c) / H


def test_fourbar_input_torque_and_shaking_force_match_a_lagrangian() -> None:
    linkage, motion, mode = full_cycle("fourbar", 0)
    rate = float(motion.input_rates[0, 0])
    prm = linkage.parameters
    A = mode.joint_centres[0, 0, :2]
    D = mode.joint_centres[0, 3, :2]
    B0 = mode.joint_centres[0, 1, :2]
    C0 = mode.joint_centres[0, 2, :2]
    theta0 = motion.inputs[0, 0]
    phi0 = np.arctan2(*(B0 - A)[::-1]) - theta0
    BD0 = D - B0
    # which circle intersection: the side of B→D that the coupler pin C lies on at sample 0
    sign = float(np.sign(BD0[0] * (C0 - B0)[1] - BD0[1] * (C0 - B0)[0]))
    links = [lk.mass for lk in linkage.links]

    def frames(theta):
        """(origin (…, 3, 2), angle (…, 3)) of crank, coupler and rocker."""
        phi = theta + phi0
        B = A + prm["d1"] * np.stack([np.cos(phi), np.sin(phi)], -1)
        BD = D - B
        dist = np.linalg.norm(BD, axis=-1, keepdims=True)
        u = BD / dist
        along = (prm["d2"] ** 2 - prm["d3"] ** 2 + dist**2) / (2 * dist)
        across = np.sqrt(prm["d2"] ** 2 - along**2)
        C = B + along * u + sign * across * np.stack([-u[..., 1], u[..., 0]], -1)
        ang = np.stack([phi, np.arctan2((C - B)[..., 1], (C - B)[..., 0]),
                        np.arctan2((D - C)[..., 1], (D - C)[..., 0])], -1)
        return np.stack([np.broadcast_to(A, B.shape), B, C], -2), ang

    def com_positions(theta):
        origin, ang = frames(theta)
        out = []
        for l, mp in enumerate(links):
            c, s = np.cos(ang[..., l]), np.sin(ang[..., l])
            x = origin[..., l, 0] + c * mp.com[0] - s * mp.com[1]
            y = origin[..., l, 1] + s * mp.com[0] + c * mp.com[1]
            out.append(np.stack([x, y, np.full_like(x, mp.com[2])], -1))
        return np.stack(out, -2)  # (…, 3, 3)

    m = np.array([mp.mass for mp in links])
    izz = np.array([mp.inertia[2, 2] for mp in links])

    def generalised_mass(theta):
        dp = d_dtheta(com_positions, theta)
        dpsi = d_dtheta(lambda t: frames(t)[1], theta)
        return np.einsum("l,nli,nli->n", m, dp, dp) + np.einsum("l,nl->n", izz, dpsi**2)

    def potential(theta):
        return -np.einsum("l,nli,i->n", m, com_positions(theta), GRAVITY)

    theta = motion.inputs[:, 0]
    torque = 0.5 * d_dtheta(generalised_mass, theta) * rate**2 + d_dtheta(potential, theta)
    accel = d_dtheta(lambda t: d_dtheta(com_positions, t), theta) * rate**2
    shaking = -np.einsum("l,nli->ni", m, accel) + m.sum() * GRAVITY

    dyn = inverse_dynamics(linkage, mode, gravity=GRAVITY)
    assert np.max(np.abs(dyn.efforts["input.theta"] - torque)) < 1e-7 * np.max(np.abs(torque))
    assert np.max(np.abs(dyn.shaking_force - shaking)) < 1e-7 * np.max(np.abs(shaking))

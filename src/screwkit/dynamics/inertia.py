"""Inertia wrenches of the moving links (Newton–Euler, world frame) and their regressor.

Direct form (what a reader checks by hand; Rahman 1996 §2.1, eqs. 2.20–2.23 in vector form):

    F = −m a_c + m g,       M_c = −(I_w α + ω × I_w ω),       I_w = R I_c Rᵀ,

with a_c = a_o + α × r_c + ω × (ω × r_c) the CoM acceleration, r_c = R c. The moment is then
carried to the reference point r: M_r = M_c + (p_c − r) × F.

Regressor form (linear in π = (m, m c, I_o) about the body-frame origin o, the order of
:meth:`screwkit.model.mass.MassProperties.inertial_parameters`): in body axes, with
â = Rᵀ(a_o − g) (gravity enters as an upward acceleration of the frame),

    K_F = m â + α × h + ω × (ω × h),
    K_M = I_o α + ω × I_o ω + h × â,            h = m c,

and the applied (inertia + weight) wrench on the link is −K, rotated to the world and moved to r.
"""

from __future__ import annotations

import numpy as np

from screwkit.dual.spatial import cross, skew
from screwkit.dynamics import component_arrays as soa
from screwkit.dynamics.screws import Array
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.mass import MassProperties


def _rotate(R: Array, v: Array) -> Array:
    """R v over leading axes: R (..., 3, 3), v (..., 3)."""
    return np.einsum("...ij,...j->...i", R, v)


def _rotate_back(R: Array, v: Array) -> Array:
    """Rᵀ v over leading axes."""
    return np.einsum("...ji,...j->...i", R, v)


def inertia_wrenches(
    masses: list[MassProperties],
    mode: ModeMotion,
    gravity: Array,
    reference: Array,
) -> Array:
    """Applied wrench of inertia and weight on every moving link, (N, L, 6): force (N) and moment
    (N·m) about ``reference``, world frame (direct form of the module docstring)."""
    m = np.array([mp.mass for mp in masses])  # (L,)
    com = np.stack([mp.com for mp in masses])  # (L, 3)
    inertia = np.stack([mp.inertia for mp in masses])  # (L, 3, 3)
    R = mode.link_rotation
    w = mode.link_angular_velocity
    al = mode.link_angular_acceleration
    rc = _rotate(R, np.broadcast_to(com, R.shape[:-1]))
    p_c = mode.link_origin + rc - reference
    a_c = mode.link_origin_acceleration + cross(al, rc) + cross(w, cross(w, rc))
    force = m[:, None] * (gravity - a_c)
    w_b = _rotate_back(R, w)
    al_b = _rotate_back(R, al)
    iw = np.einsum("lij,...lj->...li", inertia, w_b)
    ia = np.einsum("lij,...lj->...li", inertia, al_b)
    moment_c = -_rotate(R, ia + cross(w_b, iw))
    return np.concatenate([force, moment_c + cross(p_c, force)], -1)


def _inertia_operator(v: Array) -> Array:
    """The 3×6 matrix L(v) with I v = L(v) ι, ι = (I_xx, I_yy, I_zz, I_xy, I_xz, I_yz)."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    o = np.zeros_like(x)
    return np.stack(
        [
            np.stack([x, o, o, y, z, o], -1),
            np.stack([o, y, o, x, o, z], -1),
            np.stack([o, o, z, o, x, y], -1),
        ],
        -2,
    )


def inertia_wrench_regressor(mode: ModeMotion, gravity: Array, reference: Array) -> Array:
    """Regressor of the applied (inertia + weight) wrench of every moving link, (N, L, 6, 10):
    ``wrench[:, l] = Y[:, l] @ π_l`` with π_l the 10 inertial parameters of link l about its
    body-frame origin (regressor form of the module docstring)."""
    R = mode.link_rotation
    w_b = _rotate_back(R, mode.link_angular_velocity)
    al_b = _rotate_back(R, mode.link_angular_acceleration)
    a_b = _rotate_back(R, mode.link_origin_acceleration - gravity)
    shape = w_b.shape[:-1]
    k_force = np.zeros((*shape, 3, 10))
    k_moment = np.zeros((*shape, 3, 10))
    w_x = skew(w_b)
    k_force[..., 0] = a_b
    k_force[..., 1:4] = skew(al_b) + w_x @ w_x
    k_moment[..., 1:4] = -skew(a_b)
    k_moment[..., 4:] = _inertia_operator(al_b) + w_x @ _inertia_operator(w_b)
    force = -np.einsum("...ij,...jk->...ik", R, k_force)
    moment_o = -np.einsum("...ij,...jk->...ik", R, k_moment)
    arm = skew(mode.link_origin - reference)
    return np.concatenate([force, moment_o + arm @ force], -2)


def inertia_wrenches_soa(
    masses: list[MassProperties],
    rotation: list[soa.Scalar],
    origin: list[soa.Scalar],
    angular_velocity: list[soa.Scalar],
    angular_acceleration: list[soa.Scalar],
    origin_acceleration: list[soa.Scalar],
    gravity: Array,
    reference: Array,
) -> list[tuple[soa.Vec, soa.Vec]]:
    """The direct form of the module docstring for one block of samples in structure-of-arrays
    form: per moving link, the applied force and moment about ``reference`` as component
    tuples. Inputs are component rows (:func:`screwkit.dynamics.component_arrays.rows`): ``rotation`` 9 per
    link (R[3i + j]), the others 3 per link."""
    out = []
    g = soa.const(gravity)
    ref = soa.const(reference)
    for l, mp in enumerate(masses):
        R = rotation[9 * l : 9 * l + 9]
        w = soa.vec(angular_velocity, 3 * l)
        al = soa.vec(angular_acceleration, 3 * l)
        rc = soa.rotate(R, soa.const(mp.com))
        p_c = soa.sub(soa.add(soa.vec(origin, 3 * l), rc), ref)
        a_c = soa.add(soa.vec(origin_acceleration, 3 * l),
                      soa.add(soa.cross(al, rc), soa.cross(w, soa.cross(w, rc))))
        force = soa.scale(float(mp.mass), soa.sub(g, a_c))
        inertia = np.asarray(mp.inertia, dtype=float)
        w_b = soa.rotate_back(R, w)
        body = soa.add(soa.const_matvec(inertia, soa.rotate_back(R, al)),
                       soa.cross(w_b, soa.const_matvec(inertia, w_b)))
        moment = soa.sub(soa.cross(p_c, force), soa.rotate(R, body))
        out.append((force, moment))
    return out

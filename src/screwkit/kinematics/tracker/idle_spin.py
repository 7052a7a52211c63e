"""The pose of a link between two spherical joints (an S–S rod): its idle spin held at zero.

The balls cannot drive a rod's spin about its own axis u, so the rate equations hold it at zero,
ω·u = 0 (Rahman 1996 §1.2; :mod:`screwkit.kinematics.tracker.rates`). The rod's *pose* must agree: its
rotation is the zero-spin (parallel-transported) frame along the branch, whose time derivative
is [ω]× R with that ω. It is path dependent: after a closed loop of the input the rod comes back
turned about u by the holonomy of the path u traced on the unit sphere (the solid angle it
encloses), as a real rod whose spin nothing drives would.

Along a run of samples the rod's rotation is carried from sample k−1 to k by the minimal rotation
M taking u_{k−1} to u_k (the geodesic transport) and then turned about u_k by

    c_k = −∫₀¹ f(t) dt,   f = (u_{k−1} × u)·u̇ / (1 + u_{k−1}·u),

the spin the zero-spin frame gains on the true path of u relative to the geodesic (f is ω·u of
the frame transported along the geodesic; f(0) = f′(0) = 0). The integral is the two-point
Hermite rule from f(1) and f′(1), which uses the exact u̇ and ü at sample k from the rate
equations (error O(h⁵) a step, h the step of the input). At the first sample of every run the
rod's frame is the one whose proximal ball joint is a pure swing from its rest pose (its
relative rotation turns the rod's rest direction into u with no turn about u).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import cross
from screwkit.kinematics.tracker.loop import Array, Configuration, Layout, LoopFrames, forward
from screwkit.kinematics.tracker.rates import RateEquations, rate_equations, solve_rates
from screwkit.model.linkage import Linkage


def axis_rotation(axis: Array, angle: Array) -> Array:
    """Rotation matrices about unit ``axis`` (N, 3) by ``angle`` (N,) (Rodrigues)."""
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    K = _skew(axis)
    return np.asarray(np.eye(3) + s * K + (1 - c) * (K @ K))


def _skew(v: Array) -> Array:
    z = np.zeros(v.shape[0])
    return np.stack([np.stack([z, -v[:, 2], v[:, 1]], -1),
                     np.stack([v[:, 2], z, -v[:, 0]], -1),
                     np.stack([-v[:, 1], v[:, 0], z], -1)], -2)


def _dot(a: Array, b: Array) -> Array:
    return np.asarray(np.einsum("ni,ni->n", a, b))


def minimal_rotation_apply(a: Array, b: Array, v: Array) -> Array:
    """M v for the least rotation M taking unit ``a`` to unit ``b`` (rows). Where b = −a every
    half turn about an axis ⟂ a is least; the one about the axis ⟂ a nearest a coordinate
    plane is taken."""
    k = cross(a, b)
    c = _dot(a, b)
    opposite = 1.0 + c < 1e-12
    out = np.asarray(c[:, None] * v + cross(k, v)
                     + (_dot(k, v) / np.where(opposite, 1.0, 1.0 + c))[:, None] * k)
    for r in np.nonzero(opposite)[0]:
        n = perpendicular(a[r])
        out[r] = 2.0 * (n @ v[r]) * n - v[r]
    return out


def signed_angle(a: Array, b: Array, axis: Array) -> Array:
    """Angle turning ``a`` into ``b`` about ``axis`` (all (N, 3); a, b ⟂ axis)."""
    return np.asarray(np.arctan2(_dot(axis, cross(a, b)), _dot(a, b)))


def geodesic_spin_correction(u0: Array, u1: Array, u1_dot: Array, u1_ddot: Array) -> Array:
    """c = −∫₀¹ f dt of the module docstring for steps from ``u0`` to ``u1``, with the
    derivatives of u along the step at its end (per unit of the step parameter)."""
    k = cross(u0, u1)
    den = 1.0 + _dot(u0, u1)
    f1 = _dot(k, u1_dot) / den
    f1_dot = _dot(k, u1_ddot) / den - f1 * _dot(u0, u1_dot) / den
    return np.asarray(-(0.5 * f1 - f1_dot / 12.0))


def perpendicular(u: Array) -> Array:
    """A unit vector perpendicular to unit ``u`` (3,)."""
    e = np.eye(3)[int(np.argmin(np.abs(u)))]
    p = e - (e @ u) * u
    return np.asarray(p / np.linalg.norm(p))


def transported_spin(u: Array, u_dot: Array, u_ddot: Array, frame_x: Array, start_x: Array,
                     runs: NDArray[np.bool_], continues: NDArray[np.bool_],
                     exact: NDArray[np.bool_]) -> Array:
    """Angle φ (N,) to turn a rod about its axis so that its frame is parallel-transported.

    ``u`` (N, 3) the rod axes; ``u_dot``/``u_ddot`` their derivatives along the step that
    arrives at each sample (per unit of the step); ``frame_x`` (N, 3) a body vector ⟂ u of the
    rod's present frame; ``start_x`` (N, 3) the same body vector in the wanted frame at the
    first sample of each run; ``runs`` the samples that hold; ``continues`` the samples whose
    step from the previous sample stays on the run; ``exact`` where the Hermite correction's
    derivatives are known (else the geodesic transport alone)."""
    N = u.shape[0]
    phi_step = np.zeros(N)
    k = np.nonzero(continues)[0]
    if k.size:
        a, b = u[k - 1], u[k]
        corr = geodesic_spin_correction(a, b, u_dot[k], u_ddot[k])
        corr = np.where(exact[k] & np.isfinite(corr), corr, 0.0)
        carried = minimal_rotation_apply(a, b, frame_x[k - 1])
        phi_step[k] = corr - signed_angle(carried, frame_x[k], b)
    starts = runs & ~continues
    start_phi = np.zeros(N)
    s = np.nonzero(starts)[0]
    start_phi[s] = signed_angle(frame_x[s], start_x[s], u[s])
    # φ_k = φ_{k−1} + step_k along a run, φ = start_phi at its first sample
    total = np.cumsum(phi_step)
    run_id = np.maximum(np.cumsum(starts) - 1, 0)
    base = (start_phi[s] - total[s]) if s.size else np.zeros(1)
    phi = total + base[run_id]
    return np.where(runs, phi, 0.0)


def zero_spin_angle(u: Array, u_dot: Array, u_ddot: Array, rod: Array, before: Array,
                    mask: NDArray[np.bool_], exact: NDArray[np.bool_]) -> Array:
    """The turn φ (N,) about its axis that makes a rod's frame ``rod`` (N, 3, 3) the zero-spin
    frame of the module docstring: ``u`` its axes, ``u_dot``/``u_ddot`` their derivatives
    along the step arriving at each sample, ``before`` the frame of its proximal ball joint
    before the joint's motion (the rod's rest frame), ``mask`` where it holds, ``exact``
    where the derivatives are known. The turned frame is Rot(u, φ)·rod."""
    first = int(np.argmax(mask))
    u_body = rod[first].T @ u[first]
    e_body = perpendicular(u_body)
    return spin_from_frames(u, u_dot, u_ddot, rod @ e_body, u_body, e_body,
                            np.einsum("nji,nj->ni", before, u),
                            lambda x: np.asarray(np.einsum("nij,nj->ni", before, x)), mask, exact)


def spin_from_frames(u: Array, u_dot: Array, u_ddot: Array, frame_x: Array, u_body: Array,
                     e_body: Array, u_in_before: Array, from_before: Callable[[Array], Array],
                     mask: NDArray[np.bool_], exact: NDArray[np.bool_]) -> Array:
    """:func:`zero_spin_angle` from its pieces, for a caller that has them without (N, 3, 3)
    frames (the CSSP closed form): the rod's body vector ``e_body`` ⟂ its axis ``u_body`` (body
    frame, taken at the first sample), ``frame_x`` = rod·e_body (N, 3), ``u_in_before`` =
    beforeᵀ·u and ``from_before(x)`` = before·x."""
    N = u.shape[0]
    # wanted frame at a run's start: the proximal ball is a pure swing from rest
    swing_x = minimal_rotation_apply(np.broadcast_to(u_body, (N, 3)), u_in_before,
                                     np.broadcast_to(e_body, (N, 3)))
    start_x = from_before(swing_x)
    continues = np.zeros(N, dtype=bool)
    continues[1:] = mask[1:] & mask[:-1]
    return transported_spin(u, u_dot, u_ddot, frame_x, start_x, mask, continues, exact)


def hold_idle_spin(linkage: Linkage, lay: Layout, conf: Configuration, mask: NDArray[np.bool_],
                   X: Array, fr: LoopFrames, eq: RateEquations) -> Configuration:
    """``conf`` with every S–S rod turned about its axis to the zero-spin frame (module
    docstring); the loop stays closed (the turn is about the line of the two ball centres)."""
    if not eq.spin_links or not mask.any():
        return conf
    steps = np.zeros_like(X)
    steps[1:] = X[1:] - X[:-1]
    sph = conf.spherical.copy()
    for r, i in enumerate(eq.spin_links):
        if r:
            fr = forward(linkage, Configuration(conf.scalars, sph), lay)
            eq = rate_equations(linkage, lay, fr, mask)
        along = solve_rates(linkage, lay, eq, steps, np.zeros_like(X))
        w, al = along.link_V[:, i, :3], along.link_A[:, i, :3]
        u = eq.rod_axes[:, r]
        u_dot = cross(w, u)
        u_ddot = cross(al, u) + cross(w, u_dot)
        B = fr.before_R[:, i]
        exact = np.asarray(np.isfinite(along.qd).all(axis=1))
        phi = zero_spin_angle(u, u_dot, u_ddot, fr.after_R[:, i], B, mask, exact)
        k1, k2 = lay.spherical_of_joint[i], lay.spherical_of_joint[i + 1]
        sph[:, k1] = axis_rotation(np.einsum("nji,nj->ni", B, u), phi) @ sph[:, k1]
        B2 = fr.before_R[:, i + 1]
        sph[:, k2] = axis_rotation(np.einsum("nji,nj->ni", B2, u), -phi) @ sph[:, k2]
    return Configuration(conf.scalars, sph)

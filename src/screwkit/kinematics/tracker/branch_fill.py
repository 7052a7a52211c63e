"""Samples between two points of one branch by quintic Hermite interpolation: the continuation's
fill (:mod:`screwkit.kinematics.tracker.continuation`).

Between two closed configurations A and B of a branch, with the first and second derivatives of
every freedom with respect to the inputs at both (from the rate equations), the branch is
interpolated in the tangent space at A: δ(u), u ∈ [0, 1] along the input path from A to B, with

    δ(0) = 0,   δ'(0) = q_X(A) ΔX,   δ''(0) = q_XX(A)(ΔX, ΔX),
    δ(1) = B ⊖ A,   δ'(1), δ''(1) from q_X(B), q_XX(B),

(ΔX the inputs' change from A to B) by the quintic Hermite basis; the prediction is A ⊕ δ(u)
(:func:`~screwkit.kinematics.tracker.loop.apply_increment`). Its error is of sixth order in the
interval, so over a short interval the loop closes there to the corrector's tolerance without
a Newton step.

Scalar freedoms interpolate as they are. A spherical joint turns as R(u) = R_A exp([δ(u)]), and
its rates are body angular velocities ω = J_r(δ) δ' (J_r the right Jacobian of SO(3)), so at B
its end conditions are δ'(1) = J_r(δ₁)⁻¹ ω_B and δ''(1) = J_r(δ₁)⁻¹ (α_B − J̇_r δ'(1)).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import cross
from screwkit.kinematics.tracker.loop import Array


def quintic_hermite(u: Array) -> Array:
    """The six quintic Hermite basis functions (T, 6) at ``u`` (T,): weights of p0, v0, a0,
    p1, v1, a1 (values, first and second derivatives at u = 0 and u = 1)."""
    u2 = u * u
    u3 = u2 * u
    u4 = u3 * u
    u5 = u4 * u
    return np.stack([1.0 - 10.0 * u3 + 15.0 * u4 - 6.0 * u5,
                     u - 6.0 * u3 + 8.0 * u4 - 3.0 * u5,
                     0.5 * u2 - 1.5 * u3 + 1.5 * u4 - 0.5 * u5,
                     10.0 * u3 - 15.0 * u4 + 6.0 * u5,
                     -4.0 * u3 + 7.0 * u4 - 3.0 * u5,
                     0.5 * u3 - u4 + 0.5 * u5], axis=-1)


def _coefficients(th: Array) -> tuple[Array, Array, Array, Array, Array]:
    """a = (1 − cos θ)/θ², b = (θ − sin θ)/θ³, their θ-derivatives and c = 1/θ² − (1 + cos θ)
    /(2θ sin θ) (J_r = I − a[δ] + b[δ]², J_r⁻¹ = I + ½[δ] + c[δ]²); series near θ = 0."""
    small = th < 1e-3
    t = np.where(small, 1.0, th)
    t2 = th * th
    a = np.where(small, 0.5 - t2 / 24.0, (1.0 - np.cos(t)) / t**2)
    b = np.where(small, 1.0 / 6.0 - t2 / 120.0, (t - np.sin(t)) / t**3)
    da = np.where(small, -th / 12.0, (np.sin(t) * t - 2.0 * (1.0 - np.cos(t))) / t**3)
    db = np.where(small, -th / 60.0, (3.0 * np.sin(t) - t * np.cos(t) - 2.0 * t) / t**4)
    c = np.where(small, 1.0 / 12.0 + t2 / 720.0,
                 1.0 / t**2 - (1.0 + np.cos(t)) / (2.0 * t * np.sin(t)))
    return a, b, da, db, c


def spherical_end_conditions(d1: Array, w: Array, al: Array) -> tuple[Array, Array]:
    """δ'(1) and δ''(1) (..., 3) of a ball joint's interpolation R_A exp([δ(u)]) that ends at
    δ(1) = ``d1`` with body angular velocity ``w`` and acceleration ``al`` (per unit u)."""
    th = np.linalg.norm(d1, axis=-1)
    a, b, da, db, c = (x[..., None] for x in _coefficients(th))

    def jr_inv(x: Array) -> Array:
        dx = cross(d1, x)
        return np.asarray(x + 0.5 * dx + c * cross(d1, dx))

    v = jr_inv(w)
    # J̇_r v for θ' = δ·δ'/θ: −a' θ' δ×v + b' θ' δ×(δ×v) + b v×(δ×v)  (a[v]v = 0)
    th_safe = np.maximum(th, 1e-300)[..., None]
    th_dot = np.einsum("...i,...i->...", d1, v)[..., None] / th_safe
    dv = cross(d1, v)
    jdot_v = -da * th_dot * dv + db * th_dot * cross(d1, dv) + b * cross(v, dv)
    return v, jr_inv(al - jdot_v)


def hermite_increments(balls: list[list[int]], d1: Array, v0: Array, a0: Array, v1: Array,
                       a1: Array, interval: NDArray[np.intp], u: Array) -> Array:
    """Increments δ(u) (T, m) from A of the interpolation (module docstring) at targets in
    ``interval`` (T,) at positions ``u`` (T,) in it, from each interval's end data (I, m):
    ``d1`` = B ⊖ A, ``v0``/``a0`` the first and second derivatives along the interval at A,
    ``v1``/``a1`` at B (rates; a ball joint's are its body rates, converted here; ``balls``:
    each ball joint's three freedoms)."""
    v1 = v1.copy()
    a1 = a1.copy()
    for idx in balls:
        v1[:, idx], a1[:, idx] = spherical_end_conditions(d1[:, idx], v1[:, idx], a1[:, idx])
    H = quintic_hermite(u)
    return np.asarray(H[:, 1:2] * v0[interval] + H[:, 2:3] * a0[interval]
                      + H[:, 3:4] * d1[interval] + H[:, 4:5] * v1[interval]
                      + H[:, 5:6] * a1[interval])


__all__ = ["hermite_increments", "quintic_hermite", "spherical_end_conditions"]

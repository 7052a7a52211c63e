"""Real rotation helpers shared by the dual types: axis–angle (Rodrigues), unit quaternions
(scalar first, w, x, y, z; Hamilton product) and the robust matrix → quaternion map.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual.number import Array
from screwkit.dual.spatial import skew


def rotation_from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> Array:
    """Rodrigues: R = I + sin θ [u]× + (1 − cos θ)[u]×², right-handed about the unit axis u."""
    u = np.asarray(axis, dtype=float)
    th = np.asarray(angle, dtype=float)
    K = skew(u)
    s = np.sin(th)[..., None, None]
    c = np.cos(th)[..., None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def quaternion_multiply(p: ArrayLike, q: ArrayLike) -> Array:
    """Hamilton product p ⊗ q of quaternions (w, x, y, z), broadcasting over leading axes."""
    p = np.asarray(p)
    q = np.asarray(q)
    pw, px, py, pz = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    qw, qx, qy, qz = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        axis=-1,
    )


def quaternion_conjugate(q: ArrayLike) -> Array:
    """q* = (w, −x, −y, −z)."""
    q = np.asarray(q)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def rotation_from_quaternion(q: ArrayLike) -> Array:
    """Rotation matrix of a unit quaternion (w, x, y, z)."""
    q = np.asarray(q, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def quaternion_from_rotation(R: ArrayLike) -> Array:
    """Unit quaternion (w, x, y, z) with w ≥ 0 of a rotation matrix.

    Shepperd's method, vectorised: each sample uses the largest of 4w², 4x², 4y², 4z² as the
    pivot, so the result keeps full precision near a rotation by π (where w → 0), unlike the
    trace formula.
    """
    R = np.asarray(R, dtype=float)
    r00, r11, r22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    tr = r00 + r11 + r22
    # Candidate quaternions, one per pivot, each scaled by 4·pivot.
    cand = np.stack(
        [
            np.stack([1 + tr, R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                      R[..., 1, 0] - R[..., 0, 1]], -1),
            np.stack([R[..., 2, 1] - R[..., 1, 2], 1 + r00 - r11 - r22,
                      R[..., 0, 1] + R[..., 1, 0], R[..., 0, 2] + R[..., 2, 0]], -1),
            np.stack([R[..., 0, 2] - R[..., 2, 0], R[..., 0, 1] + R[..., 1, 0],
                      1 - r00 + r11 - r22, R[..., 1, 2] + R[..., 2, 1]], -1),
            np.stack([R[..., 1, 0] - R[..., 0, 1], R[..., 0, 2] + R[..., 2, 0],
                      R[..., 1, 2] + R[..., 2, 1], 1 - r00 - r11 + r22], -1),
        ],
        axis=-2,
    )
    pivots = np.stack([1 + tr, 1 + r00 - r11 - r22, 1 - r00 + r11 - r22, 1 - r00 - r11 + r22], -1)
    best = np.argmax(pivots, axis=-1)
    q = np.take_along_axis(cand, best[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


def axis_angle_from_rotation(R: ArrayLike) -> tuple[Array, Array]:
    """(unit axis u, angle θ ∈ [0, π]) of a rotation matrix, via the quaternion (robust at 0
    and π). Where θ = 0 the axis is undefined and returned as (0, 0, 1)."""
    q = quaternion_from_rotation(R)
    v = q[..., 1:]
    vn = np.linalg.norm(v, axis=-1)
    angle = 2.0 * np.arctan2(vn, q[..., 0])
    safe = np.where(vn > 0, vn, 1.0)[..., None]
    axis = np.where(vn[..., None] > 0, v / safe, np.array([0.0, 0.0, 1.0]))
    return axis, angle


__all__ = [
    "axis_angle_from_rotation",
    "quaternion_conjugate",
    "quaternion_from_rotation",
    "quaternion_multiply",
    "rotation_from_axis_angle",
    "rotation_from_quaternion",
]

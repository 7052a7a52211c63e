"""Real spatial toolbox shared by every layer: skew matrices, cross products, elementary rotations,
angle wrapping and the elevation/azimuth of a moving unit vector, batch-first over leading axes
(docs/conventions.md, "Spatial toolbox").

Conventions: vectors have shape (..., 3), matrices (..., 3, 3); rotations are right-handed and
active (``rot_z(a) @ x`` turns x by +a about z); wrapped angles lie in (-pi, pi], so +pi stays
+pi and -pi becomes +pi.  Everything here is plain numpy and imports nothing from screwkit.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError

__all__ = [
    "GIMBAL_TOL",
    "MATVEC_FROM",
    "cross",
    "matvec",
    "elementary_rotation",
    "elevation_azimuth",
    "rot_x",
    "rot_y",
    "rot_z",
    "skew",
    "vee",
    "wrap_angle",
    "wrap_angle_near",
]

Array = NDArray[Any]
FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: |cos| of an elevation (distance of a unit vector from the z axis) below which its azimuth and
#: the angle rates are undefined (`elevation_azimuth`)
GIMBAL_TOL = 1e-12


def skew(v: ArrayLike) -> FloatArray:
    """[v]x, the skew matrix with [v]x w = v x w (shape (..., 3) -> (..., 3, 3))."""
    v = np.asarray(v, dtype=float)
    z = np.zeros_like(v[..., 0])
    return np.stack(
        [
            np.stack([z, -v[..., 2], v[..., 1]], axis=-1),
            np.stack([v[..., 2], z, -v[..., 0]], axis=-1),
            np.stack([-v[..., 1], v[..., 0], z], axis=-1),
        ],
        axis=-2,
    )


def vee(w: ArrayLike) -> FloatArray:
    """Axial vector (W32, W13, W21) of a skew matrix, the inverse of `skew` ((..., 3, 3) -> (..., 3))."""
    w = np.asarray(w, dtype=float)
    return np.stack([w[..., 2, 1], w[..., 0, 2], w[..., 1, 0]], axis=-1)


def cross(a: Array, b: Array) -> Array:
    """a x b over the last axis, written out by components.

    For the small trailing axes of per-sample, per-link vectors this is several times faster than
    ``numpy.cross`` (which moves axes and checks shapes on every call); ``a`` and ``b`` must have
    the same shape (..., 3).
    """
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        -1,
    )


#: stacks of at least this many matrices take `matvec`'s one BLAS call (measured: ~1.4× faster
#: at 128, ~2.5× at 256, slower below 64)
MATVEC_FROM = 128


def matvec(R: Array, x: Array) -> Array:
    """R @ x for a stack of matrices R (..., 3, 3) and one vector x (3,), as one BLAS
    matrix–vector product on the rows of every matrix stacked ((3K, 3) @ (3,)): the same
    dot products as ``R @ x`` (bit for bit, tests/dual/test_spatial.py), an order of magnitude
    faster for many small matrices, for which numpy's matmul calls BLAS once per matrix.
    Matrices whose rows are not contiguous (transposed views) go to ``R @ x``: BLAS takes
    those by columns, with another order of operations; so do stacks of fewer than
    :data:`MATVEC_FROM` matrices, where the one call's set-up costs more than it saves."""
    R = np.asarray(R)
    if R.ndim < 3 or R.size < 9 * MATVEC_FROM or R.strides[-1] != R.itemsize \
            or R.strides[-2] != 3 * R.itemsize:
        return np.asarray(R @ x)
    return np.asarray(np.reshape(R, (-1, 3)) @ x).reshape(R.shape[:-1])


def elementary_rotation(c: Array, s: Array, axis: int) -> Array:
    """Rotation about coordinate axis 0 (x), 1 (y) or 2 (z) from its cosine ``c`` and sine ``s``.

    Right-handed (Bagci eqs. 2.6-2.8, real part; Rahman A.3-A.7); shapes (...) -> (..., 3, 3).
    """
    one = np.ones_like(c)
    zero = np.zeros_like(c)
    if axis == 0:
        rows = [[one, zero, zero], [zero, c, -s], [zero, s, c]]
    elif axis == 1:
        rows = [[c, zero, s], [zero, one, zero], [-s, zero, c]]
    elif axis == 2:
        rows = [[c, -s, zero], [s, c, zero], [zero, zero, one]]
    else:
        raise InputError(f"axis must be 0 (x), 1 (y) or 2 (z), got {axis!r}")
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def rot_x(angle: ArrayLike) -> FloatArray:
    """Rotation by ``angle`` (radians) about x; shape (...) -> (..., 3, 3)."""
    a = np.asarray(angle, dtype=float)
    return elementary_rotation(np.cos(a), np.sin(a), 0)


def rot_y(angle: ArrayLike) -> FloatArray:
    """Rotation by ``angle`` (radians) about y; shape (...) -> (..., 3, 3)."""
    a = np.asarray(angle, dtype=float)
    return elementary_rotation(np.cos(a), np.sin(a), 1)


def rot_z(angle: ArrayLike) -> FloatArray:
    """Rotation by ``angle`` (radians) about z; shape (...) -> (..., 3, 3)."""
    a = np.asarray(angle, dtype=float)
    return elementary_rotation(np.cos(a), np.sin(a), 2)


def wrap_angle(angle: ArrayLike) -> FloatArray:
    """Angles (radians) wrapped into (-pi, pi]: pi - ((pi - angle) mod 2 pi)."""
    angle = np.asarray(angle, dtype=np.float64)
    return np.pi - np.mod(np.pi - angle, 2.0 * np.pi)


def wrap_angle_near(angle: FloatArray) -> FloatArray:
    """`wrap_angle` for angles known to lie in (-3 pi, 3 pi]: one shift of 2 pi at most.

    Cheaper than the modulo (hot paths of the closed forms, e.g. a sum of two wrapped angles).
    """
    two_pi = 2.0 * np.pi
    return angle - two_pi * ((angle > np.pi).astype(np.float64) - (angle <= -np.pi))


def elevation_azimuth(
    v: FloatArray, v_dot: FloatArray, v_ddot: FloatArray
) -> tuple[BoolArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Elevation E = atan2(v_z, ρ) and azimuth A = atan2(v_y, v_x) of a unit vector v(t),
    ρ = √(v_x² + v_y²) = cos E, with exact rates:
        Ė = v̇_z/ρ,  Ë = (v̈_z + v_z Ė²)/ρ,
        Ȧ = (v_x v̇_y − v_y v̇_x)/ρ²,  Ä = (v_x v̈_y − v_y v̈_x)/ρ² − 2 Ȧ (v_x v̇_x + v_y v̇_y)/ρ².
    Where ρ ≈ 0 (v along z) A is undefined: those samples are flagged False and their rates NaN.
    """
    vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    rho2 = vx**2 + vy**2
    rho = np.sqrt(rho2)
    defined = rho > GIMBAL_TOL
    elevation = np.arctan2(vz, rho)
    azimuth = np.where(defined, np.arctan2(vy, vx), np.nan)
    safe_rho = np.where(defined, rho, 1.0)
    safe_rho2 = safe_rho**2
    e_dot = v_dot[..., 2] / safe_rho
    e_ddot = (v_ddot[..., 2] + vz * e_dot**2) / safe_rho
    a_dot = (vx * v_dot[..., 1] - vy * v_dot[..., 0]) / safe_rho2
    a_ddot = (vx * v_ddot[..., 1] - vy * v_ddot[..., 0]) / safe_rho2 - 2 * a_dot * (
        vx * v_dot[..., 0] + vy * v_dot[..., 1]
    ) / safe_rho2
    nan = np.nan
    return (
        defined,
        elevation,
        np.where(defined, e_dot, nan),
        np.where(defined, e_ddot, nan),
        azimuth,
        np.where(defined, a_dot, nan),
        np.where(defined, a_ddot, nan),
    )

"""Input validators: ``check_*`` return a clean float array or raise a ValueError that names
the offending shape or value, where it is in the batch and how to fix it (pytransform3d style).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual.number import Array, batch_index_text
from screwkit.errors import InputError

#: Default tolerance on orthogonality / unit-norm checks. Values typed from printed tables
#: (4–6 digits) fail tighter checks, so the default is loose; pass ``tol`` to tighten.
DEFAULT_TOL = 1e-6


def check_finite(x: ArrayLike, name: str = "value") -> Array:
    """``x`` as a float array; raise ValueError if it holds NaN or inf."""
    a = np.asarray(x, dtype=float)
    bad = ~np.isfinite(a)
    if np.any(bad):
        raise InputError(f"{name} contains NaN or inf{batch_index_text(bad)}; pass finite numbers")
    return a


def check_trailing_shape(x: ArrayLike, shape: tuple[int, ...], name: str = "value") -> Array:
    """``x`` as a finite float array whose last axes are ``shape`` (any leading batch axes)."""
    a = np.asarray(x, dtype=float)
    if a.ndim < len(shape) or a.shape[a.ndim - len(shape):] != shape:
        raise InputError(
            f"{name} must have shape (..., {', '.join(map(str, shape))}); got shape {a.shape}"
        )
    return check_finite(a, name)


def check_vector3(v: ArrayLike, name: str = "vector") -> Array:
    """A batch of 3-vectors, shape (..., 3)."""
    return check_trailing_shape(v, (3,), name)


def check_unit_vector(v: ArrayLike, name: str = "direction", tol: float = DEFAULT_TOL) -> Array:
    """A batch of unit 3-vectors (| |v| − 1 | ≤ tol)."""
    a = check_vector3(v, name)
    err = np.abs(np.linalg.norm(a, axis=-1) - 1.0)
    bad = err > tol
    if np.any(bad):
        raise InputError(
            f"{name} must be a unit vector: | |v| - 1 | = {err[bad].max():.3g} > {tol:g}"
            f"{batch_index_text(bad)}; normalise it first"
        )
    return a


def check_rotation_matrix(R: ArrayLike, name: str = "rotation", tol: float = DEFAULT_TOL) -> Array:
    """A batch of proper rotation matrices, shape (..., 3, 3): RᵀR = I within ``tol`` and
    det R = +1 (a reflection is rejected)."""
    a = check_trailing_shape(R, (3, 3), name)
    err = np.abs(np.swapaxes(a, -1, -2) @ a - np.eye(3)).max(axis=(-2, -1))
    bad = err > tol
    if np.any(bad):
        raise InputError(
            f"{name} is not orthogonal: max |RᵀR − I| = {err[bad].max():.3g} > {tol:g}"
            f"{batch_index_text(bad)}; re-orthonormalise it (e.g. scipy Rotation.from_matrix) or "
            "loosen tol"
        )
    det = np.linalg.det(a)
    bad = det < 0
    if np.any(bad):
        raise InputError(
            f"{name} has det = {det[bad].min():.3g} < 0{batch_index_text(bad)}: a reflection is not a "
            "rotation; check the handedness of the frame"
        )
    return a


def check_screw_matrix_parts(
    real: ArrayLike, dual: ArrayLike, name: str = "screw matrix", tol: float = DEFAULT_TOL
) -> tuple[Array, Array]:
    """Real and dual parts of a proper screw matrix T̂ = R + ε[d]×R (Bagci eq. 2.10): R a
    rotation and D·Rᵀ skew-symmetric (so that a translation d exists by transference)."""
    R = check_rotation_matrix(real, f"real part of {name}", tol)
    D = check_trailing_shape(dual, (3, 3), f"dual part of {name}")
    W = D @ np.swapaxes(R, -1, -2)
    err = np.abs(W + np.swapaxes(W, -1, -2)).max(axis=(-2, -1))
    scale = np.maximum(1.0, np.abs(D).max(axis=(-2, -1)))
    bad = err > tol * scale
    if np.any(bad):
        raise InputError(
            f"{name} dual part is not [d]×R: D·Rᵀ is not skew-symmetric (max |W + Wᵀ| = "
            f"{err[bad].max():.3g}){batch_index_text(bad)}; build it with "
            "ScrewMatrix.from_rotation_translation"
        )
    return R, D


def check_transform(T: ArrayLike, name: str = "transform", tol: float = DEFAULT_TOL) -> Array:
    """A batch of 4×4 homogeneous rigid transforms [[R, d], [0, 0, 0, 1]]."""
    a = check_trailing_shape(T, (4, 4), name)
    bottom = np.abs(a[..., 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=-1)
    bad = bottom > tol
    if np.any(bad):
        raise InputError(
            f"{name} last row must be (0, 0, 0, 1); it is off by {bottom[bad].max():.3g}"
            f"{batch_index_text(bad)}"
        )
    check_rotation_matrix(a[..., :3, :3], f"rotation block of {name}", tol)
    return a


def check_unit_dual_quaternion(
    real: ArrayLike, dual: ArrayLike, name: str = "dual quaternion", tol: float = DEFAULT_TOL
) -> tuple[Array, Array]:
    """A batch of unit dual quaternions (w, x, y, z) + ε(w, x, y, z): |r| = 1 and r·d = 0."""
    r = check_trailing_shape(real, (4,), f"real part of {name}")
    d = check_trailing_shape(dual, (4,), f"dual part of {name}")
    nerr = np.abs(np.linalg.norm(r, axis=-1) - 1.0)
    bad = nerr > tol
    if np.any(bad):
        raise InputError(
            f"{name} real part is not a unit quaternion: | |r| - 1 | = {nerr[bad].max():.3g}"
            f"{batch_index_text(bad)}; call .normalized()"
        )
    derr = np.abs(np.sum(r * d, axis=-1))
    scale = np.maximum(1.0, np.linalg.norm(d, axis=-1))
    bad = derr > tol * scale
    if np.any(bad):
        raise InputError(
            f"{name} is not unit: real·dual = {derr[bad].max():.3g} ≠ 0{batch_index_text(bad)}; "
            "call .normalized()"
        )
    return r, d


def check_unit_line(
    direction: ArrayLike, moment: ArrayLike, name: str = "line", tol: float = DEFAULT_TOL
) -> tuple[Array, Array]:
    """A batch of Plücker unit lines: |u| = 1 and u·m = 0 (the moment of a line through p is
    m = p × u, Bagci eq. A.1)."""
    u = check_unit_vector(direction, f"direction of {name}", tol)
    m = check_vector3(moment, f"moment of {name}")
    err = np.abs(np.sum(u * m, axis=-1))
    scale = np.maximum(1.0, np.linalg.norm(m, axis=-1))
    bad = err > tol * scale
    if np.any(bad):
        raise InputError(
            f"{name} is not a line: direction·moment = {err[bad].max():.3g} ≠ 0"
            f"{batch_index_text(bad)}; build it with DualVector.line(point, direction)"
        )
    return u, m


__all__ = [
    "DEFAULT_TOL",
    "check_finite",
    "check_rotation_matrix",
    "check_screw_matrix_parts",
    "check_trailing_shape",
    "check_transform",
    "check_unit_dual_quaternion",
    "check_unit_line",
    "check_unit_vector",
    "check_vector3",
]

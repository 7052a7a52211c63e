"""Unit dual quaternions q̂ = r + ε ½ t r, batch-first (the 8-parameter twin of ScrewMatrix).

Layout: ``real`` and ``dual`` are arrays of shape (..., 4), each scalar first (w, x, y, z),
as in pytransform3d; scipy's ``RigidTransform.as_dual_quat(scalar_first=True)`` uses the same
layout. r is the rotation quaternion and t the translation, so a displacement x → R x + t is
q̂ = r + ε ½ (0, t) ⊗ r (the dual-quaternion form of Bagci eq. 2.10). q̂ and −q̂ are the same
displacement.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual.number import Array, Dual
from screwkit.dual.rotation import (
    quaternion_conjugate,
    quaternion_from_rotation,
    quaternion_multiply,
    rotation_from_quaternion,
)
from screwkit.errors import InputError


def _pure(v: Array) -> Array:
    """(0, v) for vectors of shape (..., 3)."""
    return np.concatenate([np.zeros_like(v[..., :1]), v], axis=-1)


@dataclass(frozen=True, eq=False)
class DualQuaternion:
    """A batch of dual quaternions ``real + ε·dual`` (each (..., 4), scalar first).

    ``A @ B`` composes like :class:`ScrewMatrix` (apply B first, then A): it is the Hamilton
    product A ⊗ B.
    """

    real: Array
    dual: Array

    __array_ufunc__ = None

    def __init__(self, real: ArrayLike, dual: ArrayLike | None = None) -> None:
        r = np.asarray(real, dtype=float)
        d = np.zeros_like(r) if dual is None else np.asarray(dual, dtype=float)
        r, d = np.broadcast_arrays(r, d)
        if r.ndim < 1 or r.shape[-1] != 4:
            raise InputError(
                f"a dual quaternion needs parts of trailing shape (4,) (w, x, y, z); got {r.shape}"
            )
        object.__setattr__(self, "real", np.array(r))
        object.__setattr__(self, "dual", np.array(d))

    # --- factories --------------------------------------------------------------------------
    @classmethod
    def identity(cls, shape: tuple[int, ...] = ()) -> DualQuaternion:
        r = np.zeros((*shape, 4))
        r[..., 0] = 1.0
        return cls(r, np.zeros_like(r))

    @classmethod
    def from_array(cls, array: ArrayLike) -> DualQuaternion:
        """From (..., 8) = (w, x, y, z | w, x, y, z), the pytransform3d / scipy layout."""
        a = np.asarray(array, dtype=float)
        if a.ndim < 1 or a.shape[-1] != 8:
            raise InputError(f"a dual quaternion array needs trailing shape (8,); got {a.shape}")
        return cls(a[..., :4], a[..., 4:])

    def as_array(self) -> Array:
        """(..., 8) = (real w, x, y, z | dual w, x, y, z)."""
        return np.concatenate([self.real, self.dual], axis=-1)

    @classmethod
    def from_rotation_translation(cls, rotation: ArrayLike, translation: ArrayLike) -> DualQuaternion:
        """q̂ = r + ε ½ t ⊗ r for rotation matrices R (..., 3, 3) and translations t (..., 3)."""
        r = quaternion_from_rotation(rotation)
        t = np.asarray(translation, dtype=float)
        return cls(r, 0.5 * quaternion_multiply(_pure(t), r))

    @classmethod
    def from_screw_matrix(cls, screw: Any) -> DualQuaternion:
        """From a :class:`ScrewMatrix` (rotation R, translation by transference)."""
        return cls.from_rotation_translation(screw.real, screw.translation)

    def as_screw_matrix(self) -> Any:
        """The :class:`ScrewMatrix` R + ε[t]×R of this (unit) dual quaternion."""
        from screwkit.dual.screw_matrix import ScrewMatrix

        return ScrewMatrix.from_rotation_translation(self.rotation_matrix, self.translation)

    @classmethod
    def from_transform(cls, transform: ArrayLike) -> DualQuaternion:
        """From 4×4 homogeneous transforms (checked)."""
        from screwkit.dual.checks import check_transform

        T = check_transform(transform)
        return cls.from_rotation_translation(T[..., :3, :3], T[..., :3, 3])

    def as_transform(self) -> Array:
        """4×4 homogeneous transforms of this (unit) dual quaternion."""
        T = np.zeros((*self.shape, 4, 4))
        T[..., :3, :3] = self.rotation_matrix
        T[..., :3, 3] = self.translation
        T[..., 3, 3] = 1.0
        return T

    # --- access -----------------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        """Batch shape (without the trailing 4)."""
        return tuple(self.real.shape[:-1])

    def __getitem__(self, index: Any) -> DualQuaternion:
        if not isinstance(index, tuple):
            index = (index,)
        return DualQuaternion(self.real[(*index, Ellipsis, slice(None))],
                              self.dual[(*index, Ellipsis, slice(None))])

    @property
    def rotation_matrix(self) -> Array:
        """R of the real (rotation) quaternion, assumed unit."""
        return rotation_from_quaternion(self.real)

    @property
    def translation(self) -> Array:
        """t = vector part of 2 d ⊗ r* (for a unit dual quaternion)."""
        return 2.0 * quaternion_multiply(self.dual, quaternion_conjugate(self.real))[..., 1:]

    # --- algebra ----------------------------------------------------------------------------
    def __matmul__(self, other: DualQuaternion) -> DualQuaternion:
        """Hamilton product (r1 + εd1)(r2 + εd2) = r1r2 + ε(r1d2 + d1r2): apply ``other`` first."""
        if not isinstance(other, DualQuaternion):
            return NotImplemented
        return DualQuaternion(
            quaternion_multiply(self.real, other.real),
            quaternion_multiply(self.real, other.dual) + quaternion_multiply(self.dual, other.real),
        )

    def multiply(self, other: DualQuaternion) -> DualQuaternion:
        """Same as ``self @ other``."""
        return self @ other

    def conjugate(self) -> DualQuaternion:
        """Quaternion conjugate of both parts, r* + ε d*; the inverse of a unit dual
        quaternion."""
        return DualQuaternion(quaternion_conjugate(self.real), quaternion_conjugate(self.dual))

    def dual_conjugate(self) -> DualQuaternion:
        """Dual-number conjugate r − ε d."""
        return DualQuaternion(self.real, -self.dual)

    def norm_squared(self) -> Dual:
        """q̂ q̂* = |r|² + ε 2 r·d (a dual scalar; 1 + ε0 for a unit dual quaternion)."""
        return Dual(np.sum(self.real**2, axis=-1), 2.0 * np.sum(self.real * self.dual, axis=-1))

    def norm(self) -> Dual:
        """|q̂| = |r| + ε (r·d)/|r|."""
        n = np.linalg.norm(self.real, axis=-1)
        if np.any(n == 0):
            raise InputError("a dual quaternion with zero real part has no norm (pure dual)")
        return Dual(n, np.sum(self.real * self.dual, axis=-1) / n)

    def normalized(self) -> DualQuaternion:
        """q̂/|q̂|: a unit dual quaternion (|r| = 1 and r·d = 0)."""
        n = self.norm()
        r = self.real / n.real[..., None]
        d = self.dual / n.real[..., None] - r * (n.dual / n.real)[..., None]
        return DualQuaternion(r, d)

    def inverse(self) -> DualQuaternion:
        """q̂⁻¹ = r⁻¹ − ε r⁻¹ d r⁻¹ for any dual quaternion with r ≠ 0."""
        n2 = np.sum(self.real**2, axis=-1, keepdims=True)
        if np.any(n2 == 0):
            raise InputError("a dual quaternion with zero real part has no inverse")
        ri = quaternion_conjugate(self.real) / n2
        return DualQuaternion(ri, -quaternion_multiply(quaternion_multiply(ri, self.dual), ri))

    def transform_points(self, points: ArrayLike) -> Array:
        """x → R x + t for points of shape (..., 3)."""
        p = np.asarray(points, dtype=float)
        return np.einsum("...ij,...j->...i", self.rotation_matrix, p) + self.translation

    def isclose(self, other: DualQuaternion, atol: float = 1e-9) -> Array:
        """Same displacement within ``atol`` (q̂ and −q̂ count as equal)."""
        a = self.as_array()
        b = other.as_array()
        same = np.abs(a - b).max(axis=-1) <= atol
        flip = np.abs(a + b).max(axis=-1) <= atol
        return same | flip


__all__ = ["DualQuaternion"]

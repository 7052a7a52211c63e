"""Conversions between displacement representations, named ``target_from_source``
(pytransform3d style): ScrewMatrix, 4×4 homogeneous transforms, DualQuaternion, and
scipy ``Rotation`` / ``RigidTransform``.

All of them mean the same map x → R x + d (rotate, then translate; DESIGN.md "Conventions").
Inputs from outside the library (4×4 matrices, scipy objects) are checked; conversions between
screwkit's own types are not (call ``.check()`` on untrusted ScrewMatrix input).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual.checks import DEFAULT_TOL, check_rotation_matrix, check_transform, check_vector3
from screwkit.dual.number import Array
from screwkit.dual.quaternion import DualQuaternion
from screwkit.dual.screw_matrix import ScrewMatrix
from screwkit.errors import InputError

if TYPE_CHECKING:  # scipy.spatial is imported on first use: it costs 0.3 s at start-up
    from scipy.spatial.transform import RigidTransform, Rotation


# --- 4×4 homogeneous transforms -------------------------------------------------------------
def screw_matrix_from_transform(transform: ArrayLike, tol: float = DEFAULT_TOL) -> ScrewMatrix:
    """T̂ = R + ε[d]×R from 4×4 transforms [[R, d], [0, 1]] (Bagci eq. 2.10)."""
    T = check_transform(transform, tol=tol)
    return ScrewMatrix.from_rotation_translation(T[..., :3, :3], T[..., :3, 3])


def transform_from_screw_matrix(screw: ScrewMatrix) -> Array:
    """4×4 transforms [[R, d], [0, 1]], d recovered by transference [d]× = T_D·Rᵀ."""
    T = np.zeros((*screw.shape, 4, 4))
    T[..., :3, :3] = screw.real
    T[..., :3, 3] = screw.translation
    T[..., 3, 3] = 1.0
    return T


def transform_from_dual_quaternion(dq: DualQuaternion) -> Array:
    """4×4 transforms of unit dual quaternions."""
    return dq.as_transform()


def dual_quaternion_from_transform(transform: ArrayLike, tol: float = DEFAULT_TOL) -> DualQuaternion:
    """Unit dual quaternions (real part with w ≥ 0) of 4×4 transforms."""
    T = check_transform(transform, tol=tol)
    return DualQuaternion.from_rotation_translation(T[..., :3, :3], T[..., :3, 3])


# --- ScrewMatrix ↔ DualQuaternion --------------------------------------------------------------
def dual_quaternion_from_screw_matrix(screw: ScrewMatrix) -> DualQuaternion:
    """r from R (Shepperd, w ≥ 0), dual part ½ t ⊗ r with t from transference."""
    return DualQuaternion.from_screw_matrix(screw)


def screw_matrix_from_dual_quaternion(dq: DualQuaternion) -> ScrewMatrix:
    """R + ε[t]×R from a unit dual quaternion (t = 2 d ⊗ r*)."""
    result: ScrewMatrix = dq.as_screw_matrix()
    return result


# --- scipy.spatial.transform ------------------------------------------------------------------
def screw_matrix_from_rotation(
    rotation: Rotation, translation: ArrayLike | None = None
) -> ScrewMatrix:
    """R + ε[d]×R from a scipy ``Rotation`` (any batch shape) and optional translations d."""
    from scipy.spatial.transform import Rotation

    if not isinstance(rotation, Rotation):
        raise InputError(
            f"expected a scipy.spatial.transform.Rotation; got {type(rotation).__name__}"
        )
    R = rotation.as_matrix()
    if translation is None:
        return ScrewMatrix(R, np.zeros_like(R))
    d = check_vector3(translation, "translation")
    return ScrewMatrix.from_rotation_translation(R, d)


def rotation_from_screw_matrix(screw: ScrewMatrix, tol: float = DEFAULT_TOL) -> Rotation:
    """The scipy ``Rotation`` of the real part (checked to be a rotation; the translation is
    dropped)."""
    from scipy.spatial.transform import Rotation

    R = check_rotation_matrix(screw.real, "real part of screw matrix", tol)
    return Rotation.from_matrix(R)


def screw_matrix_from_rigid_transform(transform: RigidTransform) -> ScrewMatrix:
    """R + ε[d]×R from a scipy ``RigidTransform`` (any batch shape)."""
    from scipy.spatial.transform import RigidTransform

    if not isinstance(transform, RigidTransform):
        raise InputError(
            f"expected a scipy.spatial.transform.RigidTransform; got {type(transform).__name__}"
        )
    return ScrewMatrix.from_rotation_translation(
        transform.rotation.as_matrix(), transform.translation
    )


def rigid_transform_from_screw_matrix(screw: ScrewMatrix, tol: float = DEFAULT_TOL) -> RigidTransform:
    """A scipy ``RigidTransform`` with the same batch shape (real part checked)."""
    from scipy.spatial.transform import RigidTransform

    check_rotation_matrix(screw.real, "real part of screw matrix", tol)
    return RigidTransform.from_matrix(transform_from_screw_matrix(screw))


def dual_quaternion_from_rigid_transform(transform: RigidTransform) -> DualQuaternion:
    """From scipy's own dual quaternion (``as_dual_quat(scalar_first=True)``, same layout)."""
    from scipy.spatial.transform import RigidTransform

    if not isinstance(transform, RigidTransform):
        raise InputError(
            f"expected a scipy.spatial.transform.RigidTransform; got {type(transform).__name__}"
        )
    return DualQuaternion.from_array(transform.as_dual_quat(scalar_first=True))


def rigid_transform_from_dual_quaternion(dq: DualQuaternion) -> RigidTransform:
    """To a scipy ``RigidTransform`` via ``from_dual_quat(scalar_first=True)``."""
    from scipy.spatial.transform import RigidTransform

    from screwkit.dual.checks import check_unit_dual_quaternion

    check_unit_dual_quaternion(dq.real, dq.dual)
    return RigidTransform.from_dual_quat(dq.as_array(), scalar_first=True)


__all__ = [
    "dual_quaternion_from_rigid_transform",
    "dual_quaternion_from_screw_matrix",
    "dual_quaternion_from_transform",
    "rigid_transform_from_dual_quaternion",
    "rigid_transform_from_screw_matrix",
    "rotation_from_screw_matrix",
    "screw_matrix_from_dual_quaternion",
    "screw_matrix_from_rigid_transform",
    "screw_matrix_from_rotation",
    "screw_matrix_from_transform",
    "transform_from_dual_quaternion",
    "transform_from_screw_matrix",
]

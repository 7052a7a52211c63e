"""Dual-number screw calculus: dual numbers, dual vectors (lines), 3×3 screw matrices, dual
quaternions, screw parameters, dual Euler angles, conversions and the real spatial toolbox
(`screwkit.dual.spatial`: skew, cross, elementary rotations, angle wrapping; docs/conventions.md).

Names are imported from their modules on first use, so that ``from screwkit.dual import
ScrewMatrix`` does not load every module (start-up time of the command line)."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: public name -> module that defines it
_EXPORTS: dict[str, str] = {
    'Dual': 'screwkit.dual.number',
    'DualDivisionError': 'screwkit.dual.number',
    'DualEulerAngles': 'screwkit.dual.euler',
    'DualQuaternion': 'screwkit.dual.quaternion',
    'DualVector': 'screwkit.dual.vector',
    'ScrewMatrix': 'screwkit.dual.screw_matrix',
    'ScrewParameters': 'screwkit.dual.screw_parameters',
    'acos': 'screwkit.dual.number',
    'asin': 'screwkit.dual.number',
    'atan': 'screwkit.dual.number',
    'atan2': 'screwkit.dual.number',
    'check_rotation_matrix': 'screwkit.dual.checks',
    'check_screw_matrix_parts': 'screwkit.dual.checks',
    'check_transform': 'screwkit.dual.checks',
    'check_unit_dual_quaternion': 'screwkit.dual.checks',
    'check_unit_line': 'screwkit.dual.checks',
    'check_unit_vector': 'screwkit.dual.checks',
    'check_vector3': 'screwkit.dual.checks',
    'common_normal': 'screwkit.dual.vector',
    'cos': 'screwkit.dual.number',
    'dual_angle': 'screwkit.dual.vector',
    'dual_euler_from_screw_matrix': 'screwkit.dual.euler',
    'dual_quaternion_from_rigid_transform': 'screwkit.dual.conversions',
    'dual_quaternion_from_screw_matrix': 'screwkit.dual.conversions',
    'dual_quaternion_from_transform': 'screwkit.dual.conversions',
    'exp': 'screwkit.dual.number',
    'log': 'screwkit.dual.number',
    'rigid_transform_from_dual_quaternion': 'screwkit.dual.conversions',
    'rigid_transform_from_screw_matrix': 'screwkit.dual.conversions',
    'rotation_from_screw_matrix': 'screwkit.dual.conversions',
    'screw_matrix_about_line': 'screwkit.dual.screw_parameters',
    'screw_matrix_from_dual_euler': 'screwkit.dual.euler',
    'screw_matrix_from_dual_quaternion': 'screwkit.dual.conversions',
    'screw_matrix_from_rigid_transform': 'screwkit.dual.conversions',
    'screw_matrix_from_rotation': 'screwkit.dual.conversions',
    'screw_matrix_from_screw_parameters': 'screwkit.dual.screw_parameters',
    'screw_matrix_from_transform': 'screwkit.dual.conversions',
    'screw_parameters_from_screw_matrix': 'screwkit.dual.screw_parameters',
    'sin': 'screwkit.dual.number',
    'skew': 'screwkit.dual.spatial',
    'cross': 'screwkit.dual.spatial',
    'elementary_rotation': 'screwkit.dual.spatial',
    'rot_x': 'screwkit.dual.spatial',
    'rot_y': 'screwkit.dual.spatial',
    'rot_z': 'screwkit.dual.spatial',
    'wrap_angle': 'screwkit.dual.spatial',
    'wrap_angle_near': 'screwkit.dual.spatial',
    'sqrt': 'screwkit.dual.number',
    'tan': 'screwkit.dual.number',
    'transform_from_dual_quaternion': 'screwkit.dual.conversions',
    'transform_from_screw_matrix': 'screwkit.dual.conversions',
    'vee': 'screwkit.dual.spatial',
}


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'screwkit.dual' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)


if TYPE_CHECKING:
    from screwkit.dual.checks import (
        check_rotation_matrix,
        check_screw_matrix_parts,
        check_transform,
        check_unit_dual_quaternion,
        check_unit_line,
        check_unit_vector,
        check_vector3,
    )
    from screwkit.dual.conversions import (
        dual_quaternion_from_rigid_transform,
        dual_quaternion_from_screw_matrix,
        dual_quaternion_from_transform,
        rigid_transform_from_dual_quaternion,
        rigid_transform_from_screw_matrix,
        rotation_from_screw_matrix,
        screw_matrix_from_dual_quaternion,
        screw_matrix_from_rigid_transform,
        screw_matrix_from_rotation,
        screw_matrix_from_transform,
        transform_from_dual_quaternion,
        transform_from_screw_matrix,
    )
    from screwkit.dual.euler import (
        DualEulerAngles,
        dual_euler_from_screw_matrix,
        screw_matrix_from_dual_euler,
    )
    from screwkit.dual.number import (
        Dual,
        DualDivisionError,
        acos,
        asin,
        atan,
        atan2,
        cos,
        exp,
        log,
        sin,
        sqrt,
        tan,
    )
    from screwkit.dual.quaternion import DualQuaternion
    from screwkit.dual.screw_matrix import ScrewMatrix
    from screwkit.dual.screw_parameters import (
        ScrewParameters,
        screw_matrix_about_line,
        screw_matrix_from_screw_parameters,
        screw_parameters_from_screw_matrix,
    )
    from screwkit.dual.spatial import (
        cross,
        elementary_rotation,
        rot_x,
        rot_y,
        rot_z,
        skew,
        vee,
        wrap_angle,
        wrap_angle_near,
    )
    from screwkit.dual.vector import DualVector, common_normal, dual_angle

__all__ = [
    "Dual",
    "DualDivisionError",
    "DualEulerAngles",
    "DualQuaternion",
    "DualVector",
    "ScrewMatrix",
    "ScrewParameters",
    "acos",
    "asin",
    "atan",
    "atan2",
    "check_rotation_matrix",
    "check_screw_matrix_parts",
    "check_transform",
    "check_unit_dual_quaternion",
    "check_unit_line",
    "check_unit_vector",
    "check_vector3",
    "common_normal",
    "cos",
    "cross",
    "dual_angle",
    "dual_euler_from_screw_matrix",
    "dual_quaternion_from_rigid_transform",
    "dual_quaternion_from_screw_matrix",
    "dual_quaternion_from_transform",
    "elementary_rotation",
    "exp",
    "log",
    "rigid_transform_from_dual_quaternion",
    "rigid_transform_from_screw_matrix",
    "rot_x",
    "rot_y",
    "rot_z",
    "rotation_from_screw_matrix",
    "screw_matrix_about_line",
    "screw_matrix_from_dual_euler",
    "screw_matrix_from_dual_quaternion",
    "screw_matrix_from_rigid_transform",
    "screw_matrix_from_rotation",
    "screw_matrix_from_screw_parameters",
    "screw_matrix_from_transform",
    "screw_parameters_from_screw_matrix",
    "sin",
    "skew",
    "sqrt",
    "tan",
    "transform_from_dual_quaternion",
    "transform_from_screw_matrix",
    "vee",
    "wrap_angle",
    "wrap_angle_near",
]

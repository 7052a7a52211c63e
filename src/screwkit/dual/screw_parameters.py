"""Screw (Chasles) parameters of a rigid displacement and the displacement they describe
(Bagci 1969 SPEC §2.6, "equivalent screw").

Every displacement x → R x + d is a rotation θ about a line (unit direction u through point c)
combined with a translation s along the same line: the dual angle θ̂ = θ + εs about the dual
unit line û = u + ε(c × u). The pitch is p = s/θ.

Conventions (also in docs/conventions.md):

* θ ∈ [0, π]; u is chosen so that the rotation is right-handed about u.
* c is the point of the axis nearest the origin (c·u = 0).
* Identity (θ = 0, d = 0): u = (0, 0, 1), c = 0, s = 0, pitch 0 (a zero rotation about z).
* Pure translation (θ ≤ ``angle_tol``): u = d/|d|, c = 0 (the axis direction is all that is
  defined; the line through the origin is returned), s = |d|, pitch +inf.
* Rotation by π (π − θ ≤ ``angle_tol``): (u, π, s) and (−u, π, −s) are the same displacement;
  u is chosen with its largest-magnitude component positive.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual.number import Array, Dual
from screwkit.dual.rotation import axis_angle_from_rotation, rotation_from_axis_angle
from screwkit.dual.screw_matrix import ScrewMatrix
from screwkit.dual.vector import DualVector

#: Rotation angles below this (radians) are treated as pure translations, and angles within
#: this of π as half turns. Between 1e-9 and ~1e-6 the axis point c = ½ cot(θ/2) u × d is
#: genuinely ill-conditioned (it moves to infinity as θ → 0).
DEFAULT_ANGLE_TOL = 1e-9


@dataclass(frozen=True, eq=False)
class ScrewParameters:
    """A batch of screw displacements: ``angle`` θ about and ``translation`` s along the line
    through ``axis_point`` c with unit ``axis_direction`` u. Shapes: u, c (..., 3); θ, s (...).
    """

    axis_direction: Array
    axis_point: Array
    angle: Array
    translation: Array

    def __init__(
        self,
        axis_direction: ArrayLike,
        axis_point: ArrayLike,
        angle: ArrayLike,
        translation: ArrayLike,
    ) -> None:
        from screwkit.dual.checks import check_finite, check_unit_vector, check_vector3

        u = check_unit_vector(axis_direction, "axis_direction")
        c = check_vector3(axis_point, "axis_point")
        th = check_finite(angle, "angle")
        s = check_finite(translation, "translation")
        batch = np.broadcast_shapes(u.shape[:-1], c.shape[:-1], th.shape, s.shape)
        object.__setattr__(self, "axis_direction", np.array(np.broadcast_to(u, (*batch, 3))))
        object.__setattr__(self, "axis_point", np.array(np.broadcast_to(c, (*batch, 3))))
        object.__setattr__(self, "angle", np.array(np.broadcast_to(th, batch)))
        object.__setattr__(self, "translation", np.array(np.broadcast_to(s, batch)))

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.angle.shape)

    def __getitem__(self, index: Any) -> ScrewParameters:
        if not isinstance(index, tuple):
            index = (index,)
        vec = (*index, Ellipsis, slice(None))
        return ScrewParameters(
            self.axis_direction[vec], self.axis_point[vec], self.angle[index], self.translation[index]
        )

    @property
    def pitch(self) -> Array:
        """p = s/θ; +inf (or −inf) for a pure translation, 0 for the identity."""
        th = self.angle
        s = self.translation
        with np.errstate(divide="ignore", invalid="ignore"):
            p = np.where(th != 0, s / np.where(th != 0, th, 1.0), np.sign(s) * np.inf)
        return np.where((th == 0) & (s == 0), 0.0, p)

    @property
    def is_pure_translation(self) -> Array:
        """True where the rotation angle is zero and the translation is not."""
        return (self.angle == 0) & (self.translation != 0)

    @property
    def dual_angle(self) -> Dual:
        """θ̂ = θ + εs (Bagci eq. 2.1)."""
        return Dual(self.angle, self.translation)

    @property
    def axis_line(self) -> DualVector:
        """The screw axis as a dual unit vector û = u + ε(c × u)."""
        return DualVector(self.axis_direction, np.cross(self.axis_point, self.axis_direction))

    @classmethod
    def from_screw_matrix(
        cls, screw: ScrewMatrix, angle_tol: float = DEFAULT_ANGLE_TOL
    ) -> ScrewParameters:
        """See :func:`screw_parameters_from_screw_matrix`."""
        return screw_parameters_from_screw_matrix(screw, angle_tol)

    def as_screw_matrix(self) -> ScrewMatrix:
        """See :func:`screw_matrix_from_screw_parameters`."""
        return screw_matrix_from_screw_parameters(self)


def screw_parameters_from_screw_matrix(
    screw: ScrewMatrix, angle_tol: float = DEFAULT_ANGLE_TOL
) -> ScrewParameters:
    """Axis, angle, translation and pitch of T̂ = R + ε[d]×R (Bagci SPEC §2.6).

    θ and u come from the unit quaternion of R (Shepperd), which keeps full precision at θ → 0
    and θ → π, instead of cos θ = (tr R − 1)/2 and u = vee(R − Rᵀ)/(2 sin θ), which are the
    same in exact arithmetic. Then s = d·u and c = ½[d − (d·u)u + cot(θ/2) u × d].
    """
    from screwkit.dual.checks import check_screw_matrix_parts

    R, _ = check_screw_matrix_parts(screw.real, screw.dual)
    d = screw.translation
    u, theta = axis_angle_from_rotation(R)

    translation_only = theta <= angle_tol
    dn = np.linalg.norm(d, axis=-1)
    z = np.array([0.0, 0.0, 1.0])
    u_trans = np.where((dn > 0)[..., None], d / np.where(dn > 0, dn, 1.0)[..., None], z)
    u = np.where(translation_only[..., None], u_trans, u)

    # Half turn: pick the sign of u with the largest-magnitude component positive.
    half_turn = (np.pi - theta) <= angle_tol
    big = np.take_along_axis(u, np.argmax(np.abs(u), axis=-1)[..., None], axis=-1)[..., 0]
    u = np.where((half_turn & (big < 0))[..., None], -u, u)

    s = np.sum(d * u, axis=-1)
    half = np.where(translation_only, 1.0, theta / 2.0)
    cot_half = np.cos(half) / np.sin(half)
    c = 0.5 * (d - s[..., None] * u + cot_half[..., None] * np.cross(u, d))
    c = np.where(translation_only[..., None], 0.0, c)
    theta = np.where(translation_only, 0.0, theta)
    return ScrewParameters(u, c, theta, s)


def screw_matrix_from_screw_parameters(params: ScrewParameters) -> ScrewMatrix:
    """The displacement of a screw: rotation R(u, θ) about the line through c, then s along u:
    x → R(x − c) + c + s u, i.e. d = (I − R)c + s u. Equivalently T̂ = exp of the dual angle
    θ̂ about û (Bagci eq. 1.1, dual Rodrigues)."""
    u = params.axis_direction
    c = params.axis_point
    R = rotation_from_axis_angle(u, params.angle)
    d = c - np.einsum("...ij,...j->...i", R, c) + params.translation[..., None] * u
    return ScrewMatrix.from_rotation_translation(R, d)


def screw_matrix_about_line(line: DualVector, angle: Dual | ArrayLike) -> ScrewMatrix:
    """Screw displacement by the dual angle θ̂ = θ + εs about a line û = u + ε(c × u) (u is
    normalised): rotation θ about the line and translation s along it (Bagci eq. 1.1)."""
    a = Dual.coerce(angle)
    un = line.normalized()
    params = ScrewParameters(un.real, un.point(), a.real, a.dual)
    return screw_matrix_from_screw_parameters(params)


__all__ = [
    "DEFAULT_ANGLE_TOL",
    "ScrewParameters",
    "screw_matrix_about_line",
    "screw_matrix_from_screw_parameters",
    "screw_parameters_from_screw_matrix",
]

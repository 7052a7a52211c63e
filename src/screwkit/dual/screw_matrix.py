"""3×3 dual (screw) matrices T̂ = R + ε[d]×R, batch-first.

A screw matrix represents the rigid displacement x → R x + d acting on lines (Bagci eq. 2.10;
Rahman eqs. 2.1–2.7). The translation comes back by the principle of transference
[d]× = T_D·Rᵀ.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual.number import Array, Dual
from screwkit.dual.spatial import elementary_rotation, skew, vee
from screwkit.errors import InputError


@dataclass(frozen=True, eq=False)
class ScrewMatrix:
    """A batch of 3×3 dual matrices ``real + ε·dual`` (shapes (..., 3, 3)).

    For a proper rigid displacement, ``real`` is a rotation R and ``dual = [d]× R``.
    ``A @ B`` composes (apply B first, then A, as 4×4 transforms do); ``A @ line`` moves a
    :class:`~screwkit.dual.vector.DualVector`.
    """

    real: Array
    dual: Array

    __array_ufunc__ = None  # ndarray (op) ScrewMatrix defers to ScrewMatrix

    def __init__(self, real: ArrayLike, dual: ArrayLike | None = None) -> None:
        r = np.asarray(real, dtype=float)
        d = np.zeros_like(r) if dual is None else np.asarray(dual, dtype=float)
        r, d = np.broadcast_arrays(r, d)
        if r.ndim < 2 or r.shape[-2:] != (3, 3):
            raise InputError(f"a screw matrix needs trailing shape (3, 3); got {r.shape}")
        object.__setattr__(self, "real", np.array(r))
        object.__setattr__(self, "dual", np.array(d))

    @classmethod
    def _wrap(cls, real: Array, dual: Array) -> ScrewMatrix:
        """Adopt two fresh, same-shape (..., 3, 3) float arrays without copying (hot paths)."""
        out = object.__new__(cls)
        object.__setattr__(out, "real", real)
        object.__setattr__(out, "dual", dual)
        return out

    # --- factories ----------------------------------------------------------------------
    @classmethod
    def identity(cls, shape: tuple[int, ...] = ()) -> ScrewMatrix:
        eye = np.broadcast_to(np.eye(3), (*shape, 3, 3))
        return cls(eye, np.zeros_like(eye))

    @classmethod
    def from_rotation_translation(cls, rotation: ArrayLike, translation: ArrayLike) -> ScrewMatrix:
        """T̂ = R + ε[d]×R (Bagci eq. 2.10): rotate by R, then translate by d (x → Rx + d).

        ``rotation`` is not checked here (hot path); use :func:`check_rotation_matrix` or
        :meth:`check` on untrusted input.
        """
        R = np.asarray(rotation, dtype=float)
        d = np.asarray(translation, dtype=float)
        return cls(R, skew(d) @ R)

    @classmethod
    def from_transform(cls, transform: ArrayLike) -> ScrewMatrix:
        """From 4×4 homogeneous transforms (checked); see
        :func:`screwkit.dual.conversions.screw_matrix_from_transform`."""
        from screwkit.dual.conversions import screw_matrix_from_transform

        return screw_matrix_from_transform(transform)

    def as_transform(self) -> Array:
        """The 4×4 homogeneous transforms [[R, d], [0, 1]] of this displacement."""
        from screwkit.dual.conversions import transform_from_screw_matrix

        return transform_from_screw_matrix(self)

    def check(self, tol: float = 1e-6) -> ScrewMatrix:
        """``self`` if it is a proper screw matrix (R orthogonal, det +1, D·Rᵀ skew) within
        ``tol``, else ValueError naming the first offending batch index."""
        from screwkit.dual.checks import check_screw_matrix_parts

        check_screw_matrix_parts(self.real, self.dual, tol=tol)
        return self

    @classmethod
    def translation_only(cls, translation: ArrayLike) -> ScrewMatrix:
        """T̂_L = I + ε[t]× (Bagci eq. 2.9)."""
        t = np.asarray(translation, dtype=float)
        eye = np.broadcast_to(np.eye(3), (*t.shape[:-1], 3, 3))
        return cls(eye, skew(t))

    @classmethod
    def about_axis(cls, angle: Dual | ArrayLike, axis: int) -> ScrewMatrix:
        """Dual rotation by θ̂ = θ + εs about coordinate axis 0 (x), 1 (y) or 2 (z): rotation θ
        about the axis and translation s along it (Bagci eqs. 2.6–2.11; Rahman A.2–A.9)."""
        a = Dual.coerce(angle)
        c, s = np.cos(a.real), np.sin(a.real)
        R = elementary_rotation(c, s, axis)
        # d/dθ of the elementary rotation is [e_axis]× R, so the dual part is s·[e]×R.
        e = np.zeros(3)
        e[axis] = 1.0
        D = a.dual[..., None, None] * (skew(e) @ R)
        return cls(R, D)

    @classmethod
    def rot_x(cls, angle: Dual | ArrayLike) -> ScrewMatrix:
        """X(α̂): dual rotation about x (Rahman eq. A.5)."""
        return cls.about_axis(angle, 0)

    @classmethod
    def rot_y(cls, angle: Dual | ArrayLike) -> ScrewMatrix:
        """Y(η̂): dual rotation about y (Rahman eq. A.7)."""
        return cls.about_axis(angle, 1)

    @classmethod
    def rot_z(cls, angle: Dual | ArrayLike) -> ScrewMatrix:
        """Z(θ̂): dual rotation about z (Rahman eq. A.3)."""
        return cls.about_axis(angle, 2)

    @classmethod
    def hartenberg_denavit(cls, theta: Dual | ArrayLike, alpha: Dual | ArrayLike) -> ScrewMatrix:
        """Link transform M̂ = Z(θ̂)X(α̂), θ̂ = θ + εs, α̂ = α + εa (Rahman eq. 2.2)."""
        return cls.rot_z(theta) @ cls.rot_x(alpha)

    # --- access ---------------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        """Batch shape (without the trailing 3×3)."""
        return tuple(self.real.shape[:-2])

    def __getitem__(self, index: Any) -> ScrewMatrix:
        if not isinstance(index, tuple):
            index = (index,)
        return ScrewMatrix(self.real[(*index, Ellipsis, slice(None), slice(None))],
                           self.dual[(*index, Ellipsis, slice(None), slice(None))])

    @property
    def rotation(self) -> Array:
        """The real part R."""
        return self.real

    @property
    def translation(self) -> Array:
        """d from the principle of transference [d]× = T_D·Rᵀ (Rahman §2; Bagci §2.4)."""
        return vee(self.dual @ np.swapaxes(self.real, -1, -2))

    def transform_points(self, points: ArrayLike) -> Array:
        """x → R x + d for points of shape (..., 3)."""
        p = np.asarray(points, dtype=float)
        return np.einsum("...ij,...j->...i", self.real, p) + self.translation

    # --- algebra --------------------------------------------------------------------------
    def __matmul__(self, other: Any) -> Any:
        """Composition ``A @ B`` = (A_R + εA_D)(B_R + εB_D) = A_R B_R + ε(A_R B_D + A_D B_R):
        apply B first, then A. Three real batched matmuls and one in-place add (the benchmark
        in benchmarks/bench_dual.py measures it against one real matmul)."""
        if isinstance(other, ScrewMatrix):
            real = np.matmul(self.real, other.real)
            dual = np.matmul(self.real, other.dual)
            if dual.shape == real.shape:
                dual += np.matmul(self.dual, other.real)
                return ScrewMatrix._wrap(real, dual)
            return ScrewMatrix(real, dual + np.matmul(self.dual, other.real))
        from screwkit.dual.vector import DualVector

        if isinstance(other, DualVector):
            return DualVector(
                np.einsum("...ij,...j->...i", self.real, other.real),
                np.einsum("...ij,...j->...i", self.real, other.dual)
                + np.einsum("...ij,...j->...i", self.dual, other.real),
            )
        return NotImplemented

    @property
    def T(self) -> ScrewMatrix:
        """Transpose (dual parts transposed too)."""
        return ScrewMatrix(np.swapaxes(self.real, -1, -2), np.swapaxes(self.dual, -1, -2))

    def inverse(self) -> ScrewMatrix:
        """Inverse of a proper screw matrix: its transpose (Bagci §2.4, Âᵀ Â = I)."""
        return self.T

    def general_inverse(self) -> ScrewMatrix:
        """Inverse of any dual matrix with invertible real part: A⁻¹ − ε A⁻¹ B A⁻¹."""
        Ai = np.linalg.inv(self.real)
        return ScrewMatrix(Ai, -Ai @ self.dual @ Ai)

    def orthogonality_error(self) -> Array:
        """max |T̂ᵀT̂ − I| over real and dual parts, per batch element."""
        p = self.T @ self
        eye = np.eye(3)
        return np.maximum(
            np.abs(p.real - eye).max(axis=(-2, -1)), np.abs(p.dual).max(axis=(-2, -1))
        )

    def isclose(self, other: ScrewMatrix, atol: float = 1e-9) -> Array:
        return (np.abs(self.real - other.real).max(axis=(-2, -1)) <= atol) & (
            np.abs(self.dual - other.dual).max(axis=(-2, -1)) <= atol
        )

"""Dual vectors â = a + εa° and lines in Plücker coordinates (Bagci A.1–A.2, A.19–A.22)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from screwkit.dual import number as dn
from screwkit.dual.number import Array, Dual
from screwkit.errors import InputError


@dataclass(frozen=True, eq=False)
class DualVector:
    """A batch of dual 3-vectors ``real + ε·dual`` (shapes (..., 3)).

    A line through point p with direction u is the dual unit vector u + ε(p × u): ``real`` is
    the direction, ``dual`` the moment about the origin (Bagci A.1).
    """

    real: Array
    dual: Array

    __array_ufunc__ = None  # ndarray (op) DualVector defers to DualVector

    def __init__(self, real: ArrayLike, dual: ArrayLike | None = None) -> None:
        r = np.asarray(real, dtype=float)
        d = np.zeros_like(r) if dual is None else np.asarray(dual, dtype=float)
        r, d = np.broadcast_arrays(r, d)
        if r.shape[-1:] != (3,):
            raise InputError(f"a dual vector needs trailing shape (3,); got {r.shape}")
        object.__setattr__(self, "real", np.array(r))
        object.__setattr__(self, "dual", np.array(d))

    @classmethod
    def line(cls, point: ArrayLike, direction: ArrayLike) -> DualVector:
        """The unit line through ``point`` along ``direction`` (direction is normalised):
        û = u + ε(p × u) (Bagci A.1–A.2)."""
        from screwkit.dual.checks import check_vector3

        u = check_vector3(direction, "line direction")
        p = check_vector3(point, "point on the line")
        n = np.linalg.norm(u, axis=-1, keepdims=True)
        if np.any(n == 0):
            raise InputError(
                "a line needs a non-zero direction; got the zero vector"
                + dn.batch_index_text(n[..., 0] == 0)
            )
        u = u / n
        return cls(u, np.cross(p, u))

    @classmethod
    def line_through_points(cls, first: ArrayLike, second: ArrayLike) -> DualVector:
        """The unit line through two distinct points, directed from ``first`` to ``second``."""
        p = np.asarray(first, dtype=float)
        q = np.asarray(second, dtype=float)
        return cls.line(p, q - p)

    @property
    def direction(self) -> Array:
        """Real part: the direction of a line (Plücker u)."""
        return self.real

    @property
    def moment(self) -> Array:
        """Dual part: the moment p × u of a line about the origin (Plücker m)."""
        return self.dual

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.real.shape[:-1])

    def __getitem__(self, index: Any) -> DualVector:
        if not isinstance(index, tuple):
            index = (index,)
        return DualVector(self.real[(*index, Ellipsis, slice(None))],
                          self.dual[(*index, Ellipsis, slice(None))])

    def __add__(self, other: DualVector) -> DualVector:
        return DualVector(self.real + other.real, self.dual + other.dual)

    def __sub__(self, other: DualVector) -> DualVector:
        return DualVector(self.real - other.real, self.dual - other.dual)

    def __neg__(self) -> DualVector:
        return DualVector(-self.real, -self.dual)

    def scale(self, k: Dual | ArrayLike) -> DualVector:
        """k̂ â for a dual scalar k̂."""
        kk = Dual.coerce(k)
        return DualVector(
            kk.real[..., None] * self.real,
            kk.real[..., None] * self.dual + kk.dual[..., None] * self.real,
        )

    def dot(self, other: DualVector) -> Dual:
        """Â·B̂ = A·B + ε(A·B° + A°·B) = |A||B| cos φ̂ (Bagci A.19)."""
        return Dual(
            np.sum(self.real * other.real, axis=-1),
            np.sum(self.real * other.dual + self.dual * other.real, axis=-1),
        )

    def cross(self, other: DualVector) -> DualVector:
        """Â × B̂ = A×B + ε(A×B° + A°×B) (Bagci A.21)."""
        return DualVector(
            np.cross(self.real, other.real),
            np.cross(self.real, other.dual) + np.cross(self.dual, other.real),
        )

    def norm(self) -> Dual:
        """|Â| = |A| + ε (A·A°)/|A|."""
        n = np.linalg.norm(self.real, axis=-1)
        if np.any(n == 0):
            raise InputError("the norm of a dual vector with zero real part is not a dual number")
        return Dual(n, np.sum(self.real * self.dual, axis=-1) / n)

    def normalized(self) -> DualVector:
        """â/|â|: a dual unit vector (a line) with the same axis."""
        n = self.norm()
        inv = Dual(1.0, 0.0) / n
        return self.scale(inv)

    def point(self) -> Array:
        """Point of the line nearest the origin: u × m/|u|² (u × m for a unit line)."""
        n2 = np.sum(self.real * self.real, axis=-1, keepdims=True)
        if np.any(n2 == 0):
            raise InputError("a dual vector with zero real part is not a line (it has no point)")
        return np.cross(self.real, self.dual) / n2


def dual_angle(a: DualVector, b: DualVector) -> Dual:
    """Dual angle φ̂ = φ + εd from line ``a`` to line ``b`` (Bagci A.19–A.22).

    * φ ∈ [0, π] is the twist angle, measured right-handed about the common normal
      n = a × b/|a × b| (so it is never negative);
    * d is the signed length of the common normal, positive when ``b`` lies on the +n side of
      ``a``: d = (p_b − p_a)·n, equivalently cos φ̂ = â·b̂ = cos φ − ε d sin φ.

    For parallel lines (φ = 0 or π) n is taken from ``a`` towards ``b``, so d ≥ 0 is their
    distance. Directions need not be unit; they are normalised.
    """
    ua = a.normalized()
    ub = b.normalized()
    c = ua.dot(ub)
    cr = ua.cross(ub)
    s_real = np.linalg.norm(cr.real, axis=-1)
    phi = np.arctan2(s_real, c.real)
    # Skew lines: from the dual part of the cosine, c.dual = −d sin φ.
    with np.errstate(divide="ignore", invalid="ignore"):
        d_skew = -c.dual / s_real
    # Parallel lines: distance between them.
    diff = ub.point() - ua.point()
    along = np.sum(diff * ua.real, axis=-1)[..., None] * ua.real
    d_par = np.linalg.norm(diff - along, axis=-1)
    parallel = s_real < _PARALLEL_TOL
    d = np.where(parallel, d_par, d_skew)
    return Dual(phi, d)


def common_normal(a: DualVector, b: DualVector) -> DualVector:
    """The common normal line of lines ``a`` and ``b``: unit direction n = a × b/|a × b|,
    through the feet of the normal. It is n̂ = (â × b̂)/sin φ̂, the dual normalisation of the
    dual cross product (Bagci A.21–A.22, with the |A||B| factor restored).

    Parallel lines have a one-parameter family of common normals: the one through the point
    of ``a`` nearest the origin is returned, directed from ``a`` towards ``b``. Coincident lines
    (every point is a foot) raise ValueError.
    """
    ua = a.normalized()
    ub = b.normalized()
    cr = ua.cross(ub)
    s_real = np.linalg.norm(cr.real, axis=-1)
    parallel = s_real < _PARALLEL_TOL
    pa = ua.point()
    diff = ub.point() - pa
    perp = diff - np.sum(diff * ua.real, axis=-1)[..., None] * ua.real
    dist = np.linalg.norm(perp, axis=-1)
    coincident = parallel & (dist <= _PARALLEL_TOL * np.maximum(1.0, np.abs(pa).max(axis=-1)))
    if np.any(coincident):
        raise InputError(
            "the common normal of two coincident lines is undefined"
            + dn.batch_index_text(coincident)
        )
    safe_s = np.where(parallel, 1.0, s_real)
    n_skew = cr.real / safe_s[..., None]
    # Foot of the normal on a: p_a + t u_a with t = (p_b − p_a)·(u_b × n)/|u_a × u_b|.
    t = np.sum(diff * np.cross(ub.real, n_skew), axis=-1) / safe_s
    foot_skew = pa + t[..., None] * ua.real
    safe_dist = np.where(parallel, dist, 1.0)
    n_par = perp / np.where(safe_dist == 0, 1.0, safe_dist)[..., None]
    n = np.where(parallel[..., None], n_par, n_skew)
    foot = np.where(parallel[..., None], pa, foot_skew)
    return DualVector(n, np.cross(foot, n))


# Below this |u_a × u_b| two unit directions count as parallel: the skew formulas divide by it.
_PARALLEL_TOL = 1e-12

__all__ = ["DualVector", "common_normal", "dual_angle"]

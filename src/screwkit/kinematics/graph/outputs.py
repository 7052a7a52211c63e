"""Named outputs of a mechanism graph, measured the way engineers plot them: the angle a
body-fixed direction turns through about a world axis (a wheel's camber about the longitudinal
axis, its toe about the vertical: the bump-steer curves), and the travel of a point along a world
direction (track change at the contact patch).

For a direction v fixed in a body (v₀ in the drawing, v = R v₀ now) and a unit world axis u, the
angle is that of the projection p = v − (u·v)u against the drawing's p₀, signed about u:
φ = atan2(u·(p₀ × p), p₀·p). With v̇ = ω × v and v̈ = α × v + ω × (ω × v) (the body's angular
velocity and acceleration), φ̇ = u·(p × ṗ)/|p|² and φ̈ = u·(p × p̈)/|p|² − 2φ̇ (p·ṗ)/|p|².
A point's travel along a unit d is (x − x₀)·d, with rate v·d and acceleration a·d.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.model.mechanism_outputs import BodyAngle, PointTravel

Array = NDArray[np.float64]


def _dot(a: Array, b: Array) -> Array:
    return np.einsum("ni,ni->n", a, b)


def body_angle(out: BodyAngle, R: Array, w: Array, al: Array) -> tuple[Array, Array, Array]:
    """Value, rate and acceleration (N,) of a body angle from the body's rotations (N, 3, 3),
    angular velocities and accelerations (N, 3) (module docstring)."""
    u = out.about
    v = R @ out.vector
    vd = np.cross(w, v)
    vdd = np.cross(al, v) + np.cross(w, vd)
    p0 = out.vector - (u @ out.vector) * u
    p = v - (v @ u)[:, None] * u
    pd = vd - (vd @ u)[:, None] * u
    pdd = vdd - (vdd @ u)[:, None] * u
    angle = np.arctan2(np.cross(p0, p) @ u, p @ p0)
    n2 = _dot(p, p)
    rate = (np.cross(p, pd) @ u) / n2
    acc = (np.cross(p, pdd) @ u) / n2 - 2.0 * rate * _dot(p, pd) / n2
    return angle, rate, acc


def point_travel(out: PointTravel, drawn: Array, x: Array, v: Array, a: Array
                 ) -> tuple[Array, Array, Array]:
    """Value, rate and acceleration of a point's travel from where the drawing puts it."""
    d = out.along
    return (x - drawn) @ d, v @ d, a @ d

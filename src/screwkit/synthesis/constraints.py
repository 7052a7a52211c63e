"""Bagci's parameters of constraint q1, q2 (Bagci 1969, §5.3, eqs. 5.12-5.21, delta0 = 0).

In the plane normal to the output axis (X = global Y component, Y = component along
(sin lambda0, 0, cos lambda0)) the sphere centre at theta0 projects to the point
P = (d1 cos theta0, d1 cos lambda0 sin theta0) of the input-crank ellipse, the output axis to
(a, b sin lambda0), and, for delta0 = 0, the coupler projects with its true length d2 at the slope
q (the normal of the coupler circle), so the output-crank tip is C = P + d2 (cos q, sin q).
Two such points C1, C2 with a prescribed output rotation dphi12 between them fix the output
crank: centre and radius by eqs. 5.19-5.21, and a, b, d3 leave the unknowns.

Everything here is complex-safe (only +, -, *, /, sqrt, sin, cos, arctan, with branch choices
made on real parts), so the exact derivatives of the derived dimensions come by complex-step
differentiation.  Angles in radians.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError

__all__ = ["OutputCrank", "output_crank_from_constraints", "q_from_dwell"]

Array = NDArray[Any]


def _real_sign(x: Array) -> Array:
    return np.where(np.real(x) < 0.0, -1.0, 1.0)


def q_from_dwell(theta0: Any, lambda0: Any, *, other_tangency: bool = False,
                 fold: bool = True) -> Array:
    """Eq. 5.13: q = atan(tan theta0 / cos lambda0), folded into [0, pi) as Program C codes it.

    The slope of the normal to the projected input-crank ellipse at theta0.  Imposing q there
    makes the input-crank and coupler ellipses tangent: a rotation limit (d phi0/d theta0 = 0,
    App. D) at theta0, the necessary condition of a dwell of any order.  ``other_tangency`` adds
    pi (the other side of the normal: exterior vs interior tangency, SPEC §5.3 quadrant rule).
    ``fold=False`` returns the continuous atan2(sin theta0, cos theta0 cos lambda0) instead: the
    fold jumps by pi where theta0 crosses 0 or 180 deg, which a solver must not see.
    """
    t = np.asarray(theta0)
    lam = np.asarray(lambda0)
    num, den = np.sin(t), np.cos(t) * np.cos(lam)
    # arctan of the ratio (complex-safe), then the quadrant of atan2 from the real parts
    small = np.abs(np.real(den)) < 1e-300
    safe_den = np.where(small, 1.0, den)
    base = np.where(small, np.pi / 2.0, np.arctan(num / safe_den))
    base = base + np.where(np.real(den) < 0.0, np.pi, 0.0) * np.where(small, 0.0, 1.0)
    if not fold:
        return base + (np.pi if other_tangency else 0.0)
    folded = base - np.pi * np.floor(np.real(base) / np.pi)
    return folded + (np.pi if other_tangency else 0.0)


@dataclass(frozen=True)
class OutputCrank:
    """Output crank built from two constraint points (eqs. 5.19-5.21)."""

    centre_x: Array  # a (global Y coordinate of the output axis)
    centre_y: Array  # b sin(lambda0)
    d3: Array
    phi1: Array  # output-crank angle at the first point (direction centre -> C1)
    tip1: tuple[Array, Array]
    tip2: tuple[Array, Array]


def output_crank_from_constraints(
    d1: Any, d2: Any, lambda0: Any, theta01: Any, theta02: Any, q1: Any, q2: Any, dphi12: Any,
) -> OutputCrank:
    """Output-crank centre (a, b sin lambda0) and radius d3 from q1, q2 (Bagci eqs. 5.14-5.21).

    With C_i = P_i + d2 (cos q_i, sin q_i) at theta0_i and the output rotation dphi12 from C1 to
    C2 (counter-clockwise positive in the normal plane, the sense of phi0)::

        a         = (X1 + X2)/2 + (Y1 - Y2)/2 cot(dphi12/2)      (5.19)
        b sin l0  = (Y1 + Y2)/2 + (X2 - X1)/2 cot(dphi12/2)      (5.20)
        d3        = |C1 C2| / (2 |sin(dphi12/2)|)                (5.21)

    i.e. the centre of the rotation by dphi12 that takes C1 to C2.  The sign of dphi12 picks the
    side of the chord (Program C's flag KD3 with its folded bisector slope tau, eq. 5.15, which is
    ambiguous mod pi).  Broadcasts over every argument; complex-safe.
    """
    d1, d2, lam, theta01, theta02, q1, q2 = (np.asarray(v) for v in (d1, d2, lambda0, theta01,
                                                                      theta02, q1, q2))
    x1 = d1 * np.cos(theta01) + d2 * np.cos(q1)
    y1 = d1 * np.cos(lam) * np.sin(theta01) + d2 * np.sin(q1)
    x2 = d1 * np.cos(theta02) + d2 * np.cos(q2)
    y2 = d1 * np.cos(lam) * np.sin(theta02) + d2 * np.sin(q2)
    half = 0.5 * np.asarray(dphi12)
    sh = np.sin(half)
    if np.any(np.abs(np.real(sh)) < 1e-12):
        raise InputError("the output rotation between the two constraint points must not be a "
                         "multiple of 360 deg (eq. 5.21 divides by sin(dphi12/2))")
    cot = np.cos(half) / sh
    cx = 0.5 * (x1 + x2) + 0.5 * (y1 - y2) * cot
    cy = 0.5 * (y1 + y2) + 0.5 * (x2 - x1) * cot
    chord = np.sqrt((x1 - x2) ** 2 + (y2 - y1) ** 2)
    d3 = chord / (2.0 * sh * _real_sign(sh))
    ux, uy = x1 - cx, y1 - cy
    phi1 = np.arctan(uy / np.where(np.abs(np.real(ux)) < 1e-300, 1e-300, ux))
    phi1 = phi1 + np.where(np.real(ux) < 0.0, np.pi, 0.0)
    return OutputCrank(cx, cy, d3, phi1, (x1, y1), (x2, y2))

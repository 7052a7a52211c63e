"""The RSRC loop equation and its named terms M0, N0, W1, W2 (Bagci 1969, §3.4, eqs. 3.58-3.61).

With the input angle theta0 and the output angle phi0,

    M0 = b sin(lambda0) - d1 cos(lambda0) sin(theta0)        N0 = a - d1 cos(theta0)
    W1 = M0 sin(phi0) + N0 cos(phi0) + d3                     (= d2 cos chi0,            3.58)
    W2 = N0 sin(phi0) - M0 cos(phi0) - e sin(delta0)          (= d2 cos delta0 sin chi0, 3.59)

and the loop closes where G = (cos^2(delta0) (W1^2 - d2^2) + W2^2) / 2 = 0 (eq. 3.61, halved), whose
phi0-derivative is Q5 = W2 M1 + cos^2(delta0) W1 M2 (§3.5, M1 = N0 cos phi0 + M0 sin phi0,
M2 = M0 cos phi0 - N0 sin phi0).

These functions are the single implementation used by the closed form (positions, rates, limits)
and by the dimensional synthesis, which evaluates them on batches of candidate mechanisms (and in
complex arithmetic for complex-step derivatives): every dimension of `RSRCDimensionArrays` may be
a float or an array that broadcasts against the angle arrays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.kinematics.closed_forms.quartic import sin_cos
from screwkit.kinematics.closed_forms.rsrc.dimensions import RSRCDimensions

__all__ = [
    "LoopEquation",
    "LoopTerms",
    "RSRCDimensionArrays",
    "closure_terms",
    "input_terms",
    "loop_equation",
    "loop_residual",
    "loop_terms_at",
]

FloatArray = NDArray[np.float64]
#: a float or an array of floats (or of complex numbers, for complex-step derivatives)
Value = Any


@dataclass(frozen=True)
class RSRCDimensionArrays:
    """RSRC dimensions as the loop equation uses them: lengths and the sines and cosines of the
    skew angles, each a float or an array (one entry per mechanism of a batch).

    Build it with `from_dimensions` (one mechanism, Python floats, the closed form's hot path) or
    `from_arrays` (a batch, e.g. columns of shape (B, 1) against angles of shape (B, N)).
    """

    d1: Value
    d2: Value
    d3: Value
    a: Value
    b: Value
    e: Value
    sin_delta0: Value
    cos_delta0: Value
    sin_lambda0: Value
    cos_lambda0: Value

    @classmethod
    def from_dimensions(cls, dims: RSRCDimensions) -> RSRCDimensionArrays:
        """One mechanism, as Python floats."""
        return cls(
            dims.d1, dims.d2, dims.d3, dims.a, dims.b, dims.e,
            math.sin(dims.delta0), math.cos(dims.delta0),
            math.sin(dims.lambda0), math.cos(dims.lambda0),
        )

    @classmethod
    def from_arrays(
        cls, *, d1: ArrayLike, d2: ArrayLike, d3: ArrayLike, a: ArrayLike, b: ArrayLike,
        e: ArrayLike, delta0: ArrayLike, lambda0: ArrayLike,
    ) -> RSRCDimensionArrays:
        """A batch of mechanisms: every argument a float or an array (real or complex)."""
        return cls(d1, d2, d3, a, b, e, np.sin(delta0), np.cos(delta0), np.sin(lambda0),
                   np.cos(lambda0))


def input_terms(dims: RSRCDimensionArrays, sin_theta0: Value, cos_theta0: Value
                ) -> tuple[Value, Value]:
    """(M0, N0) of §3.4: M0 = b sin(lambda0) - d1 cos(lambda0) sin(theta0), N0 = a - d1 cos(theta0)."""
    m0 = dims.b * dims.sin_lambda0 - (dims.d1 * dims.cos_lambda0) * sin_theta0
    n0 = dims.a - dims.d1 * cos_theta0
    return m0, n0


def closure_terms(
    dims: RSRCDimensionArrays, m0: Value, n0: Value, sin_phi0: Value, cos_phi0: Value
) -> tuple[Value, Value]:
    """(W1, W2) of eqs. 3.58/3.59: W1 = M0 sin phi0 + N0 cos phi0 + d3 (= d2 cos chi0) and
    W2 = N0 sin phi0 - M0 cos phi0 - e sin delta0 (= d2 cos delta0 sin chi0)."""
    w1 = m0 * sin_phi0 + n0 * cos_phi0 + dims.d3
    w2 = n0 * sin_phi0 - m0 * cos_phi0 - dims.e * dims.sin_delta0
    return w1, w2


@dataclass
class LoopTerms:
    """Intermediates shared by the position and rate formulas of one block (§3.4, §3.5).

    Sines and cosines of theta0 (st, ct), phi0 (sp, cp) and chi0 (sc, cc), and M0, N0, W1, W2.
    st, ct, m0, n0 have shape (n, 1); the others (n, k).
    """

    st: FloatArray
    ct: FloatArray
    sp: FloatArray
    cp: FloatArray
    sc: FloatArray
    cc: FloatArray
    m0: FloatArray
    n0: FloatArray
    w1: FloatArray
    w2: FloatArray


def loop_terms_at(
    dims: RSRCDimensions, theta: FloatArray, phi: FloatArray, chi: FloatArray
) -> LoopTerms:
    """`LoopTerms` from angles; theta (n, 1), phi and chi (n, k)."""
    arrays = RSRCDimensionArrays.from_dimensions(dims)
    st, ct = sin_cos(theta)
    sp, cp = sin_cos(phi)
    sc, cc = sin_cos(chi)
    m0, n0 = input_terms(arrays, st, ct)
    w1, w2 = closure_terms(arrays, m0, n0, sp, cp)
    return LoopTerms(st, ct, sp, cp, sc, cc, m0, n0, w1, w2)


class LoopEquation(NamedTuple):
    """The loop equation at given angles with every named term (§3.4, §3.5); each an array of the
    broadcast shape of the dimensions and angles."""

    m0: Value
    n0: Value
    w1: Value
    w2: Value
    #: M1 = N0 cos phi0 + M0 sin phi0 = dW2/dphi0
    m1: Value
    #: M2 = M0 cos phi0 - N0 sin phi0 = dW1/dphi0
    m2: Value
    #: G = (cos^2 delta0 (W1^2 - d2^2) + W2^2) / 2 (eq. 3.61, halved): zero on every assembly
    residual: Value
    #: Q5 = dG/dphi0 = W2 M1 + cos^2 delta0 W1 M2 (§3.5): zero at an input dead centre
    slope: Value


def loop_equation(dims: RSRCDimensionArrays, theta0: Value, phi0: Value) -> LoopEquation:
    """The RSRC loop equation G(theta0, phi0) (Bagci 1969, eq. 3.61) and its terms, vectorised.

    ``dims`` may hold one mechanism (floats) or a batch (arrays broadcasting against the angles,
    real or complex: the synthesis differentiates through it by complex steps).  The angles are
    in radians.  G is zero wherever the mechanism closes; Q5 = dG/dphi0 is the denominator of the
    output rates (3.77).
    """
    m0, n0 = input_terms(dims, np.sin(theta0), np.cos(theta0))
    sp, cp = np.sin(phi0), np.cos(phi0)
    w1, w2 = closure_terms(dims, m0, n0, sp, cp)
    m1 = n0 * cp + m0 * sp
    m2 = m0 * cp - n0 * sp
    c2 = dims.cos_delta0 * dims.cos_delta0
    residual = 0.5 * (c2 * (w1 * w1 - dims.d2 * dims.d2) + w2 * w2)
    slope = w2 * m1 + c2 * w1 * m2
    return LoopEquation(m0, n0, w1, w2, m1, m2, residual, slope)


def loop_residual(
    dims: RSRCDimensions, theta: FloatArray, phi: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The residual that vanishes on a branch and its phi0-derivative, at (theta0, phi0).

    General delta0: G and Q5 of `loop_equation`.  delta0 = +-pi/2, where cos delta0 = 0 leaves
    G = W2^2 / 2 with a double zero: W2 itself (eq. 3.75) and its derivative M1.  Used to re-solve
    or check a branch's phi0 by Newton's method.
    """
    eq = loop_equation(RSRCDimensionArrays.from_dimensions(dims), theta, phi)
    if dims.special_case == "delta0_half_pi":
        return eq.w2, eq.m1
    return eq.residual, eq.slope

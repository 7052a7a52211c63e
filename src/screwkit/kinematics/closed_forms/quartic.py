"""Vectorised real roots of quartics and of degree-2 trigonometric polynomials.

The RSRC input-output equation (Bagci 1969, eq. 3.62) is a trigonometric polynomial of degree 2
in the output angle; its half-angle form is the quartic (3.63).  Bagci's Program A solves the
quartic with "Brown's method of quadratic factors" (Ferrari, eqs. 3.65-3.72) one sample at a
time.  Here the same construction runs on whole arrays:

* `real_quartic_roots` - Ferrari's factorisation of a monic quartic into two real quadratics
  (resolvent cubic by the trigonometric / Cardano formulas, as Program A does), followed by a
  guarded Newton step on the original quartic.  Pure real arithmetic, no per-sample loop and no
  eigenvalue call (batched ``numpy.linalg.eigvals`` on (N, 4, 4) companion matrices took 4.3 s
  per 10^6 quartics on the development machine, this about 0.3 s).
* `real_roots_of_trig_quadratic` - the roots phi of
  ``a0 + a1 cos phi + b1 sin phi + a2 cos 2phi + b2 sin 2phi = 0``.  Before the half-angle
  substitution the angle origin is turned, per sample, to the one of six candidate origins
  (multiples of 60 degrees) that makes the leading quartic coefficient largest.  This removes the
  root at t = tan(phi/2) -> infinity (Bagci's A4 -> 0, a root at phi = pi) and bounds every
  normalised coefficient (see the function's docstring).

Near-double roots (a limit position of the mechanism) come out of any floating-point quartic
solver as either two nearly equal real roots or a complex pair whose imaginary part is of the
order of the square root of the rounding error.  A complex pair whose imaginary part, measured as
an angle, is below ``double_root_tol`` (radians) is reported as a real double root: the mechanism
is then at its limit position to within rounding.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import wrap_angle_near

__all__ = [
    "DEFAULT_DOUBLE_ROOT_TOL",
    "real_quartic_roots",
    "real_roots_of_trig_quadratic",
    "sin_cos",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Largest imaginary part (as an angle, radians) of a complex root pair that is still reported as a
#: real double root.  Rounding alone produces imaginary parts of about 1e-8 at a true double root.
DEFAULT_DOUBLE_ROOT_TOL = 1e-6

_NEWTON_STEPS = 1


def sin_cos(angle: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """(sin x, cos x) through u = tan(x/2): sin = 2u/(1+u^2), cos = (1-u^2)/(1+u^2).

    Same accuracy as numpy's sin/cos (a few ulps; at x = pi, u ~ 1.6e16 still gives sin ~ 1e-16,
    cos = -1) but several times faster on common numpy builds, whose float64 sin and cos are not
    vectorised while tan is.  Used by every hot path of the closed forms.
    """
    u = np.tan(0.5 * np.asarray(angle, dtype=np.float64))
    u2 = u * u
    inv = 1.0 / (1.0 + u2)
    return 2.0 * u * inv, (1.0 - u2) * inv


def _largest_real_cubic_root(b: FloatArray, c: FloatArray, d: FloatArray) -> FloatArray:
    """Algebraically largest real root of x^3 + b x^2 + c x + d = 0 (closed form, vectorised).

    Trigonometric formula when the cubic has three real roots, Cardano's formula in its
    cancellation-free form otherwise (the "trisection" of Bagci 1969, §3.4; Program A uses the same
    trigonometric/hyperbolic formulas).  One guarded Newton step polishes the result.
    """
    shift = b / 3.0
    p = c - b * shift
    half_q = b * b * b / 27.0 - b * c / 6.0 + 0.5 * d
    third_p = p / 3.0
    disc = half_q * half_q + third_p * third_p * third_p
    with np.errstate(invalid="ignore", divide="ignore"):
        # three real roots: the largest is 2 sqrt(-p/3) cos(acos(-q/2 / sqrt(-p/3)^3) / 3)
        rad = np.sqrt(np.maximum(-third_p, 0.0))
        cos_arg = np.where(rad > 0.0, -half_q / (rad * rad * rad), 0.0)
        z_trig = 2.0 * rad * sin_cos(np.arccos(np.clip(cos_arg, -1.0, 1.0)) / 3.0)[1]
        # one real root: Cardano without cancellation
        u = np.cbrt(-half_q - np.copysign(np.sqrt(np.maximum(disc, 0.0)), half_q))
        z_card = np.where(u != 0.0, u - third_p / u, 0.0)
        x = np.where(disc > 0.0, z_card, z_trig) - shift
        f = ((x + b) * x + c) * x + d
        df = (3.0 * x + 2.0 * b) * x + c
        step = f / df
    return np.where(np.abs(step) <= 1e-3 * (1.0 + np.abs(x)), x - step, x)


def real_quartic_roots(
    c3: ArrayLike,
    c2: ArrayLike,
    c1: ArrayLike,
    c0: ArrayLike,
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
) -> tuple[FloatArray, BoolArray]:
    """Real roots of the monic quartics t^4 + c3 t^3 + c2 t^2 + c1 t + c0 = 0, batched.

    Ferrari's method in real arithmetic (Bagci 1969, eqs. 3.65-3.72, "Brown's method of quadratic
    factors", with the resolvent coefficient C1 = B1 B3 - 4 B0 as in Program A, not the printed
    B3 B2): the depressed quartic y^4 + p y^2 + q y + r is split into
    ``y^2 - s y + (p/2 + m + q/(2s))`` and ``y^2 + s y + (p/2 + m - q/(2s))`` with s^2 = 2m and m
    the largest real root of the resolvent cubic (always >= 0).  Each root is then polished by a
    Newton step on the original quartic; the step is taken only if it is smaller than a third of
    the distance to the other root of the same quadratic factor, so that two close roots never
    collapse onto one.

    Parameters
    ----------
    c3, c2, c1, c0
        Coefficients, broadcastable to a common shape (N,).
    double_root_tol
        A complex root pair t = u +- iv is reported as a real double root u when
        2 v / (1 + u^2) <= double_root_tol, i.e. when the imaginary part of the angle 2 atan(t)
        is below ``double_root_tol`` radians.

    Returns
    -------
    roots : (N, 4) float array
        Real roots (unsorted); entries that are not real hold NaN.
    is_real : (N, 4) bool array
        Where ``roots`` holds a real root.
    """
    b, c, d, e = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(x, dtype=np.float64)) for x in (c3, c2, c1, c0))
    )
    shift = 0.25 * b
    bb = b * b
    p = c - 0.375 * bb
    q = d - 0.5 * b * c + 0.125 * bb * b
    r = e - 0.25 * b * d + bb * c / 16.0 - 3.0 * bb * bb / 256.0

    m = np.maximum(_largest_real_cubic_root(p, 0.25 * p * p - r, -0.125 * q * q), 0.0)
    s = np.sqrt(2.0 * m)
    biquadratic = s * s <= 1e-12 * (1.0 + np.abs(p) + np.sqrt(np.abs(r)))

    with np.errstate(invalid="ignore", divide="ignore"):
        q_over_s = np.where(biquadratic, 0.0, q / s)
    # Ferrari factors y^2 -+ s y + (p/2 + m +- q/(2s)): y = (+-s +- sqrt(D+-)) / 2
    disc_plus = -2.0 * (p + m + q_over_s)
    disc_minus = -2.0 * (p + m - q_over_s)
    centre_plus = 0.5 * s - shift
    centre_minus = -0.5 * s - shift
    if biquadratic.any():
        # y^4 + p y^2 + r (q = 0 and m = 0): y^2 = w = (-p +- sqrt(p^2 - 4r)) / 2, and y = +-sqrt(w)
        # has the form of a factor with centre 0 and discriminant 4w
        w_disc = p * p - 4.0 * r
        w_sq = np.sqrt(np.maximum(w_disc, 0.0))
        complex_w = np.maximum(-w_disc, 0.0)  # complex y^2: pushes both factors to "not real"
        disc_plus = np.where(biquadratic, 2.0 * (w_sq - p) - complex_w, disc_plus)
        disc_minus = np.where(biquadratic, -2.0 * (w_sq + p) - complex_w, disc_minus)
        centre_plus = np.where(biquadratic, -shift, centre_plus)
        centre_minus = np.where(biquadratic, -shift, centre_minus)

    half_plus = 0.5 * np.sqrt(np.maximum(disc_plus, 0.0))
    half_minus = 0.5 * np.sqrt(np.maximum(disc_minus, 0.0))
    # a complex pair u +- iv with v = sqrt(-D)/2 counts as a double root if 2v/(1+u^2) <= tol
    real_plus = np.sqrt(np.maximum(-disc_plus, 0.0)) <= double_root_tol * (
        1.0 + centre_plus * centre_plus
    )
    real_minus = np.sqrt(np.maximum(-disc_minus, 0.0)) <= double_root_tol * (
        1.0 + centre_minus * centre_minus
    )
    t = np.stack(
        [
            centre_plus + half_plus,
            centre_plus - half_plus,
            centre_minus + half_minus,
            centre_minus - half_minus,
        ],
        axis=-1,
    )
    # guarded Newton polishing: |step| < (2/3) half = a third of the distance to the partner root
    gap = np.stack([half_plus, half_plus, half_minus, half_minus], axis=-1) * (2.0 / 3.0)
    bn, cn, dn, en = b[..., None], c[..., None], d[..., None], e[..., None]
    for _ in range(_NEWTON_STEPS):
        f = (((t + bn) * t + cn) * t + dn) * t + en
        df = ((4.0 * t + 3.0 * bn) * t + 2.0 * cn) * t + dn
        with np.errstate(invalid="ignore", divide="ignore"):
            step = f / df
        t = np.where(np.abs(step) < gap, t - step, t)
    is_real = np.stack([real_plus, real_plus, real_minus, real_minus], axis=-1)
    return np.where(is_real, t, np.nan), is_real


# Candidate angle origins r_k = k pi/3 - pi (k = 0..5): the leading half-angle coefficient after
# turning the origin to r is P(r + pi), i.e. P at the six angles k pi/3.
_SAMPLE_ANGLES = np.arange(6) * (np.pi / 3.0)
_ORIGINS = _SAMPLE_ANGLES - np.pi
_COS_R = np.cos(_ORIGINS)
_SIN_R = np.sin(_ORIGINS)
_COS_2R = np.cos(2.0 * _ORIGINS)
_SIN_2R = np.sin(2.0 * _ORIGINS)
_SAMPLE_BASIS = np.stack(
    [np.cos(_SAMPLE_ANGLES), np.sin(_SAMPLE_ANGLES), np.cos(2 * _SAMPLE_ANGLES),
     np.sin(2 * _SAMPLE_ANGLES)]
)


def real_roots_of_trig_quadratic(
    a0: ArrayLike,
    a1: ArrayLike,
    b1: ArrayLike,
    a2: ArrayLike,
    b2: ArrayLike,
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
) -> tuple[FloatArray, BoolArray]:
    """Real roots phi of ``a0 + a1 cos phi + b1 sin phi + a2 cos 2phi + b2 sin 2phi = 0``.

    The half-angle substitution t = tan((phi - r)/2) turns this into a quartic whose leading
    coefficient is the polynomial's value at phi = r + pi.  The origin r is chosen per sample among
    six multiples of 60 degrees to make that value largest.  A degree-2 trigonometric polynomial is
    determined by its values at six equally spaced angles (sum of their squares = 6 a0^2 +
    3 (a1^2 + b1^2 + a2^2 + b2^2)), so the largest of them is at least 1/sqrt(2) of the coefficient
    norm: the normalised quartic coefficients stay below about 20 and no root escapes to infinity.
    With r = 0 the quartic is Bagci's (3.63).

    Parameters
    ----------
    a0, a1, b1, a2, b2
        Coefficients, broadcastable to a common shape (N,).
    double_root_tol
        Largest imaginary part, as an angle (radians), of a complex root pair that is reported as a
        real double root (a limit position to within rounding).

    Returns
    -------
    phi : (N, 4) float array
        Real roots in (-pi, pi], sorted ascending; the remaining entries hold NaN (at the end).
    is_real : (N, 4) bool array
        ``~isnan(phi)``.  A polynomial that vanishes identically (all coefficients zero) has no
        isolated roots and is reported with none.
    """
    a0, a1, b1, a2, b2 = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(x, dtype=np.float64)) for x in (a0, a1, b1, a2, b2))
    )
    values = a0[..., None] + np.stack([a1, b1, a2, b2], axis=-1) @ _SAMPLE_BASIS
    k = np.argmax(np.abs(values), axis=-1)
    cr, sr, c2r, s2r = _COS_R[k], _SIN_R[k], _COS_2R[k], _SIN_2R[k]
    # coefficients in psi = phi - r
    a1r = a1 * cr + b1 * sr
    b1r = b1 * cr - a1 * sr
    a2r = a2 * c2r + b2 * s2r
    b2r = b2 * c2r - a2 * s2r
    lead = a0 - a1r + a2r
    degenerate = lead == 0.0  # only when every coefficient is zero
    inv = 1.0 / np.where(degenerate, 1.0, lead)
    c3 = (2.0 * b1r - 4.0 * b2r) * inv
    c2 = (2.0 * a0 - 6.0 * a2r) * inv
    c1 = (2.0 * b1r + 4.0 * b2r) * inv
    c0 = (a0 + a1r + a2r) * inv
    t, is_real = real_quartic_roots(c3, c2, c1, c0, double_root_tol=double_root_tol)
    if degenerate.any():
        t = np.where(degenerate[..., None], np.nan, t)
    # NaN (non-real) entries stay NaN and np.sort places them last
    phi = np.sort(wrap_angle_near(_ORIGINS[k][..., None] + 2.0 * np.arctan(t)), axis=-1)
    return phi, ~np.isnan(phi)

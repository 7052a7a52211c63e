"""Instantaneous dwells of the RSRC output: derivatives of phi0(theta0) of any order
(Bagci 1969, App. D; Harding's hesitation order)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.rsrc.dimensions import RSRCDimensions, check_input_angles
from screwkit.kinematics.closed_forms.rsrc.loop_equation import loop_residual
from screwkit.kinematics.closed_forms.rsrc.rates import LOCK_TOL
from screwkit.messages import given

__all__ = ["dwell_order", "rsrc_dwell_order", "rsrc_output_derivatives"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def _series_mul(a: FloatArray, b: FloatArray) -> FloatArray:
    """Product of truncated power series (coefficients along axis 0)."""
    out = np.zeros(np.broadcast_shapes(a.shape, b.shape))
    for k in range(len(out)):
        for j in range(k + 1):
            out[k] += a[j] * b[k - j]
    return out


def _series_sincos(a: FloatArray) -> tuple[FloatArray, FloatArray]:
    """sin and cos of a truncated power series (k s_k = sum j a_j c_(k-j), likewise c_k)."""
    s = np.zeros_like(a)
    c = np.zeros_like(a)
    s[0], c[0] = np.sin(a[0]), np.cos(a[0])
    for k in range(1, a.shape[0]):
        s[k] = sum(j * a[j] * c[k - j] for j in range(1, k + 1)) / k
        c[k] = -sum(j * a[j] * s[k - j] for j in range(1, k + 1)) / k
    return s, c


def rsrc_output_derivatives(
    dims: RSRCDimensions,
    theta0: ArrayLike,
    phi0: ArrayLike,
    *,
    order: int = 5,
) -> FloatArray:
    """d^k phi0 / d theta0^k, k = 1..order, on the branch through (theta0, phi0).

    Exact Taylor coefficients (to rounding) of the implicit function phi0(theta0) defined by the
    loop equation (3.61) (W2 = 0 for delta0 = +-pi/2): the equation is evaluated in truncated
    power-series arithmetic and solved order by order, p_k = -[G]_k / G_phi with G_phi = 2 Q5.
    Used for the order of an instantaneous dwell (App. D, Harding's hesitation order).

    Parameters
    ----------
    theta0, phi0
        Shape (M,): an assembled configuration of the branch (phi0 from `rsrc_positions`).
    order
        Highest derivative, 1..12.

    Returns
    -------
    (M, order) array; column k-1 is the k-th derivative.

    Raises
    ------
    ValueError
        If a (theta0, phi0) pair does not close the loop or is locked (Q5 = 0).
    """
    if not 1 <= int(order) <= 12:
        raise InputError(f"order must be between 1 and 12, got {order!r}")
    order = int(order)
    theta = check_input_angles(theta0)
    phi = check_input_angles(phi0, "phi0")
    if phi.shape != theta.shape:
        raise InputError(f"phi0 has shape {phi.shape}, theta0 has shape {theta.shape}")
    g0, g_phi = loop_residual(dims, theta, phi)
    scale = dims.length_scale
    half_pi = dims.special_case == "delta0_half_pi"
    residual_scale = scale if half_pi else scale * scale
    off = np.abs(g0) > 1e-8 * residual_scale
    if off.any():
        i = int(np.flatnonzero(off)[0])
        raise InputError(
            f"(theta0[{i}], phi0[{i}]) = ({theta[i]!r}, {phi[i]!r}) does not close the loop "
            f"(residual {g0[i]:.3g}); take phi0 from rsrc_positions"
        )
    locked = np.abs(g_phi) <= LOCK_TOL * residual_scale
    if locked.any():
        i = int(np.flatnonzero(locked)[0])
        raise InputError(
            f"configuration {i} (theta0 = {theta[i]!r}) is locked (Q5 = 0): phi0(theta0) has no "
            "derivatives there"
        )
    k_max = order + 1
    t_series = np.zeros((k_max, theta.shape[0]))
    t_series[0] = theta
    t_series[1] = 1.0
    st, ct = _series_sincos(t_series)
    sl, cl = math.sin(dims.lambda0), math.cos(dims.lambda0)
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    m0 = -dims.d1 * cl * st
    m0[0] += dims.b * sl
    n0 = -dims.d1 * ct
    n0[0] += dims.a
    p = np.zeros((k_max, theta.shape[0]))
    p[0] = phi
    derivative_scale = g_phi if half_pi else 2.0 * g_phi  # G_phi = 2 Q5 for G of eq. 3.61
    factorial = 1.0
    out = np.empty((theta.shape[0], order))
    for k in range(1, k_max):
        p[k] = 0.0
        sp, cp = _series_sincos(p)
        w2 = _series_mul(n0, sp) - _series_mul(m0, cp)
        w2[0] -= dims.e * sd
        if half_pi:
            g = w2
        else:
            w1 = _series_mul(m0, sp) + _series_mul(n0, cp)
            w1[0] += dims.d3
            g = cd * cd * _series_mul(w1, w1) + _series_mul(w2, w2)
        p[k] = -g[k] / derivative_scale
        factorial *= k
        out[:, k - 1] = factorial * p[k]
    return out


def dwell_order(derivatives: ArrayLike, tol: float) -> IntArray:
    """Number of leading derivatives with |d^k phi0/d theta0^k| <= tol (Harding's order).

    ``derivatives`` has shape (M, K) as returned by `rsrc_output_derivatives`; the result (M,) is
    0 for no dwell, 1 for a limit position, 2 for zero velocity and acceleration, and so on (K if
    all K vanish).  The tolerance is absolute, in rad / rad^k: with dimensions printed to 4-6
    digits a designed dwell holds only to about 1e-5 .. 1e-2 (Bagci's Fig. 9 and 10).
    """
    d = np.asarray(derivatives, dtype=np.float64)
    if d.ndim != 2:
        raise InputError(f"derivatives must have shape (M, K), got {d.shape}")
    if not tol >= 0.0:
        raise InputError(f"tol must be >= 0, got {given(tol)}")
    small = np.abs(d) <= tol
    leading = np.cumprod(small, axis=1)
    return leading.sum(axis=1).astype(np.int64)


def rsrc_dwell_order(
    dims: RSRCDimensions,
    theta0: ArrayLike,
    phi0: ArrayLike,
    *,
    tol: float = 1e-6,
    max_order: int = 6,
) -> tuple[IntArray, FloatArray]:
    """Order of the instantaneous dwell of phi0 at (theta0, phi0) (Bagci 1969, App. D).

    The order is the number of vanishing consecutive derivatives d^k phi0 / d theta0^k,
    k = 1, 2, ..., counted with the absolute tolerance ``tol`` (see `dwell_order`).  The
    derivatives are exact Taylor coefficients (`rsrc_output_derivatives`), not finite differences.

    Returns
    -------
    (order, derivatives): shapes (M,) and (M, max_order + 1); the extra derivative shows the first
    one that does not vanish.
    """
    derivatives = rsrc_output_derivatives(dims, theta0, phi0, order=max_order + 1)
    return dwell_order(derivatives[:, :max_order], tol), derivatives

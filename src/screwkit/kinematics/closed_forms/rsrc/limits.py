"""Rotation and translation limits of the RSRC output on every branch (Bagci 1969, App. D)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import wrap_angle
from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.rsrc.branches import rsrc_motion
from screwkit.kinematics.closed_forms.rsrc.dimensions import RSRCDimensions
from screwkit.kinematics.closed_forms.rsrc.loop_equation import (
    RSRCDimensionArrays,
    closure_terms,
    input_terms,
    loop_residual,
)
from screwkit.kinematics.closed_forms.rsrc.rates import rates_at_angles

__all__ = [
    "LimitPosition",
    "rsrc_rotation_limits",
    "rsrc_translation_limits",
]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class LimitPosition:
    """A rotation or translation limit of the output on one branch (Bagci 1969, App. D).

    Attributes
    ----------
    kind : "rotation" (d phi0 / d theta0 = 0, Q4 = 0, eq. D.1) or "translation" (dS/d theta0 = 0,
        corrected eq. D.3).
    theta0, phi0, chi0, S : the configuration (phi0 wrapped to (-pi, pi]).
    second_derivative : d^2 phi0 / d theta0^2 (rotation) or d^2 S / d theta0^2 (translation)
        there; zero for a higher-order dwell.
    branch : column of the `RSRCMotion` that was scanned.
    """

    kind: Literal["rotation", "translation"]
    theta0: float
    phi0: float
    chi0: float
    S: float
    second_derivative: float
    branch: int


def _chi_and_s(
    dims: RSRCDimensions, theta: FloatArray, phi: FloatArray, chi_sign: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """chi0 (eq. 3.59) and S (eq. 3.60) on a branch of known output angle."""
    arrays = RSRCDimensionArrays.from_dimensions(dims)
    st = np.sin(theta)
    m0, n0 = input_terms(arrays, st, np.cos(theta))
    w1, w2 = closure_terms(arrays, m0, n0, np.sin(phi), np.cos(phi))
    sd, cd = arrays.sin_delta0, arrays.cos_delta0
    s_input = dims.b * arrays.cos_lambda0 + dims.d1 * arrays.sin_lambda0 * st
    if dims.special_case == "delta0_half_pi":
        chi = chi_sign * np.arccos(np.clip(w1 / dims.d2, -1.0, 1.0))
        return chi, s_input - dims.d2 * sd * np.sin(chi)
    chi = np.arctan2(w2 / cd, w1)
    return chi, s_input + dims.e * cd - (sd / cd) * w2


def _polish_limits(
    dims: RSRCDimensions,
    lo: FloatArray,
    hi: FloatArray,
    f_lo: FloatArray,
    f_hi: FloatArray,
    phi_lo: FloatArray,
    phi_hi: FloatArray,
    chi_sign: FloatArray,
    which: Literal["rotation", "translation"],
    iterations: int = 40,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Safeguarded Newton on f(theta0) = d phi0/d theta0 (or dS/d theta0) along a branch.

    Vectorised over all brackets.  f' is the analytic second derivative (3.80 / 3.82 with
    theta0-dot = 1, theta0-ddot = 0); a Newton step leaving the bracket is replaced by
    bisection.  At each trial theta0 the branch's phi0 is re-solved from the loop equation by
    Newton (derivative Q5, or M1 for delta0 = +-pi/2) starting from the linear prediction.
    """
    theta = lo - f_lo * (hi - lo) / (f_hi - f_lo)  # regula falsi start
    phi = phi_lo + (phi_hi - phi_lo) * (theta - lo) / (hi - lo)
    one = np.ones_like(theta)[:, None]
    zero = np.zeros_like(one)
    f = fd = chi = s = np.zeros_like(theta)
    for _ in range(iterations):
        for _ in range(4):
            g, g_phi = loop_residual(dims, theta, phi)
            phi = phi - np.where(g_phi != 0.0, g / np.where(g_phi != 0.0, g_phi, 1.0), 0.0)
        chi, s = _chi_and_s(dims, theta, phi, chi_sign)
        res = rates_at_angles(dims, theta[:, None], phi[:, None], chi[:, None], one, zero)
        if which == "rotation":
            f, fd = res[0][:, 0], res[3][:, 0]
        else:
            f, fd = res[2][:, 0], res[5][:, 0]
        same_as_lo = np.sign(f) == np.sign(f_lo)
        lo = np.where(same_as_lo, theta, lo)
        hi = np.where(same_as_lo, hi, theta)
        with np.errstate(invalid="ignore", divide="ignore"):
            newton = theta - f / fd
        inside = np.isfinite(newton) & (newton > np.minimum(lo, hi)) & (newton < np.maximum(lo, hi))
        new_theta = np.where(inside, newton, 0.5 * (lo + hi))
        phi_rate = res[0][:, 0]
        phi = phi + np.nan_to_num(phi_rate) * (new_theta - theta)
        done = np.abs(new_theta - theta) <= 1e-15 * (1.0 + np.abs(theta))
        theta = new_theta
        if done.all():
            break
    for _ in range(4):
        g, g_phi = loop_residual(dims, theta, phi)
        phi = phi - np.where(g_phi != 0.0, g / np.where(g_phi != 0.0, g_phi, 1.0), 0.0)
    chi, s = _chi_and_s(dims, theta, phi, chi_sign)
    res = rates_at_angles(dims, theta[:, None], phi[:, None], chi[:, None], one, zero)
    fd = res[3][:, 0] if which == "rotation" else res[5][:, 0]
    return theta, phi, chi, s, fd


def _limits(
    dims: RSRCDimensions,
    which: Literal["rotation", "translation"],
    n_grid: int,
    theta0_range: tuple[float, float],
) -> tuple[LimitPosition, ...]:
    if n_grid < 16:
        raise InputError(f"n_grid must be at least 16 samples, got {n_grid}")
    start, stop = (float(v) for v in theta0_range)
    if not (math.isfinite(start) and math.isfinite(stop) and stop > start):
        raise InputError(f"theta0_range must be a finite increasing pair, got {theta0_range!r}")
    grid = np.linspace(start, stop, n_grid)
    motion = rsrc_motion(dims, grid)
    one = np.ones((n_grid, 1))
    res = rates_at_angles(dims, grid[:, None], motion.phi0, motion.chi0, one, 0.0 * one)
    f = res[0] if which == "rotation" else res[2]
    ok = motion.assembles[1:] & motion.assembles[:-1]
    ok &= np.isfinite(f[1:]) & np.isfinite(f[:-1])
    sign_prev, sign_next = np.sign(f[:-1]), np.sign(f[1:])
    bracket = ok & (sign_prev != sign_next) & (sign_prev != 0.0)
    k, branch = np.nonzero(bracket)
    if k.size == 0:
        return ()
    chi_sign = np.where(motion.chi0[k, branch] < 0.0, -1.0, 1.0)
    theta, phi, chi, s, fd = _polish_limits(
        dims, grid[k], grid[k + 1], f[k, branch], f[k + 1, branch],
        motion.phi0[k, branch], motion.phi0[k + 1, branch], chi_sign, which,
    )
    found: list[LimitPosition] = []
    period = 2.0 * math.pi
    for i in np.argsort(theta, kind="stable").tolist():
        phi_w = float(wrap_angle(phi[i]))
        duplicate = any(
            abs(math.remainder(lim.theta0 - theta[i], period)) < 1e-9
            and abs(math.remainder(lim.phi0 - phi_w, period)) < 1e-7
            and abs(lim.S - s[i]) < 1e-9 * dims.length_scale
            for lim in found
        )
        if not duplicate:
            found.append(LimitPosition(which, float(theta[i]), phi_w, float(chi[i]), float(s[i]),
                                       float(fd[i]), int(branch[i])))
    return tuple(found)


def rsrc_rotation_limits(
    dims: RSRCDimensions,
    *,
    n_grid: int = 2881,
    theta0_range: tuple[float, float] = (0.0, 2.0 * math.pi),
) -> tuple[LimitPosition, ...]:
    """Rotation limits of the output, d phi0 / d theta0 = 0 (Bagci 1969, App. D, eqs. D.1/D.2).

    The condition is Q4 = W2 L1 + cos^2(delta0) W1 L2 = 0 with Q5 != 0: the projected input-crank
    ellipse and coupler ellipse are tangent.  Up to 8 over all branches.  Every branch of
    `rsrc_motion` on a grid of ``n_grid`` input angles is scanned for sign changes of
    d phi0 / d theta0 (3.77), and each bracket is polished by safeguarded Newton with the
    analytic derivative (3.80), to about 1e-14 rad.  Limits closer together than the grid step
    on one branch (a pair of nearby sign changes) can be missed: raise ``n_grid``.
    """
    return _limits(dims, "rotation", n_grid, theta0_range)


def rsrc_translation_limits(
    dims: RSRCDimensions,
    *,
    n_grid: int = 2881,
    theta0_range: tuple[float, float] = (0.0, 2.0 * math.pi),
) -> tuple[LimitPosition, ...]:
    """Translation limits of the output, dS / d theta0 = 0 (Bagci 1969, App. D, eq. D.3).

    The corrected condition (SPEC §10, §12 L1646/L2977) is
    sin(delta0) (M2 Q4 - L2 Q5) = sin(lambda0) cos(theta0) tan(chi0) Q5, which is dS/d theta0 = 0
    written with (3.77)-(3.79); the printed geometric form (D.9) does not hold.  Located like
    `rsrc_rotation_limits` (sign changes of (3.79) on a grid, Newton with (3.82)).  For
    delta0 = n pi the limits are at theta0 = +-pi/2 on every branch (eq. 3.60a); when S is
    constant (delta0 = n pi and lambda0 = 0) there are none.
    """
    return _limits(dims, "translation", n_grid, theta0_range)

"""Closed-form kinematics of the plane 4R four-bar with Bagci's parameter names.

The plane 4R is the RSRC with delta0 = lambda0 = 0 and b = e = 0 (Bagci 1969, §3.4, eqs.
3.11-3.13 and 3.73): frame a (input pivot to output pivot, along +Y), crank d1 (input angle
theta0), coupler d2, rocker d3 (output angle phi0), both angles measured from the line of centres.
In the (Y, Z) plane the crank tip is P = d1 (cos theta0, sin theta0), the rocker tip
O2 = (a + d3 cos phi0, d3 sin phi0), and the coupler runs from P to O2 at the absolute angle
``coupler_angle`` = phi0 - chi0, chi0 being Bagci's coupler angle (the transmission angle between
rocker and coupler).

Freudenstein's equation (3.11) written with R = |O1 - O3| and beta = atan2(M0, N0)
(M0 = -d1 sin theta0, N0 = a - d1 cos theta0) is cos(phi0 - beta) = (d2^2 - d3^2 - R^2)/(2 d3 R),
so phi0 = beta -+ alpha with alpha = arccos(...) in [0, pi], with no half-angle division (the
half-angle form (3.74) divides by K + 2 d3 N0, which vanishes for some crank angles).  Assembly
mode 1 = beta - alpha is the inversion Bagci's programs call the "positive signed radical"
(label 1, chi0 <= 0), mode 2 = beta + alpha the "negative signed radical" (label 2, chi0 >= 0).
Arrays have shape (N, 2), column j = label j + 1; NaN exactly where ``assembles`` is False.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import wrap_angle_near
from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.quartic import DEFAULT_DOUBLE_ROOT_TOL, sin_cos
from screwkit.kinematics.closed_forms.rsrc.dimensions import RSRCDimensions, check_input_angles
from screwkit.messages import given

__all__ = [
    "FourBarDimensions",
    "FourBarPositions",
    "FourBarRates",
    "fourbar",
    "fourbar_positions",
    "fourbar_rates",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

GrashofType = Literal[
    "crank-rocker", "double-crank", "rocker-crank", "double-rocker", "change-point",
    "triple-rocker",
]

_CHUNK = 8192
_TWO_PI = 2.0 * math.pi

#: |sin chi0| at or below this value (relative) is an input dead centre: coupler and rocker in line.
LOCK_TOL = 1e-9


@dataclass(frozen=True)
class FourBarDimensions:
    """Plane 4R with Bagci's names: frame a, crank d1, coupler d2, rocker d3 (all > 0)."""

    a: float
    d1: float
    d2: float
    d3: float

    def __post_init__(self) -> None:
        for name, role in (("a", "frame"), ("d1", "crank"), ("d2", "coupler"), ("d3", "rocker")):
            value = getattr(self, name)
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise InputError(f"fourbar {name} ({role}) must be a number, got {given(value)}") from None
            if not (math.isfinite(number) and number > 0.0):
                raise InputError(f"fourbar {name} ({role}) must be finite and > 0, got {given(value)}")
            object.__setattr__(self, name, number)

    def as_rsrc(self) -> RSRCDimensions:
        """The same mechanism as an RSRC: delta0 = lambda0 = 0, b = e = 0 (Bagci §3.4)."""
        return RSRCDimensions(
            d1=self.d1, d2=self.d2, d3=self.d3, a=self.a, b=0.0, e=0.0, delta0=0.0, lambda0=0.0
        )

    @property
    def grashof_type(self) -> GrashofType:
        """Grashof classification with d1 as the input link and d3 as the output link.

        s + l < p + q: the shortest link decides (frame -> double-crank, crank -> crank-rocker,
        rocker -> rocker-crank, coupler -> double-rocker); s + l = p + q: change-point;
        s + l > p + q: triple-rocker (non-Grashof).
        """
        links = {"a": self.a, "d1": self.d1, "d2": self.d2, "d3": self.d3}
        lengths = sorted(links.values())
        s_plus_l = lengths[0] + lengths[3]
        p_plus_q = lengths[1] + lengths[2]
        if math.isclose(s_plus_l, p_plus_q, rel_tol=1e-12):
            return "change-point"
        if s_plus_l > p_plus_q:
            return "triple-rocker"
        shortest = min(links, key=lambda k: links[k])
        return {
            "a": "double-crank",
            "d1": "crank-rocker",
            "d3": "rocker-crank",
            "d2": "double-rocker",
        }[shortest]  # type: ignore[return-value]


def fourbar(a: float, d1: float, d2: float, d3: float) -> FourBarDimensions:
    """A plane 4R: frame a, crank d1, coupler d2, rocker d3 (Bagci's names, §3.4)."""
    return FourBarDimensions(a=a, d1=d1, d2=d2, d3=d3)


@dataclass(frozen=True)
class FourBarPositions:
    """Both assembly modes of a plane 4R at each crank angle.

    Attributes
    ----------
    theta0 : (N,) crank angles.
    phi0 : (N, 2) rocker angle in (-pi, pi]; column 0 = mode 1 (beta - alpha), column 1 = mode 2.
    chi0 : (N, 2) Bagci's coupler angle (transmission angle), <= 0 in mode 1, >= 0 in mode 2.
    assembles : (N, 2) bool; the arrays hold NaN exactly where it is False.
    """

    theta0: FloatArray
    phi0: FloatArray
    chi0: FloatArray
    assembles: BoolArray

    @property
    def coupler_angle(self) -> FloatArray:
        """(N, 2) absolute direction of the coupler from crank tip to rocker tip, phi0 - chi0,
        in (-pi, pi]."""
        return wrap_angle_near(self.phi0 - self.chi0)


def _positions_block(
    dims: FourBarDimensions, theta: FloatArray, phi: FloatArray, chi: FloatArray, tol: float
) -> None:
    """Fill phi0 and chi0 (views of shape (n, 2)) for one block; NaN where it does not close.

    Written for speed (it is the benchmark's hot path): no temporaries of shape (n, 2), each mode
    wrapped on the only side it can leave (-pi, pi].
    """
    d1, d2, d3 = dims.d1, dims.d2, dims.d3
    sin_t, cos_t = sin_cos(theta)
    m0 = -d1 * sin_t
    n0 = dims.a - d1 * cos_t
    r2 = (dims.a * dims.a + d1 * d1) - (2.0 * dims.a * d1) * cos_t  # |O1 - O3|^2
    radius = np.sqrt(r2)
    beta = np.arctan2(m0, n0)  # in (-pi, pi]
    # R cos(alpha) = (d2^2 - d3^2 - R^2) / (2 d3): Freudenstein's equation (3.11)
    r_cos_alpha = (d2 * d2 - d3 * d3 - r2) * (0.5 / d3)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos_alpha = r_cos_alpha / radius
        alpha = np.arccos(cos_alpha)  # NaN where |cos alpha| > 1: the loop does not close
        r_sin_alpha = np.sqrt(r2 - r_cos_alpha * r_cos_alpha)
    outside = np.isnan(alpha)
    if outside.any():
        # |cos alpha| up to 1 + tol^2/2 still assembles: a double root within tol (quartic.py)
        near = outside & (np.abs(cos_alpha) <= 1.0 + 0.5 * tol * tol)
        if near.any():
            alpha = np.where(near, np.arccos(np.clip(cos_alpha, -1.0, 1.0)), alpha)
            r_sin_alpha = np.where(near, 0.0, r_sin_alpha)
    # W1 = R cos(alpha) + d3 = d2 cos chi0 and |W2| = R sin(alpha) = d2 |sin chi0| >= 0, so
    # |chi0| = atan2(|W2|, W1) = pi/2 - atan(W1 / |W2|) (one arctan instead of arctan2)
    with np.errstate(invalid="ignore", divide="ignore"):
        chi_abs = (0.5 * math.pi) - np.arctan((r_cos_alpha + d3) / r_sin_alpha)
    mode1 = beta - alpha  # in (-2 pi, pi]
    phi[:, 0] = np.where(mode1 <= -math.pi, mode1 + _TWO_PI, mode1)
    mode2 = beta + alpha  # in (-pi, 2 pi]
    phi[:, 1] = np.where(mode2 > math.pi, mode2 - _TWO_PI, mode2)
    chi[:, 0] = -chi_abs
    chi[:, 1] = chi_abs


def fourbar_positions(
    dims: FourBarDimensions,
    theta0: ArrayLike,
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
) -> FourBarPositions:
    """Rocker angle phi0 and coupler angle chi0 of both assembly modes (Bagci eq. 3.11).

    Freudenstein's closed form phi0 = atan2(M0, N0) -+ arccos((d2^2 - d3^2 - R^2) / (2 d3 R)),
    vectorised in blocks over ``theta0`` (scalar or (N,), radians).  It equals `rsrc_positions`
    of ``dims.as_rsrc()`` column by column (labels 1 and 2).
    """
    theta = check_input_angles(theta0)
    n = theta.shape[0]
    phi = np.empty((n, 2))
    chi = np.empty((n, 2))
    for start in range(0, n, _CHUNK):
        block = slice(start, start + _CHUNK)
        _positions_block(dims, theta[block], phi[block], chi[block], double_root_tol)
    return FourBarPositions(theta, phi, chi, ~np.isnan(phi))


@dataclass(frozen=True)
class FourBarRates:
    """Angular velocities and accelerations of rocker and coupler, (N, 2) each.

    ``locked`` marks input dead centres (coupler and rocker in line, sin chi0 = 0), where the
    rates are unbounded; every rate is NaN exactly where ``valid`` is False.
    """

    phi0_dot: FloatArray
    coupler_angle_dot: FloatArray
    phi0_ddot: FloatArray
    coupler_angle_ddot: FloatArray
    locked: BoolArray
    valid: BoolArray


def fourbar_rates(
    dims: FourBarDimensions,
    positions: FourBarPositions,
    theta0_dot: ArrayLike = 1.0,
    theta0_ddot: ArrayLike = 0.0,
) -> FourBarRates:
    """Velocities and accelerations from the complex loop d1 e^(i th) + d2 e^(i g) = a + d3 e^(i phi).

    Differentiating the loop and projecting on the coupler and rocker directions (g = coupler
    angle, chi0 = phi0 - g):

        phi'  = d1 th' sin(th - g) / (d3 sin chi0)
        g'    = d1 th' sin(th - phi) / (d2 sin chi0)
        phi'' = [d1 th'' sin(th - g) + d1 th'^2 cos(th - g) + d2 g'^2 - d3 phi'^2 cos chi0]
                / (d3 sin chi0)
        g''   = [d1 th'' sin(th - phi) + d1 th'^2 cos(th - phi) + d2 g'^2 cos chi0 - d3 phi'^2]
                / (d2 sin chi0)

    an independent route from the RSRC formulas (3.77)-(3.81), which they match at
    delta0 = lambda0 = 0.
    """
    theta = positions.theta0
    n = theta.shape[0]
    rates = []
    for value, name in ((theta0_dot, "theta0_dot"), (theta0_ddot, "theta0_ddot")):
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim == 0:
            arr = np.full(n, float(arr))
        if arr.shape != (n,) or not np.all(np.isfinite(arr)):
            raise InputError(f"{name} must be finite, scalar or shape ({n},), got {arr.shape}")
        rates.append(arr[:, None])
    td, tdd = rates
    th = theta[:, None]
    phi, chi = positions.phi0, positions.chi0
    g = phi - chi
    sin_chi, cos_chi = sin_cos(chi)
    locked = positions.assembles & (np.abs(sin_chi) <= LOCK_TOL)
    valid = positions.assembles & ~locked
    inv = np.where(valid, 1.0 / np.where(valid, sin_chi, 1.0), np.nan)
    s_tg, c_tg = sin_cos(th - g)
    s_tp, c_tp = sin_cos(th - phi)
    phi_dot = dims.d1 * td * s_tg * inv / dims.d3
    g_dot = dims.d1 * td * s_tp * inv / dims.d2
    phi_ddot = (dims.d1 * (tdd * s_tg + td * td * c_tg) + dims.d2 * g_dot**2
                - dims.d3 * phi_dot**2 * cos_chi) * inv / dims.d3
    g_ddot = (dims.d1 * (tdd * s_tp + td * td * c_tp) + dims.d2 * g_dot**2 * cos_chi
              - dims.d3 * phi_dot**2) * inv / dims.d2
    return FourBarRates(phi_dot, g_dot, phi_ddot, g_ddot, locked, valid)


def fourbar_output_angles(dims: FourBarDimensions, theta0: ArrayLike, *,
                          double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL) -> FloatArray:
    """Rocker angle φ0 of both assembly modes only, shape (N, 2) (column 0 = mode 1), NaN where
    the loop does not close — `fourbar_positions` without the coupler angle, for sweeps where
    only the output matters (Freudenstein, Bagci eq. 3.11: φ0 = atan2(M0, N0) ∓ α)."""
    theta = check_input_angles(theta0)
    n = theta.shape[0]
    out = np.empty((2, n))  # mode-major: contiguous writes
    a, d1, d2, d3 = dims.a, dims.d1, dims.d2, dims.d3
    k = d2 * d2 - d3 * d3 - a * a - d1 * d1
    for start in range(0, n, _CHUNK):
        blk = slice(start, start + _CHUNK)
        sin_t, cos_t = sin_cos(theta[blk])
        n0 = a - d1 * cos_t
        r2 = (a * a + d1 * d1) - (2.0 * a * d1) * cos_t
        beta = np.arctan2(-d1 * sin_t, n0)
        cos_alpha = (k + (2.0 * a * d1) * cos_t) * (0.5 / d3) / np.sqrt(r2)
        with np.errstate(invalid="ignore"):
            alpha = np.arccos(cos_alpha)
        bad = np.isnan(alpha)
        if bad.any():  # a double root within the tolerance still assembles (as fourbar_positions)
            near = bad & (np.abs(cos_alpha) <= 1.0 + 0.5 * double_root_tol * double_root_tol)
            alpha[near] = np.arccos(np.clip(cos_alpha[near], -1.0, 1.0))
        m1 = beta - alpha
        m1[m1 <= -math.pi] += _TWO_PI
        m2 = beta + alpha
        m2[m2 > math.pi] -= _TWO_PI
        out[0, blk] = m1
        out[1, blk] = m2
    return out.T

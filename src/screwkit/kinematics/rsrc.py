"""Closed-form kinematics of Bagci's RSRC space four-bar (Bagci 1969, Chapter III, App. C, App. D).

Parameter names are Bagci's (SPEC §3.1): input crank d1 about the X axis (input angle theta0,
measured from +Y), coupler d2, output crank d3, fixed link a (along +Y), offset b along the input
axis, offset e along the coupler-output revolute axis, skew angle delta0 between the output axis
and that revolute axis, skew angle lambda0 between the input and output axes.  Outputs are the
output rotation phi0, the output translation S (dual output angle phi0 - eps S) and the coupler
angle chi0.  Everything is in SI units and radians, batch-first over the input angles theta0.

Result layout.  Every position/rate array has shape (N, 4): one row per input angle, one column
per *geometric inversion* (assembly mode).  Column j holds the inversion that Bagci's programs call
label j + 1:

* general delta0 (quartic 3.63): the real roots sorted by tan(phi0/2) ascending, i.e. phi0 in
  (-pi, pi] ascending; with two real roots label 1 is the smaller, label 2 the larger, exactly as
  Programs B/C label them (tables/REPRODUCTION.md, "Conventions pinned down").  With four real
  roots they are labels 1..4 in the same order (Program A's own order of its four roots follows
  Ferrari's factors and is not reproduced).
* delta0 = n pi (quadratic 3.73): column 0 = label 1 = "positive signed radical" of Programs A/C
  (W2 <= 0 when cos delta0 > 0), column 1 = label 2 ("negative signed radical"); columns 2, 3 are
  never assembled.
* delta0 = +-pi/2 (3.75/3.76): W2 = 0 fixes phi0 but not the sign of chi0.  Columns 0, 1 are the
  program's labels 1, 2 with chi0 in [0, pi] (what Program A prints), columns 2, 3 the same output
  positions with chi0 in [-pi, 0] (labels 3, 4): the coupler's mirror assembly, with the other
  value of S.  Bagci ignores that second sign (SPEC §12, L1025ff); here both are returned.

NaN policy.  Entries of a result array where the mechanism does not assemble (no real root, or a
rate at a locked configuration, see `RSRCRates`) hold NaN, and only there: the boolean masks of
the result (``assembles``; ``locked``, ``chi_singular``, ``valid``) say where.  Input arrays are validated and a non-finite input raises a
ValueError; no NaN ever leaves this module unannounced by a mask.

Labels are root orderings per sample.  Continuous assembly-mode branches over a sweep of theta0
come from `rsrc_motion`, which tracks the roots by continuity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.kinematics.quartic import (
    DEFAULT_DOUBLE_ROOT_TOL,
    real_roots_of_trig_quadratic,
    sin_cos,
    wrap_angle,
)

__all__ = [
    "LOCK_TOL",
    "SPECIAL_ANGLE_TOL",
    "BranchEvent",
    "LimitPosition",
    "RSRCCouplerPoint",
    "RSRCDimensions",
    "RSRCMotion",
    "RSRCPositions",
    "RSRCRates",
    "dwell_order",
    "rsrc_coupler_point",
    "rsrc_dwell_order",
    "rsrc_kinematics",
    "rsrc_motion",
    "rsrc_output_derivatives",
    "rsrc_positions",
    "rsrc_rates",
    "rsrc_rotation_limits",
    "rsrc_translation_limits",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]

SpecialCase = Literal["general", "delta0_n_pi", "delta0_half_pi"]

#: |sin delta0| (resp. |cos delta0|) at or below this value selects the quadratic special case
#: delta0 = n pi (resp. delta0 = +-pi/2) of Bagci §3.4.  Program A branches on exact equality of
#: the angle in degrees; in radians the floating-point value of pi/2 needs a tolerance.
SPECIAL_ANGLE_TOL = 1e-12

#: A configuration is reported as locked (input dead centre, Q5 = 0 in eq. 3.77) when
#: |Q5| <= LOCK_TOL * L^2 with L the sum of the link lengths.  A double root of the quartic is only
#: known to about the square root of the rounding error, so a tighter test would miss true locks.
LOCK_TOL = 1e-9

_CHUNK = 8192  # samples per block: keeps the temporaries small (measured best on 2 cores)


# --------------------------------------------------------------------------------------------
# Dimensions
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RSRCDimensions:
    """Dimensions of an RSRC mechanism with Bagci's parameter names (Bagci 1969, §3.1, Fig. 5).

    Lengths in metres (any consistent unit works), angles in radians.

    Attributes
    ----------
    d1 : input crank length (input axis to sphere centre), > 0.
    d2 : coupler length (coupler revolute axis to sphere centre), > 0.
    d3 : output crank length (output axis to coupler revolute axis), >= 0.
    a : fixed-link length (common normal of the input and output axes, along +Y); any sign.
    b : offset of the input-crank plane from the fixed link along the input axis.
    e : offset along the coupler revolute axis from the foot of d3 to the foot of d2.
    delta0 : skew angle between the output axis and the coupler revolute axis.
    lambda0 : skew angle between the input axis and the output axis.
    """

    d1: float
    d2: float
    d3: float
    a: float
    b: float
    e: float
    delta0: float
    lambda0: float

    def __post_init__(self) -> None:
        for name in ("d1", "d2", "d3", "a", "b", "e", "delta0", "lambda0"):
            value = getattr(self, name)
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise ValueError(
                    f"RSRCDimensions.{name} must be a real number, got {value!r}"
                ) from None
            if not math.isfinite(number):
                raise ValueError(f"RSRCDimensions.{name} must be finite, got {number!r}")
            object.__setattr__(self, name, number)
        if self.d1 <= 0.0:
            raise ValueError(
                f"RSRCDimensions.d1 (input crank) must be > 0, got {self.d1!r}; a zero crank "
                "leaves the input angle without effect"
            )
        if self.d2 <= 0.0:
            raise ValueError(
                f"RSRCDimensions.d2 (coupler) must be > 0, got {self.d2!r}"
            )
        if self.d3 < 0.0:
            raise ValueError(
                f"RSRCDimensions.d3 (output crank) must be >= 0, got {self.d3!r}; a negative "
                "crank is the same mechanism with phi0 shifted by pi, pass -d3 instead"
            )

    @property
    def special_case(self) -> SpecialCase:
        """Which closed form applies: the quartic, delta0 = n pi, or delta0 = +-pi/2 (§3.4)."""
        if abs(math.sin(self.delta0)) <= SPECIAL_ANGLE_TOL:
            return "delta0_n_pi"
        if abs(math.cos(self.delta0)) <= SPECIAL_ANGLE_TOL:
            return "delta0_half_pi"
        return "general"

    @property
    def length_scale(self) -> float:
        """Sum of the absolute lengths: the scale used by the relative tolerances."""
        return self.d1 + self.d2 + self.d3 + abs(self.a) + abs(self.b) + abs(self.e)

    @property
    def is_planar_fourbar(self) -> bool:
        """True for the plane 4R special case delta0 = lambda0 = 0, b = e = 0 (§3.4)."""
        return self.delta0 == 0.0 and self.lambda0 == 0.0 and self.b == 0.0 and self.e == 0.0


def _check_theta0(theta0: ArrayLike, name: str = "theta0") -> FloatArray:
    """Input angles as a finite 1-D float array (a scalar becomes shape (1,))."""
    arr = np.asarray(theta0, dtype=np.float64)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1:
        raise ValueError(
            f"{name} must be a scalar or a 1-D array of input angles (radians), got shape "
            f"{arr.shape}; flatten it first"
        )
    bad = ~np.isfinite(arr)
    if bad.any():
        index = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{index}] = {arr[index]!r} is not finite")
    return arr


def _check_rate(value: ArrayLike, n: int, name: str) -> FloatArray:
    """A scalar or (N,) input rate as an (N, 1) column."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have shape ({n},), got shape {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        index = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{index}] = {arr[index]!r} is not finite")
    return arr[:, None]


# --------------------------------------------------------------------------------------------
# Positions
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RSRCPositions:
    """Displacements of every geometric inversion at each input angle (Bagci 1969, §3.4).

    Attributes
    ----------
    theta0 : (N,) input angles.
    phi0 : (N, 4) output rotation in (-pi, pi]; NaN where ``~assembles``.
    chi0 : (N, 4) coupler angle, signed atan2 form of eq. 3.59; NaN where ``~assembles``.
    S : (N, 4) output translation, eq. 3.60; NaN where ``~assembles``.
    assembles : (N, 4) bool, the loop closes for that inversion.
    case : which closed form was used ("general", "delta0_n_pi", "delta0_half_pi").

    Column j is the inversion that Bagci's programs label j + 1 (module docstring).
    """

    theta0: FloatArray
    phi0: FloatArray
    chi0: FloatArray
    S: FloatArray
    assembles: BoolArray
    case: SpecialCase

    @property
    def inversion_label(self) -> IntArray:
        """(N, 4) program inversion label (1..4) of each entry, 0 where it does not assemble."""
        labels = np.broadcast_to(np.arange(1, 5), self.assembles.shape)
        return np.where(self.assembles, labels, 0)

    @property
    def n_assemblies(self) -> IntArray:
        """(N,) number of inversions that assemble at each input angle."""
        return np.count_nonzero(self.assembles, axis=1)

    def inversion(self, label: int) -> tuple[FloatArray, FloatArray, FloatArray, BoolArray]:
        """(phi0, chi0, S, assembles), each (N,), of the inversion with program label 1..4."""
        if label not in (1, 2, 3, 4):
            raise ValueError(f"inversion label must be 1, 2, 3 or 4, got {label!r}")
        j = label - 1
        return self.phi0[:, j], self.chi0[:, j], self.S[:, j], self.assembles[:, j]


def _m0_n0(dims: RSRCDimensions, sin_t: FloatArray, cos_t: FloatArray) -> tuple[
    FloatArray, FloatArray
]:
    """M0 = b sin(lambda0) - d1 cos(lambda0) sin(theta0), N0 = a - d1 cos(theta0) (§3.4)."""
    m0 = dims.b * math.sin(dims.lambda0) - (dims.d1 * math.cos(dims.lambda0)) * sin_t
    n0 = dims.a - dims.d1 * cos_t
    return m0, n0


def _clip_unit(x: FloatArray, tol: float) -> tuple[FloatArray, BoolArray]:
    """Clip a cosine/sine argument to [-1, 1]; values up to 1 + tol^2/2 count as inside.

    An argument 1 + eps has an imaginary angle of about sqrt(2 eps); the same angle tolerance as for
    the quartic's double roots is used.
    """
    inside = np.abs(x) <= 1.0 + 0.5 * tol * tol
    return np.clip(x, -1.0, 1.0), inside


@dataclass
class _Parts:
    """Per-block intermediates shared by the position and rate formulas (§3.4, §3.5).

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


def _parts_from_angles(
    dims: RSRCDimensions, theta: FloatArray, phi: FloatArray, chi: FloatArray
) -> _Parts:
    """Intermediates from angles; theta (n, 1), phi and chi (n, k)."""
    st, ct = sin_cos(theta)
    sp, cp = sin_cos(phi)
    sc, cc = sin_cos(chi)
    m0, n0 = _m0_n0(dims, st, ct)
    w1 = m0 * sp + n0 * cp + dims.d3
    w2 = n0 * sp - m0 * cp - dims.e * math.sin(dims.delta0)
    return _Parts(st, ct, sp, cp, sc, cc, m0, n0, w1, w2)


def _output_angles_general(
    dims: RSRCDimensions, m0: FloatArray, n0: FloatArray, tol: float
) -> FloatArray:
    """phi0 roots (n, 4) of the input-output equation (3.62) through the quartic (3.63)."""
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    c2, s2 = cd * cd, sd * sd
    f1 = s2 * (n0 * n0 - m0 * m0)
    f2 = (-2.0 * s2) * m0 * n0  # Bagci prints sin(delta0); sin^2 is correct (SPEC §12, L939)
    f3 = 2.0 * (dims.d3 * c2 * n0 + dims.e * sd * m0)
    f4 = 2.0 * (dims.d3 * c2 * m0 - dims.e * sd * n0)
    k = c2 * (dims.d2**2 - dims.d3**2 - n0 * n0) - m0 * m0 - dims.e**2 * s2
    # F1 s^2 + F2 s c + F3 c + F4 s - K as a0 + a1 cos + b1 sin + a2 cos 2phi + b2 sin 2phi
    phi, _ = real_roots_of_trig_quadratic(
        0.5 * f1 - k, f3, f4, -0.5 * f1, 0.5 * f2, double_root_tol=tol
    )
    return phi


def _output_angles_special(
    dims: RSRCDimensions, m0: FloatArray, n0: FloatArray, tol: float
) -> tuple[FloatArray, FloatArray]:
    """(phi0, chi0) of the quadratic cases delta0 = n pi (3.73) and delta0 = +-pi/2 (3.75)."""
    n = m0.shape[0]
    radius = np.hypot(m0, n0)
    beta = np.arctan2(m0, n0)  # M0 sin phi + N0 cos phi = R cos(phi - beta)
    phi = np.full((n, 4), np.nan)
    chi = np.full((n, 4), np.nan)
    cd = math.cos(dims.delta0)
    if dims.special_case == "delta0_n_pi":
        # eq. 3.73: W1^2 + W2^2 = d2^2 gives cos(phi - beta) = (d2^2 - d3^2 - R^2) / (2 d3 R).
        # Program label 1 ("+ radical" of its half-angle form) is phi = beta - alpha, label 2 is
        # phi = beta + alpha: W2 = R sin(phi - beta) has the sign of -+alpha.
        denom = 2.0 * dims.d3 * radius
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = (dims.d2**2 - dims.d3**2 - radius * radius) / denom
        ratio, inside = _clip_unit(ratio, tol)
        inside &= denom > 0.0
        alpha = np.arccos(ratio)
        # W1 = R cos(alpha) + d3 = d2 cos chi0, W2 = -+R sin(alpha) = d2 cos(delta0) sin chi0
        chi_abs = np.arctan2(radius * np.sqrt(1.0 - ratio * ratio) / abs(cd),
                             radius * ratio + dims.d3)
        for j, sign in enumerate((-1.0, 1.0)):
            phi[:, j] = np.where(inside, wrap_angle(beta + sign * alpha), np.nan)
            chi[:, j] = np.where(inside, (sign * math.copysign(1.0, cd)) * chi_abs, np.nan)
        return phi, chi
    # delta0 = +-pi/2, eqs. 3.75/3.76: W2 = 0, i.e. R sin(phi - beta) = e sin(delta0).
    # Program label 1 (+ radical) has cos(phi - beta) >= 0, label 2 the other root.
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(radius > 0.0, dims.e * math.sin(dims.delta0) / radius, np.inf)
    ratio, inside = _clip_unit(ratio, tol)
    gamma = np.arcsin(ratio)
    for j, offset in enumerate((gamma, np.pi - gamma)):
        w1 = radius * np.cos(offset) + dims.d3  # M0 sin phi + N0 cos phi + d3
        cos_chi, closes = _clip_unit(w1 / dims.d2, tol)
        ok = inside & closes
        chi_abs = np.arccos(cos_chi)
        phi_j = wrap_angle(beta + offset)
        for k, chi_sign in ((j, 1.0), (j + 2, -1.0)):
            phi[:, k] = np.where(ok, phi_j, np.nan)
            chi[:, k] = np.where(ok, chi_sign * chi_abs, np.nan)
    return phi, chi


def _positions_block(
    dims: RSRCDimensions, theta: FloatArray, tol: float
) -> tuple[FloatArray, FloatArray, FloatArray, _Parts]:
    """(phi0, chi0, S, intermediates) for one block, trimmed to the columns that hold roots.

    Roots are sorted with the non-assembling entries last, so only the first k columns (k = the
    largest number of inversions in the block) are worked on; the caller fills the rest with NaN.
    Within those k columns NaN still marks inversions that do not close.
    """
    st, ct = sin_cos(theta[:, None])
    m0, n0 = _m0_n0(dims, st, ct)
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    s_input = dims.b * math.cos(dims.lambda0) + (dims.d1 * math.sin(dims.lambda0)) * st
    if dims.special_case == "general":
        phi = _output_angles_general(dims, m0[:, 0], n0[:, 0], tol)
        phi = phi[:, : int(np.count_nonzero(~np.isnan(phi), axis=1).max(initial=0))]
        sp, cp = sin_cos(phi)
        w1 = m0 * sp + n0 * cp + dims.d3
        w2 = n0 * sp - m0 * cp - dims.e * sd
        # eq. 3.59: cos chi = W1/d2, sin chi = W2/(d2 cos delta0); atan2 as Program A does
        w2c = w2 / cd
        chi = np.arctan2(w2c, w1)
        inv_h = 1.0 / np.hypot(w1, w2c)
        sc, cc = w2c * inv_h, w1 * inv_h
        # eq. 3.60 with d2 sin chi0 = W2 / cos delta0 (the chi-free form of §3.4)
        s = (s_input + dims.e * cd) - (sd / cd) * w2
        return phi, chi, s, _Parts(st, ct, sp, cp, sc, cc, m0, n0, w1, w2)
    phi, chi = _output_angles_special(dims, m0[:, 0], n0[:, 0], tol)
    if dims.special_case == "delta0_n_pi":
        phi, chi = phi[:, :2], chi[:, :2]
    parts = _parts_from_angles(dims, theta[:, None], phi, chi)
    # eq. 3.60 (3.60a for delta0 = n pi, where sin delta0 = 0)
    s = (s_input + dims.e * cd) - (dims.d2 * sd) * parts.sc
    return phi, chi, s, parts


def rsrc_positions(
    dims: RSRCDimensions,
    theta0: ArrayLike,
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
) -> RSRCPositions:
    """Output rotation phi0, translation S and coupler angle chi0 of every inversion.

    Bagci 1969, §3.4: the input-output equation (3.62) with F2 corrected to -2 M0 N0 sin^2(delta0)
    is solved through its half-angle quartic (3.63) (vectorised Ferrari, see
    `screwkit.kinematics.quartic`); chi0 from the signed atan2 form of (3.59) and S from (3.60).
    delta0 = n pi uses the quadratic (3.73) with the programs' inversion labels, delta0 = +-pi/2
    uses (3.75)/(3.76) and returns both signs of chi0 as separate inversions (module docstring).
    The plane 4R is the case delta0 = lambda0 = 0, b = e = 0.

    Parameters
    ----------
    dims
        The mechanism.
    theta0
        Input angles (radians), scalar or shape (N,).
    double_root_tol
        Angle tolerance (radians) within which a near-double root is reported as a (double) real
        root, i.e. the mechanism as assembled at its limit position.

    Returns
    -------
    RSRCPositions with (N, 4) arrays; column j is program inversion label j + 1.
    """
    positions, _ = _solve(dims, theta0, None, None, double_root_tol)
    return positions


def rsrc_kinematics(
    dims: RSRCDimensions,
    theta0: ArrayLike,
    theta0_dot: ArrayLike = 1.0,
    theta0_ddot: ArrayLike = 0.0,
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
) -> tuple[RSRCPositions, RSRCRates]:
    """Positions, velocities and accelerations of every inversion in one pass.

    Same results as `rsrc_positions` followed by `rsrc_rates`, but the intermediates of
    (3.59)-(3.63) are reused by (3.77)-(3.82) block by block, which is about twice as fast.
    """
    positions, rates = _solve(dims, theta0, theta0_dot, theta0_ddot, double_root_tol)
    assert rates is not None
    return positions, rates


def _solve(
    dims: RSRCDimensions,
    theta0: ArrayLike,
    theta0_dot: ArrayLike | None,
    theta0_ddot: ArrayLike | None,
    tol: float,
) -> tuple[RSRCPositions, RSRCRates | None]:
    theta = _check_theta0(theta0)
    n = theta.shape[0]
    with_rates = theta0_dot is not None
    td = _check_rate(theta0_dot if theta0_dot is not None else 0.0, n, "theta0_dot")
    tdd = _check_rate(theta0_ddot if theta0_ddot is not None else 0.0, n, "theta0_ddot")
    # scalar input rates stay Python floats inside the blocks (cheaper broadcasting, and
    # theta0-ddot = 0 drops its terms)
    td_scalar = float(td[0, 0]) if n and np.ndim(np.asarray(theta0_dot)) == 0 else None
    tdd_scalar = float(tdd[0, 0]) if n and np.ndim(np.asarray(theta0_ddot)) == 0 else None
    # every entry is written once by its block (trimmed columns get NaN / False there)
    phi = np.empty((n, 4))
    chi = np.empty((n, 4))
    s = np.empty((n, 4))
    rate_arrays = [np.empty((n, 4)) for _ in range(6)] if with_rates else []
    flags = [np.empty((n, 4), dtype=bool) for _ in range(2)] if with_rates else []
    for start in range(0, n, _CHUNK):
        rows = slice(start, start + _CHUNK)
        phi_b, chi_b, s_b, parts = _positions_block(dims, theta[rows], tol)
        k = phi_b.shape[1]
        block = (rows, slice(0, k))
        trimmed = (rows, slice(k, 4))
        phi[block], chi[block], s[block] = phi_b, chi_b, s_b
        for arr in (phi, chi, s, *rate_arrays):
            arr[trimmed] = np.nan
        for flag in flags:
            flag[trimmed] = False
        if with_rates:
            res = _rates_from_parts(dims, parts, td_scalar if td_scalar is not None else td[rows],
                                    tdd_scalar if tdd_scalar is not None else tdd[rows])
            for arr, value in zip(rate_arrays + flags, res, strict=True):
                arr[block] = value
    assembles = ~np.isnan(phi)
    positions = RSRCPositions(theta, phi, chi, s, assembles, dims.special_case)
    if not with_rates:
        return positions, None
    return positions, _finish_rates(assembles, rate_arrays, flags[0], flags[1])


# --------------------------------------------------------------------------------------------
# Velocities and accelerations
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RSRCRates:
    """Velocities and accelerations of every inversion (Bagci 1969, eqs. 3.77-3.82).

    All arrays (N, 4), matching an `RSRCPositions`.  Every rate is NaN where the inversion does
    not assemble or is locked; the chi0 and S rates are also NaN where ``chi_singular``.  All
    rates are finite exactly where ``valid``.

    Attributes
    ----------
    phi0_dot, chi0_dot, S_dot : first time derivatives.
    phi0_ddot, chi0_ddot, S_ddot : second time derivatives.
    locked : the configuration is at (or within LOCK_TOL of) an input dead centre, Q5 = 0: the
        output rates are unbounded there for a non-zero input rate.
    chi_singular : the chi0 rates are undefined (sin chi0 = 0 and cos delta0 cos chi0 = 0, which
        happens only for delta0 = +-pi/2, where the two chi0 signs merge).
    valid : assembles & ~locked & ~chi_singular.
    """

    phi0_dot: FloatArray
    chi0_dot: FloatArray
    S_dot: FloatArray
    phi0_ddot: FloatArray
    chi0_ddot: FloatArray
    S_ddot: FloatArray
    locked: BoolArray
    chi_singular: BoolArray
    valid: BoolArray


_RateBlock = tuple[
    FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, BoolArray, BoolArray
]


def _rates_from_parts(
    dims: RSRCDimensions, parts: _Parts, td: FloatArray | float, tdd: FloatArray | float
) -> _RateBlock:
    """Eqs. 3.77-3.82 on one block; td, tdd are theta0-dot, theta0-ddot as (n, 1) or floats.

    Returns (phi_dot, chi_dot, S_dot, phi_ddot, chi_ddot, S_ddot, locked, chi_singular) with NaN
    where a denominator vanishes (the masks say where).  The products of §3.5 are regrouped to
    share factors (Q1 = M1 (M1 - c^2 W1) + M2 (W2 + c^2 M2), etc.); the result is the same.
    """
    d1, d2 = dims.d1, dims.d2
    sl, cl = math.sin(dims.lambda0), math.cos(dims.lambda0)
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    c2 = cd * cd
    st, ct, sp, cp, sc, cc = parts.st, parts.ct, parts.sp, parts.cp, parts.sc, parts.cc
    m0, n0, w1, w2 = parts.m0, parts.n0, parts.w1, parts.w2
    no_tdd = isinstance(tdd, float) and tdd == 0.0
    m1 = n0 * cp + m0 * sp
    m2 = m0 * cp - n0 * sp
    cl_ct, cl_st = cl * ct, cl * st
    l1 = st * sp + cl_ct * cp
    l2 = st * cp - cl_ct * sp
    l3 = ct * sp - cl_st * cp
    l4 = ct * cp + cl_st * sp
    td2 = td * td
    scale = dims.length_scale
    with np.errstate(divide="ignore", invalid="ignore"):
        if dims.special_case == "delta0_half_pi":
            # cos delta0 = 0: Q4 = Q5 = 0 identically; differentiate W2 = 0 instead (Program A)
            locked = np.abs(m1) <= LOCK_TOL * scale
            inv = 1.0 / m1
            inv[locked] = np.nan
            phi_dot = (-d1 * td) * l1 * inv
            acc = m2 * phi_dot * phi_dot + (2.0 * d1 * td) * l2 * phi_dot + (d1 * td2) * l3
            if not no_tdd:
                acc = acc + (d1 * tdd) * l1
            phi_ddot = -acc * inv
        else:
            c2w1 = c2 * w1
            ra = m1 - c2w1
            rb = w2 + c2 * m2
            q1 = m1 * ra + m2 * rb
            q2 = l1 * ra + l2 * rb
            q3 = d1 * (l1 * l1 + c2 * (l2 * l2)) + w2 * l3 + c2w1 * l4
            q4 = w2 * l1 + c2w1 * l2
            q5 = w2 * m1 + c2w1 * m2
            locked = np.abs(q5) <= LOCK_TOL * scale * scale
            inv = 1.0 / q5
            inv[locked] = np.nan
            phi_dot = (-d1 * td) * q4 * inv  # eq. 3.77
            # eq. 3.80: -[Q1 phi'^2 + d1 (2 Q2 phi' th' + Q3 th'^2 + Q4 th'')] / Q5
            acc = phi_dot * (q1 * phi_dot + (2.0 * d1 * td) * q2) + (d1 * td2) * q3
            if not no_tdd:
                acc = acc + (d1 * tdd) * q4
            phi_ddot = -acc * inv
        # chi0 rates.  Eq. 3.78 gives d2 sin(chi0) chi0' = A and the derivative of
        # W2 = d2 cos(delta0) sin(chi0) gives d2 cos(delta0) cos(chi0) chi0' = B (the alternative
        # of §3.5 where sin chi0 = 0).  Their least-squares combination
        # chi0' = (sin chi0 A + cos delta0 cos chi0 B) / (d2 (sin^2 chi0 + cos^2 delta0 cos^2 chi0))
        # equals either formula on the solution and never divides by zero unless both do; the
        # same combination of eq. 3.81 (corrected "+ d1[...]", SPEC §12 L1067) and of the second
        # derivative of W2 gives chi0''.
        ccd = cd * cc
        den = sc * sc + ccd * ccd
        chi_singular = den <= 1e-12
        inv_den = 1.0 / (d2 * den)
        inv_den[chi_singular] = np.nan
        p_fac = ccd * m1 - sc * m2
        q_fac = ccd * l1 - sc * l2
        chi_dot = (phi_dot * p_fac + (d1 * td) * q_fac) * inv_den
        chi_dot2 = chi_dot * chi_dot
        r_fac = sc * m1 + ccd * m2
        t_fac = ccd * l3 - sc * l4
        u_fac = sc * l1 + ccd * l2
        num = (phi_ddot * p_fac + phi_dot * (phi_dot * r_fac + (2.0 * d1 * td) * u_fac)
               + (d1 * td2) * t_fac - (d2 * sd * sd) * sc * cc * chi_dot2)
        if not no_tdd:
            num = num + (d1 * tdd) * q_fac
        chi_ddot = num * inv_den
    s_dot = (d1 * sl) * ct * td - (d2 * sd) * cc * chi_dot  # eq. 3.79
    s_ddot = (d1 * sl) * (tdd * ct - td2 * st) + (d2 * sd) * (
        chi_dot2 * sc - chi_ddot * cc
    )  # eq. 3.82
    return phi_dot, chi_dot, s_dot, phi_ddot, chi_ddot, s_ddot, locked, chi_singular


def _rates_block(
    dims: RSRCDimensions,
    theta: FloatArray,
    phi: FloatArray,
    chi: FloatArray,
    td: FloatArray,
    tdd: FloatArray,
) -> _RateBlock:
    """`_rates_from_parts` from angles: theta (n, 1), phi and chi (n, k)."""
    return _rates_from_parts(dims, _parts_from_angles(dims, theta, phi, chi), td, tdd)


def _finish_rates(
    assembles: BoolArray, rate_arrays: list[FloatArray], locked: BoolArray, chi_singular: BoolArray
) -> RSRCRates:
    # NaN propagates from the positions (not assembled) and from the masked divisions (locked:
    # every rate; chi_singular: the chi0 and S rates), so no further masking is needed
    locked &= assembles
    chi_singular &= assembles & ~locked
    valid = assembles & ~locked & ~chi_singular
    phi_dot, chi_dot, s_dot, phi_ddot, chi_ddot, s_ddot = rate_arrays
    return RSRCRates(phi_dot, chi_dot, s_dot, phi_ddot, chi_ddot, s_ddot, locked, chi_singular,
                     valid)


def rsrc_rates(
    dims: RSRCDimensions,
    positions: RSRCPositions,
    theta0_dot: ArrayLike = 1.0,
    theta0_ddot: ArrayLike = 0.0,
) -> RSRCRates:
    """Velocities and accelerations of phi0, chi0 and S (Bagci 1969, eqs. 3.77-3.82).

    Uses Q1..Q5, L1..L4, M1, M2 of §3.5; chi0-double-dot is (3.81) with the corrected sign
    "+ d1[L4 th'^2 - 2 L1 phi' th' + L2 th'']".  Where sin chi0 is small the chi0 rates lean on
    the derivative of W2 = d2 cos(delta0) sin(chi0) instead (the alternative of §3.5; both are
    combined by least squares, see the source).  For delta0 = +-pi/2, Q4 = Q5 = 0 identically and
    the output rates come from W2 = 0 as in Program A.  Locked configurations (Q5 = 0, an input
    dead centre) are reported through ``locked``, never divided through.

    Parameters
    ----------
    dims, positions
        The mechanism and its `rsrc_positions` result.
    theta0_dot, theta0_ddot
        Input angular velocity and acceleration: scalars or shape (N,).  The defaults give the
        ratios Program A tabulates (d phi0/d theta0, d^2 phi0/d theta0^2).
    """
    theta = positions.theta0
    n = theta.shape[0]
    td = _check_rate(theta0_dot, n, "theta0_dot")
    tdd = _check_rate(theta0_ddot, n, "theta0_ddot")
    rate_arrays = [np.full((n, 4), np.nan) for _ in range(6)]
    flags = [np.zeros((n, 4), dtype=bool) for _ in range(2)]
    # inversions are stored first in each row (NaN last), so a block needs only k columns
    counts = positions.n_assemblies
    for start in range(0, n, _CHUNK):
        rows = slice(start, start + _CHUNK)
        k = int(counts[rows].max(initial=0))
        if positions.case == "delta0_half_pi":
            k = 4  # the chi0 < 0 modes sit in columns 2, 3 even when 0, 1 do not assemble
        if k == 0:
            continue
        block = (rows, slice(0, k))
        res = _rates_block(
            dims, theta[rows, None], positions.phi0[block], positions.chi0[block],
            td[rows], tdd[rows],
        )
        for arr, value in zip(rate_arrays + flags, res, strict=True):
            arr[block] = value
    return _finish_rates(positions.assembles, rate_arrays, flags[0], flags[1])

# --------------------------------------------------------------------------------------------
# Coupler point (Appendix C)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RSRCCouplerPoint:
    """Coordinates of a coupler point (Bagci 1969, App. C, eqs. C.2-C.7).

    Attributes
    ----------
    global_xyz : (N, 4, 3) X_p, Y_p, Z_p in the fixed frame OXYZ.
    output_frame_xyz : (N, 4, 3) xi'_3p, eta'_3p, zeta'_3p in the output-axis frame O3 xi' eta'
        zeta' (origin (b, a, 0), xi' along the output axis (cos lambda0, 0, -sin lambda0), eta' = +Y).
    assembles : (N, 4) bool; NaN rows elsewhere.
    """

    global_xyz: FloatArray
    output_frame_xyz: FloatArray
    assembles: BoolArray


def rsrc_coupler_point(
    dims: RSRCDimensions, positions: RSRCPositions, f: float, g: float, h: float
) -> RSRCCouplerPoint:
    """Coupler point (f, g, h), given in the coupler frame at the sphere centre (App. C).

    The coupler frame is parallel to the frame O2''xi2''eta2''zeta2'' (x along the coupler
    revolute axis, y from the sphere centre towards the foot O2'' of d2 on that axis): the point
    is P = O1 + f B e1 + g B e2 + h B e3, B the coupler frame's rotation (SPEC §3.1, §9).  With f = g = h = 0 it is the sphere centre
    (0, d1 cos theta0, d1 sin theta0).  Explicit forms (C.2)-(C.4) and, with a = b = lambda0 = 0,
    (C.5)-(C.7).
    """
    for name, value in (("f", f), ("g", g), ("h", h)):
        if not math.isfinite(float(value)):
            raise ValueError(f"coupler point coordinate {name} must be finite, got {value!r}")
    f, g, h = float(f), float(g), float(h)
    sl, cl = math.sin(dims.lambda0), math.cos(dims.lambda0)
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    sp, cp = np.sin(positions.phi0), np.cos(positions.phi0)
    sc, cc = np.sin(positions.chi0), np.cos(positions.chi0)
    s = positions.S
    dg = dims.d2 - g
    ef = dims.e + f
    # output-axis frame, eqs. C.5-C.7
    xi = -s - dg * sd * sc + ef * cd - h * sd * cc
    eta = (dims.d3 * cp - dg * (cp * cc + cd * sp * sc) - ef * sd * sp
           + h * (cp * sc - cd * sp * cc))
    zeta = (dims.d3 * sp + dg * (cd * cp * sc - sp * cc) + ef * sd * cp
            + h * (cd * cp * cc + sp * sc))
    # fixed frame: O3 + xi u3 + eta e2 + zeta (sin lambda0, 0, cos lambda0), equal to eqs. C.2-C.4
    x = dims.b + cl * xi + sl * zeta
    y = dims.a + eta
    z = -sl * xi + cl * zeta
    return RSRCCouplerPoint(
        np.stack([x, y, z], axis=-1), np.stack([xi, eta, zeta], axis=-1), positions.assembles
    )


# --------------------------------------------------------------------------------------------
# Continuous assembly-mode branches over a sweep of the input angle
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BranchEvent:
    """A branch of an `RSRCMotion` stops or starts assembling between two samples.

    Attributes
    ----------
    branch : column of the motion arrays.
    kind : "stops" (the branch merges with another one: a limit position / dead centre of the
        input, beyond which the loop does not close on it) or "starts".
    theta0 : input angle of the event, refined by bisection to about 1e-15 rad, on the side where
        the branch assembles (its two roots there are a double root to within the tolerance).
    sample : index of the first sample after the event.
    """

    branch: int
    kind: Literal["stops", "starts"]
    theta0: float
    sample: int


@dataclass(frozen=True)
class RSRCMotion:
    """Continuous assembly-mode branches over a sweep of theta0 (see `rsrc_motion`).

    Attributes
    ----------
    theta0 : (N,) the sweep.
    phi0 : (N, 4) output rotation, unwrapped (continuous) along each run of valid samples of a
        column; NaN where ``~assembles``.
    chi0, S : (N, 4) coupler angle (in (-pi, pi]) and output translation.
    assembles : (N, 4) bool.
    inversion_label : (N, 4) program label (1..4, see `RSRCPositions`) of the entry at each
        sample, 0 where it does not assemble.  Along a branch the label can change: labels are
        root orderings, branches are continuous.
    events : where branches stop or start.
    """

    theta0: FloatArray
    phi0: FloatArray
    chi0: FloatArray
    S: FloatArray
    assembles: BoolArray
    inversion_label: IntArray
    events: tuple[BranchEvent, ...]


def _all_permutations() -> IntArray:
    from itertools import permutations

    return np.array(list(permutations(range(4))), dtype=np.int64)


_PERMS = _all_permutations()  # (24, 4)
_PERM_INDEX = {tuple(int(v) for v in p): i for i, p in enumerate(_PERMS)}
# _COMPOSE[a, b] = index of the permutation slot -> _PERMS[a][_PERMS[b][slot]]
_COMPOSE = np.array(
    [[_PERM_INDEX[tuple(int(_PERMS[a][_PERMS[b][s]]) for s in range(4))] for b in range(24)]
     for a in range(24)],
    dtype=np.int64,
)

_UNMATCHED_COST = 2.0  # cost of leaving a root unmatched: |unit-vector difference|^2 for 90 deg


def _branch_features(
    phi: FloatArray, chi: FloatArray, s: FloatArray, length: float
) -> tuple[FloatArray, ...]:
    """The 5 features compared when matching roots, each shaped like ``phi``: unit vectors of
    phi0, chi0 and S/L; 0 where a root does not assemble (NaN)."""
    return tuple(np.where(np.isnan(f), 0.0, f) for f in (
        np.cos(phi), np.sin(phi), np.cos(chi), np.sin(chi), s / length))


def _advanced(value: FloatArray, rate: FloatArray, step: FloatArray, limit: float) -> FloatArray:
    """``value`` moved by its rate over the step, where that move is below ``limit``."""
    delta = rate * step
    return np.where(np.abs(delta) < limit, value + delta, value)


def _match_consecutive(
    pos: RSRCPositions, rates: RSRCRates, length: float
) -> IntArray:
    """Best permutation (index into _PERMS) from the columns at k-1 to those at k, for every k.

    The roots at k-1 are first advanced by their rates (d/d theta0 times the step) when that
    step is small, then every one of the 24 assignments is scored at once (vectorised) — only at
    the steps where keeping every column is not already optimal: where each root's nearest root
    at k is its own column, the identity costs the sum of the rows' minima, a lower bound of
    every assignment's cost. Works in blocks of samples (the (n, 4, 4) costs stay in cache).
    """
    n = pos.theta0.shape[0] - 1
    best = np.full(max(n, 0), _PERM_INDEX[(0, 1, 2, 3)], dtype=np.int64)
    for start in range(0, n, _CHUNK):
        k = slice(start, min(start + _CHUNK, n))
        k1 = slice(start + 1, k.stop + 1)
        step = (pos.theta0[k1] - pos.theta0[k])[:, None]
        prev = _branch_features(_advanced(pos.phi0[k], rates.phi0_dot[k], step, 0.5),
                                _advanced(pos.chi0[k], rates.chi0_dot[k], step, 0.5),
                                _advanced(pos.S[k], rates.S_dot[k], step, 0.5 * length), length)
        nxt = _branch_features(pos.phi0[k1], pos.chi0[k1], pos.S[k1], length)
        # squared distances |p − q|², (n, 4, 4), feature by feature
        cost = np.zeros((step.shape[0], 4, 4))
        for f_prev, f_next in zip(prev, nxt, strict=True):
            diff = f_prev[:, :, None] - f_next[:, None, :]
            cost += diff * diff
        valid_prev, valid_next = pos.assembles[k], pos.assembles[k1]
        both = valid_prev[:, :, None] & valid_next[:, None, :]
        one = valid_prev[:, :, None] ^ valid_next[:, None, :]
        cost = np.where(both, cost, np.where(one, _UNMATCHED_COST, 0.0))
        diagonal = np.diagonal(cost, axis1=1, axis2=2)
        other = np.nonzero(~np.all(diagonal <= cost.min(axis=2), axis=1))[0]
        if other.size:
            total = cost[other][:, np.arange(4), _PERMS].sum(axis=-1)  # (m, 24)
            best[start + other] = np.argmin(total, axis=1)
    return best


def _unwrap_runs(angle: FloatArray, valid: BoolArray) -> FloatArray:
    """Unwrap each column of ``angle`` along its runs of valid samples (NaN elsewhere)."""
    n = angle.shape[0]
    prev_valid = np.vstack([np.zeros((1, angle.shape[1]), dtype=bool), valid[:-1]])
    start = valid & ~prev_valid
    diff = np.zeros_like(angle)
    diff[1:] = wrap_angle(np.nan_to_num(angle[1:] - angle[:-1]))
    diff = np.where(valid & ~start, diff, 0.0)
    csum = np.cumsum(diff, axis=0)
    # index of the start of the current run, per column
    run_start = np.where(start, np.arange(n)[:, None], 0)
    run_start = np.maximum.accumulate(run_start, axis=0)
    cols = np.arange(angle.shape[1])[None, :]
    base = angle[run_start, cols] - csum[run_start, cols]
    return np.where(valid, base + csum, np.nan)


def _refine_events(
    dims: RSRCDimensions,
    theta: FloatArray,
    n_assemblies: IntArray,
    samples: IntArray,
    tol: float,
    iterations: int = 60,
) -> FloatArray:
    """Bisect each interval (theta[k-1], theta[k]) for where the number of inversions changes.

    Returns, per event, the end of the final bracket (about 1e-15 wide) on the side with more
    inversions, i.e. the limit configuration itself (the double root) still assembles there.
    """
    lo = theta[samples - 1].copy()
    hi = theta[samples].copy()
    count_lo = n_assemblies[samples - 1]
    more_on_lo = count_lo > n_assemblies[samples]
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        same = rsrc_positions(dims, mid, double_root_tol=tol).n_assemblies == count_lo
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return np.where(more_on_lo, lo, hi)


def rsrc_motion(
    dims: RSRCDimensions,
    theta0_sweep: ArrayLike,
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
) -> RSRCMotion:
    """Track every assembly mode continuously over a sweep of input angles (Bagci 1969, §3.4).

    Bagci's inversion labels are root orderings at each theta0 and are not continuous in general
    (§3.4 "Branch continuity").  Here the roots of consecutive samples are matched by continuity:
    each root at sample k-1 is advanced by its rate (3.77)-(3.79) times the step, and the
    assignment of the 4 columns that minimises the summed squared distance of
    (cos phi0, sin phi0, cos chi0, sin chi0, S/L) is chosen among all 24 (vectorised over the
    sweep; a root is left unmatched when that is cheaper than a 90-degree jump).  The per-step
    permutations are then composed along the sweep (a light loop over integers).  phi0 is
    unwrapped along each run of valid samples, and every place where a branch stops or starts
    assembling is reported with its input angle, refined by bisection.

    The sweep should be monotonic and fine enough that no root moves by more than about 30
    degrees between samples.

    Parameters
    ----------
    dims
        The mechanism.
    theta0_sweep
        Input angles (radians), shape (N,), N >= 2.
    double_root_tol
        As in `rsrc_positions`.
    """
    theta = _check_theta0(theta0_sweep, "theta0_sweep")
    if theta.shape[0] < 2:
        raise ValueError("theta0_sweep needs at least 2 samples to track branches")
    pos = rsrc_positions(dims, theta, double_root_tol=double_root_tol)
    rates = rsrc_rates(dims, pos)
    length = max(dims.length_scale, np.finfo(float).tiny)
    best = _match_consecutive(pos, rates, length)

    # compose the per-step permutations: slot -> raw column at each sample
    mapping = np.empty(theta.shape[0], dtype=np.int64)
    current = _PERM_INDEX[(0, 1, 2, 3)]
    mapping[0] = current
    compose = _COMPOSE.tolist()
    for k, step_perm in enumerate(best.tolist(), start=1):
        current = compose[step_perm][current]
        mapping[k] = current
    cols = _PERMS[mapping]  # (N, 4)

    def take(arr: np.ndarray) -> np.ndarray:
        return np.take_along_axis(arr, cols, axis=1)

    assembles = take(pos.assembles)
    phi = _unwrap_runs(take(pos.phi0), assembles)
    chi = take(pos.chi0)
    s = take(pos.S)
    labels = take(pos.inversion_label)

    # events: branch stops (valid -> invalid) or starts (invalid -> valid)
    change = assembles[1:] != assembles[:-1]
    k_idx, branch_idx = np.nonzero(change)
    samples = k_idx + 1
    events: list[BranchEvent] = []
    if samples.size:
        theta_event = _refine_events(dims, theta, pos.n_assemblies, samples, double_root_tol)
        for sample, branch, th in zip(samples.tolist(), branch_idx.tolist(),
                                      theta_event.tolist(), strict=True):
            kind: Literal["stops", "starts"] = (
                "stops" if bool(assembles[sample - 1, branch]) else "starts"
            )
            events.append(BranchEvent(branch, kind, th, sample))
    return RSRCMotion(theta, phi, chi, s, assembles, labels, tuple(events))


# --------------------------------------------------------------------------------------------
# Limit positions (Appendix D)
# --------------------------------------------------------------------------------------------


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


def _loop_residual(
    dims: RSRCDimensions, theta: FloatArray, phi: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Loop equation and its phi0-derivative on a branch.

    General delta0: G/2 = (cos^2 delta0 W1^2 + W2^2 - d2^2 cos^2 delta0)/2 (eq. 3.61), whose
    phi0-derivative is Q5.  delta0 = +-pi/2: W2 (eq. 3.75), derivative M1.
    """
    sp, cp = np.sin(phi), np.cos(phi)
    m0, n0 = _m0_n0(dims, np.sin(theta), np.cos(theta))
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    w2 = n0 * sp - m0 * cp - dims.e * sd
    m1 = n0 * cp + m0 * sp
    if dims.special_case == "delta0_half_pi":
        return w2, m1
    c2 = cd * cd
    w1 = m0 * sp + n0 * cp + dims.d3
    m2 = m0 * cp - n0 * sp
    return 0.5 * (c2 * w1 * w1 + w2 * w2 - c2 * dims.d2**2), w2 * m1 + c2 * w1 * m2


def _chi_and_s(
    dims: RSRCDimensions, theta: FloatArray, phi: FloatArray, chi_sign: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """chi0 (eq. 3.59) and S (eq. 3.60) on a branch of known output angle."""
    sp, cp = np.sin(phi), np.cos(phi)
    st = np.sin(theta)
    m0, n0 = _m0_n0(dims, st, np.cos(theta))
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    w1 = m0 * sp + n0 * cp + dims.d3
    s_input = dims.b * math.cos(dims.lambda0) + dims.d1 * math.sin(dims.lambda0) * st
    if dims.special_case == "delta0_half_pi":
        chi = chi_sign * np.arccos(np.clip(w1 / dims.d2, -1.0, 1.0))
        return chi, s_input - dims.d2 * sd * np.sin(chi)
    w2 = n0 * sp - m0 * cp - dims.e * sd
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
            g, g_phi = _loop_residual(dims, theta, phi)
            phi = phi - np.where(g_phi != 0.0, g / np.where(g_phi != 0.0, g_phi, 1.0), 0.0)
        chi, s = _chi_and_s(dims, theta, phi, chi_sign)
        res = _rates_block(dims, theta[:, None], phi[:, None], chi[:, None], one, zero)
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
        g, g_phi = _loop_residual(dims, theta, phi)
        phi = phi - np.where(g_phi != 0.0, g / np.where(g_phi != 0.0, g_phi, 1.0), 0.0)
    chi, s = _chi_and_s(dims, theta, phi, chi_sign)
    res = _rates_block(dims, theta[:, None], phi[:, None], chi[:, None], one, zero)
    fd = res[3][:, 0] if which == "rotation" else res[5][:, 0]
    return theta, phi, chi, s, fd


def _limits(
    dims: RSRCDimensions,
    which: Literal["rotation", "translation"],
    n_grid: int,
    theta0_range: tuple[float, float],
) -> tuple[LimitPosition, ...]:
    if n_grid < 16:
        raise ValueError(f"n_grid must be at least 16 samples, got {n_grid}")
    start, stop = (float(v) for v in theta0_range)
    if not (math.isfinite(start) and math.isfinite(stop) and stop > start):
        raise ValueError(f"theta0_range must be a finite increasing pair, got {theta0_range!r}")
    grid = np.linspace(start, stop, n_grid)
    motion = rsrc_motion(dims, grid)
    one = np.ones((n_grid, 1))
    res = _rates_block(dims, grid[:, None], motion.phi0, motion.chi0, one, 0.0 * one)
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


# --------------------------------------------------------------------------------------------
# Instantaneous dwells: derivatives of phi0(theta0) of any order
# --------------------------------------------------------------------------------------------


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
        raise ValueError(f"order must be between 1 and 12, got {order!r}")
    order = int(order)
    theta = _check_theta0(theta0)
    phi = _check_theta0(phi0, "phi0")
    if phi.shape != theta.shape:
        raise ValueError(f"phi0 has shape {phi.shape}, theta0 has shape {theta.shape}")
    g0, g_phi = _loop_residual(dims, theta, phi)
    scale = dims.length_scale
    half_pi = dims.special_case == "delta0_half_pi"
    residual_scale = scale if half_pi else scale * scale
    off = np.abs(g0) > 1e-8 * residual_scale
    if off.any():
        i = int(np.flatnonzero(off)[0])
        raise ValueError(
            f"(theta0[{i}], phi0[{i}]) = ({theta[i]!r}, {phi[i]!r}) does not close the loop "
            f"(residual {g0[i]:.3g}); take phi0 from rsrc_positions"
        )
    locked = np.abs(g_phi) <= LOCK_TOL * residual_scale
    if locked.any():
        i = int(np.flatnonzero(locked)[0])
        raise ValueError(
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
        raise ValueError(f"derivatives must have shape (M, K), got {d.shape}")
    if not tol >= 0.0:
        raise ValueError(f"tol must be >= 0, got {tol!r}")
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

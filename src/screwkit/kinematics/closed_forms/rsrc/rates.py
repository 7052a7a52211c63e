"""Velocities and accelerations of every RSRC assembly (Bagci 1969, §3.5, eqs. 3.77-3.82).

Arrays follow the layout of `screwkit.kinematics.closed_forms.rsrc.positions` ((N, 4), one column per program
inversion label); rates are NaN exactly where a mask of `RSRCRates` says why.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.kinematics.closed_forms.quartic import DEFAULT_DOUBLE_ROOT_TOL
from screwkit.kinematics.closed_forms.rsrc.dimensions import (
    RSRCDimensions,
    check_input_angles,
    check_input_rate,
)
from screwkit.kinematics.closed_forms.rsrc.loop_equation import (
    LoopTerms,
    RSRCDimensionArrays,
    loop_terms_at,
)
from screwkit.kinematics.closed_forms.rsrc.positions import (
    BLOCK_SIZE,
    RSRCPositions,
    solve_positions,
)

__all__ = [
    "LOCK_TOL",
    "RSRCRates",
    "RateBlock",
    "rates_at_angles",
    "rates_from_terms",
    "rsrc_kinematics",
    "rsrc_rates",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: A configuration is reported as locked (input dead centre, Q5 = 0 in eq. 3.77) when
#: |Q5| <= LOCK_TOL * L^2 with L the sum of the link lengths.  A double root of the quartic is only
#: known to about the square root of the rounding error, so a tighter test would miss true locks.
LOCK_TOL = 1e-9


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


RateBlock = tuple[
    FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, BoolArray, BoolArray
]


def rates_from_terms(
    dims: RSRCDimensions, terms: LoopTerms, td: FloatArray | float, tdd: FloatArray | float
) -> RateBlock:
    """Eqs. 3.77-3.82 on one block; td, tdd are theta0-dot, theta0-ddot as (n, 1) or floats.

    Returns (phi_dot, chi_dot, S_dot, phi_ddot, chi_ddot, S_ddot, locked, chi_singular) with NaN
    where a denominator vanishes (the masks say where).  The products of §3.5 are regrouped to
    share factors (Q1 = M1 (M1 - c^2 W1) + M2 (W2 + c^2 M2), etc.); the result is the same.
    """
    d1, d2 = dims.d1, dims.d2
    arrays = RSRCDimensionArrays.from_dimensions(dims)
    sl, cl = arrays.sin_lambda0, arrays.cos_lambda0
    sd, cd = arrays.sin_delta0, arrays.cos_delta0
    c2 = cd * cd
    st, ct, sp, cp, sc, cc = terms.st, terms.ct, terms.sp, terms.cp, terms.sc, terms.cc
    m0, n0, w1, w2 = terms.m0, terms.n0, terms.w1, terms.w2
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


def rates_at_angles(
    dims: RSRCDimensions,
    theta: FloatArray,
    phi: FloatArray,
    chi: FloatArray,
    td: FloatArray,
    tdd: FloatArray,
) -> RateBlock:
    """`rates_from_terms` from angles: theta (n, 1), phi and chi (n, k)."""
    return rates_from_terms(dims, loop_terms_at(dims, theta, phi, chi), td, tdd)


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
    td = check_input_rate(theta0_dot, n, "theta0_dot")
    tdd = check_input_rate(theta0_ddot, n, "theta0_ddot")
    rate_arrays = [np.full((n, 4), np.nan) for _ in range(6)]
    flags = [np.zeros((n, 4), dtype=bool) for _ in range(2)]
    # a block needs the columns up to the last one that assembles in it (rsrc_positions puts
    # the roots first; branch order, as in rsrc_motion, may not)
    for start in range(0, n, BLOCK_SIZE):
        rows = slice(start, start + BLOCK_SIZE)
        used = np.flatnonzero(positions.assembles[rows].any(axis=0))
        k = int(used[-1]) + 1 if used.size else 0
        if positions.case == "delta0_half_pi":
            k = 4  # the chi0 < 0 modes sit in columns 2, 3 even when 0, 1 do not assemble
        if k == 0:
            continue
        block = (rows, slice(0, k))
        res = rates_at_angles(
            dims, theta[rows, None], positions.phi0[block], positions.chi0[block],
            td[rows], tdd[rows],
        )
        for arr, value in zip(rate_arrays + flags, res, strict=True):
            arr[block] = value
    return _finish_rates(positions.assembles, rate_arrays, flags[0], flags[1])


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
    theta = check_input_angles(theta0)
    n = theta.shape[0]
    td = check_input_rate(theta0_dot, n, "theta0_dot")
    tdd = check_input_rate(theta0_ddot, n, "theta0_ddot")
    # scalar input rates stay Python floats inside the blocks (cheaper broadcasting, and
    # theta0-ddot = 0 drops its terms)
    td_scalar = float(td[0, 0]) if n and np.ndim(np.asarray(theta0_dot)) == 0 else None
    tdd_scalar = float(tdd[0, 0]) if n and np.ndim(np.asarray(theta0_ddot)) == 0 else None
    # every entry is written once by its block (trimmed columns get NaN / False there)
    rate_arrays = [np.empty((n, 4)) for _ in range(6)]
    flags = [np.empty((n, 4), dtype=bool) for _ in range(2)]

    def rates_of_block(rows: slice, k: int, terms: LoopTerms) -> None:
        trimmed = (rows, slice(k, 4))
        for arr in rate_arrays:
            arr[trimmed] = np.nan
        for flag in flags:
            flag[trimmed] = False
        res = rates_from_terms(dims, terms, td_scalar if td_scalar is not None else td[rows],
                               tdd_scalar if tdd_scalar is not None else tdd[rows])
        for arr, value in zip(rate_arrays + flags, res, strict=True):
            arr[rows, 0:k] = value

    positions = solve_positions(dims, theta, double_root_tol, rates_of_block)
    return positions, _finish_rates(positions.assembles, rate_arrays, flags[0], flags[1])

"""Closed-form positions of every assembly of the RSRC (Bagci 1969, Chapter III, §3.4).

Outputs are the output rotation phi0, the output translation S (dual output angle phi0 - eps S)
and the coupler angle chi0.  Everything is in SI units and radians, batch-first over the input
angles theta0.

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
the result (``assembles``; ``locked``, ``chi_singular``, ``valid``) say where.  Input arrays are
validated and a non-finite input raises a ValueError; no NaN ever leaves this package unannounced
by a mask.

Labels are root orderings per sample.  Continuous assembly-mode branches over a sweep of theta0
come from `rsrc_motion` (`screwkit.kinematics.closed_forms.rsrc.branches`), which tracks the roots by
continuity.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import wrap_angle
from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.quartic import (
    DEFAULT_DOUBLE_ROOT_TOL,
    real_roots_of_trig_quadratic,
    sin_cos,
)
from screwkit.kinematics.closed_forms.rsrc.dimensions import (
    RSRCDimensions,
    SpecialCase,
    check_input_angles,
)
from screwkit.kinematics.closed_forms.rsrc.loop_equation import (
    LoopTerms,
    RSRCDimensionArrays,
    closure_terms,
    input_terms,
    loop_terms_at,
)

__all__ = [
    "BLOCK_SIZE",
    "RSRCPositions",
    "rsrc_positions",
    "quartic_discriminant",
    "solve_positions",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]

#: samples per block: keeps the temporaries small (measured best on 2 cores)
BLOCK_SIZE = 8192


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
            raise InputError(f"inversion label must be 1, 2, 3 or 4, got {label!r}")
        j = label - 1
        return self.phi0[:, j], self.chi0[:, j], self.S[:, j], self.assembles[:, j]


def _clip_unit(x: FloatArray, tol: float) -> tuple[FloatArray, BoolArray]:
    """Clip a cosine/sine argument to [-1, 1]; values up to 1 + tol^2/2 count as inside.

    An argument 1 + eps has an imaginary angle of about sqrt(2 eps); the same angle tolerance as for
    the quartic's double roots is used.
    """
    inside = np.abs(x) <= 1.0 + 0.5 * tol * tol
    return np.clip(x, -1.0, 1.0), inside


def _trig_coefficients(
    dims: RSRCDimensions, m0: FloatArray, n0: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """(a0, a1, b1, a2, b2) of the input-output equation (3.62), F1 sin² + F2 sin cos + F3 cos
    + F4 sin − K = 0, as a0 + a1 cos φ0 + b1 sin φ0 + a2 cos 2φ0 + b2 sin 2φ0 = 0."""
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    c2, s2 = cd * cd, sd * sd
    f1 = s2 * (n0 * n0 - m0 * m0)
    f2 = (-2.0 * s2) * m0 * n0  # Bagci prints sin(delta0); sin^2 is correct (SPEC §12, L939)
    f3 = 2.0 * (dims.d3 * c2 * n0 + dims.e * sd * m0)
    f4 = 2.0 * (dims.d3 * c2 * m0 - dims.e * sd * n0)
    k = c2 * (dims.d2**2 - dims.d3**2 - n0 * n0) - m0 * m0 - dims.e**2 * s2
    return 0.5 * f1 - k, f3, f4, -0.5 * f1, 0.5 * f2


def _output_angles_general(
    dims: RSRCDimensions, m0: FloatArray, n0: FloatArray, tol: float
) -> FloatArray:
    """phi0 roots (n, 4) of the input-output equation (3.62) through the quartic (3.63)."""
    phi, _ = real_roots_of_trig_quadratic(*_trig_coefficients(dims, m0, n0),
                                          double_root_tol=tol)
    return phi


def quartic_discriminant(dims: RSRCDimensions, theta0: ArrayLike) -> FloatArray:
    """The discriminant of the quartic (3.63) in tan(φ0/2) at each input angle (N,), divided
    by the sixth power of the norm of the trigonometric coefficients of (3.62) (a positive
    factor: the sign is the discriminant's, the value smooth in θ0): positive where four or
    no roots are real, negative where two are, zero at a fold (a double root). The general
    case only (δ0 neither a multiple of π/2): the others are quadratics."""
    theta = check_input_angles(theta0)
    arrays = RSRCDimensionArrays.from_dimensions(dims)
    m0, n0 = input_terms(arrays, np.sin(theta), np.cos(theta))
    a0, a1, b1, a2, b2 = _trig_coefficients(dims, m0, n0)
    scale = np.sqrt(a0 * a0 + a1 * a1 + b1 * b1 + a2 * a2 + b2 * b2)
    a0, a1, b1, a2, b2 = (x / scale for x in (a0, a1, b1, a2, b2))
    # times (1 + t²)² with t = tan(φ0/2): a t⁴ + b t³ + c t² + d t + e
    a, b, c = a0 - a1 + a2, 2.0 * b1 - 4.0 * b2, 2.0 * a0 - 6.0 * a2
    d, e = 2.0 * b1 + 4.0 * b2, a0 + a1 + a2
    # (4 Δ0³ − Δ1²) / 27 with the invariants Δ0 = c² − 3bd + 12ae and
    # Δ1 = 2c³ − 9bcd + 27b²e + 27ad² − 72ace
    i0 = c * c - 3.0 * b * d + 12.0 * a * e
    i1 = c * (2.0 * c * c - 9.0 * b * d - 72.0 * a * e) + 27.0 * (b * b * e + a * d * d)
    return np.asarray((4.0 * i0 * i0 * i0 - i1 * i1) / 27.0, dtype=np.float64)


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
) -> tuple[FloatArray, FloatArray, FloatArray, LoopTerms]:
    """(phi0, chi0, S, intermediates) for one block, trimmed to the columns that hold roots.

    Roots are sorted with the non-assembling entries last, so only the first k columns (k = the
    largest number of inversions in the block) are worked on; the caller fills the rest with NaN.
    Within those k columns NaN still marks inversions that do not close.
    """
    arrays = RSRCDimensionArrays.from_dimensions(dims)
    st, ct = sin_cos(theta[:, None])
    m0, n0 = input_terms(arrays, st, ct)
    sd, cd = arrays.sin_delta0, arrays.cos_delta0
    s_input = dims.b * arrays.cos_lambda0 + (dims.d1 * arrays.sin_lambda0) * st
    if dims.special_case == "general":
        phi = _output_angles_general(dims, m0[:, 0], n0[:, 0], tol)
        phi = phi[:, : int(np.count_nonzero(~np.isnan(phi), axis=1).max(initial=0))]
        sp, cp = sin_cos(phi)
        w1, w2 = closure_terms(arrays, m0, n0, sp, cp)
        # eq. 3.59: cos chi = W1/d2, sin chi = W2/(d2 cos delta0); atan2 as Program A does
        w2c = w2 / cd
        chi = np.arctan2(w2c, w1)
        inv_h = 1.0 / np.hypot(w1, w2c)
        sc, cc = w2c * inv_h, w1 * inv_h
        # eq. 3.60 with d2 sin chi0 = W2 / cos delta0 (the chi-free form of §3.4)
        s = (s_input + dims.e * cd) - (sd / cd) * w2
        return phi, chi, s, LoopTerms(st, ct, sp, cp, sc, cc, m0, n0, w1, w2)
    phi, chi = _output_angles_special(dims, m0[:, 0], n0[:, 0], tol)
    if dims.special_case == "delta0_n_pi":
        phi, chi = phi[:, :2], chi[:, :2]
    terms = loop_terms_at(dims, theta[:, None], phi, chi)
    # eq. 3.60 (3.60a for delta0 = n pi, where sin delta0 = 0)
    s = (s_input + dims.e * cd) - (dims.d2 * sd) * terms.sc
    return phi, chi, s, terms


#: called by `solve_positions` for every block: (rows, k, terms), with k the number of leading
#: columns that hold roots in that block and ``terms`` their loop-equation intermediates
BlockHook = Callable[[slice, int, LoopTerms], None]


def solve_positions(
    dims: RSRCDimensions,
    theta: FloatArray,
    double_root_tol: float,
    each_block: BlockHook | None = None,
) -> RSRCPositions:
    """`rsrc_positions` on checked angles, block by block (``BLOCK_SIZE`` samples at a time).

    ``each_block`` receives the intermediates of every block, so that further formulas (the
    rates of `rsrc_kinematics`) reuse them instead of recomputing (3.58)-(3.63).
    """
    n = theta.shape[0]
    # every entry is written once by its block (trimmed columns get NaN there)
    phi = np.empty((n, 4))
    chi = np.empty((n, 4))
    s = np.empty((n, 4))
    for start in range(0, n, BLOCK_SIZE):
        rows = slice(start, start + BLOCK_SIZE)
        phi_b, chi_b, s_b, terms = _positions_block(dims, theta[rows], double_root_tol)
        k = phi_b.shape[1]
        block = (rows, slice(0, k))
        trimmed = (rows, slice(k, 4))
        phi[block], chi[block], s[block] = phi_b, chi_b, s_b
        for arr in (phi, chi, s):
            arr[trimmed] = np.nan
        if each_block is not None:
            each_block(rows, k, terms)
    return RSRCPositions(theta, phi, chi, s, ~np.isnan(phi), dims.special_case)


def rsrc_positions(
    dims: RSRCDimensions,
    theta0: ArrayLike,
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
) -> RSRCPositions:
    """Output rotation phi0, translation S and coupler angle chi0 of every inversion.

    Bagci 1969, §3.4: the input-output equation (3.62) with F2 corrected to -2 M0 N0 sin^2(delta0)
    is solved through its half-angle quartic (3.63) (vectorised Ferrari, see
    `screwkit.kinematics.closed_forms.quartic`); chi0 from the signed atan2 form of (3.59) and S from (3.60).
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
    return solve_positions(dims, check_input_angles(theta0), double_root_tol)

"""Closed-form kinematics of the R–S–S–R loop (:func:`screwkit.model.families.rssr`).

The two ball centres move on circles: the input crank's, P(θ0) = (0, d1 cos θ0, d1 sin θ0) about
the input axis X, and the output crank's, Q(φ0) = C + d3 (cos φ0 e1 + sin φ0 e2) about the output
axis u3 = (cos λ0, 0, −sin λ0) through (b, a, 0), with C = (b + o cos λ0, a, −o sin λ0) its
centre (o the output offset), e1 = (0, 1, 0) and e2 = (sin λ0, 0, cos λ0). The coupler length
closes the loop, |Q − P|² = d2², which is linear in cos φ0 and sin φ0:

    A cos φ0 + B sin φ0 = K,   A = 2 d3 (a − d1 cos θ0),   B = 2 d3 (b sin λ0 − d1 sin θ0 cos λ0),
                               K = d2² − d3² − |C − P|²

(the offset o cancels from B). Its two roots φ0 = atan2(B, A) ± acos(K/√(A² + B²)) are the two
assembly modes; they meet (a limit position of the input, a dead centre) where |K| = √(A² + B²).
The output's rates follow by differentiating F(θ0, φ0) = A cos φ0 + B sin φ0 − K = 0:
φ0′ = −F_θ/F_φ, φ0″ = −(F_θθ + 2F_θφ φ0′ + F_φφ φ0′²)/F_φ (derivatives with respect to θ0).
φ0 is the output joint's angle with its sign turned (φ0 = −``output.theta``), as for the RSRC.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import Array

#: |F_φ| below this fraction of √(A² + B²) is a dead centre: the output rates are not defined
DEAD_CENTRE_TOL = 1e-9


@dataclass(frozen=True)
class RSSRDimensions:
    """The RSSR's dimensions with the RSRC's frame names (SI units, radians)."""

    d1: float
    d2: float
    d3: float
    a: float
    b: float
    lambda0: float
    output_offset: float = 0.0


@dataclass(frozen=True)
class RSSRMotion:
    """Both roots (columns: + then −) of the output angle over θ0 with their derivatives with
    respect to θ0, where they assemble, and where the rates are undefined (a dead centre)."""

    phi0: Array  # (N, 2)
    dphi: Array  # (N, 2) dφ0/dθ0
    ddphi: Array  # (N, 2) d²φ0/dθ0²
    assembles: NDArray[np.bool_]  # (N, 2)
    dead_centre: NDArray[np.bool_]  # (N, 2)
    coupler_ball: Array  # (N, 2, 3) the output ball's centre (world)
    crank_ball: Array  # (N, 3) the input ball's centre (world)


def trig_roots(A: Array, B: Array, K: Array) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Both roots (N, 2) of A cos x + B sin x = K (+ then − branch of the acos), the value of
    ∂/∂x (A cos x + B sin x) at each root, and where the roots are real."""
    R = np.hypot(A, B)
    ratio = K / np.where(R > 0, R, 1.0)
    ok = (R > 0) & (np.abs(ratio) <= 1.0)
    base = np.arctan2(B, A)
    spread = np.arccos(np.clip(ratio, -1.0, 1.0))
    roots = np.stack([base + spread, base - spread], axis=1)
    slope = np.stack([-R * np.sin(spread), R * np.sin(spread)], axis=1)
    return roots, slope, np.stack([ok, ok], axis=1)


def rssr_motion(dims: RSSRDimensions, theta0: Array) -> RSSRMotion:
    """Both assembly modes of the RSSR at every input angle (module docstring)."""
    th = np.asarray(theta0, dtype=float)
    d1, d2, d3, a, b = dims.d1, dims.d2, dims.d3, dims.a, dims.b
    o, lam = dims.output_offset, dims.lambda0
    cl, sl = np.cos(lam), np.sin(lam)
    ct, st = np.cos(th), np.sin(th)
    A = 2 * d3 * (a - d1 * ct)
    B = 2 * d3 * (b * sl - d1 * st * cl)
    D2 = (b + o * cl) ** 2 + (a - d1 * ct) ** 2 + (o * sl + d1 * st) ** 2
    K = d2**2 - d3**2 - D2
    # first and second derivatives with respect to θ0
    A1, A2 = 2 * d3 * d1 * st, 2 * d3 * d1 * ct
    B1, B2 = -2 * d3 * d1 * cl * ct, 2 * d3 * d1 * cl * st
    K1 = -2 * d1 * (a * st + o * sl * ct)
    K2 = -2 * d1 * (a * ct - o * sl * st)
    phi, F_phi, ok = trig_roots(A, B, K)
    c, s = np.cos(phi), np.sin(phi)
    F_t = A1[:, None] * c + B1[:, None] * s - K1[:, None]
    F_tt = A2[:, None] * c + B2[:, None] * s - K2[:, None]
    F_tp = -A1[:, None] * s + B1[:, None] * c
    F_pp = -A[:, None] * c - B[:, None] * s
    dead = ok & (np.abs(F_phi) <= DEAD_CENTRE_TOL * np.hypot(A, B)[:, None])
    safe = np.where(dead | ~ok, 1.0, F_phi)
    dphi = np.where(dead | ~ok, np.nan, -F_t / safe)
    ddphi = np.where(dead | ~ok, np.nan, -(F_tt + 2 * F_tp * dphi + F_pp * dphi**2) / safe)
    centre = np.array([b + o * cl, a, -o * sl])
    e1, e2 = np.array([0.0, 1.0, 0.0]), np.array([sl, 0.0, cl])
    ball2 = centre + d3 * (c[..., None] * e1 + s[..., None] * e2)
    ball1 = np.stack([np.zeros_like(th), d1 * ct, d1 * st], axis=-1)
    return RSSRMotion(np.where(ok, phi, np.nan), dphi, ddphi, ok, dead, ball2, ball1)

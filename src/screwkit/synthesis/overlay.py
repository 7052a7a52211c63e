"""Bagci's overlay technique as a computation (Bagci 1969, §5.4, Examples 8 and 9; delta0 = 0).

The graphical method: with d1, lambda0 and theta01 chosen (e.g. so that the sine translation
d1 sin(lambda0) sin(theta0) matches the translation component), draw the input-crank ellipse in
the plane normal to the output axis, mark the design positions P_i, draw circles of radius d2
about them (for delta0 = 0 the coupler projects with its true length), and slide an overlay
carrying radial lines at the desired output angles psi_i until one circle of the overlay passes
through the family of circles at the matching radial lines.  Its centre gives (a, b sin lambda0),
its radius d3.

Here the overlay fit is a least-squares problem in (centre_x, centre_y, d3, phi01): the output-
crank tips C_i = O + d3 (cos(phi01 + s psi_i), sin(phi01 + s psi_i)) should lie on the circles,
i.e. |C_i - P_i| = d2.  It is started from a grid over (phi01, d3) on which the centre follows
from a linear (algebraic, Kasa-type) circle fit, and refined by `least_squares` with the exact
Jacobian.  The result is checked by analysing the mechanism (`rsrc_positions`): the generated
psi at each design point is reported next to the desired one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares

from screwkit.kinematics.quartic import wrap_angle
from screwkit.kinematics.rsrc import RSRCDimensions, rsrc_positions

__all__ = ["OverlayResult", "overlay_fit"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class OverlayResult:
    """Mechanism found by the overlay fit.

    dimensions : the RSRC (delta0 = e = 0).  theta01, phi01 : input and output angles at theta = 0.
    circle_residual : (N,) |C_i - P_i| - d2, the distance of each overlay point from its circle
        (0 for an exact overlay).
    psi_generated, psi_desired : (N,) output rotation of the analysed mechanism and the target.
    rmse_phi : RMS of psi_desired - psi_generated (rad) over the points where it assembles.
    assembles : (N,) the analysed mechanism closes at the design point near the overlay position
        (an inexact overlay can leave a point outside the reach of the output crank: NaN there).
    """

    dimensions: RSRCDimensions
    theta01: float
    phi01: float
    circle_residual: FloatArray
    psi_generated: FloatArray
    psi_desired: FloatArray
    rmse_phi: float
    assembles: NDArray[np.bool_]


def overlay_fit(*, d1: float, d2: float, lambda0: float, theta01: float, theta: ArrayLike,
                psi: ArrayLike, input_direction: int = 1, output_direction: int = 1,
                d3_range: tuple[float, float] | None = None) -> OverlayResult:
    """Fit the overlay circle through the family of coupler circles (see the module docstring).

    Parameters
    ----------
    d1, d2, lambda0, theta01 : the chosen input crank, coupler, skew angle and start angle.
    theta, psi : design points (rad, from theta01) and desired output rotations there (rad).
    input_direction, output_direction : +1 counter-clockwise, -1 clockwise (as in the problem).
    d3_range : range of output-crank radii scanned for the start (default 0.05 d1 .. 20 d1).
    """
    th = np.asarray(theta, dtype=np.float64).reshape(-1)
    ps = np.asarray(psi, dtype=np.float64).reshape(-1)
    if th.shape != ps.shape or th.size < 4:
        raise ValueError("the overlay fit needs at least 4 design points (theta, psi of equal "
                         f"length), got {th.size} and {ps.size}")
    if not (d1 > 0 and d2 > 0):
        raise ValueError("d1 and d2 must be positive")
    if abs(math.sin(lambda0)) < 1e-9:
        raise ValueError("lambda0 = 0: the overlay of the plane case needs b = 0; use the "
                         "least-squares synthesis of the plane 4R instead")
    theta0 = theta01 + input_direction * th
    px = d1 * np.cos(theta0)
    py = d1 * math.cos(lambda0) * np.sin(theta0)
    ang = output_direction * ps
    lo, hi = d3_range if d3_range is not None else (0.05 * d1, 20.0 * d1)
    phis = np.linspace(-math.pi, math.pi, 73)[:-1]
    d3s = np.geomspace(lo, hi, 40)
    grid_phi, grid_d3 = np.meshgrid(phis, d3s, indexing="ij")
    pg, dg = grid_phi.reshape(-1), grid_d3.reshape(-1)
    # tip relative to the centre: v_i = d3 u(phi01 + ang_i); |O + v_i - P_i|^2 = d2^2 is linear in
    # (Ox, Oy, |O|^2): |O|^2 + 2 O.(v_i - P_i) = d2^2 - |v_i - P_i|^2
    vx = dg[:, None] * np.cos(pg[:, None] + ang[None, :]) - px[None, :]
    vy = dg[:, None] * np.sin(pg[:, None] + ang[None, :]) - py[None, :]
    a_mat = np.stack([2 * vx, 2 * vy, np.ones_like(vx)], axis=-1)  # (G, N, 3)
    rhs = d2 * d2 - vx * vx - vy * vy
    ata = np.einsum("gni,gnj->gij", a_mat, a_mat) + 1e-12 * np.eye(3)
    atb = np.einsum("gni,gn->gi", a_mat, rhs)
    sol = np.linalg.solve(ata, atb[..., None])[..., 0]
    ox, oy = sol[:, 0], sol[:, 1]
    dist = np.hypot(ox[:, None] + vx, oy[:, None] + vy) - d2

    def residual(z: FloatArray) -> FloatArray:
        cx, cy, d3, phi01 = z
        return np.hypot(cx + d3 * np.cos(phi01 + ang) - px, cy + d3 * np.sin(phi01 + ang) - py) - d2

    def jacobian(z: FloatArray) -> FloatArray:
        cx, cy, d3, phi01 = z
        c, s = np.cos(phi01 + ang), np.sin(phi01 + ang)
        dx, dy = cx + d3 * c - px, cy + d3 * s - py
        r = np.hypot(dx, dy)
        return np.stack([dx / r, dy / r, (dx * c + dy * s) / r, d3 * (-dx * s + dy * c) / r], 1)

    cost = np.sum(dist * dist, axis=1)
    candidates = []
    for g in np.argsort(cost)[:8].tolist():
        z0 = np.array([ox[g], oy[g], dg[g], pg[g]])
        fit = least_squares(residual, z0, jac=jacobian,
                            bounds=([-np.inf, -np.inf, 0.0, -np.inf], np.inf), max_nfev=500)
        cx, cy, d3, phi01 = (float(v) for v in fit.x)
        if d3 <= 0.0:
            continue
        dims = RSRCDimensions(d1, d2, d3, cx, cy / math.sin(lambda0), 0.0, 0.0, lambda0)
        pos = rsrc_positions(dims, theta0)
        want = phi01 + ang
        diff = np.where(pos.assembles, np.abs(wrap_angle(pos.phi0 - want[:, None])), np.inf)
        col = np.argmin(diff, axis=1)
        phi_g = np.where(np.isfinite(diff.min(axis=1)), pos.phi0[np.arange(th.size), col], np.nan)
        n_missing = int(np.count_nonzero(np.isnan(phi_g)))
        candidates.append((n_missing, float(2.0 * fit.cost), dims, phi01, fit.x, phi_g))
    if not candidates:
        raise ValueError("the overlay fit found no output crank; choose another d2 or theta01")
    n_missing, _, dims, phi01, z, phi_g = min(candidates, key=lambda c: (c[0], c[1]))
    psi_g = output_direction * wrap_angle(phi_g - phi01)
    err = wrap_angle(ps - psi_g)
    assembles = ~np.isnan(phi_g)
    rmse = float(np.sqrt(np.mean(err[assembles] ** 2))) if assembles.any() else math.nan
    return OverlayResult(dims, theta01, phi01, residual(z), psi_g, ps, rmse, assembles)

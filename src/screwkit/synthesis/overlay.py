"""Bagci's overlay technique as a computation (Bagci 1969, §5.4, Examples 8 and 9; delta0 = 0).

The graphical method: with d1, lambda0 and theta01 chosen (e.g. so that the sine translation
d1 sin(lambda0) sin(theta0) matches the translation component), draw the input-crank ellipse
P(theta0) = (d1 cos theta0, d1 cos lambda0 sin theta0) in the plane normal to the output axis,
mark the design positions P_i, draw circles of radius d2 about them (for delta0 = 0 the coupler
projects with its true length: SPEC §5.3), and slide an overlay carrying radial lines at the
desired output angles psi_i until one circle of the overlay passes through the family of circles
at the matching radial lines.  Its centre gives (a, b sin lambda0), its radius d3.

Here the overlay fit is a least-squares problem: the output-crank tips
C_i = O + d3 (cos(phi01 + s psi_i), sin(phi01 + s psi_i)) should lie on the coupler circles,
|C_i - P_i| = d2.  Unknowns (O, d3, phi01), and d2 when it is refined.

Dwells (§5.4, Ex. 9): "the design point on the overlay for the value of theta at which the
instantaneous dwell is to take place must be placed on the normal to the input-crank ellipse",
i.e. C_j = P_j + d2 n_j with n_j the ellipse's unit normal at P_j (the coupler then lies along
the normal: dphi0/dtheta0 = 0, eq. 5.13).  "exterior" tangency takes the outward normal (a
first-order dwell), "interior" the inward one; with d2 equal to the ellipse's radius of curvature
there (`ellipse_curvature_radius`) C_j is the centre of curvature and the dwell is of higher
order.  One dwell removes the centre from the unknowns (O = C_j - d3 u_j); two dwells fix the
circle outright (the centre that turns C_j into C_k by the desired rotation between them, as
eqs. 5.19-5.21).

The fit is started from a grid over (phi01, d3) (without a dwell the centre follows from a
linear, Kasa-type circle fit on each grid point) and refined by `least_squares` with a
complex-step Jacobian (exact to rounding).  The distinct local fits are returned; the caller
analyses each with the RSRC closed form (`screwkit.synthesis.overlay_synthesis`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares

from screwkit.dual.spatial import wrap_angle
from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_positions
from screwkit.messages import shown, shown_range

__all__ = [
    "OverlayCircle",
    "OverlayDwell",
    "OverlayResult",
    "ellipse_curvature_radius",
    "ellipse_normal",
    "fit_overlay_circles",
    "input_ellipse_point",
    "mechanism_from_circle",
    "overlay_fit",
]

FloatArray = NDArray[np.float64]
Array = NDArray[Any]
_STEP = 1e-30  # complex step: exact first derivatives to rounding


# --- the input-crank ellipse (plane normal to the output axis, SPEC §5.3) ----------------------
def input_ellipse_point(d1: float, lambda0: float, theta0: ArrayLike) -> tuple[Array, Array]:
    """P(theta0) = (d1 cos theta0, d1 cos lambda0 sin theta0): the projected input-crank tip."""
    t = np.asarray(theta0)
    return d1 * np.cos(t), d1 * math.cos(lambda0) * np.sin(t)


def ellipse_normal(d1: float, lambda0: float, theta0: ArrayLike,
                   tangency: Literal["interior", "exterior"] = "exterior"
                   ) -> tuple[FloatArray, FloatArray]:
    """Unit normal of the input-crank ellipse at theta0: outward ("exterior" tangency of the
    coupler circle) or inward ("interior").  Its slope is eq. 5.13, tan q = tan theta0 / cos l0."""
    b_axis = d1 * math.cos(lambda0)
    if abs(b_axis) < 1e-12 * d1:
        raise InputError("lambda0 = 90 deg: the input-crank ellipse degenerates to a segment and "
                         "has no normal; a dwell cannot be placed by the overlay")
    t = np.asarray(theta0, dtype=np.float64)
    nx, ny = np.cos(t) / d1, np.sin(t) / b_axis  # gradient of (x/d1)^2 + (y/B)^2: outward
    norm = np.hypot(nx, ny)
    sign = 1.0 if tangency == "exterior" else -1.0
    return sign * nx / norm, sign * ny / norm


def ellipse_curvature_radius(d1: float, lambda0: float, theta0: ArrayLike) -> FloatArray:
    """Radius of curvature of the input-crank ellipse at theta0 (§5.4: d2 near it gives a
    higher-order dwell), (d1^2 sin^2 + B^2 cos^2)^(3/2) / |d1 B| with B = d1 cos lambda0."""
    b_axis = d1 * math.cos(lambda0)
    t = np.asarray(theta0, dtype=np.float64)
    if abs(b_axis) < 1e-12 * d1:
        return np.full(t.shape, np.inf)
    return (d1**2 * np.sin(t) ** 2 + b_axis**2 * np.cos(t) ** 2) ** 1.5 / abs(d1 * b_axis)


@dataclass(frozen=True)
class OverlayDwell:
    """A dwell placed on the overlay (§5.4): at the design point theta (rad, from theta01) the
    output-crank tip lies on the ellipse normal, C = P + d2 n ("interior": inward normal)."""

    theta: float
    tangency: Literal["interior", "exterior"] = "interior"

    def __post_init__(self) -> None:
        if self.tangency not in ("interior", "exterior"):
            raise InputError(f"dwell tangency must be 'interior' or 'exterior', got "
                             f"{self.tangency!r}")
        if not math.isfinite(self.theta):
            raise InputError("dwell theta must be finite")


@dataclass(frozen=True)
class OverlayCircle:
    """One overlay circle (the output-crank circle) through the family of coupler circles.

    centre : (x, y) of the output axis in the overlay plane, = (a, b sin lambda0).
    d3, phi01 : its radius and the output-crank angle at theta = 0; d2 : the coupler length used
    (refined or as chosen).  circle_residual : (N,) |C_i - P_i| - d2 (0 for an exact overlay).
    evaluations : residual evaluations of its local fit (and of the fits that ended on the same
        circle); status : "converged", "iteration limit"
    or "time limit" (then the circle is the fit's start, not refined).
    """

    centre: tuple[float, float]
    d3: float
    phi01: float
    d2: float
    circle_residual: FloatArray
    evaluations: int
    status: Literal["converged", "iteration limit", "time limit"]

    @property
    def cost(self) -> float:
        return float(np.sum(self.circle_residual**2))


class _Geometry:
    """Points, angles and dwell normals of one overlay problem; residuals batch-first in z."""

    def __init__(self, d1: float, d2: float, lambda0: float, theta01: float, theta: FloatArray,
                 psi: FloatArray, input_direction: int, output_direction: int,
                 dwells: tuple[OverlayDwell, ...], refine_d2: bool) -> None:
        self.d2_chosen = d2
        self.refine_d2 = refine_d2
        theta0 = theta01 + input_direction * theta
        self.px, self.py = input_ellipse_point(d1, lambda0, theta0)
        self.ang = output_direction * psi  # overlay radial lines, counter-clockwise positive
        self.dwell_index: list[int] = []
        self.normals: list[tuple[float, float]] = []
        for dw in dwells:
            hit = np.flatnonzero(np.abs(theta - dw.theta) <= 1e-12 * max(1.0, abs(dw.theta)))
            if hit.size == 0:
                raise InputError(f"dwell at theta = {shown(dw.theta, 'angle')} is not one "
                                 "of the rotation design points; add it to design_points")
            j = int(hit[0])
            self.dwell_index.append(j)
            nx, ny = ellipse_normal(d1, lambda0, theta01 + input_direction * dw.theta,
                                    dw.tangency)
            self.normals.append((float(nx), float(ny)))
        if len(self.dwell_index) == 2:
            j, k = self.dwell_index
            if abs(math.sin(0.5 * (self.ang[k] - self.ang[j]))) < 1e-9:
                raise InputError(
                    "contradictory constraints: the desired output rotation between the two "
                    f"dwell points is {shown(self.ang[k] - self.ang[j], 'angle')}, a "
                    "multiple of a full turn, so no output circle carries one overlay point to the "
                    "other; drop a dwell or change the target")
        self.n_free = {0: 4, 1: 2, 2: 0}[len(self.dwell_index)] + (1 if refine_d2 else 0)

    def fixed_tip(self, i: int, d2: Array) -> tuple[Array, Array]:
        j = self.dwell_index[i]
        nx, ny = self.normals[i]
        return self.px[j] + d2 * nx, self.py[j] + d2 * ny

    def tips(self, z: Array) -> tuple[Array, Array, Array, Array, Array, Array]:
        """(B, n) unknowns -> tips C_i (B, N) x, y; centre x, y, d3, d2 (B,). Complex-safe."""
        z = np.atleast_2d(z)
        d2 = z[:, -1] if self.refine_d2 else np.full(z.shape[0], self.d2_chosen, dtype=z.dtype)
        ang = self.ang[None, :]
        nd = len(self.dwell_index)
        if nd == 0:
            cx, cy, d3, phi01 = z[:, 0], z[:, 1], z[:, 2], z[:, 3]
            tx = cx[:, None] + d3[:, None] * np.cos(phi01[:, None] + ang)
            ty = cy[:, None] + d3[:, None] * np.sin(phi01[:, None] + ang)
            return tx, ty, cx, cy, d3, d2
        j = self.dwell_index[0]
        cjx, cjy = self.fixed_tip(0, d2)
        if nd == 1:
            d3, phi01 = z[:, 0], z[:, 1]
            cx = cjx - d3 * np.cos(phi01 + self.ang[j])
            cy = cjy - d3 * np.sin(phi01 + self.ang[j])
        else:
            # the centre O that rotates C_j into C_k by the desired rotation Delta between them:
            # (I - R) O = C_k - R C_j (the construction of eqs. 5.19-5.21)
            k = self.dwell_index[1]
            ckx, cky = self.fixed_tip(1, d2)
            delta = self.ang[k] - self.ang[j]
            c, s = math.cos(delta), math.sin(delta)
            rx, ry = ckx - (c * cjx - s * cjy), cky - (s * cjx + c * cjy)
            det = (1 - c) ** 2 + s * s
            cx = ((1 - c) * rx - s * ry) / det
            cy = (s * rx + (1 - c) * ry) / det
            d3 = np.sqrt((cjx - cx) ** 2 + (cjy - cy) ** 2)
        rel = ang - self.ang[j]
        vx, vy = (cjx - cx)[:, None], (cjy - cy)[:, None]
        tx = cx[:, None] + np.cos(rel) * vx - np.sin(rel) * vy
        ty = cy[:, None] + np.sin(rel) * vx + np.cos(rel) * vy
        return tx, ty, cx, cy, d3, d2

    def residual(self, z: Array) -> Array:
        tx, ty, _, _, _, d2 = self.tips(z)
        dx, dy = tx - self.px[None, :], ty - self.py[None, :]
        return np.sqrt(dx * dx + dy * dy) - d2[:, None]

    def jacobian(self, z: FloatArray) -> FloatArray:
        n = z.size
        zc = z[None, :] + 1j * _STEP * np.eye(n)
        return np.imag(self.residual(zc)).T / _STEP

    def circle(self, z: FloatArray, evaluations: int, status: Any) -> OverlayCircle:
        tx, ty, cx, cy, d3, d2 = self.tips(z)
        phi01 = math.atan2(float(ty[0, 0] - cy[0]), float(tx[0, 0] - cx[0])) - float(self.ang[0])
        return OverlayCircle((float(cx[0]), float(cy[0])), float(d3[0]), float(wrap_angle(phi01)),
                             float(d2[0]), self.residual(z)[0], evaluations, status)


def _grid_starts(geo: _Geometry, d3_lo: float, d3_hi: float, n_starts: int) -> list[FloatArray]:
    """Start vectors: the best distinct points of a (phi01, d3) grid (Kasa centre without a
    dwell), one per grid cell neighbourhood so that different overlay positions are tried."""
    nd = len(geo.dwell_index)
    if nd == 2:
        return [np.array([geo.d2_chosen])] if geo.refine_d2 else [np.zeros(0)]
    phis = np.linspace(-math.pi, math.pi, 73)[:-1]
    d3s = np.geomspace(d3_lo, d3_hi, 40)
    gp, gd = (g.reshape(-1) for g in np.meshgrid(phis, d3s, indexing="ij"))
    if nd == 0:
        # |O + v_i|^2 = d2^2 with v_i = d3 u(phi01 + ang_i) - P_i is linear in (Ox, Oy, |O|^2)
        vx = gd[:, None] * np.cos(gp[:, None] + geo.ang[None, :]) - geo.px[None, :]
        vy = gd[:, None] * np.sin(gp[:, None] + geo.ang[None, :]) - geo.py[None, :]
        a_mat = np.stack([2 * vx, 2 * vy, np.ones_like(vx)], axis=-1)  # (G, N, 3)
        rhs = geo.d2_chosen**2 - vx * vx - vy * vy
        ata = np.einsum("gni,gnj->gij", a_mat, a_mat) + 1e-12 * np.eye(3)
        atb = np.einsum("gni,gn->gi", a_mat, rhs)
        sol = np.linalg.solve(ata, atb[..., None])[..., 0]
        z = np.stack([sol[:, 0], sol[:, 1], gd, gp], axis=1)
    else:
        z = np.stack([gd, gp], axis=1)
    if geo.refine_d2:
        z = np.concatenate([z, np.full((z.shape[0], 1), geo.d2_chosen)], axis=1)
    cost = np.sum(geo.residual(z) ** 2, axis=1)
    order = np.argsort(cost)
    picked: list[int] = []
    for g in order.tolist():  # spread the starts: skip grid neighbours of a picked one
        ip, idd = divmod(g, d3s.size)
        if all(min(abs(ip - p // d3s.size), 72 - abs(ip - p // d3s.size)) > 2
               or abs(idd - p % d3s.size) > 3 for p in picked):
            picked.append(g)
        if len(picked) == n_starts:
            break
    return [z[g] for g in picked]


def fit_overlay_circles(*, d1: float, d2: float, lambda0: float, theta01: float,
                        theta: ArrayLike, psi: ArrayLike, input_direction: int = 1,
                        output_direction: int = 1, dwells: tuple[OverlayDwell, ...] = (),
                        refine_d2: bool = False, d3_range: tuple[float, float] | None = None,
                        n_starts: int = 12, max_evaluations: int = 500,
                        deadline: float | None = None) -> list[OverlayCircle]:
    """The distinct overlay circles through the family of coupler circles (module docstring),
    best circle fit first.

    Parameters
    ----------
    d1, d2, lambda0, theta01 : chosen input crank, coupler (start when refine_d2), skew angle
        and input angle at theta = 0 (radians, lengths in any one unit).
    theta, psi : rotation design points (rad, from theta01) and the desired output rotations.
    input_direction, output_direction : +1 counter-clockwise, -1 clockwise.
    dwells : at most two `OverlayDwell` (each at one of the design points).
    refine_d2 : also fit d2 (Bagci chooses it by hand).
    d3_range : output-crank radii scanned for the starts (default 0.05 d1 .. 20 d1); the fit
        keeps d3 within [0, 5 x upper].
    n_starts, max_evaluations : grid starts refined; residual evaluations per local fit.
    deadline : ``time.perf_counter()`` value after which the remaining starts are returned
        unrefined with status "time limit".
    """
    th = np.asarray(theta, dtype=np.float64).reshape(-1)
    ps = np.asarray(psi, dtype=np.float64).reshape(-1)
    if th.shape != ps.shape:
        raise InputError(f"theta and psi must have equal length, got {th.size} and {ps.size}")
    if not (np.all(np.isfinite(th)) and np.all(np.isfinite(ps))):
        raise InputError("theta and psi must be finite")
    if not (d1 > 0 and d2 > 0 and math.isfinite(d1) and math.isfinite(d2)):
        raise InputError(f"d1 and d2 must be positive lengths, got d1 = {d1!r}, d2 = {d2!r}")
    if len(dwells) > 2:
        raise InputError(f"at most two dwells can be placed on the overlay, got {len(dwells)}: "
                         "two fix the output circle already")
    geo = _Geometry(d1, d2, lambda0, theta01, th, ps, input_direction, output_direction,
                    tuple(dwells), refine_d2)
    if th.size < geo.n_free:
        raise InputError(f"the overlay fit has {geo.n_free} unknowns but only {th.size} design "
                         "points: give more rotation design points")
    lo, hi = d3_range if d3_range is not None else (0.05 * d1, 20.0 * d1)
    if not 0 < lo < hi:
        raise InputError(f"d3_range must be 0 < lower < upper, got "
                         f"{shown_range(lo, hi, 'length')}")
    starts = _grid_starts(geo, lo, hi, n_starts)
    lower = np.full(geo.n_free, -np.inf)
    upper = np.full(geo.n_free, np.inf)
    nd = len(geo.dwell_index)
    d3_col = {0: 2, 1: 0}.get(nd)
    if d3_col is not None:
        lower[d3_col], upper[d3_col] = 0.0, 5.0 * hi
    if refine_d2:
        lower[-1] = 1e-6 * d1
    circles: list[OverlayCircle] = []
    for z0 in starts:
        if geo.n_free == 0:
            circles.append(geo.circle(z0, 1, "converged"))
            continue
        if deadline is not None and time.perf_counter() > deadline:
            circles.append(geo.circle(z0, 0, "time limit"))
            continue
        z0 = np.clip(z0, lower + 1e-12 * d1 * np.isfinite(lower), upper)
        fit = least_squares(lambda z: geo.residual(z)[0], z0, jac=geo.jacobian,
                            bounds=(lower, upper), max_nfev=max_evaluations, xtol=1e-14,
                            ftol=1e-14, gtol=1e-14)
        status = "iteration limit" if fit.status == 0 else "converged"
        circles.append(geo.circle(fit.x, int(fit.nfev), status))
    circles.sort(key=lambda c: c.cost)
    distinct: list[OverlayCircle] = []
    for c in circles:
        if c.d3 <= 1e-9 * d1:
            continue
        same = [k for k, o in enumerate(distinct)
                if math.hypot(c.centre[0] - o.centre[0], c.centre[1] - o.centre[1])
                + abs(c.d3 - o.d3) + abs(c.d2 - o.d2) <= 1e-6 * d1]
        if same:  # a duplicate: count its work on the circle kept
            k = same[0]
            distinct[k] = replace(distinct[k], evaluations=distinct[k].evaluations + c.evaluations)
        else:
            distinct.append(c)
    if not distinct:
        raise InputError("the overlay fit found no output crank (every circle shrank to a "
                         "point); choose another d2 or theta01")
    return distinct


def mechanism_from_circle(circle: OverlayCircle, *, d1: float, lambda0: float, theta01: float,
                          e: float = 0.0) -> tuple[RSRCDimensions, float, float]:
    """The RSRC (delta0 = 0) of an overlay circle: a = centre x, b = centre y / sin lambda0.

    Returns (dimensions, theta01, phi01).  In the plane case (lambda0 = 0, b = 0) the mechanism
    is turned about the input axis so that the output axis lies on the x axis at a = |centre|
    (as Program C, L6248-L6262): theta01 and phi01 are then given in that frame.
    """
    cx, cy = circle.centre
    if abs(math.sin(lambda0)) < 1e-12:
        beta = math.atan2(cy, cx)
        dims = RSRCDimensions(d1, circle.d2, circle.d3, math.hypot(cx, cy), 0.0, e, 0.0, lambda0)
        return dims, float(theta01 - beta), float(wrap_angle(circle.phi01 - beta))
    dims = RSRCDimensions(d1, circle.d2, circle.d3, cx, cy / math.sin(lambda0), e, 0.0, lambda0)
    return dims, theta01, circle.phi01


@dataclass(frozen=True)
class OverlayResult:
    """Mechanism found by the overlay fit (`overlay_fit`).

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
                d3_range: tuple[float, float] | None = None,
                dwells: tuple[OverlayDwell, ...] = (), refine_d2: bool = False) -> OverlayResult:
    """The best overlay circle (`fit_overlay_circles`), analysed point by point with the closed
    form (`rsrc_positions`, the root nearest each overlay position).  The branch-following
    analysis with whole-range check, errors and rows is `overlay_synthesis.synthesize_overlay`."""
    th = np.asarray(theta, dtype=np.float64).reshape(-1)
    ps = np.asarray(psi, dtype=np.float64).reshape(-1)
    circle = fit_overlay_circles(d1=d1, d2=d2, lambda0=lambda0, theta01=theta01, theta=th,
                                 psi=ps, input_direction=input_direction,
                                 output_direction=output_direction, dwells=dwells,
                                 refine_d2=refine_d2, d3_range=d3_range)[0]
    dims, th01, phi01 = mechanism_from_circle(circle, d1=d1, lambda0=lambda0, theta01=theta01)
    pos = rsrc_positions(dims, th01 + input_direction * th)
    want = phi01 + output_direction * ps
    diff = np.where(pos.assembles, np.abs(wrap_angle(pos.phi0 - want[:, None])), np.inf)
    col = np.argmin(diff, axis=1)
    phi_g = np.where(np.isfinite(diff.min(axis=1)), pos.phi0[np.arange(th.size), col], np.nan)
    psi_g = output_direction * wrap_angle(phi_g - phi01)
    err = wrap_angle(ps - psi_g)
    assembles = ~np.isnan(phi_g)
    rmse = float(np.sqrt(np.mean(err[assembles] ** 2))) if assembles.any() else math.nan
    return OverlayResult(dims, th01, phi01, circle.circle_residual, psi_g, ps, rmse, assembles)

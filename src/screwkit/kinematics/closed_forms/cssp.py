"""Exact closed-form kinematics of the spatial CSSP slider crank (Rahman 1996; reference SPEC §1.2).

Mechanism: crank (link 1) on a cylindrical joint about z1, connecting rod (link 2) with a ball at
each end, slider (link 3) on a prismatic joint along k4, frame (link 4). Frame {1} is fixed: z1
is the crank axis, x1 the common normal from z1 to the slider axis, origin at its foot on z1.

* crank pin      D1 = (a1 cos θ1, a1 sin θ1, s1)                        (Rahman eq. 2.44)
* slider axis    k4 = (0, sin α4, cos α4)
* slider ball    P  = −a4 i1 − s4 k4 = (−a4, −s4 sin α4, −s4 cos α4)      (Rahman eq. 2.66)
* rod direction  u  = (P − D1)/a2, |u| = 1

|P − D1| = a2 gives s4² + 2 b s4 + c = 0 with b = a1 sθ1 sα4 + s1 cα4 and
c = a4² + 2 a1 a4 cθ1 + a1² + s1² − a2². Its two roots s4 = −b ± √(b² − c) are the two assembly
modes; ``root=+1`` (s4 = −b + √(b² − c)) is the branch of Rahman's program. Velocities and
accelerations follow by differentiating the quadratic exactly (no least squares; compare SPEC
§1.3–1.4, which describes the over-determined least-squares loop closure of the seed program and
why it never closes). The rod is a two-ball link: its spin about u is a passive freedom, taken as
zero, so ω_rod = u × u̇ and α_rod = u × ü.

Units: SI and radians inside (lengths in m, angles in rad, time in s).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import elevation_azimuth, wrap_angle
from screwkit.errors import InputError
from screwkit.messages import given, listing, shown, shown_range

Array = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
AnyArray = NDArray[Any]  # real, or complex for complex-step differentiation

RootSign = Literal[1, -1]

#: the root of Rahman's FORTRAN program: s4 = −b + √(b² − c) (SPEC §1.2); mode 0 of solve_motion
SEED_ROOT: RootSign = 1

class CSSPAssemblyError(InputError):
    """The CSSP does not assemble (b² < c) or sits on a branch point (b² = c) at some inputs."""

    def __init__(self, message: str, assembles: BoolArray) -> None:
        super().__init__(message)
        self.assembles = assembles


@dataclass(frozen=True)
class CSSPDimensions:
    """Hartenberg–Denavit dimensions of a CSSP slider crank (Rahman 1996, §2.1; SPEC §1).

    a1:     crank length (crank axis z1 to crank-pin ball centre), m, > 0
    a2:     rod length between the two ball centres, m, > 0
    a4:     offset: length of the common normal from the crank axis to the slider axis, m
    alpha4: twist of the slider axis, rad: k4 = (0, sin α4, cos α4) in {1}
            (α4 = 270° is the planar slider crank, Rahman's example uses 250°)
    s1:     crank-pin offset along z1, m (a constant; ``cssp_motion`` also accepts a prescribed
            s1(t) for a driven cylindrical joint)
    """

    a1: float
    a2: float
    a4: float
    alpha4: float
    s1: float = 0.0

    def __post_init__(self) -> None:
        for name in ("a1", "a2", "a4", "alpha4", "s1"):
            value = getattr(self, name)
            if not isinstance(value, int | float | np.floating | np.integer) or not np.isfinite(
                value
            ):
                raise InputError(
                    f"CSSPDimensions.{name} must be a finite real number, got {given(value)}"
                )
            object.__setattr__(self, name, float(value))
        for name in ("a1", "a2"):
            if getattr(self, name) <= 0.0:
                raise InputError(
                    f"CSSPDimensions.{name} must be > 0 (a length in m), got {getattr(self, name)!r}"
                )

    @property
    def slider_axis(self) -> Array:
        """k4 in frame {1}: (0, sin α4, cos α4)."""
        return np.array([0.0, np.sin(self.alpha4), np.cos(self.alpha4)])


# --------------------------------------------------------------------------------------------
# closed form core (plain arithmetic and sqrt only, so it also runs on complex input; the tests
# differentiate it by complex step)
# --------------------------------------------------------------------------------------------
def _quadratic_coefficients(
    dims: CSSPDimensions, theta1: AnyArray, s1: AnyArray
) -> tuple[AnyArray, AnyArray]:
    """b, c of s4² + 2 b s4 + c = 0 (SPEC §1.2)."""
    sa, ca = np.sin(dims.alpha4), np.cos(dims.alpha4)
    b = dims.a1 * np.sin(theta1) * sa + s1 * ca
    c = dims.a4**2 + 2 * dims.a1 * dims.a4 * np.cos(theta1) + dims.a1**2 + s1**2 - dims.a2**2
    return b, c


def slider_and_rod(
    dims: CSSPDimensions,
    theta1: AnyArray,
    theta1_dot: AnyArray,
    theta1_ddot: AnyArray,
    s1: AnyArray,
    s1_dot: AnyArray,
    s1_ddot: AnyArray,
    root: int,
    disc_sqrt: Array | None = None,
) -> dict[str, AnyArray]:
    """s4 and rod direction u with their first two time derivatives (SPEC §1.2).

    With F(s4, t) = s4² + 2 b s4 + c = 0 and s4 + b = ±√(b² − c):
        ṡ4 = −(ḃ s4 + ċ/2)/(s4 + b),   s̈4 = −(ṡ4² + 2 ḃ ṡ4 + b̈ s4 + c̈/2)/(s4 + b).
    """
    a1, a2, a4 = dims.a1, dims.a2, dims.a4
    sa, ca = np.sin(dims.alpha4), np.cos(dims.alpha4)
    st, ct = np.sin(theta1), np.cos(theta1)
    b, c = _quadratic_coefficients(dims, theta1, s1)
    radical = root * (np.sqrt(b * b - c) if disc_sqrt is None else disc_sqrt)  # = s4 + b
    # −b + root cancels when root·b > 0; there use the product of the roots, s4·s4' = c
    other = -b - radical
    cancels = (root * np.real(b) > 0) & (np.real(other) != 0)
    s4 = np.where(cancels, c / np.where(cancels, other, 1.0), radical - b)

    w, wd = theta1_dot, theta1_ddot
    b_dot = a1 * ct * w * sa + s1_dot * ca
    b_ddot = a1 * sa * (ct * wd - st * w**2) + s1_ddot * ca
    c_dot = -2 * a1 * a4 * st * w + 2 * s1 * s1_dot
    c_ddot = -2 * a1 * a4 * (ct * w**2 + st * wd) + 2 * (s1_dot**2 + s1 * s1_ddot)
    s4_dot = -(b_dot * s4 + c_dot / 2) / radical
    s4_ddot = -(s4_dot**2 + 2 * b_dot * s4_dot + b_ddot * s4 + c_ddot / 2) / radical

    pin = np.stack([a1 * ct, a1 * st, s1], axis=-1)
    pin_dot = np.stack([-a1 * st * w, a1 * ct * w, s1_dot], axis=-1)
    pin_ddot = np.stack(
        [-a1 * (ct * w**2 + st * wd), a1 * (-st * w**2 + ct * wd), s1_ddot], axis=-1
    )
    k4 = np.array([0.0, sa, ca])
    ball = np.stack([np.full_like(s4, -a4), -s4 * sa, -s4 * ca], axis=-1)
    ball_dot = -s4_dot[..., None] * k4
    ball_ddot = -s4_ddot[..., None] * k4
    return {
        "s4": s4,
        "s4_dot": s4_dot,
        "s4_ddot": s4_ddot,
        "crank_pin": pin,
        "crank_pin_velocity": pin_dot,
        "crank_pin_acceleration": pin_ddot,
        "slider_ball": ball,
        "slider_ball_velocity": ball_dot,
        "slider_ball_acceleration": ball_ddot,
        "rod_direction": (ball - pin) / a2,
        "rod_direction_dot": (ball_dot - pin_dot) / a2,
        "rod_direction_ddot": (ball_ddot - pin_ddot) / a2,
    }


# --------------------------------------------------------------------------------------------
# assembly range
# --------------------------------------------------------------------------------------------
def assembly_discriminant(
    dims: CSSPDimensions, theta1: ArrayLike, s1: ArrayLike | None = None
) -> Array:
    """b² − c of the s4 quadratic (SPEC §1.2): the CSSP assembles where it is ≥ 0."""
    th = np.asarray(theta1, dtype=float)
    s1_arr = np.full_like(th, dims.s1) if s1 is None else np.asarray(s1, dtype=float)
    b, c = _quadratic_coefficients(dims, th, s1_arr)
    return np.asarray(b * b - c, dtype=float)


def assembly_intervals(dims: CSSPDimensions) -> list[tuple[float, float]]:
    """Crank-angle intervals [start, end] (rad, start in [0, 2π), end ≥ start, possibly past 2π)
    on which the CSSP with constant s1 assembles, i.e. b(θ1)² − c(θ1) ≥ 0.

    With t = tan(θ1/2), (1 + t²)²·(b² − c) is the quartic
    (C − D) t⁴ + 2B t³ + (4A + 2C) t² + 2B t + (C + D) with A = a1² sin²α4,
    B = 2 a1 s1 sin α4 cos α4, C = s1² cos²α4 − (a4² + a1² + s1² − a2²), D = −2 a1 a4; its real
    roots (polished by Newton steps on θ1) bound the intervals. ``[(0, 2π)]`` means a full
    rotation (a crank); ``[]`` means the CSSP never assembles.
    """
    sa, ca = np.sin(dims.alpha4), np.cos(dims.alpha4)
    a1, a4, s1 = dims.a1, dims.a4, dims.s1
    coef_a = a1**2 * sa**2
    coef_b = 2 * a1 * s1 * sa * ca
    coef_c = s1**2 * ca**2 - (a4**2 + a1**2 + s1**2 - dims.a2**2)
    coef_d = -2 * a1 * a4

    def disc(th: Array) -> Array:
        s, c = np.sin(th), np.cos(th)
        return np.asarray(coef_a * s * s + coef_b * s + coef_c + coef_d * c)

    def disc_dot(th: Array) -> Array:
        s, c = np.sin(th), np.cos(th)
        return np.asarray(2 * coef_a * s * c + coef_b * c - coef_d * s)

    quartic = [coef_c - coef_d, 2 * coef_b, 4 * coef_a + 2 * coef_c, 2 * coef_b, coef_c + coef_d]
    scale = max(abs(q) for q in quartic)
    roots: list[float] = []
    if scale > 0.0:
        poly = np.array(quartic) / scale
        nz = np.flatnonzero(np.abs(poly) > 1e-14)
        poly = poly[nz[0] :] if nz.size else poly
        for r in np.roots(poly) if poly.size > 1 else []:
            if abs(r.imag) <= 1e-7 * max(1.0, abs(r)):
                roots.append(2 * np.arctan(r.real))
        if abs(quartic[0]) <= 1e-12 * scale:  # degree drop: θ1 = π is a root (t = ∞)
            roots.append(np.pi)
    th = np.mod(np.array(roots, dtype=float), 2 * np.pi)
    for _ in range(3):  # Newton polish on b² − c (roots of the quartic lose digits near t = ∞)
        slope = disc_dot(th)
        step = np.where(np.abs(slope) > 1e-300, disc(th) / np.where(slope == 0, 1.0, slope), 0.0)
        th = th - np.clip(step, -1e-3, 1e-3)
    th = np.unique(np.round(np.mod(th, 2 * np.pi), 13))
    if th.size == 0:
        return [(0.0, 2 * np.pi)] if disc(np.array(0.0)) >= 0.0 else []
    ends = np.append(th[1:], th[0] + 2 * np.pi)
    inside = disc(0.5 * (th + ends)) >= 0.0
    intervals: list[tuple[float, float]] = []
    for start, end, ok in zip(th, ends, inside, strict=True):
        if not ok:
            continue
        if intervals and abs(intervals[-1][1] - start) < 1e-12:
            intervals[-1] = (intervals[-1][0], float(end))  # tangency root: merge
        else:
            intervals.append((float(start), float(end)))
    if len(intervals) > 1 and abs(intervals[-1][1] - 2 * np.pi - intervals[0][0]) < 1e-12:
        intervals[0] = (intervals[-1][0], intervals[0][1] + 2 * np.pi)
        intervals.pop()
    if len(intervals) == 1 and intervals[0][1] - intervals[0][0] >= 2 * np.pi - 1e-12:
        return [(0.0, 2 * np.pi)]
    return intervals


def _runs(mask: BoolArray) -> list[tuple[int, int]]:
    """Index ranges [i, j] of consecutive True entries."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    stops = np.concatenate([idx[breaks], [idx[-1]]])
    return list(zip(starts.tolist(), stops.tolist(), strict=True))


def assembly_message(dims: CSSPDimensions, theta1: ArrayLike, assembles: ArrayLike) -> str:
    """Human-readable report of the crank angles at which the CSSP does not assemble, e.g.
    "CSSP does not assemble for θ1 in [100°, 150°] (6 of 36 samples); it assembles for θ1 in
    [−20.12°, 80.33°] (mod 360°)." The assembling range is exact for constant s1
    (``assembly_intervals``)."""
    th = np.atleast_1d(np.asarray(theta1, dtype=float))
    ok = np.atleast_1d(np.asarray(assembles, dtype=bool))
    bad = ~ok
    parts = [
        shown_range(th[i], th[j], "angle") if i != j else shown(th[i], "angle")
        for i, j in _runs(bad)
    ]
    head = (
        f"CSSP (a1={shown(dims.a1, 'length')}, a2={shown(dims.a2, 'length')}, "
        f"a4={shown(dims.a4, 'length')}, alpha4={shown(dims.alpha4, 'angle')}, "
        f"s1={shown(dims.s1, 'length')}) "
    )
    if not parts:
        return head + "assembles at every requested crank angle."
    msg = (
        head + f"does not assemble for θ1 in {', '.join(parts)} "
        f"({int(bad.sum())} of {th.size} samples)"
    )
    intervals = assembly_intervals(dims)
    if not intervals:
        return (
            msg + "; it assembles for no crank angle: the rod a2 is too short or too long "
            "for a1, a4, s1 (need |P − D1| = a2 to have a solution)."
        )
    ranges = ", ".join(shown_range(s, e, "angle") for s, e in intervals)
    return msg + f"; it assembles for θ1 in {ranges} (mod one turn)."


# --------------------------------------------------------------------------------------------
# results
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class CSSPPositions:
    """Positions of a CSSP over N crank angles (first axis = sample), SI units, frame {1}.

    Samples where ``assembles`` is False hold NaN in every slider/rod quantity (only returned
    when the caller asked for partial results). Rahman's rod angles: u = (cη2 c(θ1+θ2),
    cη2 s(θ1+θ2), −sη2) with cη2 ≥ 0 (SPEC §1.2). Slider-side angles (θ3, η3): the rod
    direction in the slider frame {4} (k4 = z4) is (cθ3 cη3, cθ3 sη3, sθ3), the first row of
    Rahman's L3 = Z(θ3)Y(η3)X(π/2), taken with cθ3 ≥ 0. (Rahman's two-angle joint 3 cannot also
    close the rotation loop, SPEC §1.2; these are only the rod-direction angles.) Where the rod is
    parallel to z1 (resp. k4) the azimuth θ2 (resp. η3) and all rates of that angle pair are
    undefined: ``rod_angles_defined`` (resp. ``slider_angles_defined``) is False and they are NaN.
    """

    dims: CSSPDimensions
    root: int
    theta1: Array
    s1: Array
    assembles: BoolArray
    s4: Array
    crank_pin: Array
    slider_ball: Array
    rod_direction: Array
    theta2: Array
    eta2: Array
    rod_angles_defined: BoolArray
    theta3: Array
    eta3: Array
    slider_angles_defined: BoolArray
    rod_frame: Array = field(repr=False)

    @property
    def loop_closure_gap(self) -> Array:
        """Translational loop-closure gap (N,), m: |D1 + a2 û − P| = ||P − D1| − a2| with û the
        unit vector from the crank pin to the slider ball — zero to round-off for the closed
        form (the seed program leaves up to 2.1 in, SPEC §1.3)."""
        span = np.linalg.norm(self.slider_ball - self.crank_pin, axis=-1)
        return np.asarray(np.abs(span - self.dims.a2))


@dataclass(frozen=True, eq=False)
class CSSPMotion(CSSPPositions):
    """Positions, velocities and accelerations of a CSSP over N crank angles (SI, frame {1}).

    Rod angular velocity/acceleration assume zero spin of the rod about its own axis
    (ω = u × u̇, α = u × ü; the spin is a passive freedom of the two-ball rod, SPEC §1.2).
    """

    theta1_dot: Array
    theta1_ddot: Array
    s1_dot: Array
    s1_ddot: Array
    s4_dot: Array
    s4_ddot: Array
    theta2_dot: Array
    theta2_ddot: Array
    eta2_dot: Array
    eta2_ddot: Array
    theta3_dot: Array
    theta3_ddot: Array
    eta3_dot: Array
    eta3_ddot: Array
    rod_direction_dot: Array
    rod_direction_ddot: Array
    rod_angular_velocity: Array
    rod_angular_acceleration: Array
    crank_pin_velocity: Array
    crank_pin_acceleration: Array
    slider_ball_velocity: Array
    slider_ball_acceleration: Array


# --------------------------------------------------------------------------------------------
# public solvers
# --------------------------------------------------------------------------------------------
def as_sample_array(value: ArrayLike | None, n: int, name: str, default: float) -> Array:
    """A per-sample input (``default`` if None, a scalar, or shape (n,)) as a finite (n,) array;
    a ValueError names ``name`` and the offending shape or samples."""
    arr = np.asarray(default if value is None else value, dtype=float)
    if arr.ndim > 1:
        raise InputError(
            f"{name} must be a scalar or a 1-D array over the samples, got {arr.shape}"
        )
    try:
        out = np.broadcast_to(arr, (n,)).astype(float)
    except ValueError as exc:
        raise InputError(f"{name} has {arr.shape[0]} entries but theta1 has {n}") from exc
    if not np.all(np.isfinite(out)):
        raise InputError(
            f"{name} must be finite (got NaN/inf at samples "
            f"{listing(np.flatnonzero(~np.isfinite(out))[:12].tolist())}, counted from 0)"
        )
    return out


def check_root(root: int) -> int:
    """The root sign of the quadratic in s4 as an int: +1 (s4 = -b + sqrt(b^2 - c), Rahman's
    branch) or -1 — a sign, not a mode index (docs/conventions.md); else InputError."""
    if isinstance(root, bool) or root not in (1, -1):
        raise InputError(
            f"root must be +1 (s4 = -b + sqrt(b^2 - c), Rahman's branch) or -1 (the other root); "
            f"got {root!r} (solve_motion numbers the modes 0, 1: mode 0 is root +1)"
        )
    return int(root)


def rod_and_slider_angles(
    dims: CSSPDimensions,
    th: Array,
    w: Array,
    wd: Array,
    u: Array,
    ud: Array,
    udd: Array,
    assembles: BoolArray,
    need_rates: bool,
    frame: bool = True,
) -> dict[str, object]:
    """Rahman's joint angles from the rod direction u (SPEC §1.1, L2): θ2 = azimuth of u − θ1 and
    η2 = −elevation of u (rod), θ3, η3 the azimuth and elevation of u seen in the slider frame
    {4} = X(α4), with their rates when ``need_rates``, and (with ``frame``) the rod frame {3} =
    Z(θ1 + θ2) Y(η2)."""
    rod_ok, elev, e_d, e_dd, phi, phi_d, phi_dd = elevation_azimuth(u, ud, udd)
    ca, sa = float(np.cos(dims.alpha4)), float(np.sin(dims.alpha4))  # X(α4) = R_{4←1}, by rows:
    slider_ok, th3, th3_d, th3_dd, eta3, eta3_d, eta3_dd = elevation_azimuth(*(np.stack(
        [v[..., 0], ca * v[..., 1] - sa * v[..., 2], sa * v[..., 1] + ca * v[..., 2]], -1)
        for v in (u, ud, udd)))
    rod_ok &= assembles
    slider_ok &= assembles
    rod_frame = None
    if frame:  # Rahman's rod frame {3}: R_{1←3} = Z(θ1 + θ2) Y(η2), x3 = u (SPEC §1.1, L2)
        phi_frame = np.where(rod_ok, phi, 0.0)
        y3 = np.stack([-np.sin(phi_frame), np.cos(phi_frame), np.zeros(th.shape[0])], axis=-1)
        rod_frame = np.stack([u, y3, np.cross(u, y3)], axis=-1)
    out: dict[str, object] = {
        "theta2": np.where(rod_ok, wrap_angle(phi - th), np.nan),
        "eta2": -elev,
        "rod_angles_defined": rod_ok,
        "theta3": th3,
        "eta3": eta3,
        "slider_angles_defined": slider_ok,
        "rod_frame": rod_frame,
    }
    if need_rates:
        out.update(
            theta2_dot=phi_d - w,
            theta2_ddot=phi_dd - wd,
            eta2_dot=-e_d,
            eta2_ddot=-e_dd,
            theta3_dot=th3_d,
            theta3_ddot=th3_dd,
            eta3_dot=eta3_d,
            eta3_ddot=eta3_dd,
        )
    return out


def _solve(
    dims: CSSPDimensions,
    theta1: ArrayLike,
    theta1_dot: ArrayLike | None,
    theta1_ddot: ArrayLike | None,
    s1: ArrayLike | None,
    s1_dot: ArrayLike | None,
    s1_ddot: ArrayLike | None,
    root: int,
    allow_partial: bool,
    need_rates: bool,
) -> dict[str, object]:
    root = check_root(root)
    th = np.atleast_1d(np.asarray(theta1, dtype=float))
    if th.ndim != 1:
        raise InputError(f"theta1 must be a scalar or a 1-D array (N,), got shape {th.shape}")
    n = th.shape[0]
    th = as_sample_array(th, n, "theta1", 0.0)
    w = as_sample_array(theta1_dot, n, "theta1_dot", 0.0)
    wd = as_sample_array(theta1_ddot, n, "theta1_ddot", 0.0)
    s1_arr = as_sample_array(s1, n, "s1", dims.s1)
    s1d = as_sample_array(s1_dot, n, "s1_dot", 0.0)
    s1dd = as_sample_array(s1_ddot, n, "s1_ddot", 0.0)

    b, c = _quadratic_coefficients(dims, th, s1_arr)
    disc = b * b - c
    assembles = disc >= 0.0
    if need_rates:
        # b² = c is a branch point of the two modes: s4 + b = 0 and the rates are unbounded
        assembles = disc > 0.0
    if not np.all(assembles) and not allow_partial:
        msg = assembly_message(dims, th, assembles)
        if need_rates and np.any(disc == 0.0):
            msg += (
                " (b² = c exactly at some samples: a branch point where the rates are unbounded.)"
            )
        raise CSSPAssemblyError(
            msg + " Pass allow_partial=True to get NaN there instead.", assembles
        )
    disc_sqrt = np.sqrt(np.where(assembles, disc, 1.0))  # placeholder 1 where masked below
    with np.errstate(divide="ignore", invalid="ignore"):  # rates at b² = c, unused for positions
        core = slider_and_rod(dims, th, w, wd, s1_arr, s1d, s1dd, root, disc_sqrt=disc_sqrt)
    for key, value in core.items():
        if key.startswith("crank_pin"):
            continue
        mask = assembles if value.ndim == 1 else assembles[:, None]
        core[key] = np.where(mask, value, np.nan)

    u, ud, udd = core["rod_direction"], core["rod_direction_dot"], core["rod_direction_ddot"]
    out: dict[str, object] = {
        "dims": dims,
        "root": root,
        "theta1": th,
        "s1": s1_arr,
        "assembles": assembles,
        "s4": core["s4"],
        "crank_pin": core["crank_pin"],
        "slider_ball": core["slider_ball"],
        "rod_direction": u,
        **rod_and_slider_angles(dims, th, w, wd, u, ud, udd, assembles, need_rates),
    }
    if need_rates:
        out.update(
            theta1_dot=w,
            theta1_ddot=wd,
            s1_dot=s1d,
            s1_ddot=s1dd,
            s4_dot=core["s4_dot"],
            s4_ddot=core["s4_ddot"],
            rod_direction_dot=ud,
            rod_direction_ddot=udd,
            rod_angular_velocity=np.cross(u, ud),
            rod_angular_acceleration=np.cross(u, udd),
            crank_pin_velocity=core["crank_pin_velocity"],
            crank_pin_acceleration=core["crank_pin_acceleration"],
            slider_ball_velocity=core["slider_ball_velocity"],
            slider_ball_acceleration=core["slider_ball_acceleration"],
        )
    return out


def cssp_positions(
    dims: CSSPDimensions,
    theta1: ArrayLike,
    root: int = SEED_ROOT,
    *,
    s1: ArrayLike | None = None,
    allow_partial: bool = False,
) -> CSSPPositions:
    """Exact positions of the CSSP at crank angles ``theta1`` (N,) rad (SPEC §1.2).

    ``root=+1``: s4 = −b + √(b² − c), the branch of Rahman's program; ``root=-1``: the other root.
    Each mode is a continuous branch wherever b² > c. ``s1`` (scalar or (N,)) overrides
    ``dims.s1`` for a driven cylindrical joint. Inputs where the CSSP does not assemble raise
    ``CSSPAssemblyError`` (with ``assembly_message``) unless ``allow_partial=True``, which returns
    NaN there and the mask ``assembles``.
    """
    out = _solve(dims, theta1, None, None, s1, None, None, root, allow_partial, need_rates=False)
    return CSSPPositions(**out)  # type: ignore[arg-type]


def cssp_motion(
    dims: CSSPDimensions,
    theta1: ArrayLike,
    theta1_dot: ArrayLike = 0.0,
    theta1_ddot: ArrayLike = 0.0,
    root: int = SEED_ROOT,
    *,
    s1: ArrayLike | None = None,
    s1_dot: ArrayLike = 0.0,
    s1_ddot: ArrayLike = 0.0,
    allow_partial: bool = False,
) -> CSSPMotion:
    """Exact positions, velocities and accelerations of the CSSP (SPEC §1.2), vectorised over N
    crank angles. θ̇1, θ̈1 (rad/s, rad/s²) and the optional second input s1, ṡ1, s̈1 (m, m/s,
    m/s²) are scalars or (N,) arrays.

    Slider: ṡ4 = −(ḃ s4 + ċ/2)/(s4 + b), s̈4 = −(ṡ4² + 2ḃṡ4 + b̈ s4 + c̈/2)/(s4 + b) with
    ḃ = a1 cθ1 sα4 θ̇1 + ṡ1 cα4, ċ = −2 a1 a4 sθ1 θ̇1 + 2 s1 ṡ1 (and their derivatives).
    Rod: u̇ = (Ṗ − Ḋ1)/a2, ü likewise; ω_rod = u × u̇, α_rod = u × ü (zero axial spin).
    Angles: rates of η2, θ2, θ3, η3 from the exact derivatives of atan2/asin of u.
    Branch points (b² = c, where the two modes meet and the rates are unbounded) count as not
    assembling. See ``cssp_positions`` for ``root`` and ``allow_partial``.
    """
    out = _solve(
        dims,
        theta1,
        theta1_dot,
        theta1_ddot,
        s1,
        s1_dot,
        s1_ddot,
        root,
        allow_partial,
        need_rates=True,
    )
    return CSSPMotion(**out)  # type: ignore[arg-type]


__all__ = [
    "SEED_ROOT",
    "RootSign",
    "CSSPAssemblyError",
    "CSSPDimensions",
    "CSSPMotion",
    "CSSPPositions",
    "assembly_discriminant",
    "assembly_intervals",
    "as_sample_array",
    "assembly_message",
    "check_root",
    "cssp_motion",
    "cssp_positions",
    "slider_and_rod",
]

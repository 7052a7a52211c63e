"""Rebuild d3, a, b of Bagci's constrained designs from the parameters of constraint q1, q2.

Bagci 1969, §5.3, eqs. 5.13-5.21, in the form Program C codes them for delta0 = 0 (the only case
the examples use; SPEC §5.3 "Construction of C_i", PROGRAMS.md §4 "Derived dimensions").  The
printed tables were computed from the full-precision d3, a, b this construction gives, while the
text prints them rounded (or, for Example 7, not at all), so reproducing Tables IV-VII and IX-XII
to print precision needs it (tables/REPRODUCTION.md).

This lives in validation/ on purpose: it is synthesis, not kinematics, and will move to
`screwkit.synthesis`.  Angles here are in degrees, as in the seed and its tables.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any


def q_from_dwell(theta0_deg: float, lambda0_deg: float) -> float:
    """Eq. 5.13: q = atan(tan(theta0) / cos(lambda0)), folded into [0, 180) as Program C does.

    The slope of the normal to the projected input-crank ellipse at theta0: imposing it makes the
    input-crank and coupler ellipses tangent, i.e. a rotation limit at theta0 (App. D).
    """
    th = math.radians(theta0_deg)
    q = math.degrees(math.atan2(math.sin(th), math.cos(th) * math.cos(math.radians(lambda0_deg))))
    return q % 180.0


@dataclass(frozen=True)
class RebuiltDimensions:
    """Output of the construction: the output-crank centre and radius, plus what fed it."""

    d3: float
    a: float
    b: float
    q1_deg: float
    q2_deg: float
    tau_deg: float


def rebuild_from_constraints(
    *,
    d1: float,
    d2: float,
    lambda0_deg: float,
    theta01_deg: float,
    dtheta12_deg: float,
    dphi12_deg: float,
    q1_deg: float,
    q2_deg: float,
    kd3: int,
) -> RebuiltDimensions:
    """Eqs. 5.14-5.21 (delta0 = 0): output-crank centre (a, b sin lambda0) and radius d3.

    In the plane normal to the output axis (X = global Y, Y = along (sin lambda0, 0, cos lambda0))
    the sphere centre at theta0_i projects to P_i = (d1 cos theta0_i, d1 cos lambda0 sin theta0_i)
    and, for delta0 = 0, the coupler projects with its true length d2 at the slope q_i, so the
    output-crank tip is C_i = P_i + d2 (cos q_i, sin q_i).  The output-crank centre lies on the
    bisector of C1 C2 (slope tau, eq. 5.15, folded into [0, 180)) at the distance
    d3 cos(dphi12/2) from the midpoint, on the side chosen by Program C's flag KD3 (1: +, 2: -),
    with d3 = |C1 C2| / (2 |sin(dphi12/2)|) (eq. 5.21).
    """
    if kd3 not in (1, 2):
        raise ValueError(f"KD3 must be 1 or 2, got {kd3!r}")
    lam = math.radians(lambda0_deg)
    if math.sin(lam) == 0.0:
        raise ValueError("lambda0 = 0 (plane 4R) needs Program C's re-referencing; not supported")
    points = []
    for theta_deg, q_deg in ((theta01_deg, q1_deg), (theta01_deg + dtheta12_deg, q2_deg)):
        th, q = math.radians(theta_deg), math.radians(q_deg)
        points.append((d1 * math.cos(th) + d2 * math.cos(q),
                       d1 * math.cos(lam) * math.sin(th) + d2 * math.sin(q)))
    (x1, y1), (x2, y2) = points
    tau = math.atan((x1 - x2) / (y2 - y1)) if y2 != y1 else math.pi / 2.0
    tau %= math.pi
    half = math.radians(dphi12_deg) / 2.0
    d3 = math.hypot(x1 - x2, y2 - y1) / (2.0 * abs(math.sin(half)))
    side = 1.0 if kd3 == 1 else -1.0
    offset = side * d3 * math.cos(half)
    a = 0.5 * (x1 + x2) + offset * math.cos(tau)
    b_sin_lambda = 0.5 * (y1 + y2) + offset * math.sin(tau)
    return RebuiltDimensions(d3, a, b_sin_lambda / math.sin(lam), q1_deg, q2_deg,
                             math.degrees(tau))


def rebuild_from_table_json(table: dict[str, Any]) -> RebuiltDimensions:
    """The construction with the inputs a table's JSON records under ``q_reconstruction``.

    q1/q2 are the printed values when the JSON gives them (``q1_deg``/``q2_deg``), otherwise
    eq. 5.13 at theta01 (q1) or at theta01 + dtheta12 (q2).  d2 is ``d2_used`` when given (Table V
    was computed with d2 = 3.7600, not the printed 3.7602).
    """
    mech = table["mechanism_stated"]
    rec = table["q_reconstruction"]
    lam = float(mech["lambda0_deg"])
    theta01 = float(mech["theta01_deg"])
    dtheta = float(rec["dtheta12_deg"])
    q1 = float(rec["q1_deg"]) if "q1_deg" in rec else q_from_dwell(theta01, lam)
    q2 = float(rec["q2_deg"]) if "q2_deg" in rec else q_from_dwell(theta01 + dtheta, lam)
    return rebuild_from_constraints(
        d1=float(mech["d1"]),
        d2=float(rec.get("d2_used", mech["d2"])),
        lambda0_deg=lam,
        theta01_deg=theta01,
        dtheta12_deg=dtheta,
        dphi12_deg=float(rec["dphi12_deg"]),
        q1_deg=q1,
        q2_deg=q2,
        kd3=int(rec["KD3"]),
    )

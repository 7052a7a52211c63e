"""Rebuild d3, a, b of Bagci's constrained designs from the parameters of constraint q1, q2.

Bagci 1969, §5.3, eqs. 5.13-5.21 (delta0 = 0, the only case the examples use).  The printed
tables were computed from the full-precision d3, a, b this construction gives, while the text
prints them rounded (or, for Example 7, not at all), so reproducing Tables IV-VII and IX-XII to
print precision needs it (tables/REPRODUCTION.md).

The construction itself lives in `screwkit.synthesis.constraints` (`q_from_dwell`,
`output_crank_from_constraints`); this module only adapts it to the seed's degrees and to the
tables' JSON.  Program C's side flag KD3 (with its bisector slope tau folded into [0, 180)) is
not needed: the signed output rotation dphi12 between the two points picks the side, and with the
dphi12 each table records it gives Program C's centre for every table (KD3 is kept in the JSON
as the seed's record).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from screwkit.synthesis.constraints import output_crank_from_constraints
from screwkit.synthesis.constraints import q_from_dwell as _q_from_dwell


def q_from_dwell(theta0_deg: float, lambda0_deg: float) -> float:
    """Eq. 5.13 in degrees, folded into [0, 180) as Program C does."""
    return math.degrees(float(_q_from_dwell(math.radians(theta0_deg),
                                            math.radians(lambda0_deg))))


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
) -> RebuiltDimensions:
    """Eqs. 5.14-5.21 (delta0 = 0): output-crank centre (a, b sin lambda0) and radius d3.

    ``dphi12_deg`` is the signed output rotation from the first to the second point
    (counter-clockwise positive in the plane normal to the output axis).
    """
    lam = math.radians(lambda0_deg)
    if math.sin(lam) == 0.0:
        raise ValueError("lambda0 = 0 (plane 4R) needs Program C's re-referencing; not supported")
    th1 = math.radians(theta01_deg)
    crank = output_crank_from_constraints(
        d1, d2, lam, th1, th1 + math.radians(dtheta12_deg), math.radians(q1_deg),
        math.radians(q2_deg), math.radians(dphi12_deg))
    (x1, y1), (x2, y2) = crank.tip1, crank.tip2
    tau = math.atan((x1 - x2) / (y2 - y1)) if y2 != y1 else math.pi / 2.0
    return RebuiltDimensions(float(crank.d3), float(crank.centre_x),
                             float(crank.centre_y) / math.sin(lam), q1_deg, q2_deg,
                             math.degrees(tau % math.pi))


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
    )

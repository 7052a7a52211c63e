"""Generic single-loop solver: an RSSR over one cycle of 360 steps, every assembly mode
(issue: report the time). Also the closed-form/generic ratio on the Bagci Fig. 7/8 RSRC."""

from __future__ import annotations

import time

import numpy as np

from analysis_helpers import analyze
from screwkit.kinematics.generic_motion import generic_motion as motion
from screwkit.model.families import rsrc, rssr


def _best(fn, repeats: int = 3) -> float:
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def run() -> list[dict]:
    lk = rssr(0.025, 0.1, 0.075, 0.075, 0.05, np.radians(50), 0.0125)
    theta = np.radians(np.arange(0.0, 360.0, 1.0))
    modes = len(motion(lk, theta).modes)
    t_rssr = _best(lambda: motion(lk, theta), 2)
    fig7 = rsrc(0.0508, 0.1143, 0.0762, 0.0762, 0.0762, 0.0254, np.radians(18), np.radians(60))
    t_closed = _best(lambda: analyze(fig7, theta, method="closed"))
    t_generic = _best(lambda: analyze(fig7, theta, method="generic"), 2)
    return [
        {"name": "generic solver, RSSR, 360 steps, all modes", "value": t_rssr, "unit": "s",
         "target": "report", "note": f"{modes} modes; positions, velocities, accelerations"},
        {"name": "RSRC analysis 360 steps: closed form", "value": t_closed, "unit": "s",
         "target": "report", "note": "quartic + continuous branches + rates"},
        {"name": "RSRC analysis 360 steps: generic solver", "value": t_generic, "unit": "s",
         "target": "report", "note": f"{t_generic / t_closed:.0f}× the closed form"},
    ]

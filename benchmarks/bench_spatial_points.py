"""Every assembly mode of spatial R/S/U graphs by the point formulation (issue 27;
kinematics/modes/spatial_points.py), side by side with the second method each is tested
against:

- the five-link suspension (examples/mechanisms/five_link_suspension.toml; its upright a
  platform on six rods, generic count 40): the start set's first solve (monodromy, in memory
  only: ``SCREWKIT_CACHE_DIR=off``); every mode at one rocker angle (the parameter homotopy's
  40 paths), against the Stewart–Gough elimination template on the same six rods
  (modes/stewart_solve.py); and every mode along the spec's 49 samples (homotopy at anchors,
  tracking between) against the drawn mode followed alone;
- the double wishbone (generic count 4) at the spec's 41 samples: every mode by the point
  homotopy against the closed-form dyads;
- the 3-RPS robot (examples/mechanisms/three_rps.toml, generic count 16): the start set, the
  count check on it (the trace test, algebraic/trace_test.py) against the start set's own
  solve, every mode at one input, and every mode along its 37 samples against the drawn mode
  alone;
- the 3-UPU (examples/mechanisms/three_upu.toml, 84 by monodromy): the start set and every
  mode at one input;
- the Stewart platform driven by its pose (examples/mechanisms/stewart_platform_pose.toml:
  three driven translations and three driven turns of the platform, its legs struts of free
  length): every mode along its rows against the drawn mode alone.

Times are CPU seconds (process time, best of 3), OPENBLAS_NUM_THREADS=1.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ["SCREWKIT_CACHE_DIR"] = "off"

import numpy as np  # noqa: E402

import screwkit as sk  # noqa: E402
from screwkit.algebraic.trace_test import trace_test  # noqa: E402
from screwkit.kinematics.graph import solve_mechanism  # noqa: E402
from screwkit.kinematics.modes.every_mode import every_mode  # noqa: E402
from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation  # noqa: E402
from screwkit.kinematics.modes.stewart import stewart_parameters  # noqa: E402
from screwkit.kinematics.modes.stewart_solve import solve_stewart  # noqa: E402

MECHANISMS = Path(__file__).resolve().parents[1] / "examples" / "mechanisms"


def _best(f: Any, repeats: int = 3) -> float:
    out = []
    for _ in range(repeats):
        t = time.process_time()
        f()
        out.append(time.process_time() - t)
    return min(out)


def _stewart_of_five_link(mech: Any, theta: float) -> np.ndarray:
    """The Stewart parameters of the upright on its six rods at rocker angle theta."""
    rods = [("pushrod_top", "pushrod_foot")] + [(f"{n}_in", f"{n}_out") for n in (
        "upper_front", "upper_rear", "lower_front", "lower_rear", "toe_link")]
    inner = np.array([mech.joint(a).at for a, _ in rods])
    outer = np.array([mech.joint(b).at for _, b in rods])
    pivot = mech.joint("rocker_pivot")
    u, c = pivot.axis, pivot.at
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    R = np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K
    base = inner.copy()
    base[0] = c + R @ (inner[0] - c)
    return stewart_parameters(base, outer, np.linalg.norm(outer - inner, axis=1))[None, :]


def run() -> list[dict[str, Any]]:
    spec = sk.load_spec(MECHANISMS / "five_link_suspension.toml")
    mech = spec.mechanism
    form = spatial_point_formulation(mech)
    t = time.process_time()
    start = form.start()
    t_start = time.process_time() - t
    every_mode(mech, [[0.0]])  # warm up (compiled kernels)
    t_one = _best(lambda: every_mode(mech, [[0.1]]))
    p = _stewart_of_five_link(mech, 0.1)
    solve_stewart(p)
    t_st = _best(lambda: solve_stewart(p))
    x = np.asarray(spec.inputs, dtype=float)
    t_all = _best(lambda: solve_mechanism(mech, x, every_mode=True), 1)
    t_drawn = _best(lambda: solve_mechanism(mech, x))
    modes = len(solve_mechanism(mech, x, every_mode=True).modes)
    wb = sk.load_spec(MECHANISMS / "double_wishbone.toml")
    xw = np.asarray(wb.inputs, dtype=float)
    every_mode(wb.mechanism, xw[:1, None])
    t_wb = _best(lambda: every_mode(wb.mechanism, xw[:, None]))
    t_wb_closed = _best(lambda: solve_mechanism(wb.mechanism, xw, every_mode=True))
    rps = sk.load_spec(MECHANISMS / "three_rps.toml")
    xr = np.asarray(rps.inputs, dtype=float)
    rps_form = spatial_point_formulation(rps.mechanism)
    t = time.process_time()
    rps_start = rps_form.start()
    t_rps_start = time.process_time() - t
    t = time.process_time()
    rps_check = trace_test(rps_form.system, rps_start.p, rps_start.x)
    t_rps_check = time.process_time() - t
    every_mode(rps.mechanism, xr[:1])
    t_rps_one = _best(lambda: every_mode(rps.mechanism, xr[1:2]))
    t_rps_all = _best(lambda: solve_mechanism(rps.mechanism, xr, every_mode=True), 1)
    t_rps_drawn = _best(lambda: solve_mechanism(rps.mechanism, xr))
    rps_modes = len(solve_mechanism(rps.mechanism, xr, every_mode=True).modes)
    upu = sk.load_spec(MECHANISMS / "three_upu.toml")
    xu = np.asarray(upu.inputs, dtype=float)
    t = time.process_time()
    upu_start = spatial_point_formulation(upu.mechanism).start()
    t_upu_start = time.process_time() - t
    every_mode(upu.mechanism, xu[:1])
    t_upu_one = _best(lambda: every_mode(upu.mechanism, xu[10:11]))
    upu_real = every_mode(upu.mechanism, xu[10:11]).configurations[0].size
    pose = sk.load_spec(MECHANISMS / "stewart_platform_pose.toml")
    xp = np.asarray(pose.inputs, dtype=float)
    solve_mechanism(pose.mechanism, xp, every_mode=True)  # the start set, once
    t_pose_all = _best(lambda: solve_mechanism(pose.mechanism, xp, every_mode=True), 1)
    t_pose_drawn = _best(lambda: solve_mechanism(pose.mechanism, xp))
    pose_modes = len(solve_mechanism(pose.mechanism, xp, every_mode=True).modes)
    return [
        {"name": "five-link suspension: start solutions (first solve of the topology)",
         "value": t_start, "unit": "s", "target": None,
         "note": f"{start.generic_count} solutions, {start.paths} paths tracked "
                 f"({start.how_found[:60]}…)"},
        {"name": "five-link suspension: every mode at one rocker angle, points / Stewart "
                 "template",
         "value": t_one / t_st, "unit": "x", "target": None,
         "note": f"{t_one * 1e3:.3g} ms by the point homotopy (18 unknowns, 40 paths) against "
                 f"{t_st * 1e3:.3g} ms by the Stewart–Gough elimination template on the same "
                 "six rods (the test's second method)"},
        {"name": f"five-link suspension, {x.size} samples: every mode / drawn mode",
         "value": t_all / t_drawn, "unit": "x", "target": None,
         "note": f"{modes} modes in {t_all:.3g} s (homotopy at anchors, tracking between) "
                 f"against {t_drawn * 1e3:.3g} ms for the drawn mode followed"},
        {"name": f"double wishbone, {xw.size} samples: every mode, point homotopy / "
                 "closed-form dyads",
         "value": t_wb / t_wb_closed, "unit": "x", "target": None,
         "note": f"{t_wb * 1e3:.3g} ms (4 paths per sample) against {t_wb_closed * 1e3:.3g} ms "
                 "for the closed forms (with rates and accelerations)"},
        {"name": "3-RPS robot: start solutions, then every mode at one input",
         "value": t_rps_one * 1e3, "unit": "ms", "target": None,
         "note": f"{rps_start.generic_count} solutions (9 unknowns: its R–P–S legs as circles "
                 f"of their balls); the start set {t_rps_start:.3g} s once, {rps_start.paths} "
                 "paths"},
        {"name": "3-RPS robot: count check (trace test) / start set",
         "value": t_rps_check / t_rps_start, "unit": "x", "target": None,
         "note": f"{rps_check.verdict} in {t_rps_check:.3g} s: {rps_check.solutions} solutions "
                 f"and {rps_check.witnesses} slice witnesses, {rps_check.paths} paths, "
                 f"deviation {rps_check.deviation:.1e} within {rps_check.bound:.1e}; the start "
                 f"set {t_rps_start:.3g} s"},
        {"name": f"3-RPS robot, {len(xr)} samples: every mode / drawn mode",
         "value": t_rps_all / t_rps_drawn, "unit": "x", "target": None,
         "note": f"{rps_modes} modes in {t_rps_all:.3g} s (homotopy at anchors, tracking "
                 f"between) against {t_rps_drawn * 1e3:.3g} ms for the drawn mode followed"},
        {"name": "3-UPU: start solutions, then every mode at one input",
         "value": t_upu_one * 1e3, "unit": "ms", "target": None,
         "note": f"{upu_start.generic_count} solutions (18 unknowns: its U–P–U legs as two "
                 f"equations each), {upu_real} real at sample 10; the start set "
                 f"{t_upu_start:.3g} s once, {upu_start.paths} paths"},
        {"name": f"Stewart platform driven by its pose, {len(xp)} rows: every mode / drawn "
                 "mode",
         "value": t_pose_all / t_pose_drawn, "unit": "x", "target": None,
         "note": f"{pose_modes} mode in {t_pose_all:.3g} s (the start set solved before; three "
                 f"driven turns, three more rotations dropped at each anchor) against "
                 f"{t_pose_drawn * 1e3:.3g} ms for the drawn mode followed"},
    ]

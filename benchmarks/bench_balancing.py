"""Speed of screwkit.balancing (issue #6 targets).

* Rahman's example from the spec file to the optimum: spec → kinematics → regressor → load rows
  → QP (+ the non-uniqueness analysis and the nearest-member QP), target ≤ 50 ms. Timed with
  the closed-form CSSP kinematics (``cssp_mode_motion``), with the generic solver (``motion``)
  and without kinematics; the parts are timed separately to say what dominates.
* A 60-variable counterweight QP (fixed-position counterweights, random PSD Hessian of rank 40,
  box bounds and 3 equalities), the QP call alone, target ≤ 5 ms.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "rahman_cssp_balance.toml"


def _best(fn: Any, repeat: int = 7) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return float(best)


def run() -> list[dict[str, Any]]:
    from screwkit.balancing.balance import prepare, solve_setup
    from screwkit.balancing.qp import solve_qp
    from screwkit.io.balancing_table import balancing_table, blocks_from_table
    from screwkit.io.spec import load_spec
    from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion
    from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
    from screwkit.pipeline import balance_from_spec

    out: list[dict[str, Any]] = []
    spec = load_spec(EXAMPLE)

    def closed_form() -> Any:
        s = load_spec(EXAMPLE)
        mode = cssp_mode_motion(s.linkage, s.inputs, s.speed, 0.0)
        return balance_from_spec(s, mode_motion=mode)

    t_all = _best(closed_form)
    out.append({"name": "Rahman spec → optimum (closed-form kinematics)", "value": 1e3 * t_all,
                "unit": "ms", "target": "≤ 50 ms", "note": "36 samples, 8 variables"})
    t_spec = _best(lambda: load_spec(EXAMPLE))
    t_kin = _best(lambda: cssp_mode_motion(spec.linkage, spec.inputs, spec.speed, 0.0))
    mode = cssp_mode_motion(spec.linkage, spec.inputs, spec.speed, 0.0)
    table = balancing_table(spec)
    blocks = blocks_from_table(spec, table)
    t_noki = _best(lambda: balance_from_spec(spec, mode_motion=mode))
    t_prep = _best(lambda: prepare(spec.linkage, mode, blocks, speed=spec.speed))
    setup = prepare(spec.linkage, mode, blocks, speed=spec.speed)
    t_solve = _best(lambda: solve_setup(setup, table.weights))
    out.append({"name": "  without kinematics (regressor + QP + report)", "value": 1e3 * t_noki,
                "unit": "ms", "target": "≤ 50 ms", "note": ""})
    out.append({"name": "  parts: spec / kinematics / regressor+rows / QP+report",
                "value": f"{1e3 * t_spec:.1f} / {1e3 * t_kin:.1f} / {1e3 * t_prep:.1f} / "
                         f"{1e3 * t_solve:.1f}", "unit": "ms", "target": "", "note": ""})
    t_gen = _best(lambda: motion(spec.linkage, spec.inputs, spec.speed, 0.0), repeat=1)
    out.append({"name": "Rahman kinematics with the generic solver (motion)", "value": 1e3 * t_gen,
                "unit": "ms", "target": "", "note": "what balance_from_spec runs without a "
                "closed form; dominates the total"})

    rng = np.random.default_rng(0)
    n = 60
    M = rng.normal(size=(40, n))
    Q = M.T @ M
    q = rng.normal(size=n) * 5
    Ae = np.zeros((3, n))
    for k in range(3):
        Ae[k, 20 * k:20 * (k + 1)] = 1.0
    be = np.full(3, 5.0)
    Al = np.vstack([np.eye(n), -np.eye(n)])
    bl = np.concatenate([np.ones(n), np.zeros(n)])
    t_qp = _best(lambda: solve_qp(Q, q, Ae, be, Al, bl), repeat=20)
    out.append({"name": "60-variable counterweight QP (Clarabel + polish)", "value": 1e3 * t_qp,
                "unit": "ms", "target": "≤ 5 ms", "note": "rank-40 PSD Hessian, 120 bounds, "
                "3 equalities"})
    return out


if __name__ == "__main__":
    for row in run():
        print(row)

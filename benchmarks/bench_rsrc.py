"""RSRC closed form throughput: every inversion's positions, velocities and accelerations.

Bagci's Fig. 7/8 mechanism (general delta0: the quartic path, two real inversions at every input
angle) over 10^6 input angles, with `rsrc_kinematics` (one pass), with `rsrc_motion`
(continuous branches with their rates: issue 12's target, 1 µs an input) and with
`rsrc_positions` alone.  Target: >= 10^6 input angles per second on one core for positions +
rates.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from screwkit.kinematics.closed_forms.rsrc import (
    RSRCDimensions,
    rsrc_kinematics,
    rsrc_motion,
    rsrc_positions,
)

N_INPUTS = 1_000_000
REPEATS = 3

FIG7 = RSRCDimensions(d1=2.0, d2=4.5, d3=3.0, a=3.0, b=3.0, e=1.0,
                      delta0=math.radians(18.0), lambda0=math.radians(60.0))


def _best_time(fn: Any, repeats: int = REPEATS) -> float:
    """Best CPU time (process_time) of ``repeats`` calls.

    CPU time rather than wall time: the shared build machines' wall time varies by 2x with the
    host's load, while this single-threaded work's CPU time does not.
    """
    best = math.inf
    for _ in range(repeats):
        start = time.process_time()
        fn()
        best = min(best, time.process_time() - start)
    return best


def run() -> list[dict[str, Any]]:
    theta = np.linspace(0.0, 2.0 * math.pi, N_INPUTS, endpoint=False)
    rsrc_kinematics(FIG7, theta[:1000])  # warm-up
    t_all = _best_time(lambda: rsrc_kinematics(FIG7, theta, 1.0, 0.0))
    t_pos = _best_time(lambda: rsrc_positions(FIG7, theta))
    pos, _ = rsrc_kinematics(FIG7, theta[:1000])
    modes = int(pos.n_assemblies.max())

    def branches_with_rates() -> None:
        rsrc_motion(FIG7, theta, 1.0, 0.0)  # branches, their rates and accelerations

    t_motion = _best_time(branches_with_rates)
    return [
        {
            "name": "rsrc_kinematics (positions+velocities+accelerations, all modes)",
            "value": N_INPUTS / t_all,
            "unit": "inputs/s",
            "target": 1e6,
            "note": f"Fig. 7/8 mechanism, quartic path, {modes} real inversions per input, "
                    f"{N_INPUTS} inputs in {t_all:.3f} s (best of {REPEATS}, one core, CPU time)",
        },
        {
            "name": "rsrc_motion (continuous branches, rates, accelerations)",
            "value": t_motion / N_INPUTS * 1e6,
            "unit": "µs/input",
            "target": 1.0,
            "note": f"what the closed-form Motion starts from; {N_INPUTS} inputs in "
                    f"{t_motion:.3f} s (best of {REPEATS})",
        },
        {
            "name": "rsrc_positions (all modes)",
            "value": N_INPUTS / t_pos,
            "unit": "inputs/s",
            "target": None,
            "note": f"{N_INPUTS} inputs in {t_pos:.3f} s (best of {REPEATS})",
        },
    ]


if __name__ == "__main__":
    for row in run():
        print(f"{row['name']}: {row['value']:.3g} {row['unit']} (target {row['target']}) "
              f"- {row['note']}")

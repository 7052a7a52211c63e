"""One pipeline, one solve: ``screwkit dynamics`` on an RSRC with masses against ``screwkit
analyze`` on the same spec, whole commands side by side (target: dynamics ≤ 1.3× analyze), and
the in-process cost of each stage."""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "rsrc_fig7_dynamics.toml"
CLI = [sys.executable, "-c", "from screwkit.cli.main import app; app()"]


def _wall(args: list[str]) -> float:
    t = time.perf_counter()
    subprocess.run(args, check=True, capture_output=True)
    return time.perf_counter() - t


def _best(fn: Any, repeat: int = 5) -> float:
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return min(out)


def run() -> list[dict[str, Any]]:
    import screwkit as sk

    # alternate the two commands so a drift of the machine's speed hits both alike
    _wall([*CLI, "analyze", str(SPEC), "--json"])
    ratios, dyn_times, ana_times = [], [], []
    for _ in range(5):
        a = _wall([*CLI, "analyze", str(SPEC), "--json"])
        d = _wall([*CLI, "dynamics", str(SPEC), "--json"])
        ana_times.append(a)
        dyn_times.append(d)
        ratios.append(d / a)
    spec = sk.load_spec(SPEC)
    t_solve = _best(lambda: sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed))
    motion = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
    t_dyn = _best(lambda: sk.inverse_dynamics(motion, spec.mode))
    return [
        {"name": "screwkit dynamics / screwkit analyze (whole commands, RSRC Fig. 7 with masses)",
         "value": statistics.median(ratios), "unit": "ratio", "target": "≤ 1.3",
         "note": f"median of 5 alternating pairs; analyze {statistics.median(ana_times):.2f} s, "
                 f"dynamics {statistics.median(dyn_times):.2f} s"},
        {"name": "  solve_motion (closed form, every mode, frames and twists)",
         "value": 1e3 * t_solve, "unit": "ms", "target": "",
         "note": f"{len(spec.inputs)} samples"},
        {"name": "  inverse_dynamics of one mode", "value": 1e3 * t_dyn, "unit": "ms",
         "target": "", "note": "generic Newton-Euler + loop statics"},
    ]

"""Start-up time of the command line, side by side with ``python -c "import numpy, pint"`` (the
floor any screwkit command pays): ``screwkit --help`` and ``screwkit validate`` on a bundled
example, whole processes, interleaved so that a change of the machine's load hits all three
alike. Target: each at most 1.5x the floor (issue 17).

    python benchmarks/bench_startup.py          # prints the rows
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "bagci_fig7_rsrc.toml"
CLI = [sys.executable, "-c", "from screwkit.cli.main import app; app()"]
COMMANDS = {
    "python -c 'import numpy, pint'": [sys.executable, "-c", "import numpy, pint"],
    "screwkit --help": [*CLI, "--help"],
    "screwkit validate bagci_fig7_rsrc.toml": [*CLI, "validate", str(SPEC)],
}
ROUNDS = 9


def _wall(args: list[str]) -> float:
    t = time.perf_counter()
    subprocess.run(args, check=True, capture_output=True)
    return time.perf_counter() - t


def measure(rounds: int = ROUNDS) -> dict[str, list[float]]:
    """Wall times of every command, ``rounds`` interleaved rounds (after one warm-up round)."""
    for args in COMMANDS.values():
        _wall(args)
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    for _ in range(rounds):
        for name, args in COMMANDS.items():
            times[name].append(_wall(args))
    return times


def run(rounds: int = ROUNDS) -> list[dict[str, Any]]:
    times = measure(rounds)
    floor_name = next(iter(COMMANDS))
    floor = statistics.median(times[floor_name])
    rows: list[dict[str, Any]] = [
        {"name": floor_name, "value": floor, "unit": "s", "target": "",
         "note": f"median of {rounds}; min {min(times[floor_name]):.3f} s"}]
    for name, ts in list(times.items())[1:]:
        med = statistics.median(ts)
        rows.append({"name": f"{name} / floor", "value": med / floor, "unit": "ratio",
                     "target": "<= 1.5",
                     "note": f"median {med:.3f} s (min {min(ts):.3f} s) over {rounds} "
                             "interleaved rounds, whole processes"})
    return rows


if __name__ == "__main__":
    for row in run():
        print(f"{row['name']}: {row['value']:.3f} {row['unit']} (target {row['target']}) - "
              f"{row['note']}")

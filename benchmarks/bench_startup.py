"""Start-up time of the command line, side by side with ``python -c "import numpy, pint"`` (the
floor any screwkit command pays): ``screwkit --help`` and ``screwkit validate`` on a bundled
example, whole processes, interleaved so that a change of the machine's load hits all three
alike. Target: each at most 1.5x the floor (issue 17). The ratio is of CPU time (user + system of
the child process): on a shared machine the wall time varies with the other work, the CPU
time much less; the wall times are reported beside it. The children may write and use bytecode
caches (``PYTHONDONTWRITEBYTECODE`` is removed from their environment), as an installed package
has them: without them every run would compile screwkit's sources again.

    python benchmarks/bench_startup.py          # prints the rows
"""

from __future__ import annotations

import os
import resource
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


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _time(args: list[str]) -> tuple[float, float]:
    """(CPU time, wall time) of one run of ``args``, in seconds."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    c, t = _cpu(), time.perf_counter()
    subprocess.run(args, check=True, capture_output=True, env=env)
    return _cpu() - c, time.perf_counter() - t


def measure(rounds: int = ROUNDS) -> dict[str, list[tuple[float, float]]]:
    """(CPU, wall) times of every command, ``rounds`` interleaved rounds after a warm-up."""
    for args in COMMANDS.values():
        _time(args)
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in COMMANDS}
    for _ in range(rounds):
        for name, args in COMMANDS.items():
            times[name].append(_time(args))
    return times


def run(rounds: int = ROUNDS) -> list[dict[str, Any]]:
    times = measure(rounds)
    floor_name = next(iter(COMMANDS))
    floor = statistics.median(c for c, _ in times[floor_name])
    floor_wall = statistics.median(w for _, w in times[floor_name])
    rows: list[dict[str, Any]] = [
        {"name": f"{floor_name} (CPU time)", "value": floor, "unit": "s", "target": "",
         "note": f"median of {rounds}; wall {floor_wall:.3f} s"}]
    for name, ts in list(times.items())[1:]:
        cpu = statistics.median(c for c, _ in ts)
        wall = statistics.median(w for _, w in ts)
        rows.append({"name": f"{name} / floor", "value": cpu / floor, "unit": "ratio",
                     "target": "<= 1.5",
                     "note": f"CPU {cpu:.3f} s; wall {wall:.3f} s (ratio "
                             f"{wall / floor_wall:.2f}); median of {rounds} interleaved "
                             "rounds, whole processes"})
    return rows


if __name__ == "__main__":
    for row in run():
        print(f"{row['name']}: {row['value']:.3f} {row['unit']} (target {row['target']}) - "
              f"{row['note']}")

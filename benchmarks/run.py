"""Benchmark runner (not tests): runs every ``benchmarks/bench_*.py`` in a process of its own
(so that what one benchmark loads — numba for pylinkage, Pinocchio — cannot slow another), calls
its ``run() -> list[dict]`` (keys: name, value, unit, target, note) and prints a rich table.

    python benchmarks/run.py              # every benchmark
    python benchmarks/run.py dual         # only bench_dual.py (``bench_dual`` also works)
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

HERE = Path(__file__).resolve().parent


def discover(names: list[str]) -> list[Path]:
    """Paths of the bench modules to run: all of them, or those named on the command line."""
    available = {p.stem: p for p in sorted(HERE.glob("bench_*.py"))}
    if not names:
        return list(available.values())
    chosen = []
    for name in names:
        stem = name if name.startswith("bench_") else f"bench_{name}"
        stem = stem.removesuffix(".py")
        if stem not in available:
            raise SystemExit(f"no benchmark {stem!r}; available: {', '.join(available) or 'none'}")
        chosen.append(available[stem])
    return chosen


CHILD = """
import importlib.util, json, math, sys
spec = importlib.util.spec_from_file_location("bench", sys.argv[1])
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
rows = module.run()
for row in rows:
    v = row.get("value")
    if isinstance(v, float) and not math.isfinite(v):
        row["value"] = None
print(json.dumps(rows))
"""


def run_in_own_process(path: Path) -> list[dict[str, Any]]:
    """``run()`` of one bench module in a fresh interpreter; its rows."""
    import json
    import subprocess

    out = subprocess.run([sys.executable, "-c", CHILD, str(path)], check=True,
                         capture_output=True, text=True)
    rows: list[dict[str, Any]] = json.loads(out.stdout.strip().splitlines()[-1])
    return rows


def main(argv: list[str]) -> int:
    console = Console()
    table = Table(title="screwkit benchmarks")
    for column in ("module", "name", "value", "unit", "target", "note"):
        table.add_column(column, overflow="fold")
    for path in discover(argv):
        rows = run_in_own_process(path)
        for row in rows:
            value = row.get("value")
            text = f"{value:.4g}" if isinstance(value, float) else str(value)
            table.add_row(path.stem, str(row.get("name", "")), text, str(row.get("unit", "")),
                          str(row.get("target", "")), str(row.get("note", "")))
    console.print(table)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

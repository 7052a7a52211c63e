"""Design sweeps on Dask: the speed-up from one to two worker processes on the same dynamics
sweep (an embedded LocalCluster, the cluster's start-up not counted), and the cost per design of
a 10,000-design ``dynamics`` sweep of an RSRC from start to written table (cluster start-up
included), next to the same designs in one process without Dask.

    python benchmarks/run.py sweep
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "rsrc_fig7_dynamics.toml"
#: the large sweep: 100 × 100 designs over d2 and e (override with SCREWKIT_BENCH_DESIGNS=N²)
SIDE = int(round(float(os.environ.get("SCREWKIT_BENCH_DESIGNS", "10000")) ** 0.5))


def _definition(side: int) -> Any:
    from screwkit.sweep import define_sweep

    return define_sweep(SPEC, [f"d2=4.2:4.8:{side}", f"e=0.5:1.5:{side}"], "dynamics")


def _compute(definition: Any, workers: int) -> float:
    """Seconds to compute every design on an already running cluster of ``workers``."""
    import numpy as np

    from screwkit.sweep.engine import EngineConfig, batch_size, batches, start_engine
    from screwkit.sweep.evaluate import evaluate_batch

    n = len(definition.designs)
    with start_engine(EngineConfig(workers=workers)) as engine:
        size = batch_size(n, engine.workers)
        payloads = [(np.array(b), definition.designs.values[b]) for b in batches(list(range(n)), size)]
        task, first = definition.task(), payloads[0]
        engine.client.run(evaluate_batch, task, first[0][:2], first[1][:2])  # warm every worker
        t = time.perf_counter()
        engine.map(evaluate_batch, definition.task(), payloads, lambda i, r: None)
        return time.perf_counter() - t


SPIN = "import time\nt = time.perf_counter()\ns = 0\nfor i in range(10_000_000):\n    s += i\nprint(time.perf_counter() - t)"


def machine_speed_up() -> float:
    """What two processes get over one on this machine right now: the same pure-Python loop in
    one process and then in two at once (1.0 means the second core is busy with other work)."""
    import subprocess
    import sys

    def spin(k: int) -> float:
        procs = [subprocess.Popen([sys.executable, "-c", SPIN], stdout=subprocess.PIPE, text=True)
                 for _ in range(k)]
        return max(float(p.communicate()[0]) for p in procs)

    return 2 * spin(1) / spin(2)


def run() -> list[dict[str, Any]]:
    from screwkit.sweep import EngineConfig, run_sweep
    from screwkit.sweep.engine import machine_cores

    small = _definition(20)  # 400 designs
    available = machine_speed_up()
    t1 = _compute(small, 1)
    t2 = _compute(small, 2)
    rows: list[dict[str, Any]] = [
        {"name": "400-design dynamics sweep, 1 worker", "value": t1, "unit": "s",
         "note": "embedded LocalCluster, start-up not counted"},
        {"name": "same, 2 workers", "value": t2, "unit": "s", "note": f"{machine_cores()} cores"},
        {"name": "speed-up 1 → 2 workers", "value": t1 / t2, "unit": "×", "target": "≈ 2 on 2 idle cores",
         "note": "less when other processes share the cores"},
        {"name": "speed-up the machine gives two processes now", "value": available, "unit": "×",
         "note": "a pure-Python loop in 1 and in 2 processes: the ceiling of the line above"},
    ]
    big = _definition(SIDE)
    n = len(big.designs)
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        result = run_sweep(big, Path(tmp) / "big.parquet", EngineConfig(workers=2))
        total = time.perf_counter() - t
        assert result.failed == 0 and result.errors == 0, (result.failed, result.errors)
    one = _definition(10)  # 100 designs in this process, the per-design cost without Dask
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        run_sweep(one, Path(tmp) / "one.parquet", EngineConfig(workers=0))
        serial = (time.perf_counter() - t) / len(one.designs)
    rows += [
        {"name": f"{n}-design dynamics sweep, 2 workers", "value": total, "unit": "s",
         "note": "start to written Parquet, cluster start-up included"},
        {"name": "cost per design (2 workers)", "value": 1000 * total / n, "unit": "ms",
         "note": "36 input samples, 3 moving links"},
        {"name": "cost per design in one process", "value": 1000 * serial, "unit": "ms",
         "note": "--workers 0: spec validation + motion + dynamics + row"},
        {"name": "machine load (1-minute average) at the end", "value": os.getloadavg()[0],
         "unit": "", "note": f"{machine_cores()} cores: above that, other processes take a share"},
    ]
    return rows

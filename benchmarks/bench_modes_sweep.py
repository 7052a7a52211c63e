"""A ``modes`` sweep (every assembly mode of each design, sweep/modes_job.py) with stored start
solutions against the same sweep without them, where every worker process first solves its
topology's start system (issue 27, "Sweeps reuse the stored start solutions").

Two topologies: a 6-6 Stewart–Gough platform (start solutions by monodromy: 40) and a
Stephenson III six-bar (the multi-homogeneous homotopy: 6 paths, not the total degree's 16).
Each sweep runs N designs (``SCREWKIT_BENCH_MODES_DESIGNS``, default 8) on an embedded cluster
of two worker processes started (and warmed by importing screwkit) before the clock starts:

* *stored*: the scheduler's side reads the start solutions from the store on disk (written
  before the run, checked on load) and ships them with the task; the workers have no store;
* *first solve*: no store and nothing shipped: each worker solves the start system for its
  first design.

The same in one process (``--workers 0``) shows the cost of the one first solve alone.
Measured 2026-12-06 on the shared 2-core machine under a load average of ~11 (docs/sweeps.md,
"Cost"): the per-design homotopy, not the first solve, dominates a Stewart sweep.

    python benchmarks/run.py modes_sweep
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
N = int(os.environ.get("SCREWKIT_BENCH_MODES_DESIGNS", "8"))
#: runs of each sweep (alternating stored / first solve), the least time kept: the machine's
#: other load moves single runs by more than the difference (the Stewart runs are long)
REPEATS = {"Stewart–Gough": 1, "Stephenson III six-bar": 3}
#: run only the topology whose name holds this ("stewart", "six-bar"); default both
ONLY = os.environ.get("SCREWKIT_BENCH_MODES_ONLY", "")


def _specs(folder: Path) -> dict[str, tuple[Path, list[str]]]:
    """The two specs, cut short (the Stewart platform at its drawing and one pose, the six-bar
    every 60°), and the keys varied over N designs."""
    import sys

    sys.path.insert(0, str(ROOT / "tests" / "sweep"))
    from sweep_helpers import toml_text

    from screwkit.io.toml_file import read_toml

    stewart = read_toml(ROOT / "examples" / "mechanisms" / "stewart_platform.toml")
    stewart["motion"]["rows"] = stewart["motion"]["rows"][:2]
    sixbar = read_toml(ROOT / "examples" / "mechanisms" / "stephenson3_sixbar.toml")
    sixbar["motion"]["step"] = 60.0
    out = {}
    for name, data, key in (("Stewart–Gough", stewart, f"joints.S1.at[2]=390:410:{N}"),
                            ("Stephenson III six-bar", sixbar, f"joints.Q2.at[0]=70:90:{N}")):
        path = folder / f"{name.split()[0].replace('–', '_')}.toml"
        path.write_text(toml_text(data), encoding="utf-8")
        out[name] = (path, [key])
    return out


def _warm() -> None:
    """Imports and first calls of the tracker on a system of no topology of the sweep, so
    that a worker's first design pays no start-up cost but the start solutions'."""
    import numpy as np

    import screwkit.kinematics.modes.every_mode  # noqa: F401
    import screwkit.sweep.evaluate  # noqa: F401
    from screwkit.algebraic.polynomial import Poly, compile_system
    from screwkit.algebraic.solve import solve_all

    x, y, a = Poly.variable(0), Poly.variable(1), Poly.variable(2)
    solve_all(compile_system([x * x + y * y - a, x - y], ["x", "y"], ["a"]), np.ones((1, 1)))


def _timed(definition: Any, store: Path, workers: int, stored: bool) -> tuple[float, int, int]:
    """Seconds for every design (the scheduler side's start solutions included), the paths
    tracked to find start solutions on the workers, and the paths per design."""
    import numpy as np

    from screwkit.kinematics.modes import start_store, starts
    from screwkit.sweep.engine import EngineConfig, batch_size, batches, start_engine
    from screwkit.sweep.evaluate import evaluate_batch

    n = len(definition.designs)
    os.environ[start_store.CACHE_ENV] = "off"  # the workers spawned below have no store
    starts.forget()
    rows: list[dict[str, Any]] = []
    with start_engine(EngineConfig(workers=workers)) as engine:
        if engine.client is not None:
            engine.client.run(_warm)
        os.environ[start_store.CACHE_ENV] = str(store)
        size = batch_size(n, engine.workers)
        payloads = [(np.array(b), definition.designs.values[b])
                    for b in batches(list(range(n)), size)]
        t = time.perf_counter()
        if stored:
            task = definition.task()
        else:
            os.environ[start_store.CACHE_ENV] = "off"
            task = _unshipped(definition)
        engine.map(evaluate_batch, task, payloads, lambda i, r: rows.extend(r))
        seconds = time.perf_counter() - t
    assert all(r["status"] == "ok" for r in rows), [r["reason"] for r in rows]
    return seconds, sum(r["start_paths"] for r in rows), rows[0]["paths_tracked"]


def _unshipped(definition: Any) -> Any:
    from screwkit.sweep.evaluate import SweepTask

    return SweepTask(definition.data, str(definition.spec_path), definition.designs.keys,
                     definition.job, definition.options)


def run() -> list[dict[str, Any]]:
    from screwkit.kinematics.modes import start_store, starts
    from screwkit.sweep import define_sweep

    out: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        store = folder / "cache"
        for name, (path, vary) in _specs(folder).items():
            if ONLY and ONLY.lower() not in name.lower():
                continue
            os.environ[start_store.CACHE_ENV] = str(store)
            definition = define_sweep(path, vary, "modes")
            starts.forget()
            t = time.perf_counter()
            found = next(iter(definition.task().starts.values()))  # solved, then stored
            first = time.perf_counter() - t
            starts.forget()
            t = time.perf_counter()
            definition.task()  # read back from the store and checked
            load = time.perf_counter() - t
            out.append({"name": f"{name}: start solutions, first solve", "value": first,
                        "unit": "s", "note": f"{found.paths} paths; {found.how_found}"})
            out.append({"name": f"{name}: start solutions read from the store", "value": load,
                        "unit": "s", "note": "checked: key, Newton step of every point"})
            for workers in (2, 0):
                where = "2 workers" if workers else "in one process"
                with_s = without = float("inf")
                for _ in range(REPEATS[name]):  # alternated; the least of each
                    t_s, paths_s, per = _timed(definition, store, workers, True)
                    t_w, paths_w, _ = _timed(definition, store, workers, False)
                    with_s, without = min(with_s, t_s), min(without, t_w)
                out.append({"name": f"{name}: {N} designs, {where}, stored starts",
                            "value": with_s, "unit": "s",
                            "note": f"{per} paths per design; {paths_s} start paths tracked"})
                out.append({"name": f"{name}: {N} designs, {where}, first solve per worker",
                            "value": without, "unit": "s",
                            "note": f"{paths_w} start paths tracked; "
                                    f"stored is {without / with_s:.2f}× faster"})
    return out

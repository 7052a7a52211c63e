"""The native homotopy continuation (issue 27): a parameter homotopy on a random dense system
of 6 quadrics in 6 unknowns (every coefficient a parameter: 168 parameters; 2⁶ = 64 solutions),
one instance alone and a batch of 100 instances in one call.

Start: the 64 solutions at a random complex parameter point, by the total-degree homotopy
(timed too: 64 paths from x_i² = 1). Each instance: random real coefficients, all 64 paths
tracked and classified (``track_parameter_homotopy``), then the full front ``solve_all``
(tracking + α-test + dedupe). Checked: every instance yields 64 distinct certified solutions
(Bézout's number, attained by a generic dense system). Reported: paths per second (CPU time,
best of 3 for one instance, one run for the batch) and the share of the time per stage
from cProfile (on 10 instances).

Target (issue 27's Stewart numbers scaled to 64 paths, not a peer measurement): ≥ 10 000
paths/s in the batch.

The system is a set of quadrics, so the tracker evaluates it densely (algebraic/quadrics.py)
and, with numba installed (the ``fast`` extra), runs its step loop compiled
(algebraic/compiled.py; compiled or loaded by a first call outside the timings). The row
"numpy route" tracks the same batch with ``TrackOptions(compiled=False)`` (the vectorised numpy
tracker, the same algorithm), the row "sparse evaluation" 10 of the instances with
``TrackOptions(dense=False, compiled=False)`` (the term-table evaluation used before), side by
side. BLAS runs on one thread
(OPENBLAS_NUM_THREADS=1 unless set): extra threads only add spinning CPU time here.
"""

from __future__ import annotations

import cProfile
import itertools
import math
import os
import pstats
import time
from typing import Any

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from screwkit.algebraic import compiled  # noqa: E402
from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system  # noqa: E402
from screwkit.algebraic.solve import StartSolutions, solve_all  # noqa: E402
from screwkit.algebraic.track import TrackOptions, track_parameter_homotopy  # noqa: E402

N = 6
BATCH = 100
REPEATS = 3
TARGET_PATHS_PER_S = 10_000


def dense_quadrics(n: int) -> PolynomialSystem:
    """n dense quadrics in n unknowns with every coefficient a parameter."""
    xs = [Poly.variable(i) for i in range(n)]
    mons = [m for m in itertools.product(range(3), repeat=n) if sum(m) <= 2]
    equations = []
    for i in range(n):
        f = Poly.constant(0)
        for j, m in enumerate(mons):
            term = Poly.variable(n + i * len(mons) + j)
            for v, e in enumerate(m):
                term = term * xs[v] ** e
            f = f + term
        equations.append(f)
    return compile_system(equations, [f"x{i}" for i in range(n)],
                          [f"c{i}" for i in range(n * len(mons))])


def _best(fn: Any, repeats: int = REPEATS) -> float:
    best = math.inf
    for _ in range(repeats):
        t = time.process_time()
        fn()
        best = min(best, time.process_time() - t)
    return best


def _profile_shares(fn: Any) -> str:
    """The cumulative-time share of the main stages in one profiled call."""
    profile = cProfile.Profile()
    profile.runcall(fn)
    stats = pstats.Stats(profile)
    total = max(stats.total_tt, 1e-12)  # type: ignore[attr-defined]
    shares = {}
    for (_, _, name), row in stats.stats.items():  # type: ignore[attr-defined]
        if name in ("_evaluate_columns", "evaluate", "solve", "cauchy_endgame", "certify",
                    "_polish", "track_compiled"):
            shares[name] = shares.get(name, 0.0) + row[3] / total
    return ", ".join(f"{k} {100 * v:.0f}%" for k, v in sorted(shares.items(),
                                                               key=lambda kv: -kv[1]))


def run() -> list[dict[str, Any]]:
    system = dense_quadrics(N)
    t0 = time.process_time()
    start = StartSolutions.by_total_degree(system, seed=1)
    t_start = time.process_time() - t0
    m = start.generic_count
    rng = np.random.default_rng(0)
    targets = rng.standard_normal((BATCH, system.k))

    def alone() -> None:
        track_parameter_homotopy(system, start.p, targets[0], start.x)

    def batch() -> None:
        track_parameter_homotopy(system, start.p, np.repeat(targets, m, axis=0),
                                 np.tile(start.x, (BATCH, 1)))

    alone()  # the first call compiles (or loads) the step loop (numba)
    t_alone, t_batch = _best(alone), _best(batch, repeats=1)
    t0 = time.process_time()
    track_parameter_homotopy(system, start.p, np.repeat(targets, m, axis=0),
                             np.tile(start.x, (BATCH, 1)), TrackOptions(compiled=False))
    numpy_rate = BATCH * m / (time.process_time() - t0)
    t0 = time.process_time()
    track_parameter_homotopy(system, start.p, np.repeat(targets[:10], m, axis=0),
                             np.tile(start.x, (10, 1)),
                             TrackOptions(dense=False, compiled=False))
    sparse_rate = 10 * m / (time.process_time() - t0)
    t0 = time.process_time()
    solutions = solve_all(system, targets, start)
    t_solve = time.process_time() - t0
    complete = int(((solutions.found == 2**N) & (solutions.failed == 0)).sum())
    certified = bool(solutions.certified.all())

    rate = BATCH * m / t_batch
    route = "compiled, numba" if compiled.AVAILABLE else "numpy, numba absent"
    note = f"{complete}/{BATCH} instances with all {2**N}, all certified: {certified}"
    return [
        {"name": f"start: total degree, {2**N} paths", "value": t_start * 1e3, "unit": "ms",
         "target": "", "note": start.how_found},
        {"name": f"{m} paths alone", "value": m / t_alone, "unit": "paths/s", "target": "",
         "note": f"{t_alone * 1e3:.1f} ms"},
        {"name": f"{m} paths × {BATCH} instances", "value": rate, "unit": "paths/s",
         "target": f"≥ {TARGET_PATHS_PER_S}",
         "note": ("PASS" if rate >= TARGET_PATHS_PER_S else "MISS")
         + f"; {t_batch * 1e3 / BATCH:.1f} ms per instance"},
        {"name": f"{m} paths × {BATCH} instances, numpy route", "value": numpy_rate,
         "unit": "paths/s", "target": "",
         "note": f"the batch above ({route}): {rate / numpy_rate:.1f}× faster"},
        {"name": f"{m} paths × 10 instances, sparse evaluation", "value": sparse_rate,
         "unit": "paths/s", "target": "",
         "note": f"dense numpy route: {numpy_rate / sparse_rate:.1f}× faster"},
        {"name": f"solve_all × {BATCH} (track + α-test + dedupe)",
         "value": t_solve * 1e3 / BATCH, "unit": "ms/instance", "target": "", "note": note},
        {"name": "where the batch's time goes", "value": None, "unit": "",
         "target": "", "note": _profile_shares(lambda: track_parameter_homotopy(
             system, start.p, np.repeat(targets[:10], m, axis=0), np.tile(start.x, (10, 1))))},
    ]


if __name__ == "__main__":
    for row in run():
        print(row)

"""Every assembly of a single loop of R, P and C joints with six free freedoms, by the quadrics
in its joint axes (issue 27; kinematics/modes/rpc_quadrics.py, rpc_loop.py):

- per topology (5R1P RPRRRR, 4R2P PRRPRR, 3R3P PRPRPR, RRCRR, CCRR): the start set's first
  solve (monodromy or total degree, in memory only: ``SCREWKIT_CACHE_DIR=off``), one random
  real loop alone (mean of 10 calls) and a batch of 200 random real loops (every angle
  uniform, lengths standard normal; the test's loops), with the share that reaches the generic
  count;
- the loop solver's root search of a Denavit–Hartenberg RRPRRRR loop at 12 rows: the batched
  homotopy (tracker/algebraic_roots.py) side by side with Newton from 96 random starts
  (tracker/solve.py::find_assemblies), alternating, medians of 3, and the roots each found.

Times are CPU seconds (process time), OPENBLAS_NUM_THREADS=1.
"""

from __future__ import annotations

import os
import time
from typing import Any

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ["SCREWKIT_CACHE_DIR"] = "off"

import numpy as np  # noqa: E402

from screwkit.algebraic.solve import solve_all  # noqa: E402
from screwkit.kinematics.modes.general_loop_system import loop_layout  # noqa: E402
from screwkit.kinematics.modes.rpc_loop import loop_count  # noqa: E402
from screwkit.kinematics.modes.rpc_quadrics import (  # noqa: E402
    random_rpc,
    rpc_parameters,
    rpc_system,
)
from screwkit.kinematics.modes.starts import start_solutions  # noqa: E402

FAMILIES = (("RPRRRR", "5R1P"), ("PRRPRR", "4R2P"), ("PRPRPR", "3R3P"), ("RRCRR", "RRCRR"),
            ("CCRR", "CCRR"))
BATCH = 200


def real_dh(kinds: str, rng: np.random.Generator, count: int) -> np.ndarray:
    """``count`` random real loops (general-system parameters): every angle uniform, every
    length standard normal (as tests/kinematics/test_modes_rpc_loop.py draws them)."""
    g = loop_layout(kinds)
    p = np.zeros((count, g.n_parameters))
    for j in range(len(kinds)):
        for idx in (g.phi[j], g.alpha[j]):
            if idx >= 0:
                t = rng.uniform(-np.pi, np.pi, count)
                p[:, idx - g.n_unknowns], p[:, idx - g.n_unknowns + 1] = np.cos(t / 2), \
                    np.sin(t / 2)
        for idx in (g.b[j], g.a[j]):
            if idx >= 0:
                p[:, idx - g.n_unknowns] = rng.normal(size=count)
    return p


def _cpu(fn: Any) -> float:
    t = time.process_time()
    fn()
    return time.process_time() - t


def _family_rows(kinds: str, label: str) -> list[dict[str, Any]]:
    S, count = rpc_system(kinds), loop_count(kinds)
    t0 = time.process_time()
    start = start_solutions(S, lambda r: random_rpc(kinds, r, 1), count)
    t_start = time.process_time() - t0
    p = np.real(rpc_parameters(kinds, real_dh(kinds, np.random.default_rng(11), BATCH)))
    solve_all(S, p[0], start)  # compile (or load) the step loop for this layout
    t_alone = _cpu(lambda: [solve_all(S, p[i], start) for i in range(10)]) / 10
    t0 = time.process_time()
    sol = solve_all(S, p, start)
    t_batch = (time.process_time() - t0) / BATCH
    reach = float((sol.found == count).mean())
    return [
        {"name": f"R/P/C loop {label} ({kinds}): start set", "value": t_start * 1e3,
         "unit": "ms", "target": "", "note": start.how_found},
        {"name": f"R/P/C loop {label}: one loop alone", "value": t_alone * 1e3, "unit": "ms",
         "target": "", "note": f"{count} paths; mean of 10 calls"},
        {"name": f"R/P/C loop {label}: batch of {BATCH}", "value": t_batch * 1e3,
         "unit": "ms/loop", "target": "",
         "note": f"{reach:.3f} reach {count}; {int(sol.failed.sum())} failed paths"},
    ]


def _root_search_rows() -> list[dict[str, Any]]:
    from screwkit.kinematics.tracker.algebraic_roots import algebraic_roots, loop_formulation
    from screwkit.kinematics.tracker.loop import layout
    from screwkit.kinematics.tracker.solve import find_assemblies
    from screwkit.model.joints import Joint
    from screwkit.model.linkage import Linkage

    rng = np.random.default_rng(5)
    kinds = "RRPRRRR"
    lk = Linkage.from_hartenberg_denavit(
        kinds, [Joint(f"J{i + 1}", k) for i, k in enumerate(kinds)],
        list(rng.uniform(0.5, 2.0, 7)), list(rng.uniform(-1.2, 1.2, 7)), inputs=["J1.theta"])
    lay = layout(lk)
    t_form = _cpu(lambda: loop_formulation(lk, lay))
    lf = loop_formulation(lk, lay)
    assert lf is not None
    X = np.radians(np.arange(0.0, 360.0, 30.0))[:, None]
    algebraic_roots(lf, lk, lay, X[:1])  # start set and compiled step loop
    hom, newton = [], []
    for _ in range(3):
        hom.append(_cpu(lambda: algebraic_roots(lf, lk, lay, X)))
        newton.append(_cpu(lambda: find_assemblies(lk, X, starts=96, seed=1)))
    roots = algebraic_roots(lf, lk, lay, X)
    found = find_assemblies(lk, X, starts=96, seed=1)
    return [
        {"name": "RRPRRRR root search, 12 rows: homotopy", "value": float(np.median(hom)) * 1e3,
         "unit": "ms", "target": "",
         "note": f"{int(roots.assemblies.found.sum())} real roots, complete at "
         f"{int(roots.complete.sum())}/12 rows; the drawing (closed_somewhere) "
         f"{t_form * 1e3:.0f} ms once"},
        {"name": "RRPRRRR root search, 12 rows: Newton, 96 random starts",
         "value": float(np.median(newton)) * 1e3, "unit": "ms", "target": "",
         "note": f"{int(found.found.sum())} real roots (no promise of every one)"},
    ]


def run() -> list[dict[str, Any]]:
    rows = []
    for kinds, label in FAMILIES:
        rows += _family_rows(kinds, label)
    return rows + _root_search_rows()


if __name__ == "__main__":
    for row in run():
        print(row)

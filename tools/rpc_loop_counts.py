"""Measure the generic counts of single R/P/C loops on the quadrics of
src/screwkit/kinematics/modes/rpc_quadrics.py, offline: ``PYTHONPATH=src python
tools/rpc_loop_counts.py [KINDS ...]`` (a few CPU minutes for every topology; the defaults are
the 31 labellings docs/kinematics.md names).

For each labelling (free joints round the loop, turned until the last one turns): monodromy from
two seeds (``MonodromyOptions(stale_loops=9)``: stopped after nine loops in a row without a new
solution, no expected count) and, where its Bézout number is at most 4,096, a total-degree
homotopy at a third random point; then the count that ``rpc_loop.LOOP_COUNTS`` holds for the
topology. A total-degree run that loses no path is complete up to the tracker's accuracy.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from screwkit.algebraic.monodromy import MonodromyOptions, monodromy_solve
from screwkit.algebraic.solve import StartSolutions
from screwkit.algebraic.total_degree import bezout_number
from screwkit.kinematics.modes.rpc_loop import LOOP_COUNTS, canonical
from screwkit.kinematics.modes.rpc_quadrics import random_rpc, rpc_system

LABELLINGS = ("CCC CCRR RCCR CCPR CPRC PCRC CRCR CPCR CRRRR RRCRR RRRRC CPRRR RRCPR CRPRR CPPRR "
              "PRRPC CPRPR CRPPR PRRRRR RPRRRR RRRPRR PPRRRR RPPRRR PRPRRR RPRRPR PRRPRR PPPRRR "
              "RPPPRR PPRPRR PRPRPR RRRRRR").split()


def measure(kinds: str) -> str:
    """One line: the labelling, its unknowns and Bézout number, both monodromy counts, the
    total-degree count, the table's count."""
    while kinds[-1] == "P":
        kinds = kinds[1:] + kinds[0]
    S = rpc_system(kinds)
    out = [kinds, f"n={S.n}", f"bezout={bezout_number(S)}"]
    for seed in (0, 1):
        p, x = random_rpc(kinds, np.random.default_rng(seed), 1)
        t = time.process_time()
        _, X, stats = monodromy_solve(S, p[0], x, MonodromyOptions(stale_loops=9, seed=seed))
        out.append(f"monodromy({seed}) {len(X)} ({stats.loops} loops, "
                   f"{time.process_time() - t:.1f} s)")
    if bezout_number(S) <= 4096:
        start = StartSolutions.by_total_degree(S, seed=3)
        out.append(f"total degree {len(start.x)} [{start.how_found}]")
    out.append(f"table {LOOP_COUNTS.get(canonical(kinds))}")
    return " | ".join(out)


if __name__ == "__main__":
    for kinds in sys.argv[1:] or LABELLINGS:
        print(measure(kinds), flush=True)

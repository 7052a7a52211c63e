"""Global synthesis: the least-squares multistart (Bagci 1969 ch. V; synthesis/solve.py
``synthesize_multistart``) with its starts distributed over the sweep engine (docs/sweeps.md,
"Global synthesis").

The starts are drawn in this process exactly as the serial multistart draws them (the same
seed gives the same starts), solved in batches on the engine, gathered in start order and ranked
by the serial code, so the results equal the serial run's whenever no start hits a time limit
(each start keeps the problem's ``time_limit``; the serial run also stops starting new ones
after ``starts × time_limit`` in all).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.sweep.engine import Engine, batch_size, batches
from screwkit.synthesis.config import SynthesisConfig, SynthesisRun, run_synthesis
from screwkit.synthesis.problem import RSRCSynthesisProblem
from screwkit.synthesis.solve import (
    SynthesisResult,
    best_distinct,
    multistart_starts,
    solve_start,
)

#: largest number of starts per engine task (each start is a least-squares solve)
STARTS_PER_TASK = 4


def solve_starts(problem: RSRCSynthesisProblem, indices: np.ndarray,
                 starts: list[dict[str, float]], units: Any = None
                 ) -> list[tuple[list[SynthesisResult], list[str]]]:
    """One engine task: a batch of starts, each solved on every mode (``solve_start``), its
    notes in ``units`` (the caller's message units: a worker process has none of its own)."""
    from screwkit.messages import message_units

    with message_units(units):
        return [solve_start(problem, start) for start in starts]


def distributed_multistart(problem: RSRCSynthesisProblem, engine: Engine, *, n_starts: int,
                           seed: int, keep: int, spread: float,
                           progress: Callable[[int, int, int], None] | None = None
                           ) -> list[SynthesisResult]:
    """The best ``keep`` distinct results of ``n_starts`` starts solved on ``engine``."""
    if keep < 1:
        raise InputError("n_starts and keep must be >= 1")
    starts, scale = multistart_starts(problem, n_starts, seed, spread)
    size = batch_size(n_starts, engine.workers, None, largest=STARTS_PER_TASK)
    groups = batches(list(range(n_starts)), size)
    from screwkit.messages import current_units

    units = current_units()
    payloads = [(np.array(g, dtype=np.int64), [starts[i] for i in g], units) for g in groups]
    outcome: list[Any] = [None] * n_starts
    done = [0]

    def finished(task: int, solved: list[tuple[list[SynthesisResult], list[str]]]) -> None:
        for i, result in zip(groups[task], solved, strict=True):
            outcome[i] = result
        done[0] += len(solved)
        if progress is not None:
            progress(done[0], n_starts, done[0])

    engine.map(solve_starts, problem, payloads, finished)
    results = [r for found, _ in outcome for r in found]
    reasons = [w for _, why in outcome for w in why]
    return best_distinct(results, reasons, n_starts, keep, scale)


def synthesize_on_engine(config: SynthesisConfig, starts: int, engine: Engine,
                         progress: Callable[[int, int, int], None] | None = None
                         ) -> SynthesisRun:
    """``run_synthesis(config, starts=starts)`` with the least-squares multistart's starts on
    ``engine``; the other routes (overlay, generic loop) and a single solve run as
    ``run_synthesis`` runs them."""

    def on_engine(problem: RSRCSynthesisProblem, *, n_starts: int, seed: int, keep: int,
                  spread: float, progress: Callable[[int, int], None] | None = None
                  ) -> list[SynthesisResult]:
        def advance(done: int, total: int, _: int) -> None:
            if progress is not None:
                progress(done, total)

        return distributed_multistart(problem, engine, n_starts=n_starts, seed=seed, keep=keep,
                                      spread=spread, progress=advance)

    def two(done: int, total: int) -> None:
        if progress is not None:
            progress(done, total, done)

    return run_synthesis(config, starts=starts, progress=two, multistart=on_engine)

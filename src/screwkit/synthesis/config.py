"""A synthesis run described as data (what a spec file's ``[synthesis]`` table says, validated and
in SI units; :mod:`screwkit.io.synthesis_table` builds it) and :func:`run_synthesis`, which runs
either route: least squares with exact derivatives (Bagci 1969 ch. V, Programs B and C), one start
or a multistart, or the overlay technique (§5.4)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

from screwkit.synthesis.overlay_synthesis import OverlayOutcome, OverlayProblem, synthesize_overlay
from screwkit.synthesis.problem import RSRCSynthesisProblem
from screwkit.synthesis.solve import SynthesisResult, synthesize, synthesize_multistart


@dataclass(frozen=True)
class Multistart:
    """Options of a multistart (docs/synthesis.md, ``[synthesis.multistart]``)."""

    starts: int = 20
    seed: int = 0
    keep: int = 3
    spread: float = 0.5


@dataclass(frozen=True)
class SynthesisConfig:
    """One synthesis: the problem of either route, the multistart options of the least-squares
    route, and how lengths are shown (``length_unit``, e.g. ``"1 in"``)."""

    problem: RSRCSynthesisProblem | OverlayProblem
    multistart: Multistart | None = None
    length_unit: str = "1 m"

    @property
    def method(self) -> str:
        return "overlay" if isinstance(self.problem, OverlayProblem) else "least_squares"


@dataclass(frozen=True)
class SynthesisRun:
    """The results of :func:`run_synthesis`, best first; ``overlay`` holds the overlay route's
    outcomes (with their circles) when that route ran."""

    results: list[SynthesisResult]
    overlay: list[OverlayOutcome] | None = None


def run_synthesis(config: SynthesisConfig | RSRCSynthesisProblem | OverlayProblem, *,
                  starts: int | None = None, seed: int | None = None,
                  progress: Callable[[int, int], None] | None = None) -> SynthesisRun:
    """Dimensional synthesis of an RSRC (or its plane 4R case) for a desired screw displacement
    ψ_d(θ) + ε S_d(θ) (Bagci 1969 ch. V): least squares with exact derivatives (Programs B and C,
    dwell and range constraints by the parameters of constraint, eqs. 5.13–5.21), or the overlay
    technique (§5.4). Dimensions in SI units (m) and radians; results best first.

    ``config``: a :class:`SynthesisConfig` (``spec.synthesis``) or a bare problem
    (:class:`~screwkit.synthesis.problem.RSRCSynthesisProblem`,
    :class:`~screwkit.synthesis.overlay_synthesis.OverlayProblem`). ``starts`` overrides the number
    of starts (multistart of the least-squares route, or the overlay's circle-fit starts);
    ``seed`` the multistart's random seed. One start with a given inversion (or parameters of
    constraint) is a single solve. ``progress(done, total)`` is called after each start of a
    multistart."""
    if not isinstance(config, SynthesisConfig):
        config = SynthesisConfig(config)
    problem = config.problem
    if isinstance(problem, OverlayProblem):
        if starts is not None:
            problem = dataclasses.replace(problem, n_starts=starts)
        outcomes = synthesize_overlay(problem)
        return SynthesisRun([o.result for o in outcomes], outcomes)
    ms = config.multistart or Multistart(starts=1)
    n_starts = starts if starts is not None else ms.starts
    if n_starts == 1 and not (problem.inversion is None and problem.construction is None):
        return SynthesisRun([synthesize(problem)])
    return SynthesisRun(synthesize_multistart(
        problem, n_starts=n_starts, seed=ms.seed if seed is None else seed, keep=ms.keep,
        spread=ms.spread, progress=progress))

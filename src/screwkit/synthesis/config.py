"""A synthesis run described as data (what a spec file's ``[synthesis]`` table says, validated and
in SI units; :mod:`screwkit.io.synthesis_table` builds it) and :func:`run_synthesis`, which runs
its route: Bagci's closed form — least squares with exact derivatives (Bagci 1969 ch. V,
Programs B and C) or the overlay technique (§5.4) — for the RSRC and its plane case the 4R, or
the generic route for any loop (least squares with the exact Jacobian from the loop's screw
Jacobian, :mod:`screwkit.synthesis.loop_route`); one start or a multistart."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import overload

from screwkit.errors import expect_instance, expect_number
from screwkit.synthesis.graph_route import (
    GraphSynthesisProblem,
    GraphSynthesisResult,
    synthesize_graph_multistart,
)
from screwkit.synthesis.loop_route import LoopSynthesisProblem
from screwkit.synthesis.loop_solve import synthesize_loop, synthesize_loop_multistart
from screwkit.synthesis.overlay_synthesis import OverlayOutcome, OverlayProblem, synthesize_overlay
from screwkit.synthesis.problem import RSRCSynthesisProblem
from screwkit.synthesis.solve import SynthesisResult, synthesize, synthesize_multistart

Problem = RSRCSynthesisProblem | OverlayProblem | LoopSynthesisProblem


@dataclass(frozen=True)
class Multistart:
    """Options of a multistart (docs/synthesis.md, ``[synthesis.multistart]``)."""

    starts: int = 20
    seed: int = 0
    keep: int = 3
    spread: float = 0.5


@dataclass(frozen=True)
class SynthesisConfig:
    """One synthesis: the problem of its route, the multistart options of the least-squares
    routes, and how lengths are shown (``length_unit``, e.g. ``"1 in"``). ``dimensions``: the
    names a result reports (a 4R solved as Bagci's plane RSRC reports its own a, d1, d2, d3;
    None: every dimension); ``angles``: which of them are angles; ``outputs``: the variables
    that generate the target rotation and translation (None where the family has none)."""

    problem: Problem
    multistart: Multistart | None = None
    length_unit: str = "1 m"
    dimensions: tuple[str, ...] | None = None
    angles: frozenset[str] = frozenset({"delta0", "lambda0", "theta01", "q1", "q2"})
    outputs: tuple[str | None, str | None] = ("phi0", "S")

    @property
    def method(self) -> str:
        return "overlay" if isinstance(self.problem, OverlayProblem) else "least_squares"

    @property
    def route(self) -> str:
        """``"generic"`` (the loop's screw Jacobian) or ``"closed"`` (Bagci's closed form)."""
        return "generic" if isinstance(self.problem, LoopSynthesisProblem) else "closed"


@dataclass(frozen=True)
class SynthesisRun:
    """The results of :func:`run_synthesis`, best first; ``overlay`` holds the overlay route's
    outcomes (with their circles) when that route ran."""

    results: list[SynthesisResult]
    overlay: list[OverlayOutcome] | None = None


def _reported(run: SynthesisRun, names: tuple[str, ...] | None) -> SynthesisRun:
    """The run with every result's dimensions cut to ``names`` (None: all of them)."""
    if names is None:
        return run
    results = [dataclasses.replace(r, dimensions={k: v for k, v in r.dimensions.items()
                                                  if k in names}) for r in run.results]
    overlay = None if run.overlay is None else [
        dataclasses.replace(o, result=res) for o, res in zip(run.overlay, results, strict=True)]
    return SynthesisRun(results, overlay)


@overload
def run_synthesis(config: GraphSynthesisProblem, *, starts: int | None = None,
                  seed: int | None = None,
                  progress: Callable[[int, int], None] | None = None,
                  multistart: Callable[..., list[SynthesisResult]] | None = None
                  ) -> list[GraphSynthesisResult]: ...


@overload
def run_synthesis(config: SynthesisConfig | Problem, *, starts: int | None = None,
                  seed: int | None = None,
                  progress: Callable[[int, int], None] | None = None,
                  multistart: Callable[..., list[SynthesisResult]] | None = None
                  ) -> SynthesisRun: ...


def run_synthesis(config: SynthesisConfig | Problem | GraphSynthesisProblem, *,
                  starts: int | None = None, seed: int | None = None,
                  progress: Callable[[int, int], None] | None = None,
                  multistart: Callable[..., list[SynthesisResult]] | None = None
                  ) -> SynthesisRun | list[GraphSynthesisResult]:
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
    multistart. ``multistart`` replaces `synthesize_multistart` for the least-squares route
    (same arguments and results; screwkit.sweep runs its starts on a cluster).

    A mechanism graph's problem (:class:`~screwkit.synthesis.graph_route.GraphSynthesisProblem`,
    ``load_spec(graph spec).synthesis``; docs/synthesis.md "Graphs") gives its results, best
    first (:func:`~screwkit.synthesis.graph_route.synthesize_graph_multistart`; ``multistart``
    does not apply)."""
    expect_instance(config, (SynthesisConfig, RSRCSynthesisProblem, OverlayProblem,
                             LoopSynthesisProblem, GraphSynthesisProblem), "synthesize: config",
                    "a SynthesisConfig (load_spec(...).synthesis) or a synthesis problem")
    if starts is not None:
        expect_number(starts, "synthesize: starts", integer=True, positive=True)
    if seed is not None:
        expect_number(seed, "synthesize: seed", integer=True)
    if isinstance(config, GraphSynthesisProblem):
        graph = config if seed is None else dataclasses.replace(config, seed=seed)
        return synthesize_graph_multistart(graph, starts, progress)
    if not isinstance(config, SynthesisConfig):
        config = SynthesisConfig(config)
    problem = config.problem
    if isinstance(problem, OverlayProblem):
        if starts is not None:
            problem = dataclasses.replace(problem, n_starts=starts)
        outcomes = synthesize_overlay(problem)
        return _reported(SynthesisRun([o.result for o in outcomes], outcomes), config.dimensions)
    ms = config.multistart or Multistart(starts=1)
    n_starts = starts if starts is not None else ms.starts
    seed = ms.seed if seed is None else seed
    if isinstance(problem, LoopSynthesisProblem):
        if n_starts == 1 and problem.mode is not None:
            return _reported(SynthesisRun([synthesize_loop(problem)]), config.dimensions)
        return _reported(SynthesisRun(synthesize_loop_multistart(
            problem, n_starts=n_starts, seed=seed, keep=ms.keep, spread=ms.spread,
            progress=progress)), config.dimensions)
    if n_starts == 1 and not (problem.inversion is None and problem.construction is None):
        return _reported(SynthesisRun([synthesize(problem)]), config.dimensions)
    runner = multistart or synthesize_multistart
    return _reported(SynthesisRun(runner(
        problem, n_starts=n_starts, seed=seed, keep=ms.keep, spread=ms.spread,
        progress=progress)), config.dimensions)

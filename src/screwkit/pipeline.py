"""One pipeline from a spec file to every job's result: spec → :class:`Motion` (solved once) →
dynamics → balancing; and the spec's synthesis, limits and mobility. The CLI, ``demo`` and the
report all go through a :class:`Pipeline`, so the motion of a spec is solved exactly once per
run, whichever jobs run on it (docs/architecture.md)."""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from functools import cached_property
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from screwkit.constants import STANDARD_GRAVITY
from screwkit.errors import InputError, ScrewkitError, expect_instance
from screwkit.io.errors import SpecError
from screwkit.io.spec import Spec
from screwkit.kinematics.analysis.transmission import Transmission, transmission
from screwkit.kinematics.motion import AssemblyError, ModeMotion, Motion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.kinematics.tracker.loop import Array
from screwkit.messages import listing, message_units, number
from screwkit.tables import ResultTable, UnitChoice

F = TypeVar("F", bound=Callable[..., Any])


def _in_spec_units(job: F) -> F:
    """Run a job with the pipeline's display units for its notes and messages
    (:func:`screwkit.messages.message_units`)."""

    @functools.wraps(job)
    def run(self: Pipeline, *args: Any, **kwargs: Any) -> Any:
        with message_units(self.units):
            return job(self, *args, **kwargs)

    return run  # type: ignore[return-value]


if TYPE_CHECKING:  # balancing and synthesis load scipy.optimize, dynamics and mobility take
    # limits 40 ms of start-up that analyze does not need (issue 30): imported where they are used
    from screwkit.balancing.config import BalancingConfig
    from screwkit.balancing.result import BalanceResult
    from screwkit.dynamics import Dynamics
    from screwkit.kinematics.analysis.limit_positions import LimitPositions
    from screwkit.kinematics.analysis.loop_mobility import LinkageMobility
    from screwkit.synthesis.config import SynthesisConfig, SynthesisRun


class Pipeline:
    """The jobs of one spec, sharing one solved motion.

    ``method`` chooses the solver (``"auto"``, ``"closed"``, ``"generic"``; see
    :func:`~screwkit.kinematics.solve_motion.solve_motion`); ``progress`` is the solver's
    progress (a callback ``(done, total)``, ``False`` for none, ``None`` its default bar).
    ``units``: the display units of the numbers in notes and error messages (default: the
    spec's ``[units]``, ``spec.display_units()``; the CLI passes those of ``--units``/``--unit``)."""

    def __init__(self, spec: Spec, *, method: str = "auto",
                 progress: Callable[[int, int], None] | bool | None = None,
                 units: UnitChoice | None = None) -> None:
        if getattr(spec, "family", None) == "graph":  # io.mechanism_spec.GraphSpec
            raise SpecError(f"{spec.path}: a mechanism graph (bodies and joints) is not run by "
                            "a Pipeline: from Python use screwkit.kinematics.graph.motion."
                            "solve_mechanism and screwkit.balancing.graph.balance_mechanism; the "
                            "CLI's validate, analyze, mobility, limits, report, dynamics, sweep, "
                            "tolerance, balance, simulate, export-mjcf and export take it; synthesis of "
                            "graphs is not there yet (docs/mechanisms.md)")
        expect_instance(spec, Spec, "Pipeline: spec", "a Spec (sk.load_spec(path))")
        if method not in ("auto", "closed", "generic"):
            raise InputError(f"Pipeline: method must be 'auto', 'closed' or 'generic'; got "
                             f"{method!r}")
        self.spec = spec
        self.method = method
        self.progress = progress
        self._units = units

    @cached_property
    def units(self) -> UnitChoice:
        """The display units of notes and messages (``units=``, else the spec's)."""
        return self._units if self._units is not None else self.spec.display_units()

    @cached_property
    def motion(self) -> Motion:
        """Every assembly mode over the spec's ``[motion]`` sweep (solved on first use only)."""
        return self._solve()

    @_in_spec_units
    def _solve(self) -> Motion:
        s = self.spec
        return solve_motion(s.linkage, s.inputs, rates=s.speed, accelerations=s.acceleration,
                            method=self.method, progress=self.progress)

    @property
    def gravity_vector(self) -> np.ndarray:
        """The spec's gravity (magnitude along ``gravity_direction``), m/s²."""
        g = self.spec.gravity_magnitude or STANDARD_GRAVITY
        return np.asarray(g * self.spec.gravity_direction, dtype=float)

    @_in_spec_units
    def mode(self) -> ModeMotion:
        """The assembly mode of ``[motion] mode`` (what dynamics and balancing use)."""
        try:
            return self.motion.mode(self.spec.mode)
        except AssemblyError as exc:
            raise SpecError(f"{self.spec.path}: [motion.mode] {exc}") from None

    def not_assembling(self, mode: ModeMotion) -> str | None:
        """A sentence naming, in the spec's units, the inputs where ``mode`` does not assemble
        or is singular; None if it assembles everywhere."""
        ok = np.asarray(mode.assembles) & ~np.asarray(mode.singular)
        if ok.all():
            return None
        s = self.spec
        x = np.asarray(s.inputs, dtype=float).reshape(len(ok), -1)[:, 0]
        label, factor = self.units.unit_of("angle" if s.input_is_angle else "length")
        bad = x[~ok] / factor
        listed = ", ".join(number(v) for v in bad[:8]) + (" …" if bad.size > 8 else "")
        return (f"mode {s.mode} does not assemble (or is singular) at {int(bad.size)} of "
                f"{ok.size} inputs ({listed} {label})")

    @_in_spec_units
    def dynamics(self, gravity: bool = False) -> Dynamics:
        """Shaking force and moment, joint reactions and input efforts of ``[motion] mode``
        (loads are null where the mode does not assemble)."""
        from screwkit.dynamics import inverse_dynamics

        s = self.spec
        missing = [link.name for link in s.linkage.links if link.mass is None]
        if missing:
            raise SpecError(f"{s.path}: dynamics needs mass properties for every link; add "
                            f"[links.{missing[0]}] (missing for {listing(missing)}; see "
                            "docs/spec-format.md)")
        mode = self.mode()
        partial = self.not_assembling(mode) is not None
        return inverse_dynamics(s.linkage, mode, self.gravity_vector if gravity else None,
                                inputs=s.inputs, allow_partial=partial)

    def balancing_config(self) -> BalancingConfig:
        from screwkit.balancing.errors import BalancingError

        if self.spec.balancing is None:
            raise BalancingError(f"{self.spec.path}: no [balancing] table; see docs/balancing.md")
        return self.spec.balancing

    @_in_spec_units
    def balance(self, mode: ModeMotion | None = None,
                progress: Callable[[int, int], None] | None = None) -> BalanceResult:
        """The spec's ``[balancing]`` run on ``[motion] mode`` (or on ``mode`` if given);
        ``progress(done, total)`` follows a Pareto sweep."""
        from screwkit.balancing.config import balance_with_config
        from screwkit.balancing.errors import BalancingError

        s = self.spec
        config = self.balancing_config()
        if mode is None:
            try:
                mode = self.mode()
            except SpecError as exc:
                raise BalancingError(str(exc)) from None
        problem = self.not_assembling(mode)
        if problem is not None:
            raise BalancingError(
                f"{s.path}: [motion] {problem}; balancing needs loads over the whole sweep. "
                "Change [motion] start/stop/step to a range where the mode assembles, choose "
                "another [motion] mode, or change the dimensions so that the linkage turns fully")
        return balance_with_config(s.linkage, mode, config, speed=s.speed,
                                   gravity=self.gravity_vector, inputs=s.inputs,
                                   progress=progress)

    def synthesis_config(self) -> SynthesisConfig:
        if self.spec.synthesis is None:
            raise SpecError(f"{self.spec.path}: no [synthesis] table; see docs/synthesis.md")
        return self.spec.synthesis

    @_in_spec_units
    def synthesize(self, starts: int | None = None,
                   progress: Callable[[int, int], None] | None = None) -> SynthesisRun:
        """The spec's ``[synthesis]`` run (either route), best result first;
        ``progress(done, total)`` follows a multistart."""
        from screwkit.synthesis.config import run_synthesis

        return run_synthesis(self.synthesis_config(), starts=starts, progress=progress)

    @_in_spec_units
    def limits(self, dwell_tolerance: float | None = None, at: list[float] | None = None, *,
               output: str | None = None, method: str | None = None,
               max_order: int | None = None) -> LimitPositions:
        """Limit positions and dwell orders of the loop's outputs (``at`` in radians, or metres
        for a translation input): Bagci App. D's closed form where it answers, else the generic
        route on the pipeline's motion. Arguments left out come from the spec's ``[limits]``."""
        from screwkit.kinematics.analysis.limit_positions import (
            LimitsConfig,
            limit_positions,
            uses_closed_form,
        )

        c = self.spec.limits or LimitsConfig()
        out = output if output is not None else c.output
        how = method if method is not None else c.method
        tol = dwell_tolerance if dwell_tolerance is not None else c.dwell_tolerance
        where = at if at is not None else list(c.at)
        order = max_order if max_order is not None else c.max_order
        closed = uses_closed_form(self.spec.linkage, out, how)
        source = self.spec.linkage if closed else self.motion
        return limit_positions(source, tol, order, where, output=out, method=how)

    @_in_spec_units
    def analysis(self) -> dict[str, Any]:
        """The analysis document (io/documents.py) of the pipeline's motion: every mode, the
        spec's coupler points and the transmission quality (a note where a loop has none)."""
        from screwkit.io.documents import analysis_document

        tr, note = self._transmission
        return analysis_document(self.motion, name=self.spec.name,
                                 coupler_points=self.spec.coupler_points, transmission=tr,
                                 transmission_note=note)

    @_in_spec_units
    def analysis_table(self) -> ResultTable:
        """The motion as a column table (``Motion.table``) with the spec's coupler points and
        the transmission quality (where the loop has one)."""
        tr, _ = self._transmission
        return self.motion.table(coupler_points=self.spec.coupler_points, transmission=tr)

    @_in_spec_units
    def transmission(self) -> Transmission:
        """Transmission index, angle and ball-joint cone angles over every mode (a ValueError
        says why a loop has none); computed once per pipeline, like the motion."""
        tr, why = self._transmission_or_why
        if tr is None:
            raise why  # type: ignore[misc]
        return tr

    @property
    def _transmission(self) -> tuple[Transmission | None, str | None]:
        tr, why = self._transmission_or_why
        return tr, None if why is None else str(why)

    @cached_property
    def _transmission_or_why(self) -> tuple[Transmission | None, ScrewkitError | None]:
        """The transmission of the motion, or None and the error saying why the loop has none
        (the analysis document and table share one computation)."""
        try:
            return transmission(self.motion), None
        except ScrewkitError as exc:
            return None, exc

    @_in_spec_units
    def coupler_curves(self) -> list[dict[str, Array]]:
        """Per mode, the world path (N, 3) of every coupler point of the spec, by name."""
        from screwkit.kinematics.analysis.coupler_curves import coupler_curves

        return coupler_curves(self.motion, self.spec.coupler_points)

    @_in_spec_units
    def export(self, fmt: str, at: Sequence[str] = (), *, mode: int | None = None,
               splines: bool = False, binary: bool = True, max_points: int = 5000) -> Any:
        """A CAD exchange file of the spec (:mod:`screwkit.exchange`, docs/exchange.md): DXF
        curves and the skeleton at the ``at`` inputs (text in the spec's unit of the input),
        the animated glTF scene of ``mode`` (GLB, or glTF JSON if not ``binary``), or STEP link
        solids of ``mode`` at the ``at`` inputs (the ``[step]`` extra). Inputs off the sweep
        are solved with it, in one solve; otherwise the pipeline's motion is used."""
        from screwkit.exchange.export import export_format, export_motion, samples_for

        kind = export_format(fmt)
        samples, labels = samples_for(self.spec, at)
        if len(samples.inputs) == len(self.spec.inputs):
            motion = self.motion
        else:
            s = self.spec
            motion = solve_motion(s.linkage, samples.inputs, rates=s.speed,
                                  accelerations=s.acceleration, method=self.method)
        return export_motion(self.spec, motion, samples, kind, at_labels=labels, mode=mode,
                             splines=splines, binary=binary, max_points=max_points)

    @_in_spec_units
    def simulate(self, fluctuation: float | None = None, cycles: int | None = None) -> Any:
        """The spec's ``[drive]`` run forward in time (docs/simulation.md): a
        :class:`~screwkit.simulation.spec_run.SpecSimulation`; with ``fluctuation`` the
        flywheel is first sized for that coefficient of speed fluctuation."""
        from screwkit.simulation.spec_run import simulate_spec

        return simulate_spec(self.spec, fluctuation=fluctuation, cycles=cycles)

    @_in_spec_units
    def mobility(self) -> LinkageMobility:
        """Formula and Jacobian mobility at the first input where the loop assembles."""
        from screwkit.kinematics.analysis.loop_mobility import mobility

        return mobility(self.spec.linkage, self.spec.inputs)


def balance_from_spec(spec: Spec, *, mode_motion: ModeMotion | None = None) -> BalanceResult:
    """Run the balancing of a loaded spec's ``[balancing]`` table on ``[motion] mode`` (or on
    ``mode_motion``, which skips the kinematics)."""
    return Pipeline(spec).balance(mode_motion)

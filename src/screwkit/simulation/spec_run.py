"""``screwkit simulate`` on a spec: its ``[drive]`` table, ``[motion]`` start and mode, gravity,
and optionally flywheel sizing (docs/simulation.md). The CLI and the report call
:func:`simulate_spec` and format what it returns."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.constants import STANDARD_GRAVITY
from screwkit.io.drive_table import DriveConfig
from screwkit.io.errors import SpecError
from screwkit.io.spec import Spec
from screwkit.simulation.drive import EquationOfMotion, equation_of_motion
from screwkit.simulation.flywheel import FlywheelSizing, size_flywheel, with_flywheel
from screwkit.simulation.integrate import simulate_cycles
from screwkit.simulation.result import Simulation


@dataclass(frozen=True, eq=False)
class SpecSimulation:
    """A spec's simulation: the ``simulation`` (with the ``[drive]`` flywheel, or the sized
    one), the ``sizing`` when a fluctuation was asked for, and the ``drive`` used."""

    spec: Spec
    drive: DriveConfig
    simulation: Simulation
    sizing: FlywheelSizing | None

    def as_dict(self, *, loads: bool = True) -> dict[str, Any]:
        d = self.drive
        doc: dict[str, Any] = {
            "name": self.spec.name, "spec": self.spec.path,
            "drive": {"motor": vars(d.motor), "load": None if d.load is None else vars(d.load),
                      "flywheel": d.flywheel, "initial_speed": d.initial_speed,
                      "cycles": d.cycles, "samples_per_cycle": d.samples_per_cycle,
                      "rtol": d.rtol, "atol": d.atol, "gravity": d.gravity,
                      "max_time": d.max_time,
                      "friction": {f.joint: {"rotation": f.rotation,
                                             "translation": f.translation}
                                   for f in d.friction}},
            **self.simulation.as_dict(loads=loads),
        }
        if self.sizing is not None:
            doc["flywheel_sizing"] = self.sizing.as_dict()
        return doc


def spec_gravity(spec: Spec) -> np.ndarray:
    """The spec's gravity vector (m/s²): ``gravity`` (default g₀) along ``gravity_direction``."""
    g = spec.gravity_magnitude or STANDARD_GRAVITY
    return np.asarray(g * spec.gravity_direction, dtype=float)


def spec_equation_of_motion(spec: Spec, drive: DriveConfig | None = None) -> EquationOfMotion:
    """The reduced equation of motion of a spec's ``[motion] mode`` from its ``[motion] start``."""
    d = drive if drive is not None else spec.drive
    if d is None:
        raise SpecError(f"{spec.path}: no [drive] table; add one to simulate (the motor, "
                        "flywheel and load; docs/simulation.md)")
    return equation_of_motion(spec.linkage, d, mode=spec.mode, start=float(spec.inputs[0]),
                              gravity=spec_gravity(spec))


def simulate_spec(spec: Spec, *, fluctuation: float | None = None, cycles: int | None = None,
                  flywheel: float | None = None) -> SpecSimulation:
    """Simulate a spec's ``[drive]`` for ``cycles`` (default the table's) from its initial
    speed; with ``fluctuation`` first size the flywheel for that steady coefficient of speed
    fluctuation and simulate with it; ``flywheel`` (kg·m²) overrides the table's."""
    eom = spec_equation_of_motion(spec)
    d = spec.drive
    assert d is not None
    if flywheel is not None:
        eom = with_flywheel(eom, flywheel)
    sizing = None
    if fluctuation is not None:
        sizing = size_flywheel(eom, fluctuation, d.initial_speed)
        eom = with_flywheel(eom, sizing.flywheel)
    run = simulate_cycles(eom, cycles=cycles or d.cycles, initial_speed=d.initial_speed,
                          rtol=d.rtol, atol=d.atol, max_time=d.max_time)
    return SpecSimulation(spec, d, Simulation(run, d.samples_per_cycle), sizing)

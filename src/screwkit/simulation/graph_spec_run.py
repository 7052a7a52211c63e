"""``screwkit simulate`` and ``export-mjcf`` on a mechanism-graph spec: its ``[drive]`` table
(io/graph_drive.py), its first ``[motion]`` row as the start, its gravity
(docs/simulation.md, "Graphs"). The CLI calls these and formats what they return."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.io.graph_drive import GraphDriveConfig, graph_drive_config
from screwkit.simulation.graph_cycles import (
    GraphCycles,
    GraphFlywheelSizing,
    simulate_graph_cycles,
    size_graph_flywheel,
    with_graph_flywheel,
)
from screwkit.simulation.graph_eom import GraphEquationOfMotion
from screwkit.simulation.graph_run import GraphSimulation, simulate_graph
from screwkit.tables import Column, ResultTable


@dataclass(frozen=True, eq=False)
class GraphSpecSimulation:
    """A graph spec's run: the ``simulation`` with the ``drive`` it used."""

    spec: Any
    drive: GraphDriveConfig
    simulation: GraphSimulation

    def as_dict(self) -> dict[str, Any]:
        d = self.drive
        return {"name": self.spec.name, "spec": self.spec.path,
                "drive": {"duration": d.duration, "samples": d.samples,
                          "initial_rates": dict(zip(self.spec.mechanism.inputs,
                                                    d.initial_rates, strict=True)),
                          "flywheel": dict(zip(self.spec.mechanism.inputs, d.flywheel,
                                               strict=True)),
                          "motors": {n: vars(m) for n, m in
                                     zip(self.spec.mechanism.inputs, d.motors, strict=True)},
                          "friction": {f.joint: {"rotation": f.rotation,
                                                 "translation": f.translation}
                                       for f in d.friction},
                          "gravity": d.gravity, "rtol": d.rtol, "atol": d.atol,
                          "load": None if d.load is None else vars(d.load),
                          "point_force": None if d.point_force is None else
                          {"point": d.point_force[0], "force": list(d.point_force[1])}},
                **self.simulation.as_dict()}


def graph_spec_equation_of_motion(spec: Any, drive: GraphDriveConfig | None = None,
                                  flywheel: float | None = None) -> GraphEquationOfMotion:
    """The equations of motion of a graph spec with its ``[drive]`` (``flywheel`` overrides
    the table's on every input)."""
    d = drive if drive is not None else graph_drive_config(spec)
    return GraphEquationOfMotion(
        spec.mechanism, motors=d.motors,
        flywheel=d.flywheel if flywheel is None else flywheel, friction=d.friction,
        gravity=spec.gravity_vector if d.gravity else None, load=d.load,
        point_force=d.point_force)


def simulate_graph_spec(spec: Any, *, duration: float | None = None,
                        flywheel: float | None = None) -> GraphSpecSimulation:
    """Run a graph spec's ``[drive]`` from its first ``[motion]`` row for ``duration`` (default
    the table's) seconds."""
    d = graph_drive_config(spec)
    eom = graph_spec_equation_of_motion(spec, d, flywheel)
    run = simulate_graph(eom, duration=duration or d.duration, samples=d.samples,
                         initial_inputs=spec.inputs[0], initial_rates=d.initial_rates,
                         rtol=d.rtol, atol=d.atol)
    return GraphSpecSimulation(spec, d, run)


@dataclass(frozen=True, eq=False)
class GraphSpecCycles:
    """A graph spec's crank cycles (``--cycles`` / ``--fluctuation``): the ``run`` with the
    ``[drive]`` flywheel or the sized one, the ``sizing`` when a fluctuation was asked for."""

    spec: Any
    drive: GraphDriveConfig
    run: GraphCycles
    sizing: GraphFlywheelSizing | None

    def as_dict(self) -> dict[str, Any]:
        doc = {"name": self.spec.name, "spec": self.spec.path, **self.run.as_dict()}
        if self.sizing is not None:
            doc["flywheel_sizing"] = self.sizing.as_dict()
        return doc


def simulate_graph_spec_cycles(spec: Any, *, cycles: int | None = None,
                               fluctuation: float | None = None,
                               flywheel: float | None = None,
                               samples_per_cycle: int = 0) -> GraphSpecCycles:
    """``cycles`` turns (default 10) of a one-input graph spec's crank from its first
    ``[motion]`` row at the ``[drive] initial_speed``; with ``fluctuation`` first size the
    flywheel for that steady C_s (simulation/graph_cycles.py) and run with it;
    ``samples_per_cycle`` keeps samples of every cycle (``run.samples``, for ``--plot``)."""
    d = graph_drive_config(spec)
    eom = graph_spec_equation_of_motion(spec, d, flywheel)
    x0 = float(np.asarray(spec.inputs[0], dtype=float).reshape(-1)[0])
    w0 = float(d.initial_rates[0]) if d.initial_rates else 0.0
    sizing = None
    if fluctuation is not None:
        sizing = size_graph_flywheel(eom, fluctuation, w0, initial_input=x0, rtol=d.rtol)
        eom = with_graph_flywheel(eom, sizing.flywheel)
    run = simulate_graph_cycles(eom, cycles=cycles or DEFAULT_CYCLES, initial_rate=w0,
                                initial_input=x0, rtol=d.rtol, atol=d.atol,
                                samples_per_cycle=samples_per_cycle)
    return GraphSpecCycles(spec, d, run, sizing)


#: crank cycles of a graph spec when ``--fluctuation`` is given without ``--cycles``
DEFAULT_CYCLES = 3


def graph_cycles_table(run: GraphCycles) -> ResultTable:
    """One row per completed cycle (``screwkit simulate --cycles --csv``)."""
    st = run.statistics
    kinds = {"period": "time", "mean_speed": "angular_velocity",
             "min_speed": "angular_velocity", "max_speed": "angular_velocity",
             "fluctuation": "ratio", "motor_work": "energy", "friction_work": "energy",
             "load_work": "energy", "motor_torque_rms": "moment", "motor_torque_peak": "moment"}
    cols = [Column("cycle", "ratio", np.arange(1, run.cycles + 1, dtype=float)),
            Column("end_time", "time", run.cycle_times[1:])]
    cols += [Column(k, kinds[k], st[k]) for k in kinds]
    return ResultTable(tuple(cols), f"crank cycles of {run.input_name}: one row per cycle")


def graph_simulation_table(sim: GraphSimulation) -> ResultTable:
    """The samples as a table (``screwkit simulate --csv``): time, every input's value, rate,
    acceleration, motor and friction effort, the energies and works, the closure residual."""
    cols = [Column("time", "time", sim.time)]
    for k, name in enumerate(sim.input_names):
        slide = name.endswith(".s")
        kinds = (("length", "velocity", "acceleration", "force") if slide else
                 ("angle", "angular_velocity", "angular_acceleration", "moment"))
        cols += [Column(name, kinds[0], sim.inputs[:, k]),
                 Column(f"{name}.rate", kinds[1], sim.rates[:, k]),
                 Column(f"{name}.acceleration", kinds[2], sim.accelerations[:, k]),
                 Column(f"{name}.motor", kinds[3], sim.motor[:, k]),
                 Column(f"{name}.friction", kinds[3], sim.friction[:, k])]
        if sim.load is not None:
            cols.append(Column(f"{name}.load", kinds[3], sim.load[:, k]))
    cols += [Column("kinetic_energy", "energy", sim.kinetic_energy),
             Column("potential_energy", "energy", sim.potential_energy),
             Column("motor_work", "energy", sim.motor_work),
             Column("friction_work", "energy", sim.friction_work),
             *([] if sim.load_work is None or sim.output_force is None else
               [Column("load_work", "energy", sim.load_work),
                Column("output_force", "force" if str(sim.load_freedom).endswith(".s")
                       else "moment", sim.output_force)]),
             Column("closure_residual", "ratio", np.asarray(sim.closure_residual))]
    return ResultTable(tuple(cols), "simulation of a mechanism graph: one row per sample")

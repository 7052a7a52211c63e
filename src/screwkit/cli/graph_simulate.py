"""``screwkit simulate`` and ``screwkit export-mjcf`` on a mechanism graph (docs/simulation.md,
"Graphs"): the terminal view of a graph run, and the MuJoCo export of a graph spec."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from screwkit.cli.common import prose

#: samples of every crank cycle kept for ``simulate --cycles --plot`` (a loop's [drive]
#: samples_per_cycle default)
PLOT_SAMPLES_PER_CYCLE = 72


def simulate_graph_cli(s: Any, out: Any, *, flywheel: float | None, fluctuation: float | None,
                       cycles: int | None, plot: Path | None) -> None:
    """Run a graph spec's ``[drive]`` and deliver it (JSON, CSV, terminal): for ``[drive]
    duration``, or with ``--cycles``/``--fluctuation`` for crank cycles (one rotating input)."""
    from screwkit.cli.common import guard
    from screwkit.messages import message_units
    from screwkit.simulation.graph_spec_run import graph_simulation_table, simulate_graph_spec

    du = out.units_for(s.units)
    if cycles is not None or fluctuation is not None:
        _cycles_cli(s, out, du, flywheel=flywheel, fluctuation=fluctuation, cycles=cycles,
                    plot=plot)
        return
    with message_units(du):
        run = guard(lambda: simulate_graph_spec(s, flywheel=flywheel))
    doc = guard(lambda: run.as_dict())
    if plot is not None:
        from screwkit.report.simulation_plots import write_graph_simulation_png

        guard(lambda: write_graph_simulation_png(doc, plot))
        out.note_written(plot)
    out.deliver(document=lambda: doc, table=lambda: graph_simulation_table(run.simulation),
                show=lambda: _show(s, run.simulation, du), units=du)


def _cycles_cli(s: Any, out: Any, du: Any, *, flywheel: float | None,
                fluctuation: float | None, cycles: int | None, plot: Path | None) -> None:
    from screwkit.cli.common import guard, user_error
    from screwkit.messages import message_units
    from screwkit.simulation.graph_spec_run import graph_cycles_table, simulate_graph_spec_cycles

    keep = 0 if plot is None else PLOT_SAMPLES_PER_CYCLE
    with message_units(du):
        run = guard(lambda: simulate_graph_spec_cycles(s, cycles=cycles,
                                                       fluctuation=fluctuation,
                                                       flywheel=flywheel,
                                                       samples_per_cycle=keep))
    doc = guard(lambda: run.as_dict())
    if plot is not None and run.run.cycles == 0:
        user_error(f"{s.path}: --plot: no cycle was completed ({run.run.message}); nothing "
                   "to draw")
    if plot is not None:
        from screwkit.report.simulation_plots import write_graph_cycles_png

        samples = run.run.samples
        guard(lambda: write_graph_cycles_png(doc, samples or {}, plot))
        out.note_written(plot)
    out.deliver(document=lambda: doc, table=lambda: graph_cycles_table(run.run),
                show=lambda: _show_cycles(s, run, du), units=du)


def _show_cycles(s: Any, cyc: Any, units: Any) -> None:
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import TextColumn, number, print_columns

    run = cyc.run
    iu = units.pretty("inertia")
    prose(f"[bold]{escape(s.describe(units))}[/]")
    prose(f"{escape(run.message)} ({run.status}); crank {escape(run.input_name)}, flywheel "
          f"{number(units.show('inertia', run.flywheel))} {iu}; energy balance error "
          f"{run.energy_error:.2g}")
    st = run.statistics
    rpm = 60.0 / (2.0 * np.pi)
    rows = range(run.cycles)
    tu = units.pretty("moment")
    print_columns(console, "per cycle", [
        TextColumn("cycle", [str(k + 1) for k in rows]),
        TextColumn("period\n[s]", [number(st["period"][k]) for k in rows]),
        *[TextColumn(f"{h}\n[rpm]", [number(st[key][k] * rpm) for k in rows])
          for h, key in (("mean", "mean_speed"), ("min", "min_speed"), ("max", "max_speed"))],
        TextColumn("C_s", [number(st["fluctuation"][k]) for k in rows]),
        *[TextColumn(f"{h}\nwork [J]", [number(st[key][k]) for k in rows])
          for h, key in (("motor", "motor_work"), ("load", "load_work"),
                         ("friction", "friction_work"))],
        TextColumn(f"motor τ\nRMS [{tu}]",
                   [number(units.show("moment", st["motor_torque_rms"][k])) for k in rows])])
    if cyc.sizing is not None:
        z = cyc.sizing
        prose(f"flywheel for C_s = {z.requested:g}: [bold]"
              f"{number(units.show('inertia', z.flywheel))} {iu}[/] (steady C_s "
              f"{z.achieved:.6g}, {len(z.iterations)} steady-state searches)")


def _show(s: Any, sim: Any, units: Any) -> None:
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import TextColumn, number, print_columns

    prose(f"[bold]{escape(s.describe(units))}[/]")
    prose(f"{escape(sim.message)} ({sim.status}); {sim.time.size} samples; energy balance "
          f"error {sim.energy_error:.2g}; largest closure residual "
          f"{float(np.max(sim.closure_residual)):.2g}")
    rows = np.unique(np.linspace(0, sim.time.size - 1, min(sim.time.size, 11)).astype(int))
    cols = [TextColumn(f"t\n[{units.pretty('time')}]",
                       [number(units.show("time", sim.time[i])) for i in rows])]
    for k, name in enumerate(sim.input_names):
        kind, rate = (("length", "velocity") if name.endswith(".s")
                      else ("angle", "angular_velocity"))
        cols.append(TextColumn(f"{name}\n[{units.pretty(kind)}]",
                               [number(units.show(kind, sim.inputs[i, k])) for i in rows]))
        cols.append(TextColumn(f"rate\n[{units.pretty(rate)}]",
                               [number(units.show(rate, sim.rates[i, k])) for i in rows]))
    energy = sim.kinetic_energy + sim.potential_energy - sim.potential_energy[0]
    cols.append(TextColumn(f"T + V\n[{units.pretty('energy')}]",
                           [number(units.show("energy", energy[i])) for i in rows]))
    print_columns(console, "the run (every input, and the energy)", cols)


def export_graph_mjcf(s: Any, output: Path, spec_path: Path, gravity: bool | None,
                      timestep: float) -> None:
    """Write a graph spec as a MuJoCo model (simulation/graph_mjcf.py)."""
    from rich.markup import escape

    from screwkit.cli.common import console, guard
    from screwkit.io.graph_drive import graph_drive_config
    from screwkit.io.results import write_atomic
    from screwkit.simulation.graph_mjcf import graph_mjcf_model

    drive = guard(lambda: graph_drive_config(s)) if s.raw.drive is not None else None
    with_gravity = (drive.gravity if drive is not None else True) if gravity is None else gravity
    text = guard(lambda: graph_mjcf_model(
        s.mechanism, gravity=s.gravity_vector if with_gravity else None, timestep=timestep,
        solref=(20 * timestep, 1.0), friction=drive.friction if drive else (),
        flywheel=drive.flywheel if drive else None, start=s.inputs[0]))
    guard(lambda: write_atomic(output, text, [spec_path], "--output"))
    g = (f"gravity {float(np.linalg.norm(s.gravity_vector)):.6g} m/s²" if with_gravity
         else "no gravity")
    console.print(f"wrote {escape(str(output))} (the drawn configuration, keyframe 'start' at "
                  f"the first {escape('[motion]')} row; a motor on each input; {g})",
                  highlight=False)

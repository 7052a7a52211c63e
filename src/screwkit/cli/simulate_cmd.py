"""``screwkit simulate SPEC``: run the machine of a spec's ``[drive]`` table — motor, flywheel,
load — by forward dynamics; report the speed fluctuation, the motor torque, the energy per cycle
and every load of the loop; ``--fluctuation δ`` sizes the flywheel (docs/simulation.md).
Registered on the main app by ``register(app)``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from screwkit.cli.common import prose
from screwkit.cli.outputs import JsonOpt, OutputOpt, UnitOpt, UnitsOpt

RPM = 60.0 / (2.0 * 3.141592653589793)


def _table(doc: dict[str, Any], describe: str, units: Any) -> None:
    """The terminal view: per cycle (speeds in rpm, torques and work in the display units),
    the flywheel sizing, the loads; tables fitted to the width."""
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import TextColumn, number, print_columns

    prose(f"[bold]{escape(describe)}[/]")
    m = doc["model"]
    iu = units.pretty("inertia")

    def inertia(si: float) -> str:
        return number(units.show("inertia", si))

    prose(f"{escape(doc['message'])} ({doc['status']}); flywheel {inertia(doc['flywheel'])} "
          f"{iu}; J(θ) {inertia(m['inertia_min'])}…{inertia(m['inertia_max'])} {iu} (mean "
          f"{inertia(m['inertia_mean'])}), {m['harmonics']} harmonics on {m['grid_samples']} "
          f"samples; energy balance error {doc['energy_error']:.2g}")
    cycles = doc["cycles"]
    shown = cycles if len(cycles) <= 12 else cycles[:5] + cycles[-5:]
    tu = units.pretty("moment")

    def col(head: str, key: str, scale: float = 1.0, kind: str | None = None) -> TextColumn:
        return TextColumn(head, [number(units.show(kind, c[key]) if kind else c[key] * scale)
                                 for c in shown])

    print_columns(console, "per cycle" + (f" (first and last 5 of {len(cycles)})"
                                          if len(shown) < len(cycles) else ""), [
        TextColumn("cycle", [str(c["cycle"]) for c in shown]),
        col("period\n[s]", "period"), col("mean\n[rpm]", "mean_speed", RPM),
        col("min\n[rpm]", "min_speed", RPM), col("max\n[rpm]", "max_speed", RPM),
        col("C_s", "fluctuation"), col("motor\nwork [J]", "motor_work"),
        col("load\nwork [J]", "load_work"),
        *([col("friction\nwork [J]", "friction_work")]
          if any(c.get("friction_work") for c in shown) else []),
        col(f"motor τ\nRMS [{tu}]", "motor_torque_rms", kind="moment"),
        col(f"motor τ\npeak [{tu}]", "motor_torque_peak", kind="moment")])
    sizing = doc.get("flywheel_sizing")
    if sizing:
        em = sizing["energy_method"]
        prose(f"flywheel for C_s = {sizing['requested_fluctuation']:g}: "
              f"[bold]{inertia(sizing['flywheel'])} {iu}[/] (steady C_s "
              f"{sizing['achieved_fluctuation']:.6g}); energy method: ΔE "
              f"{em['energy_fluctuation']:.6g} J at {em['speed'] * RPM:.6g} rpm → "
              f"{inertia(em['flywheel'])} {iu}")
    loads = doc.get("loads")
    if loads:
        from screwkit.cli.dynamics_cmd import summary_kind

        names = list(loads["summary"])
        stats = [loads["summary"][n] for n in names]
        print_columns(console, "loads over the simulated motion (vectors by magnitude)", [
            TextColumn("quantity", names, "left"),
            TextColumn("unit", [units.pretty(summary_kind(n)) for n in names], "left"),
            TextColumn("RMS", [number(units.show(summary_kind(n), st["rms"]))
                               for n, st in zip(names, stats, strict=True)]),
            TextColumn("peak", [number(units.show(summary_kind(n), st["peak"]))
                                for n, st in zip(names, stats, strict=True)])])
        prose(f"shaft torque: inverse dynamics vs motor − flywheel·θ̈, max difference "
              f"{doc['shaft_torque_check']:.2g} of the largest")


def register(app: typer.Typer) -> None:
    """Add the ``simulate`` command to ``app``."""

    @app.command()
    def simulate(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with mass properties and a [drive] table.")],
        as_json: JsonOpt = False,
        output: OutputOpt = None,
        csv: Annotated[Path | None, typer.Option("--csv", help="Write the samples (motion, torques, energy, every load with its point of application) as CSV, units in the headers.")] = None,
        units: UnitsOpt = "spec",
        unit: UnitOpt = None,
        plot: Annotated[Path | None, typer.Option("--plot", help="Write speed and torque plots (.png, .svg or .pdf; needs matplotlib).")] = None,
        fluctuation: Annotated[float | None, typer.Option("--fluctuation", help="Size the flywheel for this steady coefficient of speed fluctuation (e.g. 0.02), then simulate with it.")] = None,
        cycles: Annotated[int | None, typer.Option("--cycles", help="Cycles to simulate (default: [drive] cycles).", min=1, max=100000)] = None,
        flywheel: Annotated[str | None, typer.Option("--flywheel", help="Flywheel inertia on the input shaft, e.g. \"0.02 kg*m^2\" (overrides [drive] flywheel).")] = None,
    ) -> None:
        """Forward dynamics of the machine: motor, flywheel and load of the [drive] table; speed fluctuation, motor torque, energy per cycle and every load; --fluctuation sizes the flywheel. A mechanism graph: a motor per input (a force motor on a slide), flywheel, friction and a load over [drive] duration, the loops closed at every step; with one crank, --cycles and --fluctuation as for a loop (docs/simulation.md, "Graphs")."""
        from screwkit.cli.common import guard, loop_only, user_error
        from screwkit.cli.outputs import Outputs
        from screwkit.io.spec import load_spec
        from screwkit.io.units import to_si
        from screwkit.simulation.spec_run import simulate_spec
        from screwkit.simulation.tables import simulation_table

        out = Outputs.prepare([spec], as_json=as_json, output=output, csv=csv, units=units,
                              unit=unit, files={"--plot": plot})
        if plot is not None and plot.suffix.lower() not in (".png", ".svg", ".pdf"):
            user_error(f"--plot {plot}: give a file ending in .png, .svg or .pdf")
        fw = None if flywheel is None else guard(
            lambda: to_si(flywheel, "inertia", "kg*m**2"))
        from screwkit.messages import message_units

        s = guard(lambda: load_spec(spec))
        if getattr(s, "family", None) == "graph":
            from screwkit.cli.graph_simulate import simulate_graph_cli

            return simulate_graph_cli(s, out, flywheel=fw, fluctuation=fluctuation,
                                      cycles=cycles, plot=plot)
        s = loop_only(s, "simulate")
        du = out.units_for(s.units)
        with message_units(du):
            run = guard(lambda: simulate_spec(s, fluctuation=fluctuation, cycles=cycles,
                                              flywheel=fw))
        doc = guard(lambda: run.as_dict())
        if plot is not None:
            from screwkit.report.simulation_plots import write_simulation_png

            guard(lambda: write_simulation_png(doc, plot))
            out.note_written(plot)
        out.deliver(document=lambda: doc, table=lambda: simulation_table(run.simulation),
                    show=lambda: _table(doc, s.describe(du), du), units=du)

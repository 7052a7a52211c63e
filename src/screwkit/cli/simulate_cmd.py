"""``screwkit simulate SPEC``: run the machine of a spec's ``[drive]`` table — motor, flywheel,
load — by forward dynamics; report the speed fluctuation, the motor torque, the energy per cycle
and every load of the loop; ``--fluctuation δ`` sizes the flywheel (docs/simulation.md).
Registered on the main app by ``register(app)``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

RPM = 60.0 / (2.0 * 3.141592653589793)


def _table(doc: dict[str, Any], describe: str) -> None:
    from rich.markup import escape
    from rich.table import Table

    from screwkit.cli.common import console

    console.print(f"[bold]{escape(describe)}[/]", highlight=False)
    m = doc["model"]
    console.print(f"{escape(doc['message'])} ({doc['status']}); flywheel {doc['flywheel']:.6g} "
                  f"kg·m²; J(θ) {m['inertia_min']:.6g}…{m['inertia_max']:.6g} kg·m² (mean "
                  f"{m['inertia_mean']:.6g}), {m['harmonics']} harmonics on {m['grid_samples']} "
                  f"samples; energy balance error {doc['energy_error']:.2g}", highlight=False)
    t = Table(title="per cycle (speeds in rpm)")
    for col in ("cycle", "period (s)", "mean", "min", "max", "C_s", "motor work (J)",
                "load work (J)", "motor τ RMS (N·m)", "motor τ peak (N·m)"):
        t.add_column(col, justify="right")
    cycles = doc["cycles"]
    shown = cycles if len(cycles) <= 12 else cycles[:5] + cycles[-5:]
    for c in shown:
        t.add_row(str(c["cycle"]), f"{c['period']:.6g}", f"{c['mean_speed'] * RPM:.6g}",
                  f"{c['min_speed'] * RPM:.6g}", f"{c['max_speed'] * RPM:.6g}",
                  f"{c['fluctuation']:.4g}", f"{c['motor_work']:.6g}", f"{c['load_work']:.6g}",
                  f"{c['motor_torque_rms']:.6g}", f"{c['motor_torque_peak']:.6g}")
    console.print(t)
    sizing = doc.get("flywheel_sizing")
    if sizing:
        em = sizing["energy_method"]
        console.print(f"flywheel for C_s = {sizing['requested_fluctuation']:g}: "
                      f"[bold]{sizing['flywheel']:.6g} kg·m²[/] (steady C_s "
                      f"{sizing['achieved_fluctuation']:.6g}); energy method: ΔE "
                      f"{em['energy_fluctuation']:.6g} J at {em['speed'] * RPM:.6g} rpm → "
                      f"{em['flywheel']:.6g} kg·m²", highlight=False)
    loads = doc.get("loads")
    if loads:
        t2 = Table(title="loads over the simulated motion (SI: N, N·m)")
        for col in ("quantity", "RMS", "peak"):
            t2.add_column(col, justify="right")
        for name, st in loads["summary"].items():
            t2.add_row(name, f"{st['rms']:.6g}", f"{st['peak']:.6g}")
        console.print(t2)
        console.print(f"shaft torque: inverse dynamics vs motor − flywheel·θ̈, max difference "
                      f"{doc['shaft_torque_check']:.2g} of the largest", highlight=False)


def register(app: typer.Typer) -> None:
    """Add the ``simulate`` command to ``app``."""

    @app.command()
    def simulate(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with mass properties and a [drive] table.")],
        as_json: Annotated[bool, typer.Option("--json", help="Print one JSON document (SI units) instead of tables.")] = False,
        output: Annotated[Path | None, typer.Option("--output", "-o", help="Write the JSON document to this file (atomically).")] = None,
        csv: Annotated[Path | None, typer.Option("--csv", help="Write the samples (motion, torques, energy, every load) as CSV.")] = None,
        plot: Annotated[Path | None, typer.Option("--plot", help="Write speed and torque plots (.png, .svg or .pdf; needs matplotlib).")] = None,
        fluctuation: Annotated[float | None, typer.Option("--fluctuation", help="Size the flywheel for this steady coefficient of speed fluctuation (e.g. 0.02), then simulate with it.")] = None,
        cycles: Annotated[int | None, typer.Option("--cycles", help="Cycles to simulate (default: [drive] cycles).", min=1, max=100000)] = None,
        flywheel: Annotated[str | None, typer.Option("--flywheel", help="Flywheel inertia on the input shaft, e.g. \"0.02 kg*m^2\" (overrides [drive] flywheel).")] = None,
    ) -> None:
        """Forward dynamics of the machine: motor, flywheel and load of the [drive] table; speed fluctuation, motor torque, energy per cycle and every load; --fluctuation sizes the flywheel."""
        from screwkit.cli.common import check_paths, emit, guard
        from screwkit.io.results import write_atomic
        from screwkit.io.spec import load_spec
        from screwkit.io.units import to_si
        from screwkit.simulation.spec_run import simulate_spec
        from screwkit.simulation.tables import simulation_csv

        check_paths([spec], {"--output": output, "--csv": csv, "--plot": plot})
        if plot is not None and plot.suffix.lower() not in (".png", ".svg", ".pdf"):
            guard(lambda: (_ for _ in ()).throw(ValueError(
                f"--plot {plot}: give a file ending in .png, .svg or .pdf")))
        fw = None if flywheel is None else guard(
            lambda: to_si(flywheel, "inertia", "kg*m**2"))
        s = guard(lambda: load_spec(spec))
        run = guard(lambda: simulate_spec(s, fluctuation=fluctuation, cycles=cycles, flywheel=fw))
        doc = guard(lambda: run.as_dict())
        if csv is not None:
            guard(lambda: write_atomic(csv, simulation_csv(run.simulation), [spec], "--csv"))
        if plot is not None:
            from screwkit.report.simulation_plots import write_simulation_png

            guard(lambda: write_simulation_png(doc, plot))
        emit(doc, as_json, output, lambda: _table(doc, s.describe()), [spec])

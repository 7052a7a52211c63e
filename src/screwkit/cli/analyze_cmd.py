"""``screwkit analyze SPEC``: positions, velocities and accelerations of every joint variable
in every assembly mode, in the spec's units (tables, CSV, plots) or as the SI JSON document
(docs/cli.md). Registered on the main app by ``register(app)``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from screwkit.cli.outputs import CsvOpt, FullOpt, JsonOpt, OutputOpt, UnitOpt, UnitsOpt


def shown_variables(mode: Any, input_name: str) -> list[str]:
    """The variables a terminal table shows: the seed's (except the input), else the first four
    joint freedoms other than the input."""
    names = [n for n in mode.variables if "." not in n and n not in ("theta0", "theta1")]
    return names or [n for n in mode.variables if n != input_name][:4]


def show_analysis(spec: Any, motion: Any, units: Any, full: bool) -> None:
    """The terminal view: per mode, the input and each shown variable with its rate and
    acceleration in the display units; events; where the mode does not assemble."""
    import numpy as np
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import print_long_table, table_columns

    console.print(f"[bold]{escape(spec.describe(units))}[/]", highlight=False)
    console.print(f"method: {motion.method}; {units.describe()}", highlight=False)
    for note in motion.notes:
        console.print(f"[yellow]note:[/] {escape(note)}", highlight=False)
    whole = motion.table()
    for md in motion.modes:
        t = whole.where(whole.column("mode").values == md.index)
        names = ["input"]
        for n in shown_variables(md, motion.input_names[0]):
            names += [c for c in (n, f"{n}_dot", f"{n}_ddot") if c in t.names]
        cols, values = table_columns(t, names, units)
        print_long_table(console, f"assembly mode {md.index}", cols, values, full)
        for ev in md.events:
            console.print(f"  • {escape(ev)}", highlight=False)
        missing = int((~np.asarray(md.assembles)).sum())
        if missing:
            console.print(f"  • does not assemble at {missing} of {motion.samples} inputs",
                          highlight=False)


def register(app: typer.Typer) -> None:
    """Add the ``analyze`` command to ``app``."""

    @app.command()
    def analyze(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
        as_json: JsonOpt = False,
        output: OutputOpt = None,
        csv: CsvOpt = None,
        units: UnitsOpt = "spec",
        unit: UnitOpt = None,
        full: FullOpt = False,
        method: Annotated[str, typer.Option("--method", help="auto (closed form where the family has one), closed, or generic (any loop; every joint variable).")] = "auto",
        plot: Annotated[Path | None, typer.Option("--plot", help="Write a PNG of every variable and its rates over the input (display units), and the coupler curve projections.")] = None,
    ) -> None:
        """Positions, velocities and accelerations of every joint variable in every assembly mode."""
        from screwkit.cli.common import guard
        from screwkit.cli.outputs import Outputs
        from screwkit.io.documents import analysis_document
        from screwkit.io.spec import load_spec
        from screwkit.pipeline import Pipeline

        out = Outputs.prepare([spec], as_json=as_json, output=output, csv=csv, units=units,
                              unit=unit, full=full, files={"--plot": plot})
        s = guard(lambda: load_spec(spec))
        pipe = Pipeline(s, method=method)
        motion = guard(lambda: pipe.motion)
        du = out.units_for(s.units)

        def document() -> dict[str, Any]:
            return analysis_document(motion, name=s.name, coupler_point=s.coupler_point)

        if plot is not None:
            from screwkit.report.plots import plot_analysis

            guard(lambda: plot_analysis(document(), plot, units=du))
            out.note_written(plot)
        out.deliver(document=document, table=lambda: motion.table(s.coupler_point),
                    show=lambda: show_analysis(s, motion, du, out.full), units=du)

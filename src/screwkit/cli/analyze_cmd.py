"""``screwkit analyze SPEC``: positions, velocities and accelerations of every joint variable
in every assembly mode, in the spec's units (tables, CSV, plots) or as the SI JSON document
(docs/cli.md). Registered on the main app by ``register(app)``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer

from screwkit.cli.common import MODES_HELP, prose
from screwkit.cli.outputs import CsvOpt, FullOpt, JsonOpt, OutputOpt, UnitOpt, UnitsOpt

T = TypeVar("T")


def shown_variables(mode: Any, input_name: str) -> list[str]:
    """The variables a terminal table shows: the seed's (except the input), else the first four
    joint freedoms other than the input."""
    names = [n for n in mode.variables if "." not in n and n not in ("theta0", "theta1")]
    return names or [n for n in mode.variables if n != input_name][:4]


def transmission_lines(entry: dict[str, Any] | None, units: Any, input_kind: str) -> list[str]:
    """One line per transmission measure of a mode (its ``transmission`` entry in the analysis
    document): the minimum index of each output, the worst transmission angle, each ball
    joint's cone limit, with the input where it occurs, in ``units``."""
    if not entry:
        return []
    summary = entry["summary"]
    a = units.label("angle")

    def where(x: float | None) -> str:
        return "—" if x is None else f"{units.show(input_kind, x):.6g} {units.label(input_kind)}"

    lines = []
    for name, st in summary["index"].items():
        if st["value"] is not None:
            lines.append(f"transmission index of {name}: min {st['value']:.4f} at input "
                         f"{where(st['at'])}")
    if "angle" in summary and summary["angle"]["value"] is not None:
        st = summary["angle"]
        lines.append(f"transmission angle: worst {units.show('angle', st['value']):.6g} {a} from "
                     f"a dead centre at input {where(st['at'])}")
    for joint, st in summary["cone_limit"].items():
        lines.append(f"ball joint {joint}: cone limit {units.show('angle', st['value']):.6g} {a} "
                     f"(at input {where(st['at'])})")
    return lines


def show_analysis(spec: Any, motion: Any, units: Any, full: bool,
                  doc: dict[str, Any] | None = None, table: Any = None) -> None:
    """The terminal view: per mode, the input and each shown variable with its rate and
    acceleration in the display units, the coupler points' paths, the transmission summary;
    events; where the mode does not assemble."""
    import numpy as np
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import print_long_table, table_columns

    prose(f"[bold]{escape(spec.describe(units))}[/]")
    prose(f"method: {motion.method}; {units.describe()}")
    for note in motion.notes:
        prose(f"[yellow]note:[/] {escape(note)}")
    from screwkit.kinematics.motion_table import column_prefix, variable_kind

    whole = table if table is not None else motion.table()
    points = [column_prefix(cp.name) for cp in getattr(spec, "coupler_points", [])]
    input_kind = variable_kind(motion.input_names[0])
    for md in motion.modes:
        t = whole.where(whole.column("mode").values == md.index)
        names = ["input"]
        shown = shown_variables(md, motion.input_names[0])
        for n in shown:
            names += [c for c in (n, f"{n}_dot", f"{n}_ddot") if c in t.names]
        names += [f"{p}_{a}" for p in points for a in "xyz" if f"{p}_{a}" in t.names]
        cols, values = table_columns(t, names, units)
        print_long_table(console, f"assembly mode {md.index}", cols, values, full)
        # a joint list shows its first four freedoms (a family its seed's variables)
        hidden = [n for n in md.variables if n not in shown and n != motion.input_names[0]]
        if hidden and all("." in n for n in shown):
            prose(f"  • {len(shown)} of {len(shown) + len(hidden)} variables shown; "
                  f"the others ({', '.join(hidden[:4])}{', …' if len(hidden) > 4 else ''}) "
                  "are in --csv and --json")
        entry = doc["modes"][md.index].get("transmission") if doc is not None else None
        for line in transmission_lines(entry, units, input_kind):
            prose(f"  • {escape(line)}")
        for ev in md.events:
            prose(f"  • {escape(ev)}")
        missing = int((~np.asarray(md.assembles)).sum())
        if missing:
            prose(f"  • does not assemble at {missing} of {motion.samples} inputs")
    if doc is not None and "note" in doc.get("transmission", {}):
        prose(f"[yellow]transmission:[/] {escape(doc['transmission']['note'])}")


def cache(build: Callable[[], T]) -> Callable[[], T]:
    """``build`` run on the first call only; later calls return its result."""
    memo: list[T] = []

    def get() -> T:
        if not memo:
            memo.append(build())
        return memo[0]

    return get


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
        plot: Annotated[Path | None, typer.Option("--plot", help="Write a PNG of every variable and its rates over the input (display units), the coupler curves (projections and 3-D) and the transmission quality.")] = None,
        modes: Annotated[str, typer.Option("--modes", help=MODES_HELP)] = "every",
        check_count: Annotated[bool, typer.Option("--check-count", help="Put start solutions that monodromy found without a known count to the trace test, so that 'every mode' is shown complete (or the missing ones found): seconds for small systems, many minutes for large ones; once per topology, kept in the start-solution store (docs/kinematics.md).")] = False,
    ) -> None:
        """Positions, velocities and accelerations of every joint variable in every assembly mode, the coupler curves of the spec's coupler points and the transmission quality over the cycle."""
        from screwkit.cli.common import every_modes, guard
        from screwkit.cli.outputs import Outputs
        from screwkit.cli.progress import SWEEP_PROGRESS_SAMPLES, staged_progress
        from screwkit.io.spec import load_spec
        from screwkit.pipeline import Pipeline

        out = Outputs.prepare([spec], as_json=as_json, output=output, csv=csv, units=units,
                              unit=unit, full=full, files={"--plot": plot})
        s = guard(lambda: load_spec(spec))
        every = every_modes(modes, s)
        if getattr(s, "family", None) == "graph":  # any mechanism as a graph
            from screwkit.cli.graph_views import analyze_graph
            from screwkit.kinematics.modes.starts import count_check

            with count_check(check_count):
                return analyze_graph(s, out, plot, every_mode=every)
        du = out.units_for(s.units)
        stages = ["solving", "coupler curves and transmission", "tables"]
        # a long sweep shows its stages (stderr, terminals only; the solver's own bar is off);
        # the bar is gone before anything is printed on stdout. The document and the table are
        # built only when asked for: `-o out.npz` needs the table, never the document (issue 30)
        with staged_progress("analyze", stages,
                             enabled=len(s.inputs) >= SWEEP_PROGRESS_SAMPLES) as stage:
            pipe = guard(lambda: Pipeline(s, method=method, progress=stage("solving"), units=du))
            motion = guard(lambda: pipe.motion)
            doc = cache(lambda: guard(pipe.analysis))
            table = cache(lambda: guard(pipe.analysis_table))
            stage("coupler curves and transmission")
            if plot is not None or out.needs_document():
                doc()
            stage("tables")
            if out.needs_table():
                table()
        if plot is not None:
            from screwkit.report.plots import plot_analysis

            guard(lambda: plot_analysis(doc(), plot, units=du))
            out.note_written(plot)
        out.deliver(document=doc, table=table,
                    show=lambda: show_analysis(s, motion, du, out.full, doc(), table()),
                    units=du)

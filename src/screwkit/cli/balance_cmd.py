"""``screwkit balance SPEC``: optimum balancing from a spec file's [balancing] table
(docs/balancing.md): the normalised measures (Rahman eq. 4.1), the RMS loads they stand for in
N and N·m, the design variables with the bounds they press on, the link masses; ``--csv`` and
``-o`` get the per-sample loads before and after. ``register(app)`` adds the command."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from screwkit.cli.common import prose
from screwkit.cli.outputs import CsvOpt, FullOpt, JsonOpt, OutputOpt, UnitOpt, UnitsOpt


def direction_range(d: Any) -> str:
    """"range -0.05 … 0.1, relative units", with "unbounded" or "could not determine" for an
    end the linear programs did not give."""
    def end(value: float | None, side: str) -> str:
        if value is not None:
            return f"{value:.3g}"
        return "could not determine" if f"could not determine {side}" in d.extent else (
            "unbounded")
    return f"range {end(d.low, 'below')} … {end(d.high, 'above')}, relative units"


def _change(b: float, a: float) -> str:
    return "new" if b == 0 else f"{100.0 * (a - b) / b:+.3f}"


def show_balance(spec: Any, res: Any, doc: dict[str, Any], units: Any,
                 written: list[str]) -> None:
    """The terminal view: measures, RMS loads, variables (bounds flagged), link masses."""
    from rich.markup import escape

    from screwkit.balancing.measures import MEASURE_TITLES, MEASURES
    from screwkit.cli.common import console
    from screwkit.cli.formatting import TextColumn, noise_floor, number, print_columns

    prose(f"[bold]{escape(spec.describe(units))}[/]")
    gravity = "on" if res.dynamics_before.gravity_on else "off ([balancing] gravity = true adds it)"
    prose(escape(f"assembly mode {spec.mode}; gravity {gravity}"))
    keys = (*MEASURES, "G")
    ch = res.changes()
    # round-off zeros (a measure balanced away) print as 0: each row's own scale
    floor = {k: noise_floor([res.measures_before[k], res.measures_after[k]]) for k in keys}
    print_columns(console, "load measures, normalised mean squares (Rahman eq. 4.1)", [
        TextColumn("measure", [f"{MEASURE_TITLES.get(k, 'objective')} ({k})" for k in keys],
                   "left"),
        TextColumn("before", [number(res.measures_before[k], floor=floor[k]) for k in keys]),
        TextColumn("after", [number(res.measures_after[k], floor=floor[k]) for k in keys]),
        TextColumn("change %", ["n/a (round-off)" if ch[k] is None else f"{ch[k]:+.3f}"
                                for k in keys])])
    rms = doc["measures_rms"]
    rms_floor = {k: noise_floor([units.show(rms["kinds"][k], rms[s][k])
                                 for s in ("before", "after") if rms[s][k] is not None])
                 for k in MEASURES}
    print_columns(console, "RMS loads over the cycle", [
        TextColumn("load", [f"{MEASURE_TITLES[k]} ({k})" for k in MEASURES], "left"),
        TextColumn("unit", [units.label(rms["kinds"][k]) for k in MEASURES], "left"),
        TextColumn("before", [number(units.show(rms["kinds"][k], rms["before"][k]),
                                     floor=rms_floor[k]) for k in MEASURES]),
        TextColumn("after", [number(units.show(rms["kinds"][k], rms["after"][k]),
                                    floor=rms_floor[k]) for k in MEASURES]),
        TextColumn("change %", ["—" if rms["change_percent"][k] is None
                                else f"{rms['change_percent'][k]:+.3f}" for k in MEASURES])])
    bounds = {b["variable"]: b["bound"] for b in doc["active_bounds"]}
    kinds = ["mass_moment" if n.rsplit(".", 1)[-1] in ("mx", "my", "mz") else "mass"
             for n in res.names]
    print_columns(console, "design variables", [
        TextColumn("variable", list(res.names), "left"),
        TextColumn("unit", [units.label(k) for k in kinds], "left"),
        TextColumn("before", [number(units.show(k, b)) for k, b in zip(kinds, res.before,
                                                                       strict=True)]),
        TextColumn("after", [number(units.show(k, a)) for k, a in zip(kinds, res.after,
                                                                      strict=True)]),
        TextColumn("change %", [_change(b, a) for b, a in zip(res.before, res.after,
                                                              strict=True)]),
        TextColumn("bound", [f"at {bounds[n]}" if n in bounds else "" for n in res.names],
                   "left")])
    links = list(res.link_mass_before)
    word = "body" if getattr(spec, "family", None) == "graph" else "link"
    print_columns(console, f"{word} masses [{units.label('mass')}]", [
        TextColumn(word, links, "left"),
        TextColumn("before", [number(units.show("mass", res.link_mass_before[k]))
                              for k in links]),
        TextColumn("after", [number(units.show("mass", res.link_mass_after[k])) for k in links]),
        TextColumn("change %", [_change(res.link_mass_before[k], res.link_mass_after[k])
                                for k in links])])
    if bounds:
        prose("active bounds: " + "; ".join(
            escape(b["constraint"]) for b in doc["active_bounds"]))
    verdict = ("could not be determined" if res.unique is None
               else "yes" if res.unique else f"no ({len(res.directions)} free direction(s))")
    prose(f"unique optimum: {verdict}")
    for d in res.directions:
        combo = " ".join(f"{c:+.4g}·{name}" for name, c in d.direction.items())
        prose(escape(f"  free direction {combo} ({direction_range(d)})"))
    bound = doc.get("redistribution_bound")
    if bound:
        prose(f"bound over all consistent redistributions (SDP): G = "
              f"{bound['measures_after']['G']:.6g}")
    if "pareto" in doc:
        eff = sum(doc["pareto"]["efficient"])
        prose(f"Pareto sweep over {doc['pareto']['measures']}: "
              f"{len(doc['pareto']['values'])} weightings, {eff} non-dominated")
    for note in res.notes:
        prose(escape(f"note: {note}"))
    for p in written:
        console.print(f"wrote {escape(p)}", highlight=False)


def register(app: typer.Typer) -> None:
    """Add the ``balance`` command to ``app``."""

    @app.command()
    def balance(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with a [balancing] table.")],
        as_json: JsonOpt = False,
        output: OutputOpt = None,
        csv: CsvOpt = None,
        units: UnitsOpt = "spec",
        unit: UnitOpt = None,
        full: FullOpt = False,
        tables: Annotated[Path | None, typer.Option("--tables", help="Write per-sample CSV tables (before/after, SI) and the mass properties into this folder.")] = None,
        plots: Annotated[Path | None, typer.Option("--plots", help="Write PNG plots of each load over the cycle (display units) into this folder (needs matplotlib).")] = None,
    ) -> None:
        """Choose the links' point masses (and counterweights) that minimise the weighted load measures over the cycle; print the before/after summary."""
        from screwkit.cli.common import guard
        from screwkit.cli.outputs import Outputs
        from screwkit.cli.progress import progress_bar
        from screwkit.io.balance_tables import write_balance_tables
        from screwkit.io.documents import balance_document
        from screwkit.io.spec import load_spec
        from screwkit.pipeline import Pipeline

        out = Outputs.prepare([spec], as_json=as_json, output=output, csv=csv, units=units,
                              unit=unit, full=full,
                              folders={"--tables": tables, "--plots": plots})
        s = guard(lambda: load_spec(spec))
        graph = getattr(s, "family", None) == "graph"
        if graph:
            from screwkit.cli.graph_views import graph_balance, solved

            if s.balancing is None:
                guard(lambda: graph_balance(s, None))  # the "no [balancing] table" sentence
            motion = guard(lambda: solved(s))
        du = out.units_for(s.units)
        pareto = s.balancing.pareto if s.balancing is not None else None
        total = None if pareto is None else pareto_size(pareto)
        with progress_bar("Pareto sweep", total, enabled=pareto is not None) as advance:
            if graph:
                res = guard(lambda: graph_balance(s, motion, advance))
            else:
                res = guard(lambda: Pipeline(s, units=du).balance(progress=advance))
        doc = balance_document(res)
        written: list[str] = []
        if tables is not None:
            written += guard(lambda: write_balance_tables(res, str(tables)))
        if plots is not None:
            from screwkit.report.balance_plots import write_pareto_plot, write_plots

            written += guard(lambda: write_plots(res, plots, units=du))
            front = res.pareto
            if front is not None:
                written.append(guard(lambda: write_pareto_plot(
                    front, Path(plots) / "balance_pareto.png")))
        for p in written:
            out.note_written(p)
        out.deliver(document=lambda: doc, table=res.table,
                    show=lambda: show_balance(s, res, doc, du, []), units=du)


def pareto_size(pareto: tuple[tuple[str, ...], int]) -> int:
    """The number of weightings of a Pareto sweep over m measures with d divisions."""
    from math import comb

    measures, divisions = pareto
    return comb(divisions + len(measures) - 1, len(measures) - 1)

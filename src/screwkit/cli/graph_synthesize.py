"""``screwkit synthesize`` on a graph spec (docs/synthesis.md, "Graphs"): the drawing's hardpoints
and axes fitted to the targets of its ``[synthesis]`` table on the drawn mode; prints the
variables before and after (and which ended on a bound), E, the RMSE and the targets against
what the result generates; ``--spec-out`` writes the synthesised spec (comments kept), ``--csv``
(or ``-o`` .csv/.parquet/.npz) the target rows, ``--plot`` desired against generated."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rich.markup import escape

from screwkit.cli.common import console, prose, user_error
from screwkit.cli.common import guard as _guard

__all__ = ["graph_synthesize"]


def _show(spec: Any, problem: Any, doc: dict[str, Any], du: Any, full: bool) -> None:
    from screwkit.cli.formatting import TextColumn, number, print_columns

    prose(f"[bold]{escape(spec.name)}[/]: graph synthesis ({doc['status']}; "
          f"{doc['iterations']} iterations, {doc['evaluations']} evaluations, "
          f"{doc['time']:.3f} s)")
    if doc["message"]:
        prose(f"  {escape(doc['message'])}")
    rows = doc["variables"]
    cols = [TextColumn("variable", [r["name"] for r in rows], "left"),
            TextColumn("before", [number(r["before"], 8) for r in rows]),
            TextColumn("after", [number(r["after"], 8) for r in rows]),
            TextColumn("unit", [r["unit"] for r in rows], "left")]
    if doc["at_bounds"]:
        cols.append(TextColumn("bound", [f"on {r['on_bound']}" if r["on_bound"] else ""
                                         for r in rows], "left"))
    print_columns(console, "design variables (the drawing before and after)", cols)
    L = du.show("length", doc["length_scale"])
    prose(f"E = Σ r² = {doc['objective']:.6g} (lengths over L = {L:g} {du.label('length')}, "
          f"angles in rad); RMSE {doc['rmse']:.6g}; |grad E| = {doc['gradient_norm']:.2g}")
    prose(f"whole motion: {escape(doc['range_check']['message'])}")
    t_rows = doc["rows"] if full else doc["rows"][:40]
    in_kind = "angle" if spec.input_is_angle else "length"

    def values(r: dict[str, Any], key: str) -> str:
        return ", ".join(number(du.show(r["kind"], v), 7) for v in r[key])

    cols = [TextColumn("target", [r["target"] for r in t_rows], "left"),
            TextColumn(f"input ({du.label(in_kind)})",
                       [", ".join(number(du.show(in_kind, v), 6) for v in r["input"])
                        for r in t_rows]),
            TextColumn("desired", [values(r, "desired") for r in t_rows]),
            TextColumn("generated", [values(r, "generated") for r in t_rows]),
            TextColumn("error", [values(r, "error") for r in t_rows]),
            TextColumn("unit", [du.label(r["kind"]) for r in t_rows], "left")]
    print_columns(console, "targets against the synthesised mechanism", cols)
    if len(doc["rows"]) > len(t_rows):
        prose(f"({len(doc['rows']) - len(t_rows)} more rows: --full shows them)")
    for k, alt in enumerate(doc["alternatives"], start=2):
        prose(f"alternative {k}: E = {alt['objective']:.6g}, whole motion "
              f"{'ok' if alt['range_check']['ok'] else 'NOT ok'}")
    if doc["synthesised_spec"]:
        prose(f"synthesised spec: {escape(doc['synthesised_spec'])} (screwkit report / analyze "
              "it to see the mechanism)")


def graph_synthesize(spec: Any, out: Any, starts: int | None, spec_out: Path | None,
                     plot: Path | None = None) -> None:
    """Run the graph spec's ``[synthesis]`` and deliver the result (module docstring)."""
    from screwkit.cli.progress import progress_bar
    from screwkit.io.graph_synthesis_output import (
        graph_synthesis_document,
        graph_synthesis_table,
        synthesised_spec_text,
    )
    from screwkit.io.results import write_atomic
    from screwkit.synthesis.graph_route import synthesize_graph_multistart

    problem = spec.synthesis
    if problem is None:
        user_error(f"{spec.path}: no [synthesis] table; see docs/synthesis.md, \"Graphs\"")
    du = out.units_for(spec.units)
    with progress_bar("synthesis starts", None) as advance:
        results = _guard(lambda: synthesize_graph_multistart(problem, starts, advance))
    doc = graph_synthesis_document(spec, problem, results, spec_out)
    if spec_out is not None:
        text = _guard(lambda: synthesised_spec_text(spec, problem, results[0].x))
        _guard(lambda: write_atomic(spec_out, text, [spec.path], "--spec-out"))
        out.note_written(spec_out)
    if plot is not None:
        from screwkit.report.graph_synthesis_plots import write_graph_synthesis_plot

        x = results[0].x
        _guard(lambda: write_graph_synthesis_plot(spec, problem, doc, x, du, plot))
        out.note_written(plot)
    out.deliver(document=lambda: doc, table=lambda: graph_synthesis_table(spec, problem, doc),
                show=lambda: _show(spec, problem, doc, du, out.full), units=du)

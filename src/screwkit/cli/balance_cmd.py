"""``screwkit balance SPEC``: optimum balancing from a spec file's [balancing] table
(docs/balancing.md). ``register(app)`` adds the command to the main Typer app."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer


def direction_range(d: Any) -> str:
    """"range -0.05 … 0.1, relative units", with "unbounded" or "could not determine" for an
    end the linear programs did not give."""
    def end(value: float | None, side: str) -> str:
        if value is not None:
            return f"{value:.3g}"
        return "could not determine" if f"could not determine {side}" in d.extent else (
            "unbounded")
    return f"range {end(d.low, 'below')} … {end(d.high, 'above')}, relative units"


def register(app: typer.Typer) -> None:
    """Add the ``balance`` command to ``app``."""

    @app.command()
    def balance(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with a [balancing] table.")],
        as_json: Annotated[bool, typer.Option("--json", help="Print one JSON document (SI units) instead of tables.")] = False,
        output: Annotated[Path | None, typer.Option("--output", "-o", help="Write the JSON document to this file (atomically).")] = None,
        tables: Annotated[Path | None, typer.Option("--tables", help="Write per-sample CSV tables (before/after) into this folder.")] = None,
        plots: Annotated[Path | None, typer.Option("--plots", help="Write PNG plots of each load over the cycle into this folder (needs matplotlib).")] = None,
    ) -> None:
        """Choose the links' point masses (and counterweights) that minimise the weighted load measures over the cycle; print the before/after summary."""
        from rich.markup import escape
        from rich.table import Table

        from screwkit.cli.common import check_paths, console
        from screwkit.cli.common import emit as _emit
        from screwkit.cli.common import guard as _guard
        from screwkit.io.balance_tables import write_balance_tables
        from screwkit.io.spec import load_spec
        from screwkit.pipeline import Pipeline

        check_paths([spec], {"--output": output}, {"--tables": tables, "--plots": plots})
        s = _guard(lambda: load_spec(spec))
        res = _guard(lambda: Pipeline(s).balance())
        doc: dict[str, Any] = res.as_dict()
        written: list[str] = []
        if tables is not None:
            written += _guard(lambda: write_balance_tables(res, str(tables)))
        if plots is not None:
            from screwkit.balancing.plots import write_plots

            written += _guard(lambda: write_plots(res, plots))
            front = res.pareto
            if front is not None:
                from screwkit.balancing.plots import write_pareto_plot

                written.append(_guard(lambda: write_pareto_plot(
                    front, Path(plots) / "balance_pareto.png")))

        def table() -> None:
            console.print(f"[bold]{escape(s.describe())}[/]", highlight=False)
            t = Table(title="optimum balancing: before / after")
            for col in ("quantity", "before", "after", "change %"):
                t.add_column(col, justify="right")
            for row in res.summary_table():
                t.add_row(*row)
            console.print(t)
            verdict = "could not determine" if res.unique is None else str(res.unique)
            console.print(f"unique optimum: {verdict}", highlight=False)
            for d in res.directions:
                console.print(escape(f"  free direction {d.direction} ({direction_range(d)})"),
                              highlight=False)
            bound = doc.get("redistribution_bound")
            if bound:
                console.print(f"bound over all consistent redistributions (SDP): G = "
                              f"{bound['measures_after']['G']:.6g}", highlight=False)
            if "pareto" in doc:
                eff = sum(doc["pareto"]["efficient"])
                console.print(f"Pareto sweep over {doc['pareto']['measures']}: "
                              f"{len(doc['pareto']['values'])} weightings, {eff} non-dominated",
                              highlight=False)
            for note in res.notes:
                console.print(escape(f"note: {note}"), highlight=False)
            for p in written:
                console.print(f"wrote {escape(p)}", highlight=False)

        _emit(doc, as_json, output, table, [spec])

"""``screwkit tolerance SPEC --tol d2=±0.05mm …``: first-order sensitivities of every output
over the cycle, worst-case and RSS stack-ups, and a Monte Carlo check on the sweep engine
(docs/sweeps.md). Registered on the main app by ``register(app)``; the work is in
:mod:`screwkit.sweep.tolerance` and :mod:`screwkit.sweep.monte_carlo`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from screwkit.cli.common import console, guard, prose
from screwkit.cli.outputs import JsonOpt, Outputs, UnitOpt, UnitsOpt
from screwkit.cli.sweep_cmd import (
    SchedulerOpt,
    WorkersOpt,
    engine_for,
    progress_bar,
    stopped,
)


def _kind(angle: bool) -> str:
    return "angle" if angle else "length"


def _show(units: Any, value: float, angle: bool) -> str:
    return f"{units.show(_kind(angle), value):.5g}"


def _tables(doc: dict[str, Any], description: str, units: Any, input_is_angle: bool) -> None:
    prose(f"[bold]{escape(description)}[/]")
    prose(f"assembly mode {doc['mode']}; {doc['convention']}; angles in "
          f"{units.pretty('angle')}, lengths in {units.pretty('length')}")
    t = Table(title="stack-ups: the largest deviation over the cycle")
    for col in ("output", "worst case ±", "RSS ±", "at input", "dominant tolerance"):
        t.add_column(col, justify="right")
    input_kind = _kind(input_is_angle)
    for row in doc["summary"]:
        angle = doc["outputs"][row["output"]]["kind"] == "angle"
        t.add_row(row["output"], _show(units, row["max_worst_case"], angle),
                  _show(units, row["max_rss"], angle),
                  f"{units.show(input_kind, row['at_input']):.4g} {units.pretty(input_kind)}",
                  row["dominant"])
    console.print(t)
    mc = doc["monte_carlo"]
    if mc is None:
        return
    if not mc["points_compared"]:
        prose("[yellow]Monte Carlo:[/] no point to compare (the outputs do not depend "
              "on these tolerances)")
        return
    lo, hi = mc["std_ratio_range"]
    verdict = "[green]agrees[/]" if mc["agree"] else "[yellow]does NOT agree[/]"
    prose(
        f"Monte Carlo ({mc['samples']} designs, seed {mc['seed']}, {mc['failed_designs']} "
        f"failed): σ_MC/σ_first-order {lo:.4f}…{hi:.4f}; first-order σ inside the 95% "
        f"interval at {mc['inside_95_percent_interval']} of {mc['points_compared']} points, "
        f"inside the Bonferroni-corrected interval at {mc['inside_bonferroni_interval']}; "
        f"first-order prediction error ≤ {mc['max_prediction_error_over_sigma']:.3g} σ — "
        f"the first-order result {verdict}")


def _plot(doc: dict[str, Any], path: Path, inputs: list[Path], units: Any,
          input_is_angle: bool) -> None:
    import matplotlib
    import numpy as np

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from screwkit.io.outputs import atomic_path
    from screwkit.report.plots import tidy_axes

    outs = list(doc["outputs"])
    fig, axes = plt.subplots(len(outs), 1, figsize=(7, 2.6 * len(outs)), sharex=True,
                             squeeze=False)
    input_kind = _kind(input_is_angle)
    x = np.asarray(doc["input"], dtype=float) * units.show(input_kind, 1.0)
    for ax, name in zip(axes[:, 0], outs, strict=True):
        o = doc["outputs"][name]
        kind = o["kind"]
        scale = units.show(kind, 1.0)
        wc, rss = np.asarray(o["worst_case"]) * scale, np.asarray(o["rss"]) * scale
        ax.fill_between(x, -wc, wc, color="tab:orange", alpha=0.25, label="worst case")
        ax.plot(x, rss, "-", color="tab:blue", label="RSS (3σ)")
        ax.plot(x, -rss, "-", color="tab:blue")
        if doc["monte_carlo"] is not None:
            sd = 3 * np.asarray(doc["monte_carlo"]["std"][name], dtype=float) * scale
            ax.plot(x, sd, ".", color="k", ms=3, label="Monte Carlo 3σ")
        ax.set_ylabel(f"Δ{name} ({units.pretty(kind)})")
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    axes[-1, 0].set_xlabel(f"input ({units.pretty(input_kind)})")
    fig.suptitle(f"{doc['mechanism']}: tolerance stack-up", fontsize=10)
    tidy_axes(fig)
    with atomic_path(path, inputs, "--plot") as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight", format="png")
    plt.close(fig)


def _graph_first_order(spec: Any, tolerances: Any, n: int, seed: int) -> tuple[Any, Any]:
    """The first-order result of a graph spec's hardpoint tolerances and its Monte Carlo run
    (:mod:`screwkit.sweep.graph_tolerance`)."""
    from screwkit.cli.graph_views import solved
    from screwkit.sweep.graph_tolerance import graph_first_order, run_graph_monte_carlo

    mode = solved(spec).modes[0]
    fo = graph_first_order(spec, tolerances, mode)

    def run(engine: Any, update: Any) -> Any:
        return run_graph_monte_carlo(engine, spec, tolerances, mode, fo, n, seed, update)

    return fo, run


def register(app: typer.Typer) -> None:
    """Add the ``tolerance`` command to ``app``."""

    @app.command()
    def tolerance(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML): the nominal design.")],
        tol: Annotated[list[str] | None, typer.Option("--tol", help="KEY=±T: a tolerance (±3σ) on a spec value, with a unit or in the spec's units (d2=±0.05mm, delta0=+-0.1deg, joints[1].length=±0.01; on a graph spec a hardpoint: joints.UB.at[2]=±0.5mm, joints.*.at=±0.5mm). Repeatable; without any, the spec's [tolerances] table.")] = None,
        monte_carlo: Annotated[int, typer.Option("--monte-carlo", min=0, max=1_000_000, help="Monte Carlo designs checking the first-order result on the sweep engine (0: none).")] = 1000,
        seed: Annotated[int, typer.Option("--seed", min=0, help="Seed of the Monte Carlo draw.")] = 0,
        as_json: JsonOpt = False,
        output: Annotated[Path | None, typer.Option("--output", "-o", help="Write the JSON document (SI units) to this file (atomically) and print one line.")] = None,
        units: UnitsOpt = "spec",
        unit: UnitOpt = None,
        plot: Annotated[Path | None, typer.Option("--plot", help="Write a PNG of the stack-ups over the cycle.")] = None,
        scheduler: SchedulerOpt = None,
        workers: WorkersOpt = None,
    ) -> None:
        """First-order sensitivities of every output over the cycle to toleranced spec values (exact, from the loop's screw Jacobian), worst-case and RSS stack-ups, and a Monte Carlo check on the sweep engine."""
        from screwkit.pipeline import Pipeline
        from screwkit.sweep.monte_carlo import compare, run_monte_carlo
        from screwkit.sweep.run import read_spec_tables
        from screwkit.sweep.tolerance import (
            first_order,
            make_tolerances,
            tolerance_document,
            tolerance_texts,
        )

        out = Outputs.prepare([spec], as_json=as_json, output=output, files={"--plot": plot},
                              formats=("json",), units=units, unit=unit)
        data, s = guard(lambda: read_spec_tables(spec))
        tolerances = guard(lambda: make_tolerances(data, s, tolerance_texts(data, tol)))
        if getattr(s, "family", None) == "graph":  # hardpoints of a mechanism graph
            fo, run = guard(lambda: _graph_first_order(s, tolerances, monte_carlo, seed))
        else:
            pipe = Pipeline(s)
            fo = guard(lambda: first_order(data, s, str(spec), tolerances, pipe))

            def run(engine: Any, update: Any) -> Any:
                return run_monte_carlo(engine, data, str(spec), tolerances, pipe.mode(), fo,
                                       monte_carlo, seed, update)
        mc = None
        if monte_carlo:
            try:
                with progress_bar("Monte Carlo") as update, \
                        engine_for(scheduler, workers, "Monte Carlo sample") as engine:
                    deviations = guard(lambda: run(engine, update))
            except KeyboardInterrupt as exc:
                stopped(exc, "nothing written")
            mc = compare(fo, tolerances, deviations, seed)
        doc = tolerance_document(spec, s, tolerances, fo, mc)
        du = out.units_for(s.units)
        if plot is not None:
            guard(lambda: _plot(doc, plot, [spec], du, s.input_is_angle))
            out.note_written(plot)
        out.deliver(document=lambda: doc, table=None,
                    show=lambda: _tables(doc, s.describe(du), du, s.input_is_angle))

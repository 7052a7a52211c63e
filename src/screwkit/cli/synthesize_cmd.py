"""``screwkit synthesize SPEC``: dimensional synthesis of an RSRC (or plane 4R) for a desired
screw displacement (Bagci 1969, Ch. V: least squares, or the overlay technique of §5.4; keys of
the spec's ``[synthesis]`` table in docs/synthesis.md).  Registered on the main app by
``register(app)``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape

from screwkit.cli.common import console, prose, user_error
from screwkit.cli.common import guard as _guard
from screwkit.cli.outputs import CsvOpt, FullOpt, JsonOpt, OutputOpt, UnitOpt, UnitsOpt
from screwkit.cli.sweep_cmd import SchedulerOpt, WorkersOpt, engine_for, stopped
from screwkit.errors import InputError

__all__ = ["register", "synthesis_document"]



def _plot(results: list[Any], path: Path, du: Any) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    best = results[0]
    rows = sorted(best.rows, key=lambda r: r["theta"])  # theta = 0 comes first in the result
    def ang(key: str) -> Any:
        return du.show("angle", np.array([r[key] for r in rows], dtype=float))

    def length(key: str) -> Any:
        return du.show("length", np.array([r[key] for r in rows], dtype=float))

    a, lu = du.label("angle"), du.label("length")
    th = ang("theta")
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    axes[0].plot(th, ang("psi_d0"), "o", label="desired ψ_d0")
    axes[0].plot(th, ang("psi_g0"), "x-", label="generated ψ_g0")
    axes[0].set_ylabel(f"output rotation ({a})")
    axes[0].legend()
    axes[1].plot(th, length("S_d"), "o", label="desired S_d")
    axes[1].plot(th, length("S_g"), "x-", label="generated S_g")
    axes[1].set_ylabel(f"output translation ({lu})")
    axes[1].set_xlabel(f"input θ from θ01 ({a})")
    axes[1].legend()
    fig.suptitle(f"synthesis: RMSE φ {du.show('angle', best.rmse_phi):.4g} {a}, "
                 f"S {du.show('length', best.rmse_S):.3g} {lu}")
    fig.tight_layout()
    from screwkit.report.plots import save_figure

    save_figure(fig, path)
    plt.close(fig)


def _tables(name: str, results: list[Any], doc: dict[str, Any], config: Any, du: Any,
            full: bool) -> None:
    from screwkit.cli.formatting import (
        TextColumn,
        number,
        print_columns,
        print_long_table,
        table_columns,
    )
    from screwkit.io.tables import synthesis_table

    scale_unit = config.length_unit
    best = results[0]
    a, lu = du.label("angle"), du.label("length")
    prose(f"[bold]{escape(name)}[/]: synthesis ({best.status}; {best.iterations} "
          f"iterations, {best.evaluations} evaluations, {best.time:.3f} s)")
    if best.message:
        prose(f"  {escape(best.message)}")
    kinds = ["angle" if k in config.angles else "length" for k in best.dimensions]
    dimension_columns = [
        TextColumn("name", list(best.dimensions), "left"),
        TextColumn("value", [number(du.show(k, v), 7) for k, v in
                             zip(kinds, best.dimensions.values(), strict=True)]),
        TextColumn("unit", [du.label(k) for k in kinds], "left")]
    if best.at_bounds:  # the synthesis ended on a bound: say which
        dimension_columns.append(TextColumn(
            "bound", [f"on {best.at_bounds[k][0]}" if k in best.at_bounds else ""
                      for k in best.dimensions], "left"))
    print_columns(console, "optimised dimensions", dimension_columns)
    rot, tra = config.outputs
    mode = (f"assembly mode {best.inversion} (sign of Q5 {best.mode_sign:+.0f})"
            if config.route == "closed" else
            f"assembly mode {best.inversion} (generic route: the loop's screw Jacobian; outputs "
            f"{', '.join(o for o in (rot, tra) if o)})")
    prose(
        f"{mode}; "
        f"E = E_phi + E_S/L² = {best.objective:.6g} with L = {best.length_scale:g} m "
        f"({scale_unit}); E_phi = {best.E_phi:.6g} rad², E_S = {best.E_S:.6g} m²")
    prose(
        f"RMSE {best.rmse:.6g}; RMSE_phi {du.show('angle', best.rmse_phi):.5g} {a}; RMSE_S "
        f"{du.show('length', best.rmse_S):.6g} {lu}; max deviation "
        f"{du.show('angle', best.max_dev_phi):.5g} {a} / {du.show('length', best.max_dev_S):.4g} "
        f"{lu}; |grad E| = {best.gradient_norm:.2g}")
    prose(f"whole range: {escape(best.range_check.message)}")
    t = synthesis_table(doc)
    cols, values = table_columns(t, t.names, du)
    print_long_table(console, "desired vs generated (as Bagci's Tables I-XII)", cols, values,
                     full)
    for k, other in enumerate(results[1:], start=2):
        prose(f"alternative {k}: mode {other.inversion}, E = {other.objective:.6g}, "
              f"whole range {'ok' if other.range_check.ok else 'NOT ok'}")


def synthesis_document(s: Any, starts: int | None = None) -> dict[str, Any]:
    """Run the synthesis of a loaded spec and return its JSON document (kept for scripts)."""
    from screwkit.io.documents import synthesis_document as document
    from screwkit.pipeline import Pipeline

    return document(Pipeline(s).synthesize(starts), s.path)


def _plot_overlay(docs: list[dict[str, Any]], problem: Any, path: Path, du: Any) -> None:
    """The overlay plane (input-crank ellipse, coupler circles, fitted output circle, overlay
    radial lines) and desired vs generated rotation (and translation) of the best mechanism."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from screwkit.synthesis.overlay import ellipse_normal, input_ellipse_point

    best = docs[0]
    ov = best["overlay"]
    pr = problem
    sense = 1 if ov["output_direction"] == "ccw" else -1
    theta = pr.target.theta_rotation
    psi = pr.target.desired_rotation(theta)
    th0 = pr.theta01 + pr.input_direction * theta
    k = 1.0 / du.unit_of("length")[1]  # the plane in the display length unit
    lu, au = du.label("length"), du.label("angle")
    px, py = (k * v for v in input_ellipse_point(pr.d1, pr.lambda0, th0))
    ex, ey = (k * v for v in input_ellipse_point(pr.d1, pr.lambda0,
                                                 np.linspace(0, 2 * np.pi, 361)))
    cx, cy = (k * v for v in ov["centre"])
    d3, d2, phi01 = k * ov["d3"], k * ov["d2"], ov["phi01"]
    tips = (cx + d3 * np.cos(phi01 + sense * psi), cy + d3 * np.sin(phi01 + sense * psi))
    ring = np.linspace(0, 2 * np.pi, 181)
    has_s = pr.target.translation is not None
    fig = plt.figure(figsize=(12, 6))
    ax = fig.add_subplot(1, 2, 1)
    ax.plot(ex, ey, "k-", lw=1, label="input-crank ellipse")
    for i in range(theta.size):
        ax.plot(px[i] + d2 * np.cos(ring), py[i] + d2 * np.sin(ring), ":", lw=0.8,
                color="tab:blue", label="coupler circles (d2)" if i == 0 else None)
        ax.plot([cx, tips[0][i]], [cy, tips[1][i]], "-", lw=0.6, color="tab:orange")
        ax.plot([px[i], tips[0][i]], [py[i], tips[1][i]], "-", lw=0.6, color="tab:gray")
    ax.plot(px, py, "o", color="tab:blue", label="design points P_i")
    ax.plot(cx + d3 * np.cos(ring), cy + d3 * np.sin(ring), "-", color="tab:orange",
            label="fitted output circle (d3)")
    ax.plot(tips[0], tips[1], "x", color="tab:red", label="overlay points C_i")
    ax.plot([cx], [cy], "+", color="tab:orange", ms=12)
    for dw in pr.dwells:
        t0 = pr.theta01 + pr.input_direction * dw.theta
        pxd, pyd = (k * v for v in input_ellipse_point(pr.d1, pr.lambda0, t0))
        nx, ny = ellipse_normal(pr.d1, pr.lambda0, t0, dw.tangency)
        ax.plot([pxd, pxd + 1.5 * d2 * nx], [pyd, pyd + 1.5 * d2 * ny], "--", color="tab:green",
                label="dwell normal")
    ax.set_aspect("equal")
    ax.set_title(f"overlay plane ({lu}): {ov['output_direction']} output, "
                 f"max circle miss {k * ov['max_circle_miss']:.3g} {lu}")
    ax.legend(fontsize=7, loc="best")
    rows = sorted(best["rows"], key=lambda r: r["theta"])  # theta = 0 comes first in the result
    def col(key: str, kind: str) -> Any:
        return du.show(kind, np.array([np.nan if r[key] is None else r[key] for r in rows],
                                      dtype=float))

    th = col("theta", "angle")
    ax1 = fig.add_subplot(2 if has_s else 1, 2, 2)
    ax1.plot(th, col("psi_d0", "angle"), "o", label="desired ψ_d0")
    ax1.plot(th, col("psi_g0", "angle"), "x-", label="generated ψ_g0")
    ax1.set_ylabel(f"output rotation ({au})")
    ax1.set_xlabel(f"input θ from θ01 ({au})")
    ax1.set_title(f"RMSE φ {du.show('angle', best['rmse_phi']):.4g} {au}")
    ax1.legend()
    if has_s:
        ax2 = fig.add_subplot(2, 2, 4)
        ax2.plot(th, col("S_d", "length"), "o", label="desired S_d")
        ax2.plot(th, col("S_g", "length"), "x-", label="generated S_g")
        ax2.set_ylabel(f"output translation ({lu})")
        ax2.set_xlabel(f"input θ from θ01 ({au})")
        ax2.legend()
    fig.tight_layout()
    from screwkit.report.plots import save_figure

    save_figure(fig, path)
    plt.close(fig)


def _overlay_lines(docs: list[dict[str, Any]]) -> None:
    for k, d in enumerate(docs, start=1):
        ov = d["overlay"]
        radii = ", ".join(f"{r:.6g}" for r in ov["dwell_curvature_radii"])
        d2_text = (f"d2 refined {ov['d2_chosen']:.6g} -> {ov['d2']:.6g} m" if ov["d2_refined"]
                   else f"d2 = {ov['d2']:.6g} m (as chosen)")
        prose(
            f"overlay {k}: {ov['output_direction']} output, centre ({ov['centre'][0]:.6g}, "
            f"{ov['centre'][1]:.6g}) m, d3 = {ov['d3']:.6g} m, {d2_text}, max circle miss "
            f"{ov['max_circle_miss']:.3g} m, RMSE_phi {math.degrees(d['rmse_phi']):.4g}°"
            + (f"; ellipse curvature radius at the dwell(s): {radii} m" if radii else ""))


def plot_path(plot: Path) -> Path:
    """The PNG file ``--plot`` writes: ``.png`` added when the name has no suffix; its folder must
    exist and the name must not be a folder (checked before the solve)."""
    path = plot if plot.suffix or plot.is_dir() else plot.with_name(plot.name + ".png")
    if path.is_dir():
        raise InputError(f"--plot {plot}: {path} is a folder; give a file name, e.g. "
                         f"{path / 'synthesis.png'}")
    folder = path.parent
    if not folder.is_dir():
        raise InputError(f"--plot {plot}: folder {folder} does not exist; create it first")
    return path


def global_synthesis(config: Any, starts: int, scheduler: str | None, workers: int | None,
                     pipe: Any) -> Any:
    """``--starts N``: the multistart's starts on the sweep engine (the same results as the
    serial run for the same seed); in this process when Dask is not installed."""
    import importlib.util

    from screwkit.cli.common import err_console
    from screwkit.cli.progress import progress_bar
    from screwkit.sweep.multistart import synthesize_on_engine

    if importlib.util.find_spec("distributed") is None and scheduler is None and not workers:
        prose("[yellow]note:[/] Dask (pip install 'screwkit\\[sweep]') is not installed; the "
              "starts run in this process", to=err_console)
        with progress_bar("synthesis starts", None) as advance:
            return _guard(lambda: pipe.synthesize(starts, progress=advance))
    from screwkit.messages import message_units

    try:
        with progress_bar("synthesis starts", starts) as advance, \
                engine_for(scheduler, workers, "synthesis start") as engine, \
                message_units(pipe.units):  # notes in the spec's units, as the serial run's
            return _guard(lambda: synthesize_on_engine(
                config, starts, engine, lambda done, total, _: advance(done, total)))
    except KeyboardInterrupt as exc:
        stopped(exc, "nothing written")


def _graph(spec: Any, out: Any, starts: int | None, spec_out: Path | None, plot: Path | None,
           scheduler: str | None, workers: int | None) -> None:
    """A graph spec: refuse what it has no counterpart for before any work, then solve."""
    import importlib.util

    from screwkit.cli.graph_synthesize import graph_synthesize

    for flag, given in (("--scheduler", scheduler), ("--workers", workers)):
        if given is not None:
            user_error(f"{flag} is not available for a graph spec's synthesis (its starts run "
                       "in this process; docs/synthesis.md, \"Graphs\")")
    if plot is not None and plot.suffix.lower() not in (".png", ".svg", ".pdf"):
        user_error(f"--plot {plot}: give a file ending in .png, .svg or .pdf")
    if spec_out is not None and importlib.util.find_spec("tomlkit") is None:
        user_error("--spec-out writes the synthesised spec with tomlkit, which is not "
                   "installed: pip install 'screwkit[synthesis]'")
    graph_synthesize(spec, out, starts, spec_out, plot)


def register(app: typer.Typer) -> None:
    """Add the ``synthesize`` command to ``app``."""

    @app.command()
    def synthesize(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with a [synthesis] table.")],
        as_json: JsonOpt = False,
        output: OutputOpt = None,
        csv: CsvOpt = None,
        units: UnitsOpt = "spec",
        unit: UnitOpt = None,
        full: FullOpt = False,
        plot: Annotated[Path | None, typer.Option("--plot", help="Write a PNG of desired vs generated (display units).")] = None,
        starts: Annotated[int | None, typer.Option("--starts", help="Multi-start: number of starts (overrides [synthesis.multistart], or [synthesis.overlay] starts); the least-squares starts run on the sweep engine (docs/sweeps.md).", min=1, max=10000)] = None,
        scheduler: SchedulerOpt = None,
        workers: WorkersOpt = None,
        spec_out: Annotated[Path | None, typer.Option("--spec-out", help="Graph spec: write the synthesised spec (the input's text with the new hardpoints; comments kept) to this file.")] = None,
    ) -> None:
        """Optimise the mechanism's dimensions to generate a desired screw displacement
        (Bagci 1969 Ch. V: least squares with exact derivatives, dwell and range constraints;
        or the overlay technique of §5.4 with [synthesis] method = "overlay")."""
        from screwkit.cli.outputs import Outputs
        from screwkit.cli.progress import progress_bar
        from screwkit.io.documents import synthesis_document as document
        from screwkit.io.spec import load_spec
        from screwkit.io.tables import synthesis_table
        from screwkit.pipeline import Pipeline

        if plot is not None:
            asked = plot
            plot = _guard(lambda: plot_path(asked))
        out = Outputs.prepare([spec], as_json=as_json, output=output, csv=csv, units=units,
                              unit=unit, full=full, files={"--plot": plot,
                                                           "--spec-out": spec_out})
        loaded = _guard(lambda: load_spec(spec))
        if getattr(loaded, "family", None) == "graph":
            _graph(loaded, out, starts, spec_out, plot, scheduler, workers)
            return
        if spec_out is not None:
            user_error("--spec-out is for graph specs (a single loop's result is its "
                       "dimensions, in the document)")
        s = loaded
        du = out.units_for(s.units)
        pipe = Pipeline(s, units=du)
        config = _guard(lambda: pipe.synthesis_config())
        problem = config.problem
        overlay = config.method == "overlay"
        from screwkit.synthesis.problem import RSRCSynthesisProblem

        if starts is not None and starts > 1 and isinstance(problem, RSRCSynthesisProblem):
            outcome = global_synthesis(config, starts, scheduler, workers, pipe)
        else:
            with progress_bar("synthesis starts", None) as advance:
                outcome = _guard(lambda: pipe.synthesize(starts, progress=advance))
        results = outcome.results
        doc = document(outcome, spec)
        docs = [doc, *doc["alternatives"]]
        if plot is not None:
            png = plot
            _guard(lambda: _plot_overlay(docs, problem, png, du) if overlay
                   else _plot(results, png, du))
            out.note_written(plot)

        def show() -> None:
            _tables(s.name, results, doc, config, du, out.full)
            if overlay:
                _overlay_lines(docs)

        out.deliver(document=lambda: doc, table=lambda: synthesis_table(doc), show=show,
                    units=du)

"""``screwkit synthesize SPEC``: dimensional synthesis of an RSRC (or plane 4R) for a desired
screw displacement (Bagci 1969, Ch. V; keys of the spec's ``[synthesis]`` table in
docs/synthesis.md).  Registered on the main app by ``register(app)``."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

__all__ = ["register", "result_document"]

console = Console()
err_console = Console(stderr=True)


def _user_errors() -> tuple[type[BaseException], ...]:
    from screwkit.io.spec import SpecError
    from screwkit.io.units import UnitError

    return (SpecError, UnitError, ValueError, FileNotFoundError)


def _guard(fn: Any) -> Any:
    try:
        return fn()
    except _user_errors() as exc:
        err_console.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False)
        raise typer.Exit(2) from None


def result_document(result: Any) -> dict[str, Any]:
    """A `SynthesisResult` as a JSON-able dict (SI units, radians)."""
    rc = result.range_check
    return {
        "dimensions": dict(result.dimensions),
        "mode": result.inversion,
        "mode_sign": result.mode_sign,
        "objective": result.objective,
        "E_phi": result.E_phi,
        "E_S": result.E_S,
        "length_scale": result.length_scale,
        "rmse": result.rmse,
        "rmse_phi": result.rmse_phi,
        "rmse_S": result.rmse_S,
        "max_dev_phi": result.max_dev_phi,
        "max_dev_S": result.max_dev_S,
        "gradient_norm": result.gradient_norm,
        "relative_gradient": result.relative_gradient,
        "iterations": result.iterations,
        "evaluations": result.evaluations,
        "time": result.time,
        "status": result.status,
        "message": result.message,
        "range_check": {"ok": rc.ok, "gaps": [list(g) for g in rc.gaps],
                        "branch_mismatch": list(rc.branch_mismatch),
                        "min_transmission": rc.min_transmission, "message": rc.message},
        "rows": result.rows,
    }


def _plot(results: list[Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    best = results[0]
    rows = best.rows
    th = np.degrees([r["theta"] for r in rows])
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    axes[0].plot(th, np.degrees([r["psi_d0"] for r in rows]), "o", label="desired ψ_d0")
    axes[0].plot(th, np.degrees([r["psi_g0"] for r in rows]), "x-", label="generated ψ_g0")
    axes[0].set_ylabel("output rotation (deg)")
    axes[0].legend()
    axes[1].plot(th, [r["S_d"] for r in rows], "o", label="desired S_d")
    axes[1].plot(th, [r["S_g"] for r in rows], "x-", label="generated S_g")
    axes[1].set_ylabel("output translation (m)")
    axes[1].set_xlabel("input θ from θ01 (deg)")
    axes[1].legend()
    fig.suptitle(f"synthesis: RMSE φ {math.degrees(best.rmse_phi):.4g}°, S {best.rmse_S:.3g} m")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _tables(name: str, results: list[Any], scale_unit: str) -> None:
    best = results[0]
    console.print(f"[bold]{escape(name)}[/]: synthesis ({best.status}; {best.iterations} "
                  f"iterations, {best.evaluations} evaluations, {best.time:.3f} s)",
                  highlight=False)
    if best.message:
        console.print(f"  {escape(best.message)}", highlight=False)
    t = Table(title="optimised dimensions (lengths in m, angles in deg)")
    t.add_column("name")
    t.add_column("value", justify="right")
    for k, v in best.dimensions.items():
        angle = k in ("delta0", "lambda0", "theta01", "q1", "q2")
        t.add_row(k, f"{math.degrees(v):.6f}" if angle else f"{v:.6g}")
    console.print(t)
    console.print(
        f"assembly mode {best.inversion} (sign of Q5 {best.mode_sign:+.0f}); "
        f"E = E_phi + E_S/L² = {best.objective:.6g} with L = {best.length_scale:g} m "
        f"({scale_unit}); E_phi = {best.E_phi:.6g} rad², E_S = {best.E_S:.6g} m²", highlight=False)
    console.print(
        f"RMSE {best.rmse:.6g}; RMSE_phi {best.rmse_phi:.6g} rad = "
        f"{math.degrees(best.rmse_phi):.5g}°; RMSE_S {best.rmse_S:.6g} m; max deviation "
        f"{math.degrees(best.max_dev_phi):.5g}° / {best.max_dev_S:.4g} m; |grad E| = "
        f"{best.gradient_norm:.2g}", highlight=False)
    console.print(f"whole range: {escape(best.range_check.message)}", highlight=False)
    rt = Table(title="desired vs generated (as Bagci's Tables I-XII)")
    for col in ("θ (deg)", "θ0 (deg)", "φ_g (deg)", "ψ_g0 (deg)", "ψ_d0 (deg)", "ψ_d0-ψ_g0",
                "S (m)", "S_g (m)", "S_d (m)", "S_d-S_g"):
        rt.add_column(col, justify="right")
    for r in best.rows:
        d = math.degrees
        s_d = r["S_d"]
        rt.add_row(f"{d(r['theta']):.3f}", f"{d(r['theta0']):.4f}", f"{d(r['phi_g']):.5f}",
                   f"{d(r['psi_g0']):.5f}",
                   "—" if r["psi_d0"] != r["psi_d0"] else f"{d(r['psi_d0']):.5f}",
                   "—" if r["psi_d0"] != r["psi_d0"] else f"{d(r['psi_d0'] - r['psi_g0']):.5f}",
                   f"{r['S']:.6g}", f"{r['S_g']:.6g}",
                   "—" if s_d != s_d else f"{s_d:.6g}",
                   "—" if s_d != s_d else f"{s_d - r['S_g']:.3g}")
    console.print(rt)
    for k, other in enumerate(results[1:], start=2):
        console.print(f"alternative {k}: mode {other.inversion}, E = {other.objective:.6g}, "
                      f"whole range {'ok' if other.range_check.ok else 'NOT ok'}", highlight=False)


def synthesis_document(s: Any, starts: int | None = None) -> dict[str, Any]:
    """Run the synthesis of a loaded spec (its ``[synthesis]`` table) and return the JSON-able
    document of the best result with the alternatives (used by ``demo``)."""
    from screwkit.synthesis.config import problem_from_spec
    from screwkit.synthesis.solve import synthesize as solve_one
    from screwkit.synthesis.solve import synthesize_multistart

    problem, table = problem_from_spec(s)
    ms = table.multistart
    n_starts = starts if starts is not None else (ms.starts if ms is not None else 1)
    if n_starts == 1 and not (problem.inversion is None and problem.construction is None):
        results = [solve_one(problem)]
    else:
        results = synthesize_multistart(problem, n_starts=n_starts, seed=ms.seed if ms else 0,
                                        keep=ms.keep if ms else 3, spread=ms.spread if ms else 0.5)
    doc = result_document(results[0])
    doc["alternatives"] = [result_document(r) for r in results[1:]]
    doc["spec"] = str(s.path)
    return doc


def register(app: typer.Typer) -> None:
    """Add the ``synthesize`` command to ``app``."""

    @app.command()
    def synthesize(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with a [synthesis] table.")],
        as_json: Annotated[bool, typer.Option("--json", help="Print one JSON document (SI units) instead of tables.")] = False,
        output: Annotated[Path | None, typer.Option("--output", "-o", help="Write the JSON document to this file (atomically).")] = None,
        plot: Annotated[Path | None, typer.Option("--plot", help="Write a PNG of desired vs generated.")] = None,
        starts: Annotated[int | None, typer.Option("--starts", help="Multi-start: number of starts (overrides [synthesis.multistart]).", min=1, max=10000)] = None,
    ) -> None:
        """Optimise the mechanism's dimensions to generate a desired screw displacement
        (Bagci 1969 Ch. V: least squares with exact derivatives, dwell and range constraints)."""
        from screwkit.io.results import dumps, write_atomic
        from screwkit.io.spec import load_spec
        from screwkit.synthesis.config import problem_from_spec
        from screwkit.synthesis.solve import synthesize as solve_one
        from screwkit.synthesis.solve import synthesize_multistart

        s = _guard(lambda: load_spec(spec))
        problem, table = _guard(lambda: problem_from_spec(s))
        ms = table.multistart
        n_starts = starts if starts is not None else (ms.starts if ms is not None else 1)
        runs_all_modes = problem.inversion is None and problem.construction is None

        def run() -> list[Any]:
            if n_starts == 1 and not runs_all_modes:
                return [solve_one(problem)]
            return synthesize_multistart(
                problem, n_starts=n_starts, seed=ms.seed if ms else 0,
                keep=ms.keep if ms else 3, spread=ms.spread if ms else 0.5)

        if as_json or not sys.stderr.isatty():
            results = _guard(run)
        else:
            with Progress(TextColumn("synthesising"), BarColumn(), TimeElapsedColumn(),
                          console=err_console, transient=True) as progress:
                task = progress.add_task("run", total=None)
                results = _guard(run)
                progress.update(task, completed=1, total=1)
        doc = result_document(results[0])
        doc["alternatives"] = [result_document(r) for r in results[1:]]
        doc["spec"] = str(spec)
        text = dumps(doc)
        if output is not None:
            _guard(lambda: write_atomic(output, text + "\n"))
        if plot is not None:
            _guard(lambda: _plot(results, plot))
        if as_json:
            sys.stdout.write(text + "\n")
        else:
            unit = s.units.get("length", "m")
            _tables(s.name, results, f"1 {unit}" if table.length_scale is None
                    else str(table.length_scale))
            if output is not None:
                console.print(f"wrote {output}")
            if plot is not None:
                console.print(f"wrote {plot}")

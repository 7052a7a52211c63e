"""``screwkit`` command line (typer + rich). Every subcommand prints a readable table by default
and, with ``--json``, one JSON document in SI units (keys in docs/cli.md). A user mistake exits
with status 2 and a one-paragraph message, never a traceback."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer
from rich.markup import escape
from rich.table import Table

from screwkit import __version__
from screwkit.cli.common import (
    JsonOpt,
    OutputOpt,
    attempt,
    check_paths,
    console,
    emit,
    err_console,
    guard,
)

app = typer.Typer(
    name="screwkit",
    help="Analysis, synthesis and dynamic balancing of spatial linkages (dual-number screw calculus).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
_guard = guard
_emit = emit


@app.callback(invoke_without_command=True)
def main(
    version: Annotated[bool, typer.Option("--version", help="Print the version.")] = False,
    max_memory: Annotated[str | None, typer.Option("--max-memory", help="Refuse work estimated to need more memory than this (e.g. 16GB; default: half the machine's memory, at most 16 GiB; also SCREWKIT_MAX_MEMORY).")] = None,
) -> None:
    from screwkit.budget import set_memory_limit

    _guard(lambda: set_memory_limit(max_memory))  # None: the default (or SCREWKIT_MAX_MEMORY)
    if version:
        console.print(f"screwkit {__version__}")
        raise typer.Exit(0)


@app.command()
def validate(specs: Annotated[list[Path], typer.Argument(help="Spec files (TOML).")]) -> None:
    """Load and validate spec files and say what each describes."""
    from screwkit.io.spec import load_spec

    failed = 0
    for path in specs:  # every file is reported, good or bad
        ok, spec = attempt(lambda p=path: load_spec(p))  # type: ignore[misc]
        if ok and spec is not None:
            console.print(f"[green]ok[/] {escape(spec.describe())}", highlight=False)
        else:
            failed += 1
    if failed:
        err_console.print(f"{failed} of {len(specs)} spec file(s) failed", highlight=False)
        raise typer.Exit(2)


def _fmt(x: float | None, angle: bool) -> str:
    if x is None or x != x:
        return "—"
    return f"{np.degrees(x):.4f}" if angle else f"{x:.6g}"


@app.command()
def analyze(
    spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
    as_json: JsonOpt = False,
    output: OutputOpt = None,
    method: Annotated[str, typer.Option("--method", help="auto (closed form where the family has one), closed, or generic (any loop; every joint variable).")] = "auto",
    plot: Annotated[Path | None, typer.Option("--plot", help="Write a PNG of every variable and its rates over the input, and the coupler curve projections.")] = None,
) -> None:
    """Positions, velocities and accelerations of every joint variable in every assembly mode."""
    from screwkit.io.documents import analysis_document
    from screwkit.io.spec import load_spec
    from screwkit.pipeline import Pipeline

    check_paths([spec], {"--output": output, "--plot": plot})
    s = _guard(lambda: load_spec(spec))
    pipe = Pipeline(s, method=method)
    motion = _guard(lambda: pipe.motion)
    doc = analysis_document(motion, name=s.name, coupler_point=s.coupler_point)
    if plot is not None:
        from screwkit.report.plots import plot_analysis

        _guard(lambda: plot_analysis(doc, plot))

    def table() -> None:
        console.print(f"[bold]{escape(s.describe())}[/]", highlight=False)
        console.print(f"method: {doc['method']}; angles in deg (rates deg/s, deg/s²), lengths in m (m/s, m/s²)")
        if "method_note" in doc:
            console.print(f"[yellow]note:[/] {escape(doc['method_note'])}", highlight=False)
        for mode in doc["modes"]:
            names = [n for n in mode["variables"] if "." not in n and n not in ("theta0", "theta1")]
            names = names or [n for n in mode["variables"] if n != doc["input_name"]][:4]
            t = Table(title=f"assembly mode {mode['mode']}", show_lines=False)
            t.add_column("input (deg)" if s.input_is_angle else "input (m)", justify="right")
            for n in names:
                t.add_column(n, justify="right")
                t.add_column(f"{n}'", justify="right")
                t.add_column(f"{n}''", justify="right")
            for i, x in enumerate(doc["input"]):
                row = [f"{np.degrees(x):8.3f}" if s.input_is_angle else f"{x:.6g}"]
                for n in names:
                    ang = not (n in ("S", "s4") or n.endswith(".s"))
                    row += [_fmt(mode["variables"][n][i], ang), _fmt(mode["velocities"][n][i], ang),
                            _fmt(mode["accelerations"][n][i], ang)]
                t.add_row(*row)
            console.print(t)
            for ev in mode["events"]:
                console.print(f"  • {escape(ev)}", highlight=False)
            missing = int((~np.asarray(mode["assembles"])).sum())
            if missing:
                console.print(f"  • does not assemble at {missing} of {len(doc['input'])} inputs", highlight=False)

    _emit(doc, as_json, output, table, [spec])


@app.command()
def limits(
    spec: Annotated[Path, typer.Argument(help="Spec file (TOML) of an RSRC or a planar 4R.")],
    as_json: JsonOpt = False,
    output: OutputOpt = None,
    dwell_tolerance: Annotated[float, typer.Option("--dwell-tol", help="A derivative dᵏφ0/dθ0ᵏ counts as vanishing below this (rad/radᵏ). Printed dimensions hold a designed dwell only to ~1e-4.")] = 1e-6,
    at: Annotated[list[float] | None, typer.Option("--at", help="Also give the dwell order at this input angle (degrees); repeatable.")] = None,
) -> None:
    """Limit positions of the output rotation and translation over a full turn, and the order of the instantaneous dwell at each rotation limit (Bagci App. D)."""
    from screwkit.io.spec import load_spec
    from screwkit.pipeline import Pipeline

    check_paths([spec], {"--output": output})
    s = _guard(lambda: load_spec(spec))
    doc = _guard(lambda: Pipeline(s).limits(dwell_tolerance, at=[float(np.radians(x)) for x in at or []]).as_dict())

    def table() -> None:
        console.print(f"[bold]{escape(s.describe())}[/]", highlight=False)
        t = Table(title=f"limit positions (dwell tolerance {dwell_tolerance:g})")
        for col in ("kind", "branch", "θ0 (deg)", "φ0 (deg)", "S (m)", "2nd derivative", "dwell order"):
            t.add_column(col, justify="right")
        for lim in doc["limits"]:
            t.add_row(lim["kind"], str(lim["branch"]), f"{np.degrees(lim['theta0']):.4f}",
                      f"{np.degrees(lim['phi0']):.4f}", "—" if lim["S"] is None else f"{lim['S']:.6g}",
                      f"{lim['second_derivative']:.4g}", str(lim.get("dwell_order", "—")))
        console.print(t)
        if doc["dwells_at"]:
            t2 = Table(title="dwell order at given inputs")
            for col in ("θ0 (deg)", "inversion", "φ0 (deg)", "dwell order", "dφ0/dθ0 … (rad/radᵏ)"):
                t2.add_column(col, justify="right")
            for d in doc["dwells_at"]:
                t2.add_row(f"{np.degrees(d['theta0']):.4f}", str(d["inversion_label"]),
                           f"{np.degrees(d['phi0']):.4f}", str(d["dwell_order"]),
                           ", ".join(f"{x:.3g}" for x in d["derivatives"]))
            console.print(t2)

    _emit(doc, as_json, output, table, [spec])


@app.command()
def mobility(
    spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
    as_json: JsonOpt = False,
    output: OutputOpt = None,
) -> None:
    """Mobility by formula (each term shown) and from the loop's screw Jacobian at a sample configuration: redundant constraints and undetermined (passive) motions named by joint."""
    from screwkit.io.spec import load_spec
    from screwkit.pipeline import Pipeline

    check_paths([spec], {"--output": output})
    s = _guard(lambda: load_spec(spec))
    doc = _guard(lambda: Pipeline(s).mobility().as_dict())

    def table() -> None:
        console.print(f"[bold]{escape(s.describe())}[/]", highlight=False)
        for line in doc["summary"]:
            console.print(escape(str(line)), highlight=False)
            console.print()

    _emit(doc, as_json, output, table, [spec])


@app.command()
def dynamics(
    spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with [links.<name>] mass properties.")],
    as_json: JsonOpt = False,
    output: OutputOpt = None,
    gravity: Annotated[bool, typer.Option("--gravity/--no-gravity", help="Include gravity: magnitude 'gravity' (default 9.80665 m/s²) along 'gravity_direction' (default −z) of the spec.")] = False,
) -> None:
    """Shaking force and moment, every joint reaction and the actuator efforts over the cycle, with the RMS and peak of each (one assembly mode: motion.mode in the spec)."""
    from screwkit.io.spec import load_spec
    from screwkit.pipeline import Pipeline

    check_paths([spec], {"--output": output})
    s = _guard(lambda: load_spec(spec))
    doc = _guard(lambda: dynamics_job(Pipeline(s), gravity))

    def table() -> None:
        console.print(f"[bold]{escape(s.describe())}[/]", highlight=False)
        console.print(f"assembly mode {doc['mode']}; {escape(doc['indeterminacy'])}", highlight=False)
        if "note" in doc:
            console.print(f"[yellow]note:[/] {escape(doc['note'])}", highlight=False)
        t = Table(title="loads over the cycle (SI: N, N·m)")
        for col in ("quantity", "RMS", "peak"):
            t.add_column(col, justify="right")
        for name, st in doc["summary"].items():
            if isinstance(st, dict) and "rms" in st:
                t.add_row(name, f"{st['rms']:.6g}", f"{st['peak']:.6g}")
            elif isinstance(st, dict):
                for sub, st2 in st.items():
                    t.add_row(f"{name} {sub}", f"{st2['rms']:.6g}", f"{st2['peak']:.6g}")
        console.print(t)

    _emit(doc, as_json, output, table, [spec])


def dynamics_job(pipe: Any, gravity: bool) -> dict[str, Any]:
    """The dynamics document of a pipeline's spec (``[motion] mode``; null loads, with a note,
    where the mode does not assemble)."""
    from screwkit.io.documents import dynamics_document

    dyn = pipe.dynamics(gravity)
    problem = pipe.not_assembling(pipe.mode())
    note = None if problem is None else f"{problem}: the loads there are null"
    return dynamics_document(dyn, mode=pipe.spec.mode, note=note)


@app.command()
def demo(
    examples: Annotated[Path, typer.Argument(help="Folder of spec files.")] = Path("examples"),
    output_dir: Annotated[Path, typer.Option("--output-dir", help="Where results are written.")] = Path("out"),
    plots: Annotated[bool, typer.Option("--plots/--no-plots", help="Also write a PNG per example.")] = True,
    write_reports: Annotated[bool, typer.Option("--reports/--no-reports", help="Also write each example's animated HTML report (<example>.html).")] = True,
) -> None:
    """Run the main job on every bundled example: validate, analyse, write the results and an animated HTML report per example (out/index.html links them)."""
    from screwkit.io.documents import analysis_document, synthesis_document
    from screwkit.io.results import dumps, write_atomic
    from screwkit.io.spec import load_spec
    from screwkit.pipeline import Pipeline

    files = sorted(examples.glob("*.toml"))
    if not files:
        _guard(lambda: (_ for _ in ()).throw(ValueError(f"no spec files (*.toml) in {examples}")))
    from screwkit.io.outputs import make_output_folder

    _guard(lambda: make_output_folder(output_dir, "--output-dir"))

    def write(path: Path, result: Any) -> None:
        _guard(lambda: write_atomic(path, dumps(result) + "\n", files))
    t = Table(title=f"screwkit demo: {len(files)} examples")
    for col in ("example", "family", "samples", "modes", "assembling", "max closure residual", "jobs"):
        t.add_column(col)
    entries: list[dict[str, Any]] = []
    for f in files:
        spec = _guard(lambda f=f: load_spec(f))  # type: ignore[misc]
        console.print(f"[green]ok[/] {escape(spec.describe())}", highlight=False)
        pipe = Pipeline(spec)
        motion = _guard(lambda p=pipe: p.motion)  # type: ignore[misc]
        doc = analysis_document(motion, name=spec.name, coupler_point=spec.coupler_point)
        out = output_dir / f"{f.stem}.analysis.json"
        write(out, doc)
        if plots:
            from screwkit.report.plots import plot_analysis

            _guard(lambda d=doc, f=f: plot_analysis(d, output_dir / f"{f.stem}.analysis.png"))  # type: ignore[misc]
        mob = _guard(lambda p=pipe: p.mobility().as_dict())  # type: ignore[misc]
        write(output_dir / f"{f.stem}.mobility.json", mob)
        jobs = ["analysis", "mobility"]
        if all(link.mass is not None for link in spec.linkage.links):
            dyn = _guard(lambda p=pipe: dynamics_job(p, False))  # type: ignore[misc]
            write(output_dir / f"{f.stem}.dynamics.json", dyn)
            jobs.append("dynamics")
        if spec.balancing is not None:
            bal = _guard(lambda p=pipe: p.balance())  # type: ignore[misc]
            write(output_dir / f"{f.stem}.balance.json", bal.as_dict())
            jobs.append("balance")
        if spec.synthesis is not None:
            syn = _guard(lambda p=pipe: synthesis_document(p.synthesize(), p.spec.path))  # type: ignore[misc]
            write(output_dir / f"{f.stem}.synthesis.json", syn)
            jobs.append("synthesis")
        if spec.drive is not None:
            sim = _guard(lambda p=pipe: p.simulate().as_dict(loads=False))  # type: ignore[misc]
            write(output_dir / f"{f.stem}.simulation.json", sim)
            jobs.append("simulation")
        if write_reports:
            from screwkit.report.spec_report import write_spec_report

            bal_doc = bal.as_dict() if "balance" in jobs else None
            syn_doc = syn if "synthesis" in jobs else None
            _guard(lambda p=pipe, f=f, b=bal_doc, y=syn_doc: write_spec_report(  # type: ignore[misc]
                p, output_dir / f"{f.stem}.html", balance_doc=b, synthesis_doc=y))
        res = max((np.nanmax(np.asarray(m["closure_residual"], dtype=float)) for m in doc["modes"]), default=np.nan)
        asm = ", ".join(str(int(np.sum(m["assembles"]))) for m in doc["modes"])
        t.add_row(f.stem, spec.family, str(len(spec.inputs)), str(len(doc["modes"])), asm, f"{res:.1e}", ", ".join(jobs))
        summary: list[tuple[str, Any]] = [
            ("input samples", len(spec.inputs)), ("analysis method", doc["method"]),
            ("assembly modes (samples assembling)", f"{len(doc['modes'])} ({asm})"),
            ("max loop-closure residual", f"{res:.1e}"),
            ("mobility (formula / Jacobian)", f"{mob['formula']['mobility']} / {mob['numeric']['mobility']}"),
        ]
        if "dynamics" in jobs:
            sf = dyn["summary"]["shaking_force"]
            summary.append(("shaking force RMS / peak (N)", f"{sf['rms']:.6g} / {sf['peak']:.6g}"))
        if "balance" in jobs:
            g = bal.as_dict()["measures"]
            summary.append(("balancing objective G before → after", f"{g['before']['G']:.6g} → {g['after']['G']:.6g}"))
        if "simulation" in jobs:
            last = sim["cycles"][-1] if sim.get("cycles") else {}
            summary.append(("simulated speed fluctuation (last cycle)",
                            f"{last.get('fluctuation', float('nan')):.4g}"))
        if "synthesis" in jobs:
            summary.append(("synthesis RMSE (φ rad, S m)", f"{syn.get('rmse_phi')} , {syn.get('rmse_S')}"))
        entries.append({
            "name": f.stem, "family": spec.family, "description": spec.describe(),
            "jobs": [(j, f"{f.stem}.{j}.json") for j in jobs], "summary": summary,
            "picture": f"{f.stem}.analysis.png" if plots else None, "report": f"{f.stem}.html" if write_reports else None,
        })
    console.print(t)
    from screwkit.report.html import write_index

    reports = sorted(Path("validation").glob("*/*.md")) if Path("validation").is_dir() else []
    index = _guard(lambda: write_index(output_dir, entries, [Path("..") / r for r in reports]
                                       if output_dir.resolve().parent == Path.cwd().resolve() else None))
    console.print(f"wrote {index}")


def _register_subcommands() -> None:
    from screwkit.cli.balance_cmd import register as register_balance
    from screwkit.cli.mjcf_cmd import register as register_mjcf
    from screwkit.cli.report_cmd import register as register_report
    from screwkit.cli.simulate_cmd import register as register_simulate
    from screwkit.cli.sweep_cmd import register as register_sweep
    from screwkit.cli.synthesize_cmd import register as register_synthesize
    from screwkit.cli.tolerance_cmd import register as register_tolerance

    register_synthesize(app)
    register_balance(app)
    register_report(app)
    register_simulate(app)
    register_mjcf(app)
    register_sweep(app)
    register_tolerance(app)


_register_subcommands()


if __name__ == "__main__":  # pragma: no cover
    app()

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
    """Load and validate spec files and say what each describes and which jobs it has: every table is checked against what the family offers (coupler points, limits, synthesis routes, balancing), so what a job would refuse is reported here."""
    from screwkit.io.spec import load_spec

    failed = 0
    for path in specs:  # every file is reported, good or bad
        ok, spec = attempt(lambda p=path: load_spec(p))  # type: ignore[misc]
        if ok and spec is not None:
            console.print(f"[green]ok[/] {escape(spec.describe())}", highlight=False)
            console.print(f"   jobs: {escape(', '.join(spec.jobs()))}", highlight=False)
        else:
            failed += 1
    if failed:
        err_console.print(f"{failed} of {len(specs)} spec file(s) failed", highlight=False)
        raise typer.Exit(2)


def transmission_lines(entry: dict[str, Any] | None, input_is_angle: bool) -> list[str]:
    """One line per transmission measure of a mode: the minimum index of each output, the worst
    transmission angle, each ball joint's cone limit, with the input where it occurs."""
    if not entry:
        return []
    summary = entry["summary"]

    def where(x: float | None) -> str:
        if x is None:
            return "—"
        return f"{np.degrees(x):.4g} deg" if input_is_angle else f"{x:.6g} m"

    lines = []
    for name, st in summary["index"].items():
        if st["value"] is not None:
            lines.append(f"transmission index of {name}: min {st['value']:.4f} at input {where(st['at'])}")
    if "angle" in summary and summary["angle"]["value"] is not None:
        st = summary["angle"]
        lines.append(f"transmission angle: worst {np.degrees(st['value']):.4f} deg from a dead "
                     f"centre at input {where(st['at'])}")
    for joint, st in summary["cone_limit"].items():
        lines.append(f"ball joint {joint}: cone limit {np.degrees(st['value']):.4f} deg (at input "
                     f"{where(st['at'])})")
    return lines


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
    """Positions, velocities and accelerations of every joint variable in every assembly mode, the coupler curves of the spec's coupler points and the transmission quality over the cycle."""
    from screwkit.io.spec import load_spec
    from screwkit.pipeline import Pipeline

    check_paths([spec], {"--output": output, "--plot": plot})
    s = _guard(lambda: load_spec(spec))
    pipe = Pipeline(s, method=method)
    _guard(lambda: pipe.motion)
    doc = _guard(pipe.analysis)
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
            names = names or [n for n in mode["variables"]
                              if n != doc["input_name"] and n in mode["velocities"]][:4]
            t = Table(title=f"assembly mode {mode['mode']}", show_lines=False)
            t.add_column("input (deg)" if s.input_is_angle else "input (m)", justify="right")
            for n in names:
                t.add_column(n, justify="right")
                t.add_column(f"{n}'", justify="right")
                t.add_column(f"{n}''", justify="right")
            points = mode.get("coupler_points", {})
            for p in points:
                for ax in "xyz":
                    t.add_column(f"{p} {ax} (m)", justify="right")
            for i, x in enumerate(doc["input"]):
                row = [f"{np.degrees(x):8.3f}" if s.input_is_angle else f"{x:.6g}"]
                for n in names:
                    ang = not (n in ("S", "s4") or n.endswith(".s"))
                    row += [_fmt(mode["variables"][n][i], ang), _fmt(mode["velocities"][n][i], ang),
                            _fmt(mode["accelerations"][n][i], ang)]
                for p in points.values():
                    row += [_fmt(p[ax][i], False) for ax in "xyz"]
                t.add_row(*row)
            console.print(t)
            for line in transmission_lines(mode.get("transmission"), s.input_is_angle):
                console.print(f"  • {escape(line)}", highlight=False)
            for ev in mode["events"]:
                console.print(f"  • {escape(ev)}", highlight=False)
            missing = int((~np.asarray(mode["assembles"])).sum())
            if missing:
                console.print(f"  • does not assemble at {missing} of {len(doc['input'])} inputs", highlight=False)
        if "note" in doc.get("transmission", {}):
            console.print(f"[yellow]transmission:[/] {escape(doc['transmission']['note'])}", highlight=False)

    _emit(doc, as_json, output, table, [spec])


@app.command()
def limits(
    spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
    as_json: JsonOpt = False,
    output: OutputOpt = None,
    variable: Annotated[str | None, typer.Option("--output-variable", "--var", help="The output variable: a joint freedom (e.g. output.theta) or a seed name (phi0, S, s4 …); default the loop's outputs (or [limits] output).")] = None,
    method: Annotated[str | None, typer.Option("--method", help="auto (Bagci's App. D closed form for the RSRC/4R φ0 and S, else generic), closed, or generic (any loop, over the [motion] sweep).")] = None,
    dwell_tolerance: Annotated[float | None, typer.Option("--dwell-tol", help="A derivative dᵏy/dxᵏ counts as vanishing below this (output unit / input unitᵏ; default 1e-6 or [limits]). Printed dimensions hold a designed dwell only to ~1e-4.")] = None,
    at: Annotated[list[float] | None, typer.Option("--at", help="Also give the dwell order at this input (degrees, or m for a translation input); repeatable.")] = None,
) -> None:
    """Limit positions of the output variables (d output/d input = 0) and the order of the instantaneous dwell at each (Bagci App. D for the RSRC and 4R; the generic route for any loop)."""
    from screwkit.io.spec import load_spec
    from screwkit.pipeline import Pipeline

    check_paths([spec], {"--output": output})
    s = _guard(lambda: load_spec(spec))
    where = None if at is None else [float(np.radians(x)) if s.input_is_angle else float(x) for x in at]
    doc = _guard(lambda: Pipeline(s).limits(dwell_tolerance, where, output=variable, method=method).as_dict())

    def table() -> None:
        console.print(f"[bold]{escape(s.describe())}[/]", highlight=False)
        console.print(f"method: {doc['method']}; derivatives: {escape(doc['derivatives'])}", highlight=False)
        t = Table(title=f"limit positions (dwell tolerance {doc['dwell_tolerance']:g})")
        inp = "input (deg)" if s.input_is_angle else "input (m)"
        for col in ("output", "kind", "mode" if doc["method"] == "generic" else "branch", inp, "value", "2nd derivative", "dwell order"):
            t.add_column(col, justify="right")
        for lim in doc["limits"]:
            ang = lim["kind"] == "rotation"
            t.add_row(lim["output"], lim["kind"], str(lim.get("mode", lim.get("branch"))),
                      _fmt(lim["input"], s.input_is_angle), _fmt(lim["value"], ang) + (" deg" if ang else " m"),
                      f"{lim['second_derivative']:.4g}", "—" if lim["dwell_order"] is None else str(lim["dwell_order"]))
        console.print(t)
        if doc["dwells_at"]:
            t2 = Table(title="dwell order at given inputs")
            for col in ("output", inp, "mode" if doc["method"] == "generic" else "inversion",
                        "value", "dwell order", "dᵏy/dxᵏ, k = 1 …"):
                t2.add_column(col, justify="right")
            for d in doc["dwells_at"]:
                ang = not (d["output"] in ("S", "s4") or d["output"].endswith(".s"))
                t2.add_row(d["output"], _fmt(d["input"], s.input_is_angle), str(d.get("mode", d.get("inversion_label"))),
                           _fmt(d["value"], ang), str(d["dwell_order"]), ", ".join(f"{x:.3g}" for x in d["derivatives"]))
            console.print(t2)
        for note in doc["notes"]:
            console.print(f"[yellow]note:[/] {escape(note)}", highlight=False)

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
    from screwkit.io.documents import synthesis_document
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
        _guard(lambda p=pipe: p.motion)  # type: ignore[misc]
        doc = _guard(pipe.analysis)
        out = output_dir / f"{f.stem}.analysis.json"
        write(out, doc)
        if plots:
            from screwkit.report.plots import plot_analysis

            _guard(lambda d=doc, f=f: plot_analysis(d, output_dir / f"{f.stem}.analysis.png"))  # type: ignore[misc]
        mob = _guard(lambda p=pipe: p.mobility().as_dict())  # type: ignore[misc]
        write(output_dir / f"{f.stem}.mobility.json", mob)
        jobs = ["analysis", "mobility"]
        if spec.limits is not None:
            lim = _guard(lambda p=pipe: p.limits().as_dict())  # type: ignore[misc]
            write(output_dir / f"{f.stem}.limits.json", lim)
            jobs.append("limits")
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
        summary = _demo_summary(spec, doc, mob, asm, res, {
            "limits": lim if "limits" in jobs else None, "dynamics": dyn if "dynamics" in jobs
            else None, "balance": bal.as_dict() if "balance" in jobs else None,
            "simulation": sim if "simulation" in jobs else None,
            "synthesis": syn if "synthesis" in jobs else None})
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


def _demo_summary(spec: Any, doc: dict[str, Any], mob: dict[str, Any], asm: str, res: float,
                  done: dict[str, Any]) -> list[tuple[str, Any]]:
    """The lines of an example's entry in the demo's index: the analysis (with transmission),
    mobility and one line per other job that ran (``done``: job -> its document or None)."""
    summary: list[tuple[str, Any]] = [
        ("input samples", len(spec.inputs)), ("analysis method", doc["method"]),
        ("assembly modes (samples assembling)", f"{len(doc['modes'])} ({asm})"),
        ("max loop-closure residual", f"{res:.1e}"),
        ("mobility (formula / Jacobian)", f"{mob['formula']['mobility']} / {mob['numeric']['mobility']}"),
    ]
    for m in doc["modes"]:
        for line in transmission_lines(m.get("transmission"), spec.input_is_angle):
            summary.append((f"mode {m['mode']}", line))
    if (lim := done.get("limits")) is not None:
        summary.append(("limit positions (output: input, dwell order)", "; ".join(
            f"{x['output']} {_fmt(x['input'], spec.input_is_angle)}, {x['dwell_order']}"
            for x in lim["limits"]) or "none"))
    if (dyn := done.get("dynamics")) is not None:
        sf = dyn["summary"]["shaking_force"]
        summary.append(("shaking force RMS / peak (N)", f"{sf['rms']:.6g} / {sf['peak']:.6g}"))
    if (bal := done.get("balance")) is not None:
        g = bal["measures"]
        summary.append(("balancing objective G before → after", f"{g['before']['G']:.6g} → {g['after']['G']:.6g}"))
    if (sim := done.get("simulation")) is not None:
        last = sim["cycles"][-1] if sim.get("cycles") else {}
        summary.append(("simulated speed fluctuation (last cycle)",
                        f"{last.get('fluctuation', float('nan')):.4g}"))
    if (syn := done.get("synthesis")) is not None:
        summary.append(("synthesis RMSE (φ rad, S m)", f"{syn.get('rmse_phi')} , {syn.get('rmse_S')}"))
    return summary


def _register_subcommands() -> None:
    from screwkit.cli.balance_cmd import register as register_balance
    from screwkit.cli.mjcf_cmd import register as register_mjcf
    from screwkit.cli.report_cmd import register as register_report
    from screwkit.cli.simulate_cmd import register as register_simulate
    from screwkit.cli.synthesize_cmd import register as register_synthesize

    register_synthesize(app)
    register_balance(app)
    register_report(app)
    register_simulate(app)
    register_mjcf(app)


_register_subcommands()


if __name__ == "__main__":  # pragma: no cover
    app()

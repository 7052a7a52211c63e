"""``screwkit demo [EXAMPLES]``: the main job on every bundled example — validate, analyse,
and every job the spec supports — writing ``<name>.<job>.json`` (SI), ``<name>.analysis.csv``
and the plot in the spec's units, and an animated HTML report per example; ``index.html`` shows
them as a gallery (a small picture and one line each) linking to the reports. A progress bar counts the examples (on a terminal)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from screwkit.cli.common import prose


def run_example(f: Path, output_dir: Path, files: list[Path], plots: bool,
                reports: bool) -> tuple[list[str], dict[str, Any]]:
    """Every job of one example: the demo table's row and the index entry."""
    import numpy as np
    from rich.markup import escape

    from screwkit.cli.common import guard
    from screwkit.cli.dynamics_cmd import dynamics_job
    from screwkit.io.documents import synthesis_document
    from screwkit.io.results import write_json_atomic
    from screwkit.io.spec import load_spec
    from screwkit.io.tables import write_table
    from screwkit.pipeline import Pipeline

    def write(path: Path, result: Any) -> None:
        guard(lambda: write_json_atomic(path, result, files))

    if f.parent.name == "mechanisms":  # any mechanism as a graph (docs/mechanisms.md)
        from screwkit.cli.graph_views import demo_graph_example

        return demo_graph_example(f, output_dir, files, plots, reports)
    spec = guard(lambda: load_spec(f))
    du = spec.display_units()
    prose(f"[green]ok[/] {escape(spec.describe())}")
    pipe = Pipeline(spec)
    motion = guard(lambda: pipe.motion)
    doc = guard(pipe.analysis)
    write(output_dir / f"{f.stem}.analysis.json", doc)
    table = guard(pipe.analysis_table)
    guard(lambda: write_table(table, output_dir / f"{f.stem}.analysis.csv", "csv", du, files))
    if plots:
        from screwkit.report.plots import plot_analysis

        guard(lambda: plot_analysis(doc, output_dir / f"{f.stem}.analysis.png", units=du))
    mob = guard(lambda: pipe.mobility().as_dict())
    write(output_dir / f"{f.stem}.mobility.json", mob)
    jobs = ["analysis", "mobility"]
    dyn = bal = syn = sim = lim = None
    if spec.limits is not None:
        lim = guard(lambda: pipe.limits().as_dict())
        write(output_dir / f"{f.stem}.limits.json", lim)
        jobs.append("limits")
    if all(link.mass is not None for link in spec.linkage.links):
        dyn = guard(lambda: dynamics_job(pipe, False))
        write(output_dir / f"{f.stem}.dynamics.json", dyn)
        jobs.append("dynamics")
    if spec.balancing is not None:
        bal = guard(lambda: pipe.balance().as_dict())
        write(output_dir / f"{f.stem}.balance.json", bal)
        jobs.append("balance")
    if spec.synthesis is not None:
        syn = guard(lambda: synthesis_document(pipe.synthesize(), pipe.spec.path))
        write(output_dir / f"{f.stem}.synthesis.json", syn)
        jobs.append("synthesis")
    if spec.drive is not None:
        sim = guard(lambda: pipe.simulate().as_dict(loads=False))
        write(output_dir / f"{f.stem}.simulation.json", sim)
        jobs.append("simulation")
    if reports:
        from screwkit.report.spec_report import write_spec_report

        guard(lambda: write_spec_report(pipe, output_dir / f"{f.stem}.html", balance_doc=bal,
                                        synthesis_doc=syn))
    res = max((float(np.nanmax(np.asarray(m.closure_residual, dtype=float)))
               for m in motion.modes), default=float("nan"))
    asm = ", ".join(str(int(np.sum(m.assembles))) for m in motion.modes)
    row = [f.stem, spec.family, str(len(spec.inputs)), str(len(motion.modes)), asm,
           f"{res:.1e}", ", ".join(jobs)]
    summary = example_summary(spec, motion, doc, mob, asm, res,
                              {"limits": lim, "dynamics": dyn, "balance": bal,
                               "simulation": sim, "synthesis": syn})
    entry = {
        "name": f.stem, "family": spec.family, "description": spec.describe(),
        "thumbnail": guard(lambda: thumbnail(spec, motion, syn)),
        # every example has analysis and mobility: the line names the other jobs
        "line": " · ".join([spec.family, f"{len(motion.modes)} mode(s)",
                            *[j for j in jobs if j not in ("analysis", "mobility")]]),
        "jobs": [(j, f"{f.stem}.{j}.json") for j in jobs], "summary": summary,
        "picture": f"{f.stem}.analysis.png" if plots else None,
        "report": f"{f.stem}.html" if reports else None,
    }
    return row, entry


def thumbnail(spec: Any, motion: Any, synthesis_doc: dict[str, Any] | None) -> str:
    """The gallery picture of an example: the mechanism its report animates — the synthesised
    one for a synthesis spec (:mod:`screwkit.report.synthesis_scene`), else the spec's."""
    from screwkit.errors import ScrewkitError
    from screwkit.report.synthesis_scene import synthesised_motion
    from screwkit.report.thumbnail import mechanism_svg

    if synthesis_doc is not None and spec.synthesis is not None:
        try:
            shown = synthesised_motion(spec.synthesis, synthesis_doc, spec.family or "LOOP")
            return mechanism_svg(shown.linkage, shown.motion, shown.mode,
                                 f"{spec.name} (synthesised)")
        except ScrewkitError:
            pass  # the report shows the spec's mechanism then, and so does the picture
    return mechanism_svg(spec.linkage, motion, spec.mode, spec.name)


def example_summary(spec: Any, motion: Any, doc: dict[str, Any], mob: dict[str, Any], asm: str,
                    res: float, done: dict[str, Any]) -> list[tuple[str, Any]]:
    """An example's lines in the demo's index: the analysis (with the transmission quality),
    the mobility and one line per other job that ran (``done``: job -> document or None)."""
    from screwkit.cli.analyze_cmd import transmission_lines
    from screwkit.kinematics.motion_table import variable_kind

    du = spec.display_units()
    input_kind = variable_kind(motion.input_names[0])
    summary: list[tuple[str, Any]] = [
        ("input samples", len(spec.inputs)), ("analysis method", motion.method),
        ("assembly modes (samples assembling)", f"{len(motion.modes)} ({asm})"),
        ("max loop-closure residual", f"{res:.1e}"),
        ("mobility (formula / Jacobian)",
         f"{mob['formula']['mobility']} / {mob['numeric']['mobility']}"),
    ]
    for m in doc["modes"]:
        summary += [(f"mode {m['mode']}", line)
                    for line in transmission_lines(m.get("transmission"), du, input_kind)]
    if (lim := done.get("limits")) is not None:
        xk = variable_kind(lim["input_name"] if lim["method"] == "generic" else "theta0")
        summary.append((f"limit positions (output: input [{du.label(xk)}], dwell order)",
                        "; ".join(f"{x['output']}: {du.show(xk, x['input']):.6g}, "
                                  f"{x['dwell_order']}" for x in lim["limits"]) or "none"))
    if (dyn := done.get("dynamics")) is not None:
        sf = dyn["summary"]["shaking_force"]
        summary.append((f"shaking force RMS / peak ({du.label('force')})",
                        f"{du.show('force', sf['rms']):.6g} / {du.show('force', sf['peak']):.6g}"))
    if (bal := done.get("balance")) is not None:
        g = bal["measures"]
        summary.append(("balancing objective G before → after",
                        f"{g['before']['G']:.6g} → {g['after']['G']:.6g}"))
    if (sim := done.get("simulation")) is not None:
        last = sim["cycles"][-1] if sim.get("cycles") else {}
        summary.append(("simulated speed fluctuation (last cycle)",
                        f"{last.get('fluctuation', float('nan')):.4g}"))
    if (syn := done.get("synthesis")) is not None:
        summary.append(("synthesis RMSE (φ rad, S m)",
                        f"{syn.get('rmse_phi')} , {syn.get('rmse_S')}"))
    return summary


def register(app: typer.Typer) -> None:
    """Add the ``demo`` command to ``app``."""

    @app.command()
    def demo(
        examples: Annotated[Path, typer.Argument(help="Folder of spec files.")] = Path("examples"),
        output_dir: Annotated[Path, typer.Option("--output-dir", help="Where results are written.")] = Path("out"),
        plots: Annotated[bool, typer.Option("--plots/--no-plots", help="Also write a PNG per example.")] = True,
        write_reports: Annotated[bool, typer.Option("--reports/--no-reports", help="Also write each example's animated HTML report (<example>.html).")] = True,
    ) -> None:
        """Run the main job on every bundled example: validate, analyse, write the results (JSON in SI, CSV and plots in each spec's units) and an animated HTML report per example (out/index.html links them)."""
        from screwkit.cli.common import console, guard, user_error
        from screwkit.cli.formatting import TextColumn, print_columns
        from screwkit.cli.progress import progress_bar
        from screwkit.io.outputs import make_output_folder

        files = sorted(examples.glob("*.toml")) + sorted(examples.glob("mechanisms/*.toml"))
        if not files:
            user_error(f"no spec files (*.toml) in {examples}")
        guard(lambda: make_output_folder(output_dir, "--output-dir"))
        rows: list[list[str]] = []
        entries: list[dict[str, Any]] = []
        with progress_bar("examples", total=len(files)) as advance:
            for k, f in enumerate(files):
                row, entry = run_example(f, output_dir, files, plots, write_reports)
                rows.append(row)
                entries.append(entry)
                advance(k + 1, len(files))
        heads = ("example", "family", "samples", "modes", "assembling", "max closure\nresidual",
                 "jobs")
        cols = [TextColumn(h, [r[i] for r in rows], "left") for i, h in enumerate(heads)]
        print_columns(console, f"screwkit demo: {len(files)} examples", cols)
        from screwkit.report.html import write_index

        reports = sorted(Path("validation").glob("*/*.md")) if Path("validation").is_dir() else []
        here = output_dir.resolve().parent == Path.cwd().resolve()
        index = guard(lambda: write_index(output_dir, entries,
                                          [Path("..") / r for r in reports] if here else None))
        console.print(f"wrote {index}", highlight=False, markup=False)

"""The commands' views of a graph spec (any mechanism, docs/mechanisms.md): ``analyze`` and
``mobility``. They only call the library and format its documents."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np


def solved(spec: Any, every_mode: bool = False) -> Any:
    """The drawn mode (and with ``every_mode`` every mode the closed-form sub-chains find)
    over the spec's inputs, with a progress bar on long runs."""
    from screwkit.cli.progress import progress_bar
    from screwkit.kinematics.graph import solve_mechanism

    with progress_bar("following the drawn mode", spec.inputs.shape[0]) as report:
        return solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                               accelerations=spec.acceleration, progress=report,
                               every_mode=every_mode)


def graph_mobility(spec: Any) -> dict[str, Any]:
    """The topology document, with the Jacobian's rank at up to 24 solved samples."""
    from screwkit.kinematics.graph.topology import mechanism_topology

    motion = solved(spec)
    md = motion.modes[0]
    idx = np.nonzero(md.assembles)[0]
    idx = idx[np.linspace(0, idx.size - 1, min(24, idx.size)).astype(int)] if idx.size else idx
    return mechanism_topology(spec.mechanism, md.conf.take(idx)).as_dict()


def graph_limits(spec: Any, output: str | None, dwell_tolerance: float | None
                 ) -> dict[str, Any]:
    """The limits document of a one-input graph spec."""
    from screwkit.kinematics.graph.limits import graph_limit_positions

    return graph_limit_positions(solved(spec), output,
                                 1e-6 if dwell_tolerance is None else dwell_tolerance).as_dict()


def analyze_graph(spec: Any, out: Any, plot: Path | None, every_mode: bool = True) -> None:
    """``screwkit analyze`` on a graph spec: tables in the spec's units, or the document;
    every mode, or the drawn one only (``--modes drawn``)."""
    from screwkit.cli.common import guard
    from screwkit.io.mechanism_documents import mechanism_document, mechanism_table

    motion = guard(lambda: solved(spec, every_mode=every_mode))
    du = out.units_for(spec.units)
    if plot is not None:  # the loops' picture of every variable and point path fits a graph
        from screwkit.report.plots import plot_analysis

        document = mechanism_document(motion, spec.topology)
        guard(lambda: plot_analysis(document, plot, units=du))
        out.note_written(plot)
    out.deliver(document=lambda: mechanism_document(motion, spec.topology),
                table=lambda: mechanism_table(motion),
                show=lambda: _show(spec, motion, du, out.full), units=du)


def _show(spec: Any, motion: Any, units: Any, full: bool) -> None:
    from rich.markup import escape

    from screwkit.cli.common import console, prose
    from screwkit.cli.formatting import print_long_table, table_columns
    from screwkit.io.mechanism_documents import mechanism_table

    prose(f"[bold]{escape(spec.describe(units))}[/]")
    prose(f"method: {motion.method}; {units.describe()}")
    for note in motion.notes:
        prose(f"[yellow]note:[/] {escape(note)}")
    table = mechanism_table(motion)
    mech = spec.mechanism
    for md in motion.modes:
        names = ["input"] + [f"input_{k + 1}" for k in range(1, len(mech.driven_names))]
        outs = [o.name for o in mech.outputs][:4]
        order = [*mech.actuated, *(n for n in md.variables if n not in mech.actuated)]
        shown = [n for n in order if n not in mech.inputs][:max(0, 3 - len(outs))]
        for n in outs + shown:
            names += [n, f"{n}_dot"]
        for p in list(md.points)[:2]:
            names += [f"{p}_{a}" for a in "xyz"]
        t = table.where(table.column("mode").values == md.index)
        cols, values = table_columns(t, [n for n in names if n in t.names], units)
        drawn = not md.label or md.label == "drawn"
        if not drawn:  # the branches on a line of their own: a long label would widen the title
            prose(f"assembly mode {md.index}: {escape(md.label)}")
        print_long_table(console, f"assembly mode {md.index}{' (drawn)' if drawn else ''}",
                         cols, values, full)
        hidden = len(md.variables) - len(shown) - len(mech.inputs)
        if hidden > 0:
            prose(f"  • {len(shown)} of {len(shown) + hidden} variables shown; every "
                  "variable and point is in --csv and --json")
        for ev in md.events:
            prose(f"  • {escape(ev)}")
        missing = int((~np.asarray(md.assembles)).sum())
        if missing:
            prose(f"  • does not assemble at {missing} of {motion.samples} inputs")


def graph_dynamics(spec: Any, gravity: bool) -> Any:
    """The loads of a graph spec's drawn mode (gravity along the spec's direction if asked)."""
    from screwkit.dynamics.graph_inverse import graph_inverse_dynamics

    return graph_inverse_dynamics(solved(spec), 0, spec.gravity_vector if gravity else None)


def graph_balance(spec: Any, motion: Any, progress: Any = None) -> Any:
    """The spec's ``[balancing]`` run on a graph spec's drawn mode (``motion``, from
    :func:`solved`; docs/balancing.md, "Mechanism graphs"); ``progress(done, total)`` follows
    a Pareto sweep."""
    from screwkit.balancing.errors import BalancingError
    from screwkit.balancing.graph import balance_mechanism

    if spec.balancing is None:
        raise BalancingError(f"{spec.path}: no [balancing] table; see docs/balancing.md")
    try:
        return balance_mechanism(motion, 0, spec.balancing, speed=float(spec.speed[0]),
                                 gravity=spec.gravity_vector, progress=progress)
    except BalancingError as exc:
        raise BalancingError(f"{spec.path}: {exc}") from None


def dynamics_table(spec: Any, dyn: Any) -> Any:
    """One row per sample: the inputs, every effort, the shaking loads, every reaction."""
    from screwkit.tables import Column, ResultTable

    mech = spec.mechanism
    cols = []
    for k, slide in enumerate(mech.driven_is_translation()):
        kind = "length" if slide else "angle"
        cols.append(Column("input" if k == 0 else f"input_{k + 1}", kind, spec.inputs[:, k]))
    cols.append(Column("assembles", "flag", dyn.ok))
    for k, name in enumerate(dyn.input_names):
        cols.append(Column(f"effort_{name}", "force" if name.endswith(".s") else "moment",
                           dyn.efforts[:, k]))
    for what, kind, arr in (("shaking_force", "force", dyn.shaking_force),
                            ("shaking_moment", "moment", dyn.shaking_moment)):
        cols += [Column(f"{what}_{a}", kind, arr[:, i]) for i, a in enumerate("xyz")]
    for j, name in enumerate(dyn.joint_names):
        cols += [Column(f"{name}.force_{a}", "force", dyn.reaction_force[:, j, i])
                 for i, a in enumerate("xyz")]
        cols += [Column(f"{name}.moment_{a}", "moment", dyn.reaction_moment[:, j, i])
                 for i, a in enumerate("xyz")]
    return ResultTable(tuple(cols), f"{mech.name}: loads of the drawn mode, one row per sample")


def dynamics_summary(dyn: Any) -> dict[str, dict[str, Any]]:
    """RMS and peak (with the sample where it occurs) of every effort, the shaking loads and
    the largest joint reaction."""
    out: dict[str, dict[str, Any]] = {}

    def add(name: str, kind: str, size: np.ndarray) -> None:
        ok = np.isfinite(size)
        if not ok.any():
            return
        k = int(np.nanargmax(np.abs(size)))
        out[name] = {"kind": kind, "rms": float(np.sqrt(np.mean(size[ok] ** 2))),
                     "peak": float(np.abs(size[k])), "sample": k}

    for k, name in enumerate(dyn.input_names):
        add(f"effort {name}", "force" if name.endswith(".s") else "moment", dyn.efforts[:, k])
    add("shaking force", "force", np.linalg.norm(dyn.shaking_force, axis=1))
    add("shaking moment", "moment", np.linalg.norm(dyn.shaking_moment, axis=1))
    for j, name in enumerate(dyn.joint_names):
        add(f"reaction {name} force", "force", np.linalg.norm(dyn.reaction_force[:, j], axis=1))
    return out


def dynamics_graph(spec: Any, out: Any, gravity: bool) -> None:
    """``screwkit dynamics`` on a graph spec."""
    from screwkit.cli.common import guard

    dyn = guard(lambda: graph_dynamics(spec, gravity))
    du = out.units_for(spec.units)
    summary = dynamics_summary(dyn)

    def document() -> dict[str, Any]:
        doc = dyn.as_dict()
        doc.update(mode=0, gravity_on=bool(gravity), summary=summary,
                   input=spec.inputs[:, 0] if spec.inputs.shape[1] == 1 else spec.inputs)
        return doc

    out.deliver(document=document, table=lambda: dynamics_table(spec, dyn),
                show=lambda: _show_dynamics(spec, dyn, summary, du, gravity), units=du)


def _show_dynamics(spec: Any, dyn: Any, summary: dict[str, dict[str, Any]], units: Any,
                   gravity: bool) -> None:
    from rich.markup import escape

    from screwkit.cli.common import console, prose
    from screwkit.cli.formatting import TextColumn, number, print_columns

    prose(f"[bold]{escape(spec.describe(units))}[/]")
    prose("gravity on" if gravity else "gravity off (add it with --gravity)")
    kind0 = "length" if spec.mechanism.driven_is_translation()[0] else "angle"
    names = list(summary)
    cols = [TextColumn("load", names, "left"),
            TextColumn("unit", [units.label(summary[n]["kind"]) for n in names], "left"),
            TextColumn("RMS", [number(units.show(summary[n]["kind"], summary[n]["rms"]), 6)
                               for n in names]),
            TextColumn("peak", [number(units.show(summary[n]["kind"], summary[n]["peak"]), 6)
                                for n in names]),
            TextColumn(f"at input\n[{units.label(kind0)}]",
                       [number(units.show(kind0, spec.inputs[summary[n]["sample"], 0]), 6)
                        for n in names])]
    print_columns(console, "loads of the drawn mode (RMS and peak over the motion)", cols)
    if dyn.indeterminate:
        prose(f"  • {dyn.indeterminate} statically indeterminate reaction component(s) "
              f"(joints {', '.join(dyn.indeterminate_joints[:6])}"
              f"{', …' if len(dyn.indeterminate_joints) > 6 else ''}): the least-norm "
              "reactions are shown")
    bad = int((~dyn.ok).sum())
    if bad:
        prose(f"  • no loads at {bad} sample(s) where the mode does not assemble or "
              "is singular")


def demo_graph_example(f: Path, output_dir: Path, files: list[Path], plots: bool,
                       reports: bool) -> tuple[list[str], dict[str, Any]]:
    """``screwkit demo`` on a graph spec: analysis (JSON, CSV), topology, loads when every body
    has mass properties, and the 3-D report; the demo table's row and the index entry."""
    from rich.markup import escape

    from screwkit.cli.common import guard, prose
    from screwkit.io.mechanism_documents import mechanism_document, mechanism_table
    from screwkit.io.results import write_json_atomic
    from screwkit.io.spec import load_spec
    from screwkit.io.tables import write_table
    from screwkit.report.thumbnail import graph_svg

    def write(path: Path, result: Any) -> None:
        guard(lambda: write_json_atomic(path, result, files))

    spec: Any = guard(lambda: load_spec(f))
    du = spec.display_units()
    prose(f"[green]ok[/] {escape(spec.describe())}")
    motion = guard(lambda: solved(spec))
    write(output_dir / f"{f.stem}.analysis.json", mechanism_document(motion, spec.topology))
    guard(lambda: write_table(mechanism_table(motion), output_dir / f"{f.stem}.analysis.csv",
                              "csv", du, files))
    mob = guard(lambda: graph_mobility(spec))
    write(output_dir / f"{f.stem}.mobility.json", mob)
    jobs = ["analysis", "mobility"]
    md = motion.modes[0]
    res = float(np.nanmax(md.closure_residual))
    summary: list[tuple[str, Any]] = [
        ("input samples", len(spec.inputs)), ("analysis method", "graph continuation"),
        ("samples assembling", int(np.sum(md.assembles))),
        ("max loop-closure residual", f"{res:.1e}"),
        ("loops", len(mob["loops"])),
        ("mobility (Grübler–Kutzbach / Jacobian)", f"{mob['grubler_kutzbach']} / "
                                                   f"{mob['mobility']}"),
        ("redundant constraints, idle freedoms",
         f"{len(mob['redundant_constraints'])}, {len(mob['idle_freedoms'])}")]
    if all(b.mass is not None for b in spec.mechanism.bodies):
        dyn = guard(lambda: graph_dynamics(spec, True))
        doc = dyn.as_dict()
        doc["summary"] = dynamics_summary(dyn)
        write(output_dir / f"{f.stem}.dynamics.json", doc)
        jobs.append("dynamics")
        sf = doc["summary"]["shaking force"]
        summary.append((f"shaking force RMS / peak, gravity on ({du.label('force')})",
                        f"{du.show('force', sf['rms']):.6g} / {du.show('force', sf['peak']):.6g}"))
    if spec.balancing is not None:
        from screwkit.io.documents import balance_document

        bal = balance_document(guard(lambda: graph_balance(spec, motion)))
        write(output_dir / f"{f.stem}.balance.json", bal)
        jobs.append("balance")
        g = bal["measures"]
        summary.append(("balancing objective G before → after",
                        f"{g['before']['G']:.6g} → {g['after']['G']:.6g}"))
    if reports:
        from screwkit.report.spec_report import write_spec_report

        guard(lambda: write_spec_report(spec, output_dir / f"{f.stem}.html"))
    row = [f.stem, "graph", str(len(spec.inputs)), "1", str(int(np.sum(md.assembles))),
           f"{res:.1e}", ", ".join(jobs)]
    entry = {
        "name": f.stem, "family": "graph", "description": spec.describe(),
        "thumbnail": graph_svg(spec.mechanism, motion, spec.name),
        "line": " · ".join(["graph", f"{len(mob['loops'])} loop(s)",
                            *[j for j in jobs if j not in ("analysis", "mobility")]]),
        "jobs": [(j, f"{f.stem}.{j}.json") for j in jobs], "summary": summary,
        "picture": None, "report": f"{f.stem}.html" if reports else None,
    }
    return row, entry

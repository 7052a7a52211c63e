"""The commands' views of a graph spec (any mechanism, docs/mechanisms.md): ``analyze`` and
``mobility``. They only call the library and format its documents."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np


def solved(spec: Any) -> Any:
    """The drawn mode over the spec's inputs, with a progress bar on long runs."""
    from screwkit.cli.progress import progress_bar
    from screwkit.kinematics.graph import solve_mechanism

    with progress_bar("following the drawn mode", spec.inputs.shape[0]) as report:
        return solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                               accelerations=spec.acceleration, progress=report)


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


def analyze_graph(spec: Any, out: Any, plot: Path | None) -> None:
    """``screwkit analyze`` on a graph spec: tables in the spec's units, or the document."""
    from screwkit.cli.common import guard
    from screwkit.io.mechanism_documents import mechanism_document, mechanism_table

    motion = guard(lambda: solved(spec))
    du = out.units_for(spec.units)
    if plot is not None:
        from screwkit.cli.common import user_error

        user_error("--plot is not offered for graph specs yet; use `screwkit report` or --csv")
    out.deliver(document=lambda: mechanism_document(motion, spec.topology),
                table=lambda: mechanism_table(motion),
                show=lambda: _show(spec, motion, du, out.full), units=du)


def _show(spec: Any, motion: Any, units: Any, full: bool) -> None:
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import print_long_table, table_columns
    from screwkit.io.mechanism_documents import mechanism_table

    console.print(f"[bold]{escape(spec.describe(units))}[/]", highlight=False)
    console.print(f"method: {motion.method}; {units.describe()}", highlight=False)
    table = mechanism_table(motion)
    mech = spec.mechanism
    for md in motion.modes:
        names = ["input"] + [f"input_{k + 1}" for k in range(1, len(mech.inputs))]
        outs = [o.name for o in mech.outputs][:4]
        shown = [n for n in md.variables if n not in mech.inputs][:max(0, 3 - len(outs))]
        for n in outs + shown:
            names += [n, f"{n}_dot"]
        for p in list(md.points)[:2]:
            names += [f"{p}_{a}" for a in "xyz"]
        cols, values = table_columns(table, [n for n in names if n in table.names], units)
        print_long_table(console, f"assembly mode {md.index} (the drawn mode)", cols, values,
                         full)
        hidden = len(md.variables) - len(shown) - len(mech.inputs)
        if hidden > 0:
            console.print(f"  • {len(shown)} of {len(shown) + hidden} variables shown; every "
                          "variable and point is in --csv and --json", highlight=False)
        for ev in md.events:
            console.print(f"  • {escape(ev)}", highlight=False)
        missing = int((~np.asarray(md.assembles)).sum())
        if missing:
            console.print(f"  • does not assemble at {missing} of {motion.samples} inputs",
                          highlight=False)

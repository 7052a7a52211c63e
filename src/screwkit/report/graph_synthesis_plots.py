"""The report of a graph spec with a ``[synthesis]`` table (docs/synthesis.md, "Graphs"): each
target against what the spec's own drawing generates — for a spec written by ``screwkit
synthesize --spec-out``, the synthesised mechanism. Not linked to the animation (the targets
sit at their own inputs)."""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.report.scene_plots import DEG

__all__ = ["graph_synthesis_plots", "write_graph_synthesis_plot"]


def graph_synthesis_plots(spec: Any, units: dict[str, Any]
                          ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Plots (desired vs generated, and the error) per target and their group."""
    from screwkit.synthesis.graph_route import graph_target_values

    problem = spec.synthesis
    values, why = graph_target_values(problem)
    angle_in = not spec.mechanism.driven_is_translation()[0]
    x_scale = DEG if angle_in else units["factor"]
    x_label = f"{spec.mechanism.driven_names[0]} ({'deg' if angle_in else units['length']})"
    plots: list[dict[str, Any]] = []
    for k, t in enumerate(problem.targets):
        scale = DEG if t.kind == "angle" else units["factor"]
        unit = "deg" if t.kind == "angle" else units["length"]
        x = t.inputs[:, 0]
        order = np.argsort(x, kind="stable")
        series = []
        for c, comp in enumerate(t.components):
            tag = f" {'xyz'[comp]}" if t.what == "point" else ""
            series.append({"name": f"desired{tag}", "mode": None, "style": "points",
                           "x": x[order], "y": t.values[order, c]})
            if values is not None:
                series.append({"name": f"generated{tag}", "mode": None, "style": "line+points",
                               "x": x[order], "y": values[k][order, c]})
        plots.append({"id": f"gsyn-{k}", "group": "synthesis", "title": f"{t.label}: desired vs "
                      "generated", "kind": "line", "x_label": x_label,
                      "y_label": f"{t.label} ({unit})", "x_scale": x_scale, "y_scale": scale,
                      "linked": False, "series": series})
    note = ("The targets of the spec's [synthesis] table against what this drawing generates "
            "on its drawn mode (for a spec written by `screwkit synthesize --spec-out`, the "
            "synthesised mechanism).")
    if values is None:
        note += f" This drawing does not reach every target: {why}."
    return plots, [{"id": "synthesis", "title": "Synthesis", "note": note}]


def _dense_curve(problem: Any, x: Any, k: int, n: int = 121) -> tuple[Any, Any] | None:
    """The synthesised design's target ``k`` over its input range, n inputs (one-input
    mechanisms): (inputs (n,), values (n, c)) SI on the drawn mode, NaN where it does not
    assemble; None for several inputs or when the design does not solve."""
    from screwkit.errors import ScrewkitError
    from screwkit.kinematics.graph import solve_mechanism

    t = problem.targets[k]
    if t.inputs.shape[1] != 1:
        return None
    lo, hi = float(t.inputs[:, 0].min()), float(t.inputs[:, 0].max())
    grid = np.linspace(lo, hi, n)
    try:
        md = solve_mechanism(problem.design(x), grid[:, None], rates=problem.rates).modes[0]
    except (ScrewkitError, ValueError):
        return None
    if t.what == "point":
        vals = np.asarray(md.points[t.name])[:, list(t.components)]
    else:
        vals = np.asarray((md.outputs if t.what == "output" else md.variables)[t.name])[:, None]
    ok = np.asarray(md.assembles) & ~np.asarray(md.singular)
    return grid, np.where(ok[:, None], vals, np.nan)


def write_graph_synthesis_plot(spec: Any, problem: Any, doc: dict[str, Any], x: Any, du: Any,
                               path: Any) -> None:
    """``screwkit synthesize GRAPH --plot FILE`` (PNG, SVG or PDF by the suffix): one panel per
    target — the desired values (points), what the synthesised design ``x`` generates at the
    target inputs (crosses, the document's ``rows``) and, for a one-input mechanism, its curve
    over the targets' input range (the drawn mode solved anew at 121 inputs); display units."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from screwkit.report.plots import save_figure

    slide = bool(spec.mechanism.driven_is_translation()[0])
    in_kind = "length" if slide else "angle"
    n = len(problem.targets)
    fig, axes = plt.subplots(n, 1, figsize=(7, 2.8 * n + 0.6), squeeze=False)
    for k, (t, ax) in enumerate(zip(problem.targets, axes[:, 0], strict=True)):
        rows = [r for r in doc["rows"] if r["target"] == t.label]
        inp = du.show(in_kind, np.array([r["input"][0] for r in rows], dtype=float))
        curve = _dense_curve(problem, x, k)
        for c, comp in enumerate(t.components):
            tag = f" {'xyz'[comp]}" if t.what == "point" else ""
            des = du.show(t.kind, np.array([r["desired"][c] for r in rows], dtype=float))
            gen = du.show(t.kind, np.array([r["generated"][c] for r in rows], dtype=float))
            ax.plot(inp, des, "o", ms=5, label=f"desired{tag}")
            ax.plot(inp, gen, "x", ms=6, label=f"generated{tag}")
            if curve is not None:
                ax.plot(du.show(in_kind, curve[0]), du.show(t.kind, curve[1][:, c]), "-",
                        lw=1, label=f"synthesised design{tag}")
        ax.set_title(f"{t.label}: desired vs generated", fontsize=9)
        ax.set_ylabel(f"{t.label} ({du.label(t.kind)})")
        ax.set_xlabel(f"{spec.mechanism.driven_names[0]} ({du.label(in_kind)})")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{spec.name}: graph synthesis, E = {doc['objective']:.4g}, "
                 f"RMSE {doc['rmse']:.4g}", fontsize=10)
    fig.tight_layout()
    try:
        save_figure(fig, path)
    finally:
        plt.close(fig)

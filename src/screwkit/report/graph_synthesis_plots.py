"""The report of a graph spec with a ``[synthesis]`` table (docs/synthesis.md, "Graphs"): each
target against what the spec's own drawing generates — for a spec written by ``screwkit
synthesize --spec-out``, the synthesised mechanism. Not linked to the animation (the targets
sit at their own inputs)."""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.report.scene_plots import DEG

__all__ = ["graph_synthesis_plots"]


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

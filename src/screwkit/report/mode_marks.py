"""Where each assembly mode of a graph's motion is born, dies and crosses a singularity, marked
in the report (report/graph_scene.py): a ``marks`` list per mode and a plot of the modes
against the first input.

A mode is **born** at the first sample of a run of samples where it assembles (after one where
it does not) and **dies** at the last; the fold itself lies between the two samples, and the
mode's events give it to round-off (kinematics/modes/along.py, graph/closed_modes.py). A
sample with a singularity class (graph/singular.py: input, output, constraint, dead centre,
bifurcation) is marked with that class. The plot draws mode k as a line at height k over the
inputs where it assembles, with its births, deaths and singular samples as points on it, so
crossings of homotopy modes and of closed-form modes are drawn alike.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def mode_marks(assembles: NDArray[np.bool_], singular_class: Any) -> list[dict[str, Any]]:
    """The marks of one mode: ``{"frame": i, "kind": "born" | "dies" | <class>}``, by frame."""
    ok = np.asarray(assembles, dtype=bool)
    N = ok.size
    marks = []
    before = np.concatenate([[False], ok[:-1]])
    after = np.concatenate([ok[1:], [False]])
    for i in np.flatnonzero(ok & ~before):
        if i > 0:
            marks.append({"frame": int(i), "kind": "born"})
    for i in np.flatnonzero(ok & ~after):
        if i < N - 1:
            marks.append({"frame": int(i), "kind": "dies"})
    cls = np.asarray(singular_class if singular_class is not None else [], dtype=str)
    if cls.size == N:
        for i in np.flatnonzero((cls != "") & ok):
            marks.append({"frame": int(i), "kind": str(cls[i])})
    return sorted(marks, key=lambda m: (m["frame"], m["kind"]))


def mode_chart(entries: list[dict[str, Any]], x_label: str, x_scale: float
               ) -> tuple[dict[str, Any], dict[str, Any]]:
    """The plot of every mode (``entries``: the scene's modes, each with ``assembles`` and
    ``marks``) and its group."""
    series = []
    for k, e in enumerate(entries):
        ok = np.asarray(e["assembles"], dtype=bool)
        y = np.where(ok, float(k), np.nan)
        series.append({"name": f"mode {k}", "mode": k, "style": "line", "y": y})
        for kinds, name in ((("born", "dies"), "born / dies"), (None, "singular")):
            at = [m["frame"] for m in e["marks"]
                  if (m["kind"] in kinds if kinds else m["kind"] not in ("born", "dies"))]
            if at:
                pts = np.full(ok.size, np.nan)
                pts[at] = float(k)
                series.append({"name": f"mode {k}: {name}", "mode": k, "style": "points",
                               "y": pts})
    plot = {"id": "modes-chart", "group": "modes", "title": "Assembly modes over the input",
            "kind": "line", "x_label": x_label, "y_label": "mode", "x_scale": x_scale,
            "y_scale": 1.0, "linked": True, "series": series}
    group = {"id": "modes", "title": "Assembly modes: births, deaths and singular crossings",
             "note": "Mode k is drawn at height k where it assembles; points mark where it is "
                     "born or dies (a fold lies between that sample and the next; the mode's "
                     "events give it) and its singular samples (input, output, constraint, dead "
                     "centre, bifurcation)."}
    return plot, group

"""Plots of a balancing run (like Rahman 1996, Figures 5.1–5.6) and of a Pareto front, in the
units asked for. matplotlib is imported lazily (the ``plot`` extra)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from screwkit.balancing.errors import MissingSolverError
from screwkit.balancing.result import SAMPLE_LOADS, BalanceResult


def _pyplot() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise MissingSolverError("plots need matplotlib: pip install 'screwkit[plot]'") from exc
    return plt


def write_plots(result: BalanceResult, folder: str | Path, units: Any = None) -> list[str]:
    """One PNG per per-sample load, before and after, against the input: in ``units`` (an
    object with ``unit_of(kind) -> (label, SI value of one unit)``, e.g. the spec's
    :class:`~screwkit.io.display_units.DisplayUnits`), by default the input in degrees and the
    loads in SI."""
    from screwkit.balancing.result_table import LOAD_KINDS
    from screwkit.io.display_units import pretty_unit
    from screwkit.io.outputs import make_output_folder
    from screwkit.tables import SI_LABELS

    plt = _pyplot()
    out = make_output_folder(folder, "--plots")

    def unit_of(kind: str) -> tuple[str, float]:
        if units is not None:
            return tuple(units.unit_of(kind))  # type: ignore[return-value]
        return ("deg", np.pi / 180) if kind == "angle" else (SI_LABELS[kind], 1.0)

    x_label, x_factor = unit_of("length" if result.dynamics_before.input_names[0].endswith(".s")
                                else "angle")
    x = result.inputs / x_factor
    paths = []
    for key, title, _ in SAMPLE_LOADS:
        label, factor = unit_of(LOAD_KINDS[key])
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        ax.plot(x, result.per_sample_before[key] / factor, "o-", ms=3, label="before")
        ax.plot(x, result.per_sample_after[key] / factor, "s--", ms=3, label="after")
        ax.set_xlabel(f"input ({x_label})")
        ax.set_ylabel(f"{title} ({pretty_unit(label) or '1'})")
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        p = out / f"balance_{key}.png"
        _save(fig, p)
        plt.close(fig)
        paths.append(str(p))
    return paths


def write_pareto_plot(front: Any, path: str | Path, x: str | None = None, y: str | None = None,
                      colour: str | None = None) -> str:
    """Scatter of a :class:`~screwkit.balancing.pareto.ParetoFront`: measure ``x`` against ``y``,
    coloured by ``colour`` (non-dominated points outlined). By default the swept measures in
    order: the first two on the axes, the third (if any) as the colour — a sweep of F and T0
    alone is a plain scatter."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    vals = front.measures
    names = list(front.names)
    x = x or names[0]
    y = y or names[1]
    colour = colour or (names[2] if len(names) > 2 else None)
    cols = {k: i for i, k in enumerate(names)}
    edges = np.where(front.efficient, "k", "none")
    if colour is not None:
        sc = ax.scatter(vals[:, cols[x]], vals[:, cols[y]], c=vals[:, cols[colour]],
                        edgecolors=edges)
        fig.colorbar(sc, ax=ax, label=colour)
    else:
        ax.scatter(vals[:, cols[x]], vals[:, cols[y]], edgecolors=edges)
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.set_title("balancing trade-off (outlined: non-dominated)")
    fig.tight_layout()
    _save(fig, Path(path))
    plt.close(fig)
    return str(path)


def _save(fig: Any, path: Path) -> None:
    """PNG through a temporary file and a rename (screwkit.io.outputs: no partial file)."""
    from screwkit.io.outputs import atomic_path
    from screwkit.report.plots import tidy_axes

    tidy_axes(fig)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")

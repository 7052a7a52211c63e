"""Plots of a balancing run (like Rahman 1996, Figures 5.1–5.6) and of a Pareto front.
matplotlib is imported lazily (the ``plot`` extra)."""

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


def write_plots(result: BalanceResult, folder: str | Path) -> list[str]:
    """One PNG per per-sample load, before and after, against the input in degrees."""
    plt = _pyplot()
    from screwkit.io.outputs import make_output_folder

    out = make_output_folder(folder, "--plots")
    x = np.degrees(result.inputs)
    paths = []
    for key, title, unit in SAMPLE_LOADS:
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        ax.plot(x, result.per_sample_before[key], "o-", ms=3, label="before")
        ax.plot(x, result.per_sample_after[key], "s--", ms=3, label="after")
        ax.set_xlabel("input (deg)")
        ax.set_ylabel(f"{title} ({unit})")
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        p = out / f"balance_{key}.png"
        _save(fig, p)
        plt.close(fig)
        paths.append(str(p))
    return paths


def write_pareto_plot(front: Any, path: str | Path, x: str = "F", y: str = "T",
                      colour: str = "T0") -> str:
    """Scatter of a :class:`~screwkit.balancing.pareto.ParetoFront`: measure ``x`` against ``y``,
    coloured by ``colour`` (non-dominated points filled)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    vals = front.measures
    cols = {k: i for i, k in enumerate(front.names)}
    sc = ax.scatter(vals[:, cols[x]], vals[:, cols[y]], c=vals[:, cols[colour]],
                    edgecolors=np.where(front.efficient, "k", "none"))
    fig.colorbar(sc, ax=ax, label=colour)
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

    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")

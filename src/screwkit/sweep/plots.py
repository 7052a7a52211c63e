"""Pictures of a sweep (docs/sweeps.md, "Plots"): a line plot of one column over one varied
key, a heat map over two keys of a grid, and a scatter matrix (every pair of keys, coloured by
the column; the column against each key on the diagonal) for more keys or for Latin-hypercube
designs. Failed designs are marked, never drawn as values.

The PNG carries its title and description as text chunks with ``Software = "screwkit sweep"``,
which is how the HTML index (:mod:`screwkit.report.html`) finds and shows sweep pictures.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.io.outputs import atomic_path
from screwkit.messages import listing
from screwkit.report.plots import tidy_axes
from screwkit.report.sweep_pictures import PICTURE_SOFTWARE

Row = dict[str, Any]

#: the column a job's picture shows unless ``--plot-column`` says otherwise
HEADLINE = {"dynamics": "shaking_force.rms", "balance": "G.after", "synthesize": "E",
            "mobility": "numeric.mobility", "limits": "limits", "analyze": "assembling_samples",
            "modes": "modes"}


def default_column(job: str, rows: Sequence[Row]) -> str:
    """The job's headline column, or the first numeric job column the rows have."""
    wanted = HEADLINE.get(job)
    if wanted is not None and any(wanted in r for r in rows):
        return wanted
    for r in rows:
        for k, v in r.items():
            if k not in ("design", "modes") and isinstance(v, int | float) and not isinstance(v, bool):
                return k
    return "assembling_samples"


def _values(rows: Sequence[Row], column: str) -> np.ndarray:
    out = np.full(len(rows), np.nan)
    for i, r in enumerate(rows):
        v = r.get(column)
        if r.get("status") == "ok" and isinstance(v, int | float) and not isinstance(v, bool):
            out[i] = float(v)
    return out


def _line(ax: Any, x: np.ndarray, z: np.ndarray, xlabel: str, column: str) -> None:
    ok = np.isfinite(z)
    ax.plot(x[ok], z[ok], "o-", color="tab:blue", ms=4, label=column)
    if (~ok).any():
        base = np.nanmin(z) if ok.any() else 0.0
        ax.plot(x[~ok], np.full((~ok).sum(), base), "x", color="tab:red",
                label="failed / not assembling")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(column)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)


def _heat(fig: Any, ax: Any, x: np.ndarray, y: np.ndarray, z: np.ndarray, labels: list[str],
          column: str) -> None:
    import matplotlib

    xs, ys = np.unique(x), np.unique(y)
    grid = z.reshape(xs.size, ys.size).T  # the first key varies slowest
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="lightgrey")
    mesh = ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(grid), cmap=cmap,
                         shading="flat")
    fig.colorbar(mesh, ax=ax, label=column)
    if np.isnan(grid).any():
        ax.text(0.01, 0.01, "grey: failed / not assembling", transform=ax.transAxes, fontsize=8)
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])


def _edges(v: np.ndarray) -> np.ndarray:
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _matrix(fig: Any, keys: np.ndarray, z: np.ndarray, labels: list[str], column: str) -> None:
    k = len(labels)
    axes = fig.subplots(k, k, squeeze=False)
    ok = np.isfinite(z)
    lo, hi = (np.nanmin(z), np.nanmax(z)) if ok.any() else (0.0, 1.0)
    sc = None
    for i in range(k):
        for j in range(k):
            ax = axes[i, j]
            if i == j:
                ax.plot(keys[ok, j], z[ok], ".", ms=3, color="tab:blue")
                ax.set_ylabel(column if j == 0 else "", fontsize=7)
            else:
                sc = ax.scatter(keys[ok, j], keys[ok, i], c=z[ok], s=6, cmap="viridis",
                                vmin=lo, vmax=hi)
                ax.scatter(keys[~ok, j], keys[~ok, i], marker="x", s=8, color="tab:red")
                if j == 0:
                    ax.set_ylabel(labels[i], fontsize=7)
            if i == k - 1:
                ax.set_xlabel(labels[j], fontsize=7)
            ax.tick_params(labelsize=6)
    if sc is not None:
        fig.colorbar(sc, ax=axes, label=column, shrink=0.8)


def plot_sweep(rows: Sequence[Row], metadata: dict[str, Any], path: Path, column: str,
               inputs: Sequence[Path] = ()) -> None:
    """Write the picture of a sweep's ``column`` (module docstring) to ``path`` (PNG,
    atomically)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if not any(column in r for r in rows):
        raise InputError(f"--plot-column {column!r}: the table has no such column; its columns "
                         f"include {listing(sorted({k for r in rows for k in r})[:12])}")
    labels = [k["column"] for k in metadata["keys"]]
    keys = np.array([[float(r[c]) for c in labels] for r in rows]).reshape(len(rows), -1)
    z = _values(rows, column)
    grid = metadata["sampling"] == "grid"
    if len(labels) == 1:
        fig, ax = plt.subplots(figsize=(7, 4.5))
        order = np.argsort(keys[:, 0], kind="stable")
        _line(ax, keys[order, 0], z[order], labels[0], column)
    elif len(labels) == 2 and grid:
        fig, ax = plt.subplots(figsize=(7, 5.5))
        _heat(fig, ax, keys[:, 0], keys[:, 1], z, labels, column)
    else:
        size = min(3.0 * len(labels), 14.0)
        fig = plt.figure(figsize=(size + 1.5, size))
        _matrix(fig, keys, z, labels, column)
    failed = int(np.isnan(z).sum())
    title = f"{metadata['mechanism']}: {metadata['job']} sweep, {len(rows)} designs"
    fig.suptitle(title + (f" ({failed} without a value)" if failed else ""), fontsize=10)
    description = (f"{column} over {', '.join(labels)} ({metadata['sampling']}; spec "
                   f"{Path(metadata['spec']).name})")
    text = {"Title": title, "Description": description, "Software": PICTURE_SOFTWARE}
    tidy_axes(fig)
    with atomic_path(path, inputs, "--plot") as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight", format="png", metadata=text)
    plt.close(fig)

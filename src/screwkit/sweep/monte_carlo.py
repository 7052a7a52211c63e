"""The Monte Carlo check of a tolerance analysis, on the sweep engine (docs/sweeps.md,
"Tolerance analysis").

Each toleranced value is drawn from a normal scatter with σ = t/3 (``seed`` makes the draw
reproducible); each drawn design is validated like a spec file and solved by Newton's method from
the nominal mode's configuration at every input (the same assembly mode, no mode search), in
batches on the engine. Over the designs, the standard deviation of every output at every input
is compared with the first-order σ = RSS/3: the first-order value must lie inside the Monte
Carlo's confidence interval for σ (chi-square, n − 1 degrees of freedom; Bonferroni-corrected
over all the points compared), and the first-order prediction Σ ∂y/∂x_k δx_k of each drawn
design must match its solved deviation to second order.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.io.spec import spec_from_data
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.tracker.loop import Array, Configuration, layout
from screwkit.kinematics.tracker.solve import newton
from screwkit.sweep.engine import Engine, batch_size, batches
from screwkit.sweep.keys import SpecKey, with_values
from screwkit.sweep.tolerance import FirstOrder, Tolerance

#: Monte Carlo designs per engine task (each is one Newton solve over the cycle)
MC_BATCH = 50
#: confidence level of the interval for σ
CONFIDENCE = 0.95


@dataclass(frozen=True)
class MonteCarloTask:
    """What every Monte Carlo batch shares: the spec's tables, the toleranced keys, the
    nominal configuration of the mode and where it assembles, and the outputs (scalar column,
    sign)."""

    data: dict[str, Any]
    path: str
    keys: tuple[SpecKey, ...]
    scalars: Array
    spherical: Array
    assembles: np.ndarray
    columns: tuple[tuple[int, float], ...]


def monte_carlo_batch(task: MonteCarloTask, indices: np.ndarray, values: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Solved deviations (n, outputs, N) of a batch of drawn designs from the nominal outputs
    (NaN where a design fails to close its loop or is not a valid spec)."""
    n, N = len(indices), task.scalars.shape[0]
    out = np.full((n, len(task.columns), N), np.nan)
    ok = task.assembles
    start = Configuration(task.scalars[ok], task.spherical[ok])
    for r, v in enumerate(values):
        overrides = [(k.path, k.toml_value(x)) for k, x in zip(task.keys, v, strict=True)]
        try:
            with np.errstate(over="raise", divide="raise", invalid="raise"):
                linkage = spec_from_data(with_values(task.data, overrides), task.path).linkage
        except (ValueError, FloatingPointError):
            continue
        res = newton(linkage, start, max_iter=60, lay=layout(linkage))
        for c, (col, sign) in enumerate(task.columns):
            dev = sign * (res.conf.scalars[:, col] - start.scalars[:, col])
            dev[~res.converged] = np.nan
            out[r, c, ok] = dev
    return indices, out


def draw_designs(tolerances: list[Tolerance], n: int, seed: int) -> np.ndarray:
    """``n`` designs (n, k): nominal + normal scatter with σ_k = t_k/3."""
    rng = np.random.default_rng(seed)
    nominal = np.array([t.nominal for t in tolerances])
    sigma = np.array([t.sigma for t in tolerances])
    return nominal + rng.standard_normal((n, len(tolerances))) * sigma


def run_monte_carlo(engine: Engine, data: dict[str, Any], path: str, tolerances: list[Tolerance],
                    mode: ModeMotion, fo: FirstOrder, n: int, seed: int,
                    progress: Callable[[int, int, int], None] | None = None) -> np.ndarray:
    """Solved deviations (n, outputs, N) of ``n`` drawn designs, in draw order."""
    lk_layout = layout(spec_from_data(data, path).linkage)
    columns = tuple((lk_layout.scalar_col[lk_layout.names.index(fo.freedom_of[o][0])],
                     fo.freedom_of[o][1]) for o in fo.outputs)
    task = MonteCarloTask(data, path, tuple(t.key for t in tolerances), mode.conf.scalars,
                          mode.conf.spherical, np.asarray(mode.assembles) & ~mode.singular,
                          columns)
    values = draw_designs(tolerances, n, seed)
    result = np.full((n, len(columns), mode.conf.size), np.nan)
    size = batch_size(n, engine.workers, None, largest=MC_BATCH)
    payloads = [(np.array(b, dtype=np.int64), values[b]) for b in batches(list(range(n)), size)]
    done = [0]

    def finished(_: int, batch: tuple[np.ndarray, np.ndarray]) -> None:
        idx, dev = batch
        result[idx] = dev
        done[0] += len(idx)
        if progress is not None:
            progress(done[0], n, done[0])

    engine.map(monte_carlo_batch, task, payloads, finished)
    return result


def compare(fo: FirstOrder, tolerances: list[Tolerance], deviations: np.ndarray, seed: int
            ) -> dict[str, Any]:
    """The Monte Carlo standard deviations against the first-order σ = RSS/3 (module
    docstring); ``agree`` when every compared point lies in its Bonferroni-corrected interval
    and the first-order prediction of each design matches to second order."""
    from scipy.stats import chi2

    n_draw = deviations.shape[0]
    dev = deviations
    values = draw_designs(tolerances, n_draw, seed)
    delta = values - np.array([t.nominal for t in tolerances])
    sens = np.stack([np.stack([fo.sensitivity[o][t.key.text] for t in tolerances])
                     for o in fo.outputs])  # (outputs, k, N)
    predicted = np.einsum("dk,okn->don", delta, sens)
    sigma_lin = np.stack([fo.rss[o] for o in fo.outputs]) / 3.0  # (outputs, N)
    with np.errstate(invalid="ignore", divide="ignore"):
        counts = np.isfinite(dev).sum(axis=0)
        std = np.nanstd(dev, axis=0, ddof=1)
        mean = np.nanmean(dev, axis=0)
    big = sigma_lin > 1e-6 * np.nanmax(sigma_lin)
    points = big & (counts > 2)
    m = int(points.sum())
    dof = np.where(points, counts - 1, 1)
    alpha = 1 - CONFIDENCE
    lo95 = std * np.sqrt(dof / chi2.ppf(1 - alpha / 2, dof))
    hi95 = std * np.sqrt(dof / chi2.ppf(alpha / 2, dof))
    a = alpha / max(m, 1)
    lo = std * np.sqrt(dof / chi2.ppf(1 - a / 2, dof))
    hi = std * np.sqrt(dof / chi2.ppf(a / 2, dof))
    inside = points & (sigma_lin >= lo) & (sigma_lin <= hi)
    inside95 = points & (sigma_lin >= lo95) & (sigma_lin <= hi95)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(points, std / sigma_lin, np.nan)
        residual = np.nanmax(np.abs(dev - predicted), axis=0) / np.nanmax(sigma_lin)
    second_order = float(np.nanmax(np.where(points, residual, np.nan))) if m else float("nan")
    failed = int((~np.isfinite(dev).any(axis=(1, 2))).sum())
    return {
        "samples": n_draw, "seed": seed, "failed_designs": failed, "confidence": CONFIDENCE,
        "points_compared": m, "inside_95_percent_interval": int(inside95.sum()),
        "inside_bonferroni_interval": int(inside.sum()),
        "std_ratio_range": [float(np.nanmin(ratio)), float(np.nanmax(ratio))] if m else None,
        "max_mean_shift_over_sigma": float(np.nanmax(np.where(points, np.abs(mean) / sigma_lin,
                                                             np.nan))) if m else None,
        "max_prediction_error_over_sigma": second_order,
        "agree": bool(m > 0 and inside.sum() == m and failed == 0 and second_order < 0.1),
        "std": {o: std[i] for i, o in enumerate(fo.outputs)},
        "std_interval": {o: {"low": lo95[i], "high": hi95[i]} for i, o in enumerate(fo.outputs)},
    }

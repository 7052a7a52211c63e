"""The Cauchy endgame: the end point of a path that ends singular or at infinity.

Near σ = 1 a path y(σ) is a convergent Puiseux series in t^(1/c), t = 1 − σ, where c is its
winding number (cycle number). Tracking around the circle |t| = r returns to the start after
exactly c loops, and the mean of y over c·M equally spaced samples is the trapezoid rule for
Cauchy's integral (1/2πi)∮ y(t) dt/t = y(0), exact up to O((r/R)^(cM)) where R is the distance to
the next branch point (Morgan, Sommese & Wampler, "Computing singular solutions to nonlinear
analytic systems", Numer. Math. 58, 1991; Sommese & Wampler 2005, §10.3.3). The loops never
touch the singular end point, so its accuracy is not limited by the conditioning there. The
radius shrinks by 4 between estimates until two successive ones agree. A path stops when it
has used ``endgame_max_steps`` steps in the endgame (it is then reported failed): without that
bound one path could take levels × max_winding × samples_per_loop × max_steps steps (~10⁶
with the defaults), minutes on its own.

All paths run together: each loop segment between samples is one batched call of the tracker.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic.path import Homotopy, Index, TrackOptions, circle, line, track
from screwkit.algebraic.polynomial import Complex


@dataclass(frozen=True)
class EndgameResult:
    y: Complex  # (m, n+1) estimated end points on the patch
    winding: NDArray[np.int64]  # (m,) cycle number c (0 when the loop never closed)
    converged: NDArray[np.bool_]  # (m,) two successive estimates agreed
    steps: NDArray[np.int64]


def _loops(hom: Homotopy, y: Complex, rows: Index, radius: NDArray[np.float64],
           options: TrackOptions, budget: NDArray[np.int64]
           ) -> tuple[Complex, NDArray[np.int64], NDArray[np.int64]]:
    """Cauchy's integral around |t| = radius from y (on the circle at τ = 0): the mean of
    the samples over the c loops until y comes back, c ≤ max_winding (c = 0: never closed,
    the tracking failed, or the path used up its ``budget`` of steps)."""
    m = len(rows)
    M = options.samples_per_loop
    by_row = np.zeros(hom.p_start.shape[0])
    by_row[rows] = radius
    curve = circle(by_row)
    total = np.zeros_like(y)
    count = np.zeros(m, dtype=np.int64)
    winding = np.zeros(m, dtype=np.int64)
    steps = np.zeros(m, dtype=np.int64)
    current = y.copy()
    active = np.arange(m)
    for loop in range(options.max_winding):
        for j in range(M):
            total[active] += current[active]
            count[active] += 1
            tau0 = np.full(len(active), 2 * np.pi * (loop * M + j) / M)
            end, ok, used = track(hom, curve, current[active], rows[active], tau0,
                                  tau0 + 2 * np.pi / M, options)
            current[active] = end
            steps[active] += used
            active = active[ok & (steps[active] < budget[active])]
            if not active.size:
                break
        scale = 1.0 + np.abs(y[active]).max(axis=1)
        back = np.abs(current[active] - y[active]).max(axis=1) <= 1e-6 * scale
        winding[active[back]] = loop + 1
        active = active[~back]
        if not active.size:
            break
    estimate = total / np.maximum(count, 1)[:, None]
    return estimate, winding, steps


def cauchy_endgame(hom: Homotopy, y: Complex, rows: Index,
                   options: TrackOptions) -> EndgameResult:
    """End points at σ = 1 of the paths ``rows``, given their points y at
    σ = 1 − ``options.endgame_radius`` on the straight segment."""
    m = len(rows)
    radius = np.full(m, options.endgame_radius)
    best = np.full_like(y, np.nan)
    winding = np.zeros(m, dtype=np.int64)
    converged = np.zeros(m, dtype=bool)
    steps = np.zeros(m, dtype=np.int64)
    current = y.copy()
    active = np.arange(m)
    for level in range(options.endgame_levels):
        estimate, c, used = _loops(hom, current[active], rows[active], radius[active], options,
                                   options.endgame_max_steps - steps[active])
        steps[active] += used
        closed = c > 0
        scale = 1.0 + np.abs(estimate).max(axis=1)
        agree = np.abs(estimate - best[active]).max(axis=1) <= options.endgame_tolerance * scale
        agree &= closed & (winding[active] == c)
        best[active[closed]] = estimate[closed]
        winding[active] = c
        converged[active[agree]] = True
        active = active[closed & ~agree]
        if not active.size or level == options.endgame_levels - 1:
            break
        # move inward along the segment to the next, 4× smaller circle
        start = 1.0 - radius[active]
        end, ok, used = track(hom, line, current[active], rows[active], start,
                              1.0 - radius[active] / 4, options)
        steps[active] += used
        current[active] = end
        radius[active] /= 4
        active = active[ok & (steps[active] < options.endgame_max_steps)]
    return EndgameResult(best, winding, converged, steps)

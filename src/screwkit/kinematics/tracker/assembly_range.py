"""Where over a full input turn an RSRC (or plane 4R) assembles, in words for error messages:
``limits`` on a mechanism that never assembles, or asked about inputs where it does not, says
so and where it does (docs/reliability.md)."""

from __future__ import annotations

import math

import numpy as np

from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_positions
from screwkit.messages import shown

#: samples per turn of the assembly scan (0.25° apart)
SCAN_SAMPLES = 1440


def assembling_intervals(dims: RSRCDimensions, samples: int = SCAN_SAMPLES) -> list[tuple[float, float]]:
    """Input-angle intervals (radians, start ≤ end within [0, 2π)) where at least one
    inversion assembles, from a scan at ``samples`` equal steps (Bagci 1969 §3.4 quartic; an
    interval shorter than one step can be missed, which the limit positions then reveal)."""
    theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    with np.errstate(all="ignore"):
        ok = np.asarray(np.asarray(rsrc_positions(dims, theta).assembles).any(axis=1), dtype=bool)
    return runs_over_a_turn(theta, ok)


def runs_over_a_turn(theta: np.ndarray, ok: np.ndarray) -> list[tuple[float, float]]:
    """The intervals (start ≤ end, start in [0, 2π)) of a scan ``theta`` of one full turn where
    ``ok`` holds, a run through 360° = 0° joined into one."""
    if not ok.any():
        return []
    if ok.all():
        return [(0.0, 2 * math.pi)]
    idx = np.flatnonzero(ok)
    starts = idx[np.r_[True, np.diff(idx) > 1]]
    ends = idx[np.r_[np.diff(idx) > 1, True]]
    runs = [(float(theta[s]), float(theta[e])) for s, e in zip(starts, ends, strict=True)]
    if ok[0] and ok[-1] and len(runs) > 1:  # a run through 360° = 0°
        runs = [(runs[-1][0], runs[0][1] + 2 * math.pi), *runs[1:-1]]
    return runs


def describe_intervals(runs: list[tuple[float, float]]) -> str:
    """``"for θ0 from 12.5 deg to 80.25 deg, from 200 deg through 0 to 20 deg"`` (in the
    message units, :mod:`screwkit.messages`; the ends are the scan's outermost assembling
    samples)."""
    if not runs:
        return "at no input angle"
    if runs == [(0.0, 2 * math.pi)]:
        return "at every input angle"
    parts = [f"from {shown(a, 'angle')} to {shown(b, 'angle')}" if b < 2 * math.pi else
             f"from {shown(a, 'angle')} through 0 to {shown(b - 2 * math.pi, 'angle')}"
             for a, b in runs[:6]]
    more = f" and {len(runs) - 6} more intervals" if len(runs) > 6 else ""
    return "for θ0 " + ", ".join(parts) + more

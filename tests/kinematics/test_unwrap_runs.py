"""``unwrap_runs`` (continuous angles along each run of assembling samples, each run starting in
(−π, π]) sums np.unwrap's corrections at the jumps only: it equals, bit for bit, the plain
definition by ``np.unwrap`` on every run — random walks with and without jumps of 2π, angles
exactly on ±π (np.unwrap's boundary rule), more jumps than the sparse path takes, NaN samples
and runs broken by samples that do not assemble."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.kinematics.tracker.mode_frames import start_in_half_open, unwrap_runs


def _by_definition(angle: np.ndarray, ok: np.ndarray) -> np.ndarray:
    out = np.array(angle, dtype=float)
    idx = np.flatnonzero(ok & np.isfinite(out))
    if idx.size == 0:
        return out
    for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1):
        out[run] = start_in_half_open(np.unwrap(out[run]))
    return out


@pytest.mark.parametrize("kind", ["walk", "wrapped", "boundary", "many_jumps"])
def test_unwrap_runs_equals_np_unwrap_on_every_run(kind: str) -> None:
    rng = np.random.default_rng(7)
    for trial in range(300):
        n = int(rng.integers(0, 700))
        if kind == "walk":
            a = np.cumsum(rng.normal(0.0, 2.0, n))
        elif kind == "wrapped":
            a = (np.cumsum(rng.normal(0.0, 0.5, n)) + np.pi) % (2 * np.pi) - np.pi
        elif kind == "boundary":
            a = (rng.choice([-np.pi, np.pi, 0.0, np.pi / 2, 3.0, -3.0], n)
                 + rng.choice([0.0, 1e-16, -1e-16], n))
        else:
            a = rng.uniform(-20.0, 20.0, n)
        ok = rng.uniform(size=n) > (0.1 if trial % 2 else -1.0)
        if trial % 5 == 0 and n:
            a[rng.integers(0, n)] = np.nan
        got = unwrap_runs(a, ok)
        np.testing.assert_array_equal(got, _by_definition(a, ok))
    assert np.array_equal(unwrap_runs(np.array([3.0, -3.0]), np.array([True, True])),
                          [3.0, 2 * np.pi - 3.0])

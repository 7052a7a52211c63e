"""`rsrc_motion`'s branch tracking: the cheap identity test never changes the matching that full
scoring of every assignment gives, and the rates it returns equal `rsrc_rates` evaluated
directly on its branches (the chain rule x' θ̇, x'' θ̇² + x' θ̈ is exact for eqs. 3.77-3.82)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from screwkit.kinematics.closed_forms.rsrc import (
    RSRCDimensions,
    RSRCPositions,
    branches,
    rsrc_motion,
    rsrc_rates,
)

DEG = math.pi / 180.0


def _mechanisms(count: int) -> list[RSRCDimensions]:
    rng = np.random.default_rng(20261202)
    out = [
        RSRCDimensions(d1=2, d2=4.5, d3=3, a=3, b=3, e=1, delta0=18 * DEG, lambda0=60 * DEG),
        # δ0 = ±π/2: four columns (the χ0 mirror assemblies)
        RSRCDimensions(d1=1, d2=3, d3=2, a=2.5, b=1, e=0.5, delta0=90 * DEG, lambda0=40 * DEG),
        # plane 4R double rocker: branches stop and start
        RSRCDimensions(d1=2.0, d2=1.5, d3=1.8, a=2.2, b=0, e=0, delta0=0, lambda0=0),
    ]
    while len(out) < count:
        d1, d2, d3, a, b, e = rng.uniform(0.3, 5.0, 6)
        out.append(RSRCDimensions(d1=d1, d2=d2, d3=d3, a=a, b=b - 2.5, e=e - 2.5,
                                  delta0=rng.uniform(-math.pi, math.pi),
                                  lambda0=rng.uniform(-math.pi, math.pi)))
    return out


@pytest.mark.parametrize("samples", [73, 361, 2001])
def test_the_identity_shortcut_never_changes_the_matching(monkeypatch, samples):
    theta = np.linspace(-math.pi, math.pi, samples)
    checked = 0
    accepted = []
    real = branches._identity_is_best

    def counting(*args, **kwargs):
        ok = real(*args, **kwargs)
        accepted.append(ok.mean())
        return ok

    for dims in _mechanisms(60):  # the sweep's own matching: no fold search (its own sweeps)
        with monkeypatch.context() as m:
            m.setattr(branches, "_identity_is_best", counting)
            fast = rsrc_motion(dims, theta, events=False)
        if not fast.assembles.any():
            continue
        with monkeypatch.context() as m:
            m.setattr(branches, "_identity_is_best",
                      lambda prev, *a, **k: np.zeros(prev[0].shape[0], dtype=bool))
            full = rsrc_motion(dims, theta, events=False)
        np.testing.assert_array_equal(fast.assembles, full.assembles)
        np.testing.assert_array_equal(fast.inversion_label, full.inversion_label)
        np.testing.assert_array_equal(fast.phi0, full.phi0)
        checked += 1
    assert checked >= 30
    # the shortcut does the work on fine sweeps (that is its point)
    if samples >= 361:
        assert np.mean(accepted) > 0.9


def test_branch_rates_equal_the_direct_rates_at_any_input_rate():
    rng = np.random.default_rng(7)
    theta = np.linspace(0.0, 2 * math.pi, 721)
    td = rng.uniform(-20.0, 20.0, theta.size)
    tdd = rng.uniform(-300.0, 300.0, theta.size)
    for dims in _mechanisms(25):
        mot = rsrc_motion(dims, theta, td, tdd)
        pos = RSRCPositions(mot.theta0, mot.phi0, mot.chi0, mot.S, mot.assembles,
                            dims.special_case)
        direct = rsrc_rates(dims, pos, td, tdd)
        for name in ("phi0_dot", "chi0_dot", "S_dot", "phi0_ddot", "chi0_ddot", "S_ddot"):
            got, want = getattr(mot.rates, name), getattr(direct, name)
            np.testing.assert_array_equal(np.isnan(got), np.isnan(want), err_msg=name)
            scale = np.nanmax(np.abs(want), initial=1.0)
            np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-11 * scale, err_msg=name)
        for name in ("locked", "chi_singular", "valid"):
            np.testing.assert_array_equal(getattr(mot.rates, name), getattr(direct, name))


def test_rsrc_rates_accept_columns_in_any_order():
    """rsrc_rates on positions whose assembling columns are not first (branch order, e.g. a
    column that does not assemble before one that does) gives the rates of each column."""
    dims = _mechanisms(1)[0]
    theta = np.linspace(0.0, 2 * np.pi, 50)
    pos = rsrc_motion(dims, theta)
    order = np.array([2, 0, 3, 1])  # Fig. 7 assembles in columns 0, 1: now 1 and 3
    moved = RSRCPositions(pos.theta0, pos.phi0[:, order], pos.chi0[:, order], pos.S[:, order],
                          pos.assembles[:, order], dims.special_case)
    assert not moved.assembles[:, 0].any() and moved.assembles[:, 3].all()
    got = rsrc_rates(dims, moved, 2.0, 3.0)
    want = rsrc_rates(dims, RSRCPositions(pos.theta0, pos.phi0, pos.chi0, pos.S, pos.assembles,
                                          dims.special_case), 2.0, 3.0)
    for name in ("phi0_dot", "chi0_ddot", "S_ddot"):
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name)[:, order])

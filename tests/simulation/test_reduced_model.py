"""The reduced equation of motion against the inverse dynamics and the regressor, on every
bundled example with masses; and the Fourier fit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.simulation.reactions import loop_loads
from screwkit.simulation.reduced import SimulationError, fit_fourier, reduced_model

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
WITH_MASSES = ["rahman_cssp", "rsrc_fig7_dynamics", "rssr_spatial", "fourbar_dynamics"]
GRAVITY = np.array([0.7, -1.3, -9.80665])


@pytest.fixture(scope="module", params=WITH_MASSES)
def example(request):
    spec = sk.load_spec(EXAMPLES / f"{request.param}.toml")
    free = spec.linkage.joints[-1].freedom_names()[0]
    model = reduced_model(spec.linkage, mode=spec.mode, start=float(spec.inputs[0]),
                          gravity=GRAVITY, ratios=(free,), samples_per_cycle=36)
    return spec, model, free


def test_inverse_dynamics_torque_is_the_reduced_equation(example):
    """τ = J α + ½ J′ ω² − Q_g at every grid angle, for a speed and an acceleration."""
    spec, model, _ = example
    n = model.grid.size
    w, a = 23.0 + np.linspace(0, 5, n), -40.0 + np.linspace(0, 80, n)
    dyn = sk.inverse_dynamics(spec.linkage, model.motion_at(np.arange(n), w, a), GRAVITY)
    tau = dyn.efforts[spec.linkage.inputs[0]]
    s = model.samples
    expected = s["inertia"] * a + 0.5 * s["inertia_slope"] * w ** 2 - s["gravity_torque"]
    assert np.max(np.abs(tau - expected)) <= 1e-9 * np.max(np.abs(tau))


def test_motion_at_a_speed_is_the_solved_motion(example):
    """The grid mode moved at θ̇, θ̈ equals solve_motion at those rates (the velocity
    coefficients and quadratic terms are exact)."""
    spec, model, _ = example
    idx = np.arange(0, model.grid.size, 9)
    w, a = np.full(idx.size, 7.5), np.full(idx.size, 3.0)
    ours = model.motion_at(idx, w, a)
    solved = sk.solve_motion(spec.linkage, model.grid[idx], rates=w, accelerations=a
                             ).mode(spec.mode)
    for field in ("link_angular_velocity", "link_origin_velocity",
                  "link_angular_acceleration", "link_origin_acceleration"):
        x, y = getattr(ours, field), getattr(solved, field)
        assert np.max(np.abs(x - y)) <= 1e-9 * np.max(np.abs(y)), field


def test_generalised_inertia_is_the_regressors(example):
    """J(θ) = the input effort of the regressor at zero speed and unit acceleration, Y·π."""
    spec, model, _ = example
    idx = np.arange(0, model.grid.size, 6)
    m0 = sk.solve_motion(spec.linkage, model.grid[idx], rates=0.0, accelerations=1.0)
    Y = sk.regressor(spec.linkage, m0.mode(spec.mode))
    J = Y.efforts[spec.linkage.inputs[0]] @ Y.parameters_of()
    assert np.max(np.abs(J - model.samples["inertia"][idx])) <= 1e-9 * np.max(J)


def test_series_reproduces_the_exact_samples_and_slope(example):
    _, model, _ = example
    assert model.converged
    J, dJ = model.inertia(model.grid)
    assert np.max(np.abs(J - model.samples["inertia"])) <= 1e-10 * np.max(J)
    assert model.interpolation_error <= 1e-9  # J′ of the series vs the exact J′


def test_unit_output_load_gives_minus_the_velocity_ratio(example):
    """Virtual work: a unit generalised force on the output needs an input effort −r(θ)."""
    spec, model, free = example
    n = model.grid.size
    zeros = np.zeros(n)
    d0, _ = loop_loads(model, np.arange(n), zeros + 1.0, zeros)
    d1, _ = loop_loads(model, np.arange(n), zeros + 1.0, zeros, load_freedom=free,
                       output_force=zeros + 1.0)
    name = spec.linkage.inputs[0]
    r = model.grid_mode.velocities[free]
    assert np.max(np.abs(d1.efforts[name] - d0.efforts[name] + r)) <= 1e-9 * np.max(np.abs(r))


def test_fourier_fit_of_a_known_function():
    th = 2 * np.pi * np.arange(64) / 64
    f = np.stack([3 + np.cos(th) - 0.25 * np.sin(3 * th)])
    series, ok = fit_fourier(0.0, f)
    assert ok and series.harmonics == 3
    x = np.linspace(-1, 7, 50)
    assert np.allclose(series(x)[0], 3 + np.cos(x) - 0.25 * np.sin(3 * x), atol=1e-14)
    assert np.allclose(series(x, 1)[0], -np.sin(x) - 0.75 * np.cos(3 * x), atol=1e-13)
    assert np.allclose(series.integral(x)[0], np.sin(x) + (np.cos(3 * x) - 1) / 12, atol=1e-13)


def test_a_rocker_input_is_refused_with_the_angles():
    lk = sk.fourbar(a=1.0, d1=2.0, d2=1.2, d3=1.5)  # the input cannot turn fully
    from screwkit.model.linkage import Link
    lk = lk.with_links([Link(l.name, sk.MassProperties(1.0, [0, 0, 0], np.eye(3) * 1e-2))
                        for l in lk.links])
    with pytest.raises(SimulationError, match="does not turn fully"):
        reduced_model(lk, samples_per_cycle=8)

"""Every bundled graph example (each ``examples/mechanisms/*.toml``, found by glob, so a new one
is checked too) carries a dynamics spec — mass properties on every body — and its loads obey
laws that hold exactly, per sample, to 1e-9 relative (issue 28, "Checks"; no finite
differences), with its own mass properties at a dozen of its samples, random rates and
accelerations of its driven freedoms (joint inputs, or a body's pose / a wheel's travel for the
``[[drives]]`` examples) and its own gravity plus a random one:

* ``screwkit dynamics SPEC --gravity --json`` runs (exit 0) and reports the efforts of an
  independent ``graph_inverse_dynamics`` of the spec's own motion, to 1e-12;
* every moving body's Newton–Euler balance with the reported joint reactions (m a_c and
  dH_c/dt = I α + ω × I ω from the body's pose, twist and acceleration);
* input power Σ effort × rate of each effort's freedom (the actuated freedoms: leg slides of a
  pose-driven platform, the arm's angle of a travel-driven wheel) = d(KE + PE)/dt
  = Σ m v_c·(a_c − g) + ω·(I α + ω × I ω);
* shaking force = weight − dP/dt and shaking moment (about the origin) = Σ c × m g − dH_O/dt;
* the load regressor times the stacked inertial parameters = the direct efforts.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from tests.graphs.test_graph_dynamics_random import _body_motion, _dH
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.dynamics.graph_inverse import graph_inverse_dynamics, graph_regressor
from screwkit.kinematics.graph import solve_mechanism

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
NAMES = sorted(p.stem for p in EXAMPLES.glob("*.toml"))


def test_the_glob_finds_the_examples() -> None:
    assert {"fourbar_graph", "stewart_platform_pose", "double_wishbone_travel"} <= set(NAMES)


def _pick(spec: sk.Spec, n: int = 12) -> np.ndarray:
    inputs = np.asarray(spec.inputs, dtype=float)
    return inputs[np.unique(np.linspace(0, len(inputs) - 1, n).round().astype(int))]


@pytest.mark.parametrize("name", NAMES)
def test_bundled_example_loads_obey_newton_euler_and_power(name: str) -> None:
    path = EXAMPLES / f"{name}.toml"
    spec = sk.load_spec(path)
    mech = spec.mechanism
    assert mech.bodies and all(b.mass is not None for b in mech.bodies), name
    # the command runs and reports the spec's own loads
    r = CliRunner().invoke(app, ["dynamics", str(path), "--gravity", "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    own = graph_inverse_dynamics(solve_mechanism(mech, spec.inputs, rates=spec.speed,
                                                 accelerations=spec.acceleration),
                                 gravity=spec.gravity_vector)
    assert doc["inputs"] == list(own.input_names)
    for k, n in enumerate(own.input_names):
        want = own.efforts[:, k]
        got = np.array(doc["efforts"][n], dtype=float)
        assert np.allclose(got, want, rtol=1e-12, atol=1e-12 * np.nanmax(np.abs(want))), n
    # random rates and accelerations at a dozen samples, gravity the spec's plus a random one
    rng = np.random.default_rng(28)
    x = _pick(spec)
    slide = np.array(mech.driven_is_translation(), dtype=bool)
    scale = np.where(slide, 0.05 * mech.length_scale, 1.0)
    rates = rng.uniform(0.5, 1.5, x.shape) * rng.choice([-1.0, 1.0], x.shape) * scale
    accs = rng.uniform(-2.0, 2.0, x.shape) * scale
    g = np.asarray(spec.gravity_vector, dtype=float) + rng.normal(size=3)
    motion = solve_mechanism(mech, x, rates=rates, accelerations=accs)
    md = motion.modes[0]
    dyn = graph_inverse_dynamics(motion, gravity=g)
    ok = dyn.ok
    assert ok.sum() >= min(len(x), 10), name
    bodies = _body_motion(mech, md)
    F = max(np.abs(bd["m"] * g).max() + np.abs(bd["m"] * bd["a"][ok]).max() for bd in bodies)
    Mscale = F * mech.length_scale
    names = mech.body_names
    for k, bd in enumerate(bodies):
        force = bd["m"] * g - bd["m"] * bd["a"]
        moment = np.cross(bd["c"], force) - _dH(bd)
        for j, joint in enumerate(mech.joints):
            if names[k] in joint.bodies:
                sign = 1.0 if joint.bodies[1] == names[k] else -1.0
                f = dyn.reaction_force[:, j]
                force = force + sign * f
                moment = moment + sign * (dyn.reaction_moment[:, j]
                                          + np.cross(md.joint_centres[:, j], f))
        assert np.abs(force[ok]).max() <= 1e-9 * F, (name, names[k])
        assert np.abs(moment[ok]).max() <= 1e-9 * Mscale, (name, names[k])
    # input power = d(KE + PE)/dt, the rate of each effort's own freedom
    q_dot = np.stack([md.velocities[n] for n in dyn.input_names], axis=1)
    power = np.einsum("nk,nk->n", dyn.efforts, q_dot)
    dE = sum(bd["m"] * np.einsum("ni,ni->n", bd["v"], bd["a"] - g)
             + np.einsum("ni,ni->n", bd["w"], _dH(bd)) for bd in bodies)
    P = F * max(np.abs(bd["v"][ok]).max() + np.abs(bd["w"][ok]).max() * mech.length_scale
                for bd in bodies)
    assert np.abs(power - dE)[ok].max() <= 1e-9 * P, name
    assert np.abs(dE[ok]).max() > 1e-3 * P  # the law is not met trivially (0 = 0)
    # shaking force and moment (about the origin) = weight − dP/dt, Σ c × m g − dH_O/dt
    weight = sum(bd["m"] for bd in bodies) * g
    dP = sum(bd["m"] * bd["a"] for bd in bodies)
    dHO = sum(np.cross(bd["c"], bd["m"] * bd["a"]) + _dH(bd) for bd in bodies)
    moment_g = sum(np.cross(bd["c"], bd["m"] * g) for bd in bodies)
    assert np.abs(dyn.shaking_force - (weight - dP))[ok].max() <= 1e-9 * F, name
    assert np.abs(dyn.shaking_moment - (moment_g - dHO))[ok].max() <= 1e-9 * Mscale, name
    # regressor · π = the direct efforts
    Y = graph_regressor(motion, gravity=g)
    pi = np.concatenate([b.mass.inertial_parameters() for b in mech.bodies])
    E = np.abs(dyn.efforts[ok]).max()
    assert np.abs(Y @ pi - dyn.efforts)[ok].max() <= 1e-9 * E, name

"""Inverse dynamics on graphs (issue 28) checked by physical laws and a second method: input power
= d(kinetic + potential energy)/dt, shaking force and moment = weight − d(momentum)/dt, every
body's Newton–Euler balance, regressor·π = direct, and a loop as a graph = the loop's dynamics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from six_sps import six_sps_spec

import screwkit as sk
from screwkit.dynamics.graph_inverse import graph_inverse_dynamics, graph_regressor
from screwkit.kinematics.graph import solve_mechanism
from screwkit.model.mass import MassProperties
from screwkit.model.spin_groups import spin_groups

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
G = np.array([0.3, -9.81, -1.1])


def _with_masses(mech: sk.Mechanism, seed: int) -> sk.Mechanism:
    """Random, physically consistent mass properties on every body (world axes, drawing)."""
    rng = np.random.default_rng(seed)
    # a rod between two balls, or a telescopic leg slid along their line, spins idly: its load
    # must do no work along the spin, so each body's centre of mass is on the line and its
    # inertia is symmetric about it
    legs = {b: tuple(mech.joints[k].at for k in g.balls) for g in spin_groups(mech)
            for b in g.bodies}
    bodies = []
    for b in mech.bodies:
        joints = [j for j in mech.joints if b.name in j.bodies]
        pts = [j.at for j in joints]
        if b.name in legs:
            ends = legs[b.name]
            u = (ends[1] - ends[0]) / np.linalg.norm(ends[1] - ends[0])
            com = ends[0] + rng.uniform(0.3, 0.7) * (ends[1] - ends[0])
            inertia = 1e-4 * (np.eye(3) - 0.9 * np.outer(u, u))
        else:
            com = np.mean(pts, axis=0) + 0.1 * mech.length_scale * rng.standard_normal(3)
            q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
            moments = np.sort(rng.uniform(0.5, 1.5, 3)) * 1e-4  # the largest bounded next
            moments[2] = min(moments[2], moments[0] + moments[1])
            inertia = q @ np.diag(moments) @ q.T
        bodies.append(sk.Body(b.name, MassProperties(rng.uniform(0.2, 2.0), com, inertia)))
    return mech.with_bodies(bodies)


def _energy_and_momentum(mech: sk.Mechanism, md: object, g: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Kinetic + potential energy (N,), linear momentum (N, 3) and angular momentum about the
    origin (N, 3), from the body poses and twists alone."""
    E = 0.0
    P = 0.0
    H = 0.0
    for k, b in enumerate(mech.bodies):
        R, p = md.link_rotation[:, k], md.link_origin[:, k]  # type: ignore[attr-defined]
        w, vo = md.link_angular_velocity[:, k], md.link_origin_velocity[:, k]  # type: ignore[attr-defined]
        mp = b.mass
        c = np.einsum("nij,j->ni", R, mp.com) + p
        vc = vo + np.cross(w, c - p)
        Iw = np.einsum("nij,jk,nlk->nil", R, mp.inertia, R)
        Iww = np.einsum("nij,nj->ni", Iw, w)
        E = E + 0.5 * mp.mass * np.einsum("ni,ni->n", vc, vc) + 0.5 * np.einsum(
            "ni,ni->n", w, Iww) - mp.mass * c @ g
        P = P + mp.mass * vc
        H = H + np.cross(c, mp.mass * vc) + Iww
    return E, P, H  # type: ignore[return-value]


@pytest.mark.parametrize("name", ["watt_sixbar", "stephenson3_sixbar", "double_wishbone",
                                  "stewart_platform", "delta_robot", "six_sps", "three_rps"])
def test_power_momentum_and_balance_laws(name: str, tmp_path: Path) -> None:
    spec = sk.load_spec(six_sps_spec(tmp_path) if name == "six_sps"
                        else EXAMPLES / f"{name}.toml")
    mech = _with_masses(spec.mechanism, 7)
    x0 = spec.inputs[len(spec.inputs) // 3]
    n_in = len(mech.inputs)
    direction = np.linspace(1.0, 0.4, n_in)  # a constant input rate along this direction
    h = 1e-3 * (mech.length_scale if name in ("stewart_platform", "six_sps", "three_rps")
                else 1.0)
    steps = np.array([-2, -1, 0, 1, 2], dtype=float)
    X = x0 + steps[:, None] * h * direction
    motion = solve_mechanism(mech, X, rates=direction, accelerations=0.0)
    md = motion.modes[0]
    assert md.assembles.all() and not md.singular.any()
    dyn = graph_inverse_dynamics(motion, gravity=G)
    assert np.nanmax(dyn.residual) < 1e-10
    E, P, H = _energy_and_momentum(mech, md, G)
    five = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) / (12.0 * h)  # d/dt at the middle sample

    def ddt(v: np.ndarray) -> np.ndarray:
        return np.tensordot(five, v, axes=(0, 0))

    power = float(dyn.efforts[2] @ direction)
    assert abs(power - ddt(E)) <= 1e-7 * (abs(power) + np.abs(E).max() * 1e-3 + 1e-12)
    weight = sum(b.mass.mass for b in mech.bodies) * G
    np.testing.assert_allclose(dyn.shaking_force[2], weight - ddt(P),
                               atol=1e-7 * np.abs(weight).max())
    com_weight = sum(np.cross(np.einsum("ij,j->i", md.link_rotation[2, k], b.mass.com)
                              + md.link_origin[2, k], b.mass.mass * G)
                     for k, b in enumerate(mech.bodies))
    np.testing.assert_allclose(dyn.shaking_moment[2], com_weight - ddt(H),
                               atol=1e-7 * np.abs(com_weight).max())
    # regressor · π = the direct solve
    Y = graph_regressor(motion, gravity=G)
    pi = np.concatenate([b.mass.inertial_parameters() for b in mech.bodies])
    np.testing.assert_allclose(Y @ pi, dyn.efforts, rtol=1e-9,
                               atol=1e-9 * np.abs(dyn.efforts).max())


def test_a_loop_as_a_graph_has_the_loops_loads() -> None:
    from screwkit.kinematics.graph.from_loop import mechanism_from_loop

    lk = sk.fourbar(a=4.0, d1=1.0, d2=3.5, d3=3.0)
    rng = np.random.default_rng(3)
    links = []
    for link in lk.links:
        links.append(sk.Link(link.name, MassProperties(rng.uniform(0.5, 2.0),
                                                       rng.standard_normal(3) * 0.3,
                                                       np.diag(rng.uniform(0.01, 0.02, 3)))))
    lk = lk.with_links(links)
    x = np.radians(np.arange(0.0, 360.0, 5.0))
    loop = sk.solve_motion(lk, x, rates=2.0, accelerations=0.5)
    direct = sk.inverse_dynamics(loop, 0, gravity=G)
    mech = mechanism_from_loop(loop, 0, 0)
    # the graph's bodies are drawn at sample 0: carry each link's mass properties there
    md0 = loop.mode(0)
    bodies = []
    for k, link in enumerate(lk.links):
        R0, p0 = md0.link_rotation[0, k], md0.link_origin[0, k]
        m = link.mass
        bodies.append(sk.Body(link.name, MassProperties(m.mass, R0 @ m.com + p0,
                                                        R0 @ m.inertia @ R0.T)))
    mech = mech.with_bodies(bodies)
    graph = solve_mechanism(mech, x - x[0], rates=2.0, accelerations=0.5)
    dyn = graph_inverse_dynamics(graph, gravity=G)
    np.testing.assert_allclose(dyn.efforts[:, 0], direct.efforts[lk.inputs[0]], rtol=1e-9,
                               atol=1e-9)
    np.testing.assert_allclose(dyn.shaking_force, direct.shaking_force, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(dyn.shaking_moment, direct.shaking_moment, rtol=1e-9, atol=1e-9)


def test_missing_masses_are_named() -> None:
    mech = sk.load_spec(EXAMPLES / "fourbar_graph.toml").mechanism
    mech = mech.with_bodies([sk.Body(b.name) for b in mech.bodies])  # the masses left out
    motion = solve_mechanism(mech, np.radians(np.arange(5.0))[:, None])
    with pytest.raises(sk.ScrewkitError, match="crank, coupler, rocker have none"):
        graph_inverse_dynamics(motion)


def test_dynamics_command_on_a_graph_spec() -> None:
    import json

    from typer.testing import CliRunner

    from screwkit.cli.main import app

    path = EXAMPLES / "watt_sixbar.toml"
    r = CliRunner().invoke(app, ["dynamics", str(path), "--gravity", "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    spec = sk.load_spec(path)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed)
    dyn = graph_inverse_dynamics(motion, gravity=spec.gravity_vector)
    np.testing.assert_allclose(doc["efforts"]["OA.theta"], dyn.efforts[:, 0], rtol=1e-12)
    assert doc["indeterminate"]["count"] == 6  # two planar loops drawn in 3-D: 3 each
    assert doc["summary"]["shaking force"]["peak"] > 0
    r = CliRunner().invoke(app, ["dynamics", str(path)])
    assert r.exit_code == 0 and "gravity off" in r.output

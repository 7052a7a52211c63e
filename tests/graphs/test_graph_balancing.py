"""Balancing on mechanism graphs (issue 28): the graph load regressor against direct graph
inverse dynamics, the QP's predicted measures against inverse dynamics re-run with the balanced
bodies, a four-bar as a graph against the same four-bar balanced as a single loop, the SDP's
physical consistency, the Pareto front's monotony, and `screwkit balance` on a graph spec."""

from __future__ import annotations

import dataclasses
import json
from functools import cache
from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.balancing import balance, counterweight_variables, point_mass_variables
from screwkit.balancing.errors import BalancingError
from screwkit.balancing.graph import balance_mechanism, prepare_graph
from screwkit.balancing.measures import MEASURES
from screwkit.balancing.pareto import pareto_front
from screwkit.balancing.sdp import redistribution_bound
from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
from screwkit.dynamics.graph_regressor import graph_load_regressor
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.model.families import fourbar
from screwkit.model.linkage import Link
from screwkit.model.mass import MassProperties
from screwkit.model.mechanism import Body

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "mechanisms" / "watt_sixbar_balance.toml"
GRAVITY = np.array([0.0, -9.80665, 0.0])


@cache
def _sixbar():
    spec = sk.load_spec(EXAMPLE)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                             accelerations=spec.acceleration)
    return spec, motion


def _rel(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(b)))


def _measures(dyn, mech, mode, norm) -> dict[str, float]:
    """The five measures from a GraphDynamics directly (measures.py's definitions)."""
    F0, ell, b = norm.force, norm.length, norm.bearing_length
    out = {"F": np.mean(np.sum(dyn.shaking_force**2, -1)) / F0**2,
           "T": np.mean(np.sum(dyn.shaking_moment**2, -1)) / (F0 * ell) ** 2,
           "R": np.mean(np.sum(dyn.reaction_force**2, (-1, -2))) / F0**2}
    moments = dyn.reaction_moment.copy()
    for name in mech.inputs:
        j = [jt.name for jt in mech.joints].index(name.rsplit(".", 1)[0])
        axis = mode.joint_axes[:, j]
        moments[:, j] -= axis * np.sum(axis * moments[:, j], -1)[:, None]
    out["M"] = np.mean(np.sum(moments**2, (-1, -2))) / (F0 * b) ** 2
    out["T0"] = np.mean(np.sum(dyn.efforts**2, -1)) / (F0 * ell) ** 2
    return {k: float(v) for k, v in out.items()}


def test_load_regressor_equals_graph_inverse_dynamics() -> None:
    spec, motion = _sixbar()
    reg = graph_load_regressor(motion, 0, GRAVITY)
    pi = np.concatenate([b.mass.inertial_parameters() for b in spec.mechanism.bodies])
    direct = graph_inverse_dynamics(motion, 0, GRAVITY)
    linear = reg.apply(pi)
    for key in ("efforts", "reaction_force", "reaction_moment", "shaking_force",
                "shaking_moment"):
        assert _rel(getattr(linear, key), getattr(direct, key)) <= 1e-9, key
    assert reg.indeterminacy.count == direct.indeterminate  # planar, drawn in 3-D
    assert reg.indeterminacy.idle_freedoms == 0


@pytest.mark.parametrize("gravity", [None, GRAVITY])
def test_balanced_measures_equal_rerun_inverse_dynamics(gravity) -> None:
    """Every measure predicted by the QP equals the one computed from graph inverse dynamics of
    bodies with the balanced mass properties (new mechanism, same motion)."""
    spec, motion = _sixbar()
    mech = spec.mechanism
    blocks = [point_mass_variables(mech, "coupler", max_decrease=0.5, pair_sum="free"),
              counterweight_variables(mech, "crank", "cw1", mass_max=0.1,
                                      at=[-0.017, -0.010, 0.0]),
              counterweight_variables(mech, "rocker", "cw2", mass_max=0.2,
                                      at=[0.042, -0.020, 0.0])]
    weights = {"F": 1.0, "T": 0.5, "R": 0.2, "M": 0.1, "T0": 0.3}
    res = balance_mechanism(motion, 0, blocks, weights, gravity=gravity)
    assert res.measures_after["G"] < res.measures_before["G"]
    for props, predicted in ((res.mass_properties_before, res.measures_before),
                             (res.mass_properties_after, res.measures_after)):
        new = dataclasses.replace(mech, bodies=tuple(Body(b.name, props[b.name])
                                                     for b in mech.bodies))
        dyn = graph_inverse_dynamics(dataclasses.replace(motion, mechanism=new), 0, gravity)
        got = _measures(dyn, mech, motion.mode(0), res.normalisation)
        floor = 1e-12 * max(predicted[k] for k in MEASURES)  # M is round-off: planar
        for k in MEASURES:
            assert abs(got[k] - predicted[k]) <= 1e-9 * predicted[k] + floor, k
        np.testing.assert_allclose(dyn.shaking_force, res.dynamics_after.shaking_force
                                   if props is res.mass_properties_after
                                   else res.dynamics_before.shaking_force,
                                   rtol=1e-9, atol=1e-12)


def _fourbar_pair():
    """A 4R as a single loop and as a graph drawn at its first sample, with the same bodies."""
    lk = fourbar(0.30, 0.10, 0.28, 0.22).with_links([
        Link("crank", MassProperties(0.4, [0.05, 0.0, 0.0], np.diag([1e-5, 4e-4, 4e-4]))),
        Link("coupler", MassProperties(0.9, [0.12, 0.01, 0.0], np.diag([2e-5, 6e-3, 6e-3]))),
        Link("rocker", MassProperties(0.7, [0.10, 0.0, 0.0], np.diag([1e-5, 3e-3, 3e-3]))),
    ])
    x = np.radians(np.arange(0.0, 360.0, 10.0))
    loop = sk.solve_motion(lk, x, rates=20.0, accelerations=0.0)
    md = loop.mode(0)
    assert md.assembles.all() and not md.singular.any()
    R0, p0 = md.link_rotation[0], md.link_origin[0]

    def drawn(k: int, mp: MassProperties) -> MassProperties:  # link frame → drawing
        return MassProperties(mp.mass, R0[k] @ mp.com + p0[k], R0[k] @ mp.inertia @ R0[k].T)

    mech = dataclasses.replace(mechanism_from_loop(loop, 0, 0), bodies=tuple(
        Body(link.name, drawn(k, link.mass)) for k, link in enumerate(lk.links)))
    graph = solve_mechanism(mech, x - x[0], rates=20.0, accelerations=0.0)
    return lk, loop, mech, graph, (R0, p0)


def test_fourbar_graph_equals_single_loop_balancing() -> None:
    lk, loop, mech, graph, (R0, p0) = _fourbar_pair()
    # fixed counterweights (a point of the body: link frame for the loop, drawing for the graph)
    at = {"crank": np.array([-0.04, 0.01, 0.0]), "rocker": np.array([-0.05, 0.0, 0.0])}
    idx = {"crank": 0, "rocker": 2}
    weights = {"F": 1.0, "T": 0.2, "T0": 0.3}
    r1 = balance(loop, 0, [counterweight_variables(lk, b, f"cw_{b}", mass_max=5.0, at=p)
                           for b, p in at.items()], weights)
    r2 = balance_mechanism(graph, 0, [counterweight_variables(
        mech, b, f"cw_{b}", mass_max=5.0, at=R0[idx[b]] @ p + p0[idx[b]])
        for b, p in at.items()], weights)
    np.testing.assert_allclose(r2.after, r1.after, rtol=1e-9, atol=1e-12)
    # the front door takes a solved mechanism too
    r3 = balance(graph, 0, [counterweight_variables(
        mech, b, f"cw_{b}", mass_max=5.0, at=R0[idx[b]] @ p + p0[idx[b]])
        for b, p in at.items()], weights)
    np.testing.assert_array_equal(r3.after, r2.after)
    for k in ("F", "T", "T0", "R", "G"):  # M: round-off on both sides (planar, z axes)
        assert abs(r2.measures_before[k] - r1.measures_before[k]) <= 1e-9 * r1.measures_before[k]
        assert abs(r2.measures_after[k] - r1.measures_after[k]) <= 1e-9 * r1.measures_after[k]


def test_fourbar_graph_is_fully_force_balanced_like_the_loop() -> None:
    """Berkof–Lowen: free counterweights on crank and rocker zero the shaking force of a 4R,
    as a graph as well as as a loop."""
    lk, loop, mech, graph, _ = _fourbar_pair()
    box = ([-1.0, -1.0, -0.1], [1.0, 1.0, 0.1])
    r1 = balance(loop, 0, [counterweight_variables(lk, b, f"cw_{b}", mass_max=20.0, box=box)
                           for b in ("crank", "rocker")], {"F": 1.0})
    r2 = balance_mechanism(graph, 0, [counterweight_variables(mech, b, f"cw_{b}",
                                                              mass_max=20.0, box=box)
                                      for b in ("crank", "rocker")], {"F": 1.0})
    before = r1.measures_before["F"]
    assert abs(r2.measures_before["F"] - before) <= 1e-9 * before
    assert r1.measures_after["F"] <= 1e-12 * before
    assert r2.measures_after["F"] <= 1e-12 * before
    # re-run: the balanced graph's shaking force is zero by its own inverse dynamics
    new = dataclasses.replace(mech, bodies=tuple(Body(b.name, r2.mass_properties_after[b.name])
                                                 for b in mech.bodies))
    dyn = graph_inverse_dynamics(dataclasses.replace(graph, mechanism=new), 0)
    peak = np.max(np.linalg.norm(r2.dynamics_before.shaking_force, axis=-1))
    assert np.max(np.linalg.norm(dyn.shaking_force, axis=-1)) <= 1e-6 * peak


def test_sdp_bound_on_a_graph_is_physically_consistent() -> None:
    spec, motion = _sixbar()
    mech = spec.mechanism
    blocks = [counterweight_variables(mech, "crank", "cw1", mass_max=0.1,
                                      at=[-0.017, -0.010, 0.0])]
    setup = prepare_graph(motion, 0, blocks)
    weights = {"F": 1.0, "T0": 0.5}
    qp = balance_mechanism(motion, 0, blocks, weights)
    coms = {b.name: b.mass.com for b in mech.bodies}
    ell = {"coupler": (coms["coupler"], [0.06, 0.06, 0.01]),
           "rocker": (coms["rocker"], [0.05, 0.05, 0.01])}
    bound = redistribution_bound(setup, weights, ell)
    assert bound.measures_after["G"] < bound.measures_before["G"]
    for name, mp in bound.mass_properties_after.items():
        h = mp.mass * np.asarray(mp.com)
        inertia_o = np.asarray(mp.inertia) + mp.mass * (
            np.dot(mp.com, mp.com) * np.eye(3) - np.outer(mp.com, mp.com))
        sigma = 0.5 * np.trace(inertia_o) * np.eye(3) - inertia_o
        J = np.block([[sigma, h[:, None]], [h[None, :], np.array([[mp.mass]])]])
        scale = np.max(np.abs(J))
        assert np.min(np.linalg.eigvalsh(J)) >= -1e-7 * scale, name  # pseudo-inertia ⪰ 0
        orig = next(b.mass for b in mech.bodies if b.name == name)
        assert mp.mass == pytest.approx(orig.mass, rel=1e-6)
    # both start from the same design: the same objective before
    assert qp.measures_before["G"] == pytest.approx(bound.measures_before["G"], rel=1e-9)


def test_pareto_front_on_a_graph_is_monotone() -> None:
    spec, motion = _sixbar()
    setup = prepare_graph(motion, 0, list(spec.balancing.blocks))
    front = pareto_front(setup, ("F", "T0"), 10)
    eff = front.measures[front.efficient]
    assert len(eff) >= 5
    order = np.argsort(eff[:, 0])
    F, T0 = eff[order, 0], eff[order, 1]
    tol = 1e-9 * np.max(np.abs(front.measures), axis=0)
    assert np.all(np.diff(F) >= -tol[0])
    assert np.all(np.diff(T0) <= tol[1])  # more shaking force buys less torque fluctuation
    assert F[0] < F[-1] and T0[0] > T0[-1]  # a real trade-off


def test_balance_command_on_a_graph_spec(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from screwkit.cli.main import app

    out = tmp_path / "b.json"
    r = CliRunner().invoke(app, ["balance", str(EXAMPLE), "-o", str(out), "--plots",
                                 str(tmp_path / "plots")], env={"MPLBACKEND": "Agg"})
    assert r.exit_code == 0, r.output
    # a sweep of two measures (F, T0) draws its front as a plain scatter
    assert (tmp_path / "plots" / "balance_pareto.png").read_bytes()[:4] == b"\x89PNG"
    doc = json.loads(out.read_text())
    assert doc["variables"]["names"] == ["cw_crank.mass", "cw_rocker.mass"]
    assert doc["variables"]["links"] == ["crank", "rocker"]
    assert doc["measures"]["after"]["F"] < 0.1 * doc["measures"]["before"]["F"]
    assert len(doc["pareto"]["values"]) == 11
    # the library's result, independently: the spec's config through balance_mechanism
    spec, motion = _sixbar()
    res = balance_mechanism(motion, 0, spec.balancing)
    np.testing.assert_allclose(doc["variables"]["after"], res.after, rtol=1e-9)
    table = CliRunner().invoke(app, ["balance", str(EXAMPLE)], env={"COLUMNS": "80"})
    assert table.exit_code == 0, table.output
    assert "body masses" in table.output and "cw_rocker.mass" in table.output


def test_graph_balancing_bad_input() -> None:
    spec, motion = _sixbar()
    with pytest.raises(BalancingError, match="give the mode as an index"):
        balance(motion, motion.mode(0), [], {"F": 1.0})
    with pytest.raises(BalancingError, match="no moving body named 'crnk'"):
        counterweight_variables(spec.mechanism, "crnk", "cw", mass_max=1.0, at=[0, 0, 0])
    bare = dataclasses.replace(spec.mechanism, bodies=tuple(
        Body(b.name, None if b.name == "link_eg" else b.mass) for b in spec.mechanism.bodies))
    blocks = [counterweight_variables(bare, "crank", "cw", mass_max=1.0, at=[0, 0, 0])]
    with pytest.raises(BalancingError, match="'link_eg' has none"):
        balance_mechanism(dataclasses.replace(motion, mechanism=bare), 0, blocks, {"F": 1.0})


def test_spec_bound_table_on_a_graph(tmp_path: Path) -> None:
    """[balancing.bound.ellipsoids.<body>] in drawing coordinates: the SDP runs on the graph;
    an ellipsoid that does not hold the body is refused at load, naming the body."""
    text = EXAMPLE.read_text(encoding="utf-8")
    good = tmp_path / "bound.toml"
    good.write_text(text + "\n[balancing.bound.ellipsoids.coupler]\n"
                    "centre = [45.256277, 34.969036, 0.0]\nsemi_axes = [60, 60, 10]\n",
                    encoding="utf-8")
    spec = sk.load_spec(good)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed)
    res = balance_mechanism(motion, 0, spec.balancing)
    bound = res.redistribution_bound
    assert bound is not None
    assert bound.measures_after["G"] < bound.measures_before["G"]
    assert bound.measures_before["G"] == pytest.approx(res.measures_before["G"], rel=1e-12)
    bad = tmp_path / "bad.toml"
    bad.write_text(good.read_text(encoding="utf-8").replace("[60, 60, 10]", "[6, 6, 1]"),
                   encoding="utf-8")
    with pytest.raises(BalancingError, match="the body 'coupler' as it is does not lie inside"):
        sk.load_spec(bad)


def test_delta_rod_stays_axisymmetric_when_balanced() -> None:
    """A Delta robot's S–S rods spin idly: point masses on a rod get the equality that keeps
    the rod axisymmetric, and graph inverse dynamics of the balanced bodies loads no idle
    freedom (the residual stays at round-off)."""
    spec = sk.load_spec(ROOT / "examples" / "mechanisms" / "delta_robot.toml")
    mech = spec.mechanism
    motion = solve_mechanism(mech, spec.inputs, rates=spec.speed)
    assert graph_load_regressor(motion, 0).indeterminacy.idle_freedoms == 6
    blocks = [point_mass_variables(mech, "rod1a", max_decrease=0.5, pair_sum="free")]
    res = balance_mechanism(motion, 0, blocks, {"F": 1.0, "T": 1.0, "T0": 1.0})
    assert any("axisymmetric" in n for n in res.notes)
    assert res.measures_after["G"] < res.measures_before["G"]
    assert not np.allclose(res.after, res.before)  # the rod's mass did move
    new = dataclasses.replace(mech, bodies=tuple(Body(b.name, res.mass_properties_after[b.name])
                                                 for b in mech.bodies))
    dyn = graph_inverse_dynamics(dataclasses.replace(motion, mechanism=new), 0)
    assert np.nanmax(dyn.residual) < 1e-8

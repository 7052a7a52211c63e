"""A loop given as a graph equals the same loop as a family or joint list (issue 26): joint
variables, body poses and rates at every sample, to 1e-10."""

from __future__ import annotations

import numpy as np
import pytest

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.from_loop import mechanism_from_loop


def _loops():
    return {
        "fourbar": sk.fourbar(a=4.0, d1=1.0, d2=3.5, d3=3.0),
        "rssr": sk.rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.3),
        "rccc": sk.rccc((1.0, 1.5, 1.2, 1.4), (0.3, 0.5, -0.4, 0.6)),
    }


@pytest.mark.parametrize("name", ["fourbar", "rssr", "rccc"])
def test_a_loop_as_a_graph_equals_the_loop(name: str) -> None:
    lk = _loops()[name]
    x = np.radians(np.arange(0.0, 360.0, 3.0))
    motion = sk.solve_motion(lk, x, rates=1.3, accelerations=0.4)
    md = motion.mode(0)
    ok = np.nonzero(md.assembles & ~md.singular)[0]
    # the loop's first assembled run from its first sample
    run = ok[: np.argmax(np.diff(np.r_[ok, -10]) != 1) + 1]
    assert run.size > 10
    k0 = int(run[0])
    mech = mechanism_from_loop(motion, 0, k0)
    graph = solve_mechanism(mech, x[run] - x[k0], rates=1.3, accelerations=0.4)
    gm = graph.modes[0]
    assert gm.assembles.all()
    assert np.nanmax(gm.closure_residual) < 1e-12
    balls = {j.name for j in lk.joints if j.kind == "S"}
    for f in lk.freedom_names:
        if f.split(".")[0] in balls:
            continue  # a ball's rates are in its own frame (and a rod's spin is idle): poses below
        if f in gm.variables:  # scalar freedoms
            d = gm.variables[f] - (md.variables[f][run] - md.variables[f][k0])
            wrapped = np.angle(np.exp(1j * d)) if not f.endswith(".s") else d
            assert np.max(np.abs(wrapped)) < 1e-10, f
        np.testing.assert_allclose(gm.velocities[f], md.velocities[f][run], atol=1e-9, rtol=1e-9)
        np.testing.assert_allclose(gm.accelerations[f], md.accelerations[f][run], atol=1e-8,
                                   rtol=1e-9)
    # body poses: the graph's pose maps the drawing (sample k0) to the sample
    R0, p0 = md.link_rotation[k0], md.link_origin[k0]
    np.testing.assert_allclose(gm.joint_centres, md.joint_centres[run],
                               atol=1e-10 * mech.length_scale)
    for b in range(len(lk.links)):
        if lk.joints[b].kind == "S" and lk.joints[b + 1].kind == "S":
            continue  # a rod between two balls: its spin is idle (centres compared above)
        Rg = md.link_rotation[run, b] @ R0[b].T
        pg = md.link_origin[run, b] - np.einsum("nij,j->ni", Rg, p0[b])
        np.testing.assert_allclose(gm.link_rotation[:, b], Rg, atol=1e-10)
        np.testing.assert_allclose(gm.link_origin[:, b], pg, atol=1e-10 * mech.length_scale)
        np.testing.assert_allclose(gm.link_angular_velocity[:, b],
                                   md.link_angular_velocity[run, b], atol=1e-9)


def test_rates_are_derivatives_of_positions() -> None:
    lk = _loops()["rssr"]
    motion = sk.solve_motion(lk, np.radians([0.0]), rates=1.0)
    mech = mechanism_from_loop(motion)
    x = np.array([0.2, 0.2 - 1e-6, 0.2 + 1e-6])
    g = solve_mechanism(mech, x, rates=1.0).modes[0]
    for f, v in g.variables.items():
        if f in g.velocities:
            fd = (v[2] - v[1]) / 2e-6
            assert abs(fd - g.velocities[f][0]) < 1e-6 * (1 + abs(fd)), f
            fd2 = (g.velocities[f][2] - g.velocities[f][1]) / 2e-6
            assert abs(fd2 - g.accelerations[f][0]) < 1e-5 * (1 + abs(fd2)), f
    assert not g.points  # none here: body origins instead
    fd = (g.link_origin[2] - g.link_origin[1]) / 2e-6
    crank_and_rocker = [0, 2]  # the rod (body 1) spins idly between its balls
    np.testing.assert_allclose(g.link_origin_velocity[0][crank_and_rocker], fd[crank_and_rocker],
                               atol=1e-6)
    fd = (g.joint_centres[2] - g.joint_centres[1]) / 2e-6
    v = (g.link_origin_velocity[0][0] + np.cross(g.link_angular_velocity[0][0],
                                                  g.joint_centres[0][1] - g.link_origin[0][0]))
    np.testing.assert_allclose(v, fd[1], atol=1e-6)  # the crank's ball centre

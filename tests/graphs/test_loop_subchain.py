"""A single loop drawn as a graph is solved by the loop engine (graph/loop_subchain.py, issue 26:
one solving path): the family's closed form where the drawing is one (4R, RSRC), else the joint
list in frame form; mode 0 the drawn mode, ``every_mode`` every loop mode."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.kinematics.graph.loop_subchain import loop_chain
from screwkit.model.mechanism import BodyPoint, MechanismJoint

#: an RSRC with four assembly modes over a turn of the crank (two whole, two that fold)
RSRC4 = dict(d1=0.681, d2=2.147, d3=0.633, a=1.955, b=0.248, e=0.174, delta0=1.177,
             lambda0=0.273)
X = np.radians(np.arange(0.0, 360.0, 5.0))


@pytest.fixture(scope="module")
def rsrc4() -> tuple[sk.Linkage, object]:
    lk = sk.rsrc(**RSRC4)
    return lk, sk.solve_motion(lk, X, rates=1.3, accelerations=0.4)


def _match(a: np.ndarray, b: np.ndarray, scale: float) -> bool:
    return bool(np.nanmax(np.abs(a - b)) < 1e-10 * scale)


def test_an_rsrc_drawn_as_a_graph_gets_every_closed_form_mode(rsrc4) -> None:
    lk, motion = rsrc4
    assert len(motion.modes) == 4
    drawn = 3  # the closed form's mode 3 is the drawing: the graph must call it mode 0
    assert motion.mode(drawn).assembles[0] and motion.mode(drawn).assembles.all()
    mech = mechanism_from_loop(motion, drawn, 0)
    chain = loop_chain(mech)
    assert chain is not None and chain.linkage.family == "RSRC"
    g = solve_mechanism(mech, X - X[0], rates=1.3, accelerations=0.4, every_mode=True)
    assert g.method == "graph (loop, closed)"
    assert len(g.modes) == len(motion.modes)
    scale = mech.length_scale
    md0 = g.modes[0]
    assert md0.label == "drawn" and md0.assembles.all()
    assert _match(md0.joint_centres, motion.mode(drawn).joint_centres, scale)
    # every mode of the loop is one mode of the graph: the same samples, the same joints
    unused = list(range(1, 4))
    for m in (0, 1, 2):
        ref = motion.mode(m)
        hit = [k for k in unused if np.array_equal(g.modes[k].assembles, ref.assembles)
               and _match(g.modes[k].joint_centres[ref.assembles],
                          ref.joint_centres[ref.assembles], scale)]
        assert len(hit) == 1, m
        unused.remove(hit[0])
        gm = g.modes[hit[0]]
        ok = ref.assembles & ~ref.singular & ~gm.singular
        np.testing.assert_allclose(gm.velocities["input.theta"][ok], 1.3)
        np.testing.assert_allclose(gm.velocities["output_C.s"][ok],
                                   ref.velocities["output_C.s"][ok], atol=1e-9)
    # the drawn mode alone is mode 0 of the drawn-mode solve, the same configurations
    one = solve_mechanism(mech, X - X[0])
    assert len(one.modes) == 1
    assert _match(one.modes[0].joint_centres, md0.joint_centres, scale)


def test_a_loop_as_a_graph_equals_the_loop_variables_points_and_rates(rsrc4) -> None:
    lk, motion = rsrc4
    md = motion.mode(0)
    assert md.assembles.all()
    # drawn at sample 20, solved from sample 10 on: the first row is reached from the drawing
    k0, run = 20, np.arange(10, X.size)
    mech = mechanism_from_loop(motion, 0, k0)
    # a point on the coupler, drawn where the loop puts it at sample k0
    local = np.array([0.3, -0.2, 0.5])
    R0, p0 = md.link_rotation[k0, 1], md.link_origin[k0, 1]
    mech = replace(mech, points=(BodyPoint("P", "coupler", R0 @ local + p0),))
    g = solve_mechanism(mech, X[run] - X[k0], rates=1.3, accelerations=0.4).modes[0]
    assert g.assembles.all() and np.nanmax(g.closure_residual) < 1e-12
    for f in ("input.theta", "coupler_R.theta", "output_C.theta", "output_C.s"):
        d = g.variables[f] - (md.variables[f][run] - md.variables[f][k0])
        assert np.max(np.abs(d)) < 1e-10, f
        np.testing.assert_allclose(g.velocities[f], md.velocities[f][run], atol=1e-10, rtol=0)
        np.testing.assert_allclose(g.accelerations[f], md.accelerations[f][run], atol=1e-9,
                                   rtol=0)
    x = np.einsum("nij,j->ni", md.link_rotation[run, 1], local) + md.link_origin[run, 1]
    w = md.link_angular_velocity[run, 1]
    v = md.link_origin_velocity[run, 1] + np.cross(w, x - md.link_origin[run, 1])
    np.testing.assert_allclose(g.points["P"], x, atol=1e-10 * mech.length_scale)
    np.testing.assert_allclose(g.point_velocities["P"], v, atol=1e-9 * mech.length_scale)


def test_rates_are_derivatives_of_positions_on_the_loop_route(rsrc4) -> None:
    _, motion = rsrc4
    mech = mechanism_from_loop(motion, 3, 0)
    h = 1e-6
    x = np.array([0.4, 0.4 - h, 0.4 + h])
    g = solve_mechanism(mech, x, rates=1.0, accelerations=0.0).modes[0]
    for f, v in g.variables.items():
        if f in g.velocities:
            fd = (v[2] - v[1]) / (2 * h)
            assert abs(fd - g.velocities[f][0]) < 1e-6 * (1 + abs(fd)), f
            fd2 = (g.velocities[f][2] - g.velocities[f][1]) / (2 * h)
            assert abs(fd2 - g.accelerations[f][0]) < 1e-5 * (1 + abs(fd2)), f
    fd = (g.link_origin[2] - g.link_origin[1]) / (2 * h)
    np.testing.assert_allclose(g.link_origin_velocity[0], fd, atol=1e-6)


def test_a_reversed_input_joint_turns_the_loop_the_other_way() -> None:
    """The input joint drawn between (crank, ground): its freedom turns the crank the other way
    about the same axis, so graph input x is the loop's input −x."""
    lk = sk.fourbar(a=4.0, d1=1.0, d2=3.5, d3=3.0)
    motion = sk.solve_motion(lk, X)
    mech = mechanism_from_loop(motion, 0, 0)
    j0 = mech.joints[0]
    flipped = MechanismJoint(j0.name, "R", (j0.bodies[1], j0.bodies[0]), j0.at, j0.axis)
    mech2 = replace(mech, joints=(flipped, *mech.joints[1:]))
    assert loop_chain(mech2) is not None and loop_chain(mech2).linkage.family == "4R"
    x = np.radians(np.arange(0.0, 90.0, 5.0))
    a = solve_mechanism(mech, x).modes[0]
    b = solve_mechanism(mech2, -x).modes[0]
    np.testing.assert_allclose(a.joint_centres, b.joint_centres, atol=1e-10 * mech.length_scale)
    np.testing.assert_allclose(a.variables["output.theta"], b.variables["output.theta"],
                               atol=1e-10)


def test_a_loop_without_a_closed_form_takes_the_loop_engine_and_its_joint_list_agrees() -> None:
    """An RCCC driven at a cylinder (no closed form) has its drawn mode followed by the loop
    engine's continuation (graph/loop_track.py); its joint list in frame form
    (loop_chain(generic=True)) solved by the generic loop solver gives the same motion, every
    joint variable 0 at the drawing and equal to the loop's."""
    from screwkit.kinematics.graph.closure import graph_layout
    from screwkit.kinematics.graph.loop_motion import loop_motion

    lk = sk.rccc((1.0, 1.5, 1.2, 1.4), (0.3, 0.5, -0.4, 0.6))
    lk = replace(lk, inputs=("C2.theta",), family=None)
    x = np.radians(np.arange(0.0, 30.0, 2.0))
    motion = sk.solve_motion(lk, x)
    md = motion.mode(0)
    mech = mechanism_from_loop(motion, 0, 0)
    assert loop_chain(mech) is None
    chain = loop_chain(mech, generic=True)
    assert chain is not None and chain.linkage.family is None
    X0 = (x - x[0])[:, None]
    ones, zeros = np.ones_like(X0), np.zeros_like(X0)
    looped = loop_motion(mech, graph_layout(mech), chain, X0, ones, zeros, False)
    tracked = solve_mechanism(mech, x - x[0])
    assert tracked.method == "graph" and looped.method == "graph (loop, generic)"
    assert "loop engine" in tracked.solver
    ok = md.assembles
    for gm in (looped.modes[0], tracked.modes[0]):
        for f in lk.freedom_names:
            np.testing.assert_allclose(gm.variables[f][ok],
                                       md.variables[f][ok] - md.variables[f][0], atol=1e-10,
                                       err_msg=f)
            np.testing.assert_allclose(gm.velocities[f][ok], md.velocities[f][ok], atol=1e-9,
                                       err_msg=f)


@pytest.mark.parametrize("family", ["4R", "RSSR", "RCCC", "CSSP"])
def test_each_family_read_off_its_drawing_gives_the_closed_form_modes(family: str) -> None:
    """The 4R, RSSR (with its output crank off the crank plane), RCCC (with an input offset) and
    CSSP (with a crank offset) drawn as graphs are read back as their families; every graph mode is a loop mode, sample
    by sample."""
    lk = {"4R": sk.fourbar(a=4.0, d1=1.0, d2=3.5, d3=3.0),
          "RSSR": sk.rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.3, 0.4),
          "RCCC": sk.rccc((1.0, 1.5, 1.2, 1.4), (0.3, 0.5, -0.4, 0.6), 0.3),
          "CSSP": sk.cssp(1.0, 3.0, 1.5, 0.4, -0.5)}[family]
    x = np.radians(np.arange(0.0, 360.0, 10.0))
    motion = sk.solve_motion(lk, x)
    k0 = int(np.argmax(motion.mode(1).assembles))
    mech = mechanism_from_loop(motion, 1, k0)  # drawn in the loop's mode 1
    chain = loop_chain(mech)
    assert chain is not None and chain.linkage.family == family
    g = solve_mechanism(mech, x[k0:] - x[k0], every_mode=True)
    assert g.method == "graph (loop, closed)" and len(g.modes) == len(motion.modes) == 2
    scale = mech.length_scale
    ref = [motion.mode(m) for m in (1, 0)]  # the drawn mode first
    for gm, md in zip(g.modes, ref, strict=True):
        ok = md.assembles[k0:]
        assert np.array_equal(gm.assembles, ok)
        assert _match(gm.joint_centres[ok], md.joint_centres[k0:][ok], scale)
        assert np.nanmax(gm.closure_residual) < 1e-12


def test_random_loops_of_every_family_are_read_back_as_their_family() -> None:
    """Seeded random dimensions of each family, drawn in each of their modes: every drawing is
    read back as its family (the reading is checked against the closed form's joint lines)."""
    rng = np.random.default_rng(5)
    x = np.radians(np.arange(0.0, 360.0, 30.0))
    seen: dict[str, int] = {}
    for _ in range(4):
        d1, d2, d3, a = rng.uniform(0.5, 3.0, 4)
        b, e = rng.uniform(-1.0, 1.0, 2)
        de, la = rng.uniform(-1.5, 1.5, 2)
        for fam, lk in (("RSRC", sk.rsrc(d1, d2, d3, a, b, e, de, la)),
                        ("RSSR", sk.rssr(d1, d2 + 1.0, d3, a, b, la, e)),
                        ("CSSP", sk.cssp(d1, d2 + 2.0, abs(b), la, e)),
                        ("RCCC", sk.rccc((d1, d2, d3, a), (de, la, b, e), e)),
                        ("4R", sk.fourbar(a, d1, d2, d3))):
            try:
                motion = sk.solve_motion(lk, x)
            except sk.AssemblyError:
                continue  # these dimensions do not close over these inputs
            for m, md in enumerate(motion.modes):
                if md.assembles.any():
                    mech = mechanism_from_loop(motion, m, int(np.argmax(md.assembles)))
                    chain = loop_chain(mech)
                    assert chain is not None and chain.linkage.family == fam, (fam, m)
                    seen[fam] = seen.get(fam, 0) + 1
    assert set(seen) == {"RSRC", "RSSR", "CSSP", "RCCC", "4R"}


def test_the_rod_between_two_balls_turns_as_its_angular_velocity_says() -> None:
    """An RSSR drawn as a graph: the rod's pose comes from the closed form, its angular velocity
    from the stacked closure with the idle spin held still; the pose's derivative (central
    differences) is that angular velocity, the spin about the rod included."""
    lk = sk.rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.3)
    mech = mechanism_from_loop(sk.solve_motion(lk, np.radians([0.0, 1.0])))
    h = 1e-6
    g = solve_mechanism(mech, np.array([0.4, 0.4 - h, 0.4 + h])).modes[0]
    R = g.link_rotation[:, 1]  # the coupler rod
    W = (R[2] - R[1]) / (2 * h) @ R[0].T
    np.testing.assert_allclose([W[2, 1], W[0, 2], W[1, 0]], g.link_angular_velocity[0, 1],
                               atol=1e-8)

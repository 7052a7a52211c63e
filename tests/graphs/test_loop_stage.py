"""A family loop as a sub-chain stage inside a larger graph (issue 27; graph/subchains.py's
LoopStage, graph/loop_stage.py): an RSRC loop driven at its ground R joint whose coupler carries
an RSS leg (an arm on an R joint, an S–S tie rod to the ground). Checked against routes that do
not use the loop stage: at every sample the loop's every mode from the homotopy
(modes/every_mode.py on the RSRC alone) times the leg's every root found by sign changes on a
fine grid of the arm angle and brentq on the rod's length law; the drawn mode against the graph
tracker; rates against finite differences; every mode's loops close."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

import screwkit as sk
from loop_stage_helpers import knee
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.kinematics.graph.idle import rods
from screwkit.kinematics.graph.motion import MechanismMotion
from screwkit.kinematics.graph.subchains import LoopStage, decompose
from screwkit.kinematics.modes.every_mode import every_mode
from screwkit.model.mechanism import Body, Mechanism, MechanismJoint

#: Bagci's RSRC dimensions (d1, d2, d3, a, b, e, δ0, λ0): two modes over every turn, and four,
#: two of which fold (tests/graphs/test_loop_subchain.py)
RSRC2 = (1.0, 3.5, 2.0, 3.0, 0.5, 0.2, 0.3, 0.4)
RSRC4 = (0.681, 2.147, 0.633, 1.955, 0.248, 0.174, 1.177, 0.273)
#: the legs hung on the RSRC's coupler: (arm pivot K, arm axis, ball T on the arm, ground ball G)
LEGS = {"full": ([-0.17, 4.581, -1.036], [-0.378, 2.043, 0.647], [-0.705, 3.766, 0.092],
                 [-0.609, 1.462, 0.833]),
        "folding": ([-1.797, 4.77, -0.752], [0.914, -0.02, -1.249], [-1.108, 4.03, -0.026],
                    [-2.96, 1.52, 2.105]),
        "loop folding": ([-1.86, 1.262, 0.175], [0.648, -0.121, -0.23], [-1.756, 1.077, 0.469],
                         [-1.017, 2.443, -0.149])}
X = np.radians(np.arange(0.0, 360.0, 6.0))[:, None]


def _loop(dims: tuple[float, ...] = RSRC2) -> Mechanism:
    """Bagci's RSRC drawn where its first mode is at input 0."""
    lk = sk.rsrc(*dims)
    return mechanism_from_loop(sk.solve_motion(lk, np.radians([0.0, 2.0])), 0, 0)


def _with_leg(which: str) -> Mechanism:
    K, u, T, G = (np.asarray(v, dtype=float) for v in LEGS[which])
    loop = _loop(RSRC4 if which == "loop folding" else RSRC2)
    joints = (MechanismJoint("K", "R", ("coupler", "arm"), K, u),
              MechanismJoint("T", "S", ("arm", "tie"), T, np.array([0.0, 0.0, 1.0])),
              MechanismJoint("G", "S", ("tie", "ground"), G, np.array([0.0, 0.0, 1.0])))
    return Mechanism(f"RSRC with a {which} leg", (*loop.bodies, Body("arm"), Body("tie")),
                     (*loop.joints, *joints), loop.inputs)


@pytest.fixture(scope="module", params=sorted(LEGS))
def case(request: pytest.FixtureRequest) -> tuple[Mechanism, MechanismMotion]:
    mech = _with_leg(request.param)
    return mech, solve_mechanism(mech, X, every_mode=True)


def _rotation(u: np.ndarray, phi: float) -> np.ndarray:
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return np.eye(3) + np.sin(phi) * K + (1.0 - np.cos(phi)) * K @ K


def _pose_vector(R: np.ndarray, p: np.ndarray, L: float) -> np.ndarray:
    """Poses of the crank, coupler, output and arm (rotation entries, positions over L)."""
    return np.concatenate([np.ravel(R[:4]), np.ravel(p[:4]) / L])


def _independent(mech: Mechanism, X: np.ndarray = X) -> list[np.ndarray]:
    """Every configuration at every input row, without the loop stage: the RSRC's modes from
    the homotopy, then every arm angle φ where |T(φ) − G| is the rod's length (a sign change
    on a 0.1° grid refined by brentq)."""
    loop = _loop(RSRC4 if mech.name.endswith("loop folding leg") else RSRC2)
    lay = graph_layout(loop)
    K0, u0 = mech.joints[4].at, mech.joints[4].axis
    T0, G = mech.joints[5].at, mech.joints[6].at
    rod2 = float(np.sum((T0 - G) ** 2))
    grid = np.radians(np.arange(0.0137, 360.0, 0.1))  # no root (φ = 0 is one) on the grid
    on_arm = K0 + np.array([_rotation(u0, f) @ (T0 - K0) for f in grid])  # T(φ) on the coupler
    found = every_mode(loop, X)
    out = []
    for conf in found.configurations:
        fr = graph_forward(loop, lay, conf)
        rows = []
        for R, p in zip(fr.R, fr.p, strict=True):  # (B+1, 3, 3): crank, coupler, output, ground
            Rc, pc = R[1], p[1]

            def gap(phi: float, Rc: np.ndarray = Rc, pc: np.ndarray = pc) -> float:
                T = Rc @ (K0 + _rotation(u0, phi) @ (T0 - K0)) + pc
                return float(np.sum((T - G) ** 2)) - rod2

            values = np.sum((on_arm @ Rc.T + pc - G) ** 2, axis=1) - rod2  # gap on the grid
            change = np.flatnonzero(np.sign(values) != np.sign(np.roll(values, -1)))
            for i in change:
                phi = brentq(gap, grid[i], grid[i] + np.radians(0.1), xtol=1e-15)
                Ra = Rc @ _rotation(u0, phi)
                pa = Rc @ (K0 - _rotation(u0, phi) @ K0) + pc
                rows.append(_pose_vector(np.stack([*R[:3], Ra]), np.stack([*p[:3], pa]),
                                         mech.length_scale))
        out.append(np.array(rows).reshape(-1, 48))
    return out


def test_the_loop_is_a_stage_of_the_decomposition() -> None:
    mech = _with_leg("full")
    dec = decompose(mech)
    assert dec.complete and [type(s).__name__ for s in dec.steps] == ["Driven", "LoopStage",
                                                                      "Dyad"]
    stage = dec.loops[0]
    assert isinstance(stage, LoopStage) and stage.kind == "RSRC"
    assert set(stage.bodies) == {"coupler", "output"} and dec.dyads[0].kind == "RSS"
    assert "RSRC loop input–sphere–coupler_R–output_C" in dec.describe(mech)[1]
    # the loop alone is the loop engine's (graph/loop_subchain.py), as before
    assert solve_mechanism(_loop(), X[:3]).method == "graph (loop, closed)"


def test_every_mode_is_every_configuration_at_every_sample(
        case: tuple[Mechanism, MechanismMotion]) -> None:
    """Per sample, the modes that assemble are one to one the independent configurations (to
    1e-9), so the counts agree too; and every combination of 2 loop modes × 2 leg branches is
    a mode where it assembles."""
    mech, motion = case
    assert motion.method == "graph (closed forms)"
    L = mech.length_scale
    theirs = _independent(mech)
    counts = []
    for n, want in enumerate(theirs):
        here = [md for md in motion.modes if md.assembles[n]]
        mine = np.array([_pose_vector(md.link_rotation[n], md.link_origin[n], L)
                         for md in here]).reshape(-1, 48)
        assert len(mine) == len(want), n
        if len(want):
            gap = np.abs(mine[:, None] - want[None]).max(axis=2)
            assert np.all(gap.min(axis=1) <= 1e-9) and np.all(gap.min(axis=0) <= 1e-9), n
        counts.append(len(want))
    assert max(counts) == 4  # two loop modes, each with both leg branches
    four = mech.name.endswith("loop folding leg")  # four loop modes: 8 combinations
    assert motion.notes[0].startswith(f"{8 if four else 4} branch combination(s) of 2 "
                                      "sub-chain(s)")


def test_every_mode_closes_and_the_folds_are_named(
        case: tuple[Mechanism, MechanismMotion]) -> None:
    mech, motion = case
    lay = graph_layout(mech)
    for md in motion.modes:
        ok = np.flatnonzero(md.assembles)
        res = graph_forward(mech, lay, md.conf.take(ok)).residual
        assert np.abs(res).max() <= 1e-10 * mech.length_scale
        for e in md.events:
            if e.startswith(("dies", "is born")):
                assert "the RSS leg K–T–G folds" in e or "the RSRC loop" in e, e
    births = sum(e.startswith(("dies", "is born")) for md in motion.modes for e in md.events)
    if mech.name.endswith("loop folding leg"):  # the loop's folds and the leg's
        assert len(motion.modes) == 5 and births >= 4
        # the loop's two modes that fold (its modes 1 and 2; 0 and 3 are whole) named
        assert any("the RSRC loop input–sphere–coupler_R–output_C folds (its modes 1 and 2 "
                   "meet)" in e for md in motion.modes for e in md.events)
        # loop mode 2 meets mode 1 alone: not the drawn loop mode's leg branches born nearby
        assert motion.notes[1].endswith("{0, 1, 4}, {2, 3}")
    elif mech.name.endswith("folding leg"):
        assert births >= 4 and len(motion.modes) == 5
        assert "the drawn branches again" in motion.modes[-1].label
    else:
        assert [int(md.assembles.sum()) for md in motion.modes[:2]] == [X.shape[0]] * 2


@pytest.mark.parametrize("which", ["folding", "loop folding"])
def test_each_fold_is_where_the_independent_count_changes_by_two(which: str) -> None:
    """The births and deaths the loop stage reports (located between samples): just before
    and just after each, the independent count of configurations changes (a fold: pairs of
    configurations meet), the leg's folds and the loop's."""
    mech = _with_leg(which)
    motion = solve_mechanism(mech, X, every_mode=True)
    folds = {float(e.split(" deg")[0].split("= ")[1]) for md in motion.modes for e in md.events
             if e.startswith(("dies at", "is born at"))}
    assert len(folds) == 6
    eps = 2e-4  # the event's six digits place it within 1e-5 rad
    x = np.radians(np.array(sorted(folds)))
    around = _independent(mech, np.stack([x - eps, x + eps], axis=1).reshape(-1, 1))
    counts = np.array([len(c) for c in around]).reshape(-1, 2)
    change = np.abs(counts[:, 0] - counts[:, 1])
    # two configurations meet at a leg's fold; at the loop's, two loop modes with whatever
    # assembles on them (both leg branches on each: four)
    assert np.all((change > 0) & (change % 2 == 0)), counts


def test_the_drawn_mode_is_the_graph_tracker_s(case: tuple[Mechanism, MechanismMotion]) -> None:
    mech, motion = case
    lay = graph_layout(mech)
    followed = follow_drawn_mode(mech, lay, X)
    drawn = motion.modes[0]
    assert np.array_equal(drawn.assembles, followed.mask)
    ok = followed.mask
    spinning = {b for b, _, _ in rods(mech)}
    cols = [lay.scalar_col[f] for f in range(lay.m) if lay.scalar_col[f] >= 0]
    assert np.max(np.abs(drawn.conf.scalars - followed.conf.scalars)[ok][:, cols]) <= 1e-10
    held = [k for k, b in enumerate(mech.bodies) if b.name not in spinning]
    fr = graph_forward(mech, lay, followed.conf)
    assert np.max(np.abs(drawn.link_origin - fr.p[:, :len(mech.bodies)])[ok][:, held]) \
        <= 1e-10 * mech.length_scale
    assert np.max(np.abs(drawn.link_rotation - fr.R[:, :len(mech.bodies)])[ok][:, held]) <= 1e-10


def test_rates_and_accelerations_are_the_finite_differences_of_the_positions() -> None:
    mech = _with_leg("full")
    h = 1e-4
    x0 = np.radians(37.0)
    t = x0 + h * np.arange(-2, 3)
    motion = solve_mechanism(mech, t, every_mode=True)
    assert len(motion.modes) == 2  # the drawn loop mode with both leg branches
    for md in motion.modes:
        assert md.assembles.all()
        for name in ("coupler_R.theta", "output_C.theta", "output_C.s", "K.theta"):
            q = md.variables[name]
            d1 = (q[3] - q[1]) / (2 * h)
            d2 = (q[3] - 2 * q[2] + q[1]) / h ** 2
            assert abs(md.velocities[name][2] - d1) <= 1e-7 * max(1.0, abs(d1)), name
            assert abs(md.accelerations[name][2] - d2) <= 1e-4 * max(1.0, abs(d2)), name
        # every body's origin velocity from the twists against the positions' differences (not
        # the tie rod's: its spin about its own axis is idle, its pose there a convention)
        v = (md.link_origin[3, :4] - md.link_origin[1, :4]) / (2 * h)
        assert np.max(np.abs(md.link_origin_velocity[2, :4] - v)) <= 1e-7 * mech.length_scale


def _fourbar() -> Mechanism:
    """A crank–rocker four-bar (frame 4, crank 1, coupler 3.5, rocker 3) in the x–y plane."""
    lk = sk.fourbar(a=4.0, d1=1.0, d2=3.5, d3=3.0)
    return mechanism_from_loop(sk.solve_motion(lk, np.radians([30.0, 32.0])), 0, 0)


@pytest.mark.parametrize("family", ["RSRC", "4R"])
def test_a_loop_hung_on_a_driven_body_is_the_loop_alone_in_that_body_s_frame(family: str
                                                                             ) -> None:
    loop = _loop() if family == "RSRC" else _fourbar()
    mech = knee(loop)
    dec = decompose(mech)
    assert dec.complete and dec.loops[0].parent == "thigh" and dec.loops[0].kind == family
    # the same four-bar on the ground is a crank and an RRR dyad, not a loop stage
    assert family == "RSRC" or [s.kind for s in decompose(_fourbar()).stages] == ["RRR"]
    t = np.linspace(0.0, 1.0, 41)
    rows = np.stack([0.8 * np.sin(2 * np.pi * t), 2 * np.pi * t], axis=1)
    motion = solve_mechanism(mech, rows, every_mode=True)
    assert motion.method == "graph (closed forms)"
    # the loop alone at the knee's inputs, from the homotopy
    lay_loop = graph_layout(loop)
    found = every_mode(loop, rows[:, 1:])
    for n, conf in enumerate(found.configurations):
        fr = graph_forward(loop, lay_loop, conf)
        want = np.concatenate([fr.R[:, :3].reshape(len(conf.scalars), -1),
                               fr.p[:, :3].reshape(len(conf.scalars), -1)], axis=1)
        mine = []
        for md in motion.modes:
            if not md.assembles[n]:
                continue
            Rt, pt = md.link_rotation[n, 0], md.link_origin[n, 0]  # the thigh
            R = Rt.T @ md.link_rotation[n, 1:4]
            p = (md.link_origin[n, 1:4] - pt) @ Rt
            mine.append(np.concatenate([R.ravel(), p.ravel()]))
        assert len(mine) == len(want) == 2, n
        gap = np.abs(np.array(mine)[:, None] - want[None]).max(axis=2)
        assert np.all(gap.min(axis=1) <= 1e-9) and np.all(gap.min(axis=0) <= 1e-9), n
    lay = graph_layout(mech)
    followed = follow_drawn_mode(mech, lay, rows)
    assert followed.mask.all() and motion.modes[0].assembles.all()
    assert np.max(np.abs(motion.modes[0].conf.scalars - followed.conf.scalars)) <= 1e-10
    for md in motion.modes:
        res = graph_forward(mech, lay, md.conf.take(np.flatnonzero(md.assembles))).residual
        assert np.abs(res).max() <= 1e-10 * mech.length_scale

"""every_mode on mechanisms (issue 27): the graph tracker's drawn mode is among the homotopy's
modes at every input row, every mode closes by the tracker's own closure, and what no
formulation takes is refused with the reason (H joints are not algebraic)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from modes_helpers import random_r_loop, tilted
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.closure import graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.modes.every_mode import CLOSURE_TOLERANCE, closure_formulation, every_mode
from screwkit.model.mechanism import Mechanism, MechanismJoint

EXAMPLES = Path(__file__).parents[2] / "examples" / "mechanisms"


def wrapped(a: np.ndarray) -> np.ndarray:
    return np.mod(a + np.pi, 2 * np.pi) - np.pi


def assert_tracked_mode_among(mech: Mechanism, X: np.ndarray, modes: int | None) -> None:
    result = every_mode(mech, X)
    followed = follow_drawn_mode(mech, graph_layout(mech), X)
    assert followed.mask.all()
    assert result.worst_closure <= CLOSURE_TOLERANCE
    for b in range(len(X)):
        conf = result.configurations[b]
        if modes is not None:
            assert conf.size == modes and result.certified[b].all()
        gap = np.abs(wrapped(conf.scalars - followed.conf.scalars[b])).max(axis=1)
        assert gap.min() <= 1e-9, f"{mech.name}: the tracked mode is missing at row {b}"


@pytest.mark.parametrize("name,modes", [("fourbar_graph", 2), ("stephenson3_sixbar", 2),
                                        ("watt_sixbar", 4)])
def test_the_tracked_mode_is_among_every_mode_of_the_planar_examples(name: str, modes: int
                                                                     ) -> None:
    mech = sk.load_spec(EXAMPLES / f"{name}.toml").mechanism
    assert_tracked_mode_among(mech, np.array([[0.0], [0.5], [1.0]]), modes)


def test_the_tracked_mode_is_among_every_mode_of_a_7r_loop() -> None:
    mech = random_r_loop(np.random.default_rng(21), 7, [2])
    assert_tracked_mode_among(mech, np.array([[0.0], [0.1], [0.2]]), None)


def test_an_h_joint_is_refused_as_not_algebraic() -> None:
    mech = sk.load_spec(EXAMPLES / "fourbar_graph.toml").mechanism
    j = mech.joints[1]
    joints = list(mech.joints)
    joints[1] = MechanismJoint(j.name, "H", j.bodies, j.at, j.axis, pitch=0.01)
    helical = Mechanism(mech.name, mech.bodies, tuple(joints), mech.inputs)
    with pytest.raises(CapabilityError, match="not algebraic"):
        every_mode(helical, [[0.0]])


@pytest.mark.parametrize("which", ["7R", "fourbar_graph"])
def test_a_joint_made_off_its_drawing_is_refused_not_solved_as_drawn(which: str) -> None:
    """A seat offset (a part made off its drawing, as a hardpoint tolerance makes it) moves the
    mechanism off what the formulations read: before, every_mode solved the drawn mechanism
    and its graph-closure check then dropped every root, so a 7R loop with a 1 mm offset
    silently had no mode at all (2 without it). Now it is refused, naming the joint."""
    from dataclasses import replace

    mech = (random_r_loop(np.random.default_rng(5), 7, [0]) if which == "7R" else
            sk.load_spec(EXAMPLES / f"{which}.toml").mechanism)
    X = np.full((1, len(mech.inputs)), 0.1)
    assert every_mode(mech, X).configurations[0].size >= 1
    joints = list(mech.joints)
    delta = np.array([1e-3, 0.0, 0.0])
    joints[2] = replace(joints[2], at=joints[2].at + delta, seat_offset=delta)
    off = Mechanism(mech.name, mech.bodies, tuple(joints), mech.inputs)
    with pytest.raises(CapabilityError, match=f"joints \\['{joints[2].name}'\\] are made off"):
        every_mode(off, X)


def test_a_mechanism_no_formulation_takes_is_refused_by_name(tmp_path: Path) -> None:
    """A 3-UPU whose platform U axes are not square to its legs: no formulation takes it, and
    the message says why the nearest one (the point formulation: 90 unknowns) does not."""
    from tests.graphs.three_upu import write_tilted

    mech = sk.load_spec(write_tilted(tmp_path / "tilted.toml", (1, 2, 3))).mechanism
    with pytest.raises(CapabilityError, match="no polynomial formulation takes.*90 unknowns"):
        every_mode(mech, np.zeros((1, len(mech.inputs))))


def test_every_pose_of_the_stewart_example_holds_the_tracked_one() -> None:
    """The bundled UPS platform (symmetric, so not generic: fewer than 40 finite poses, some
    paths end singular or fail, and the solver says so): the pose the graph tracker reaches is
    among the real poses, and every real pose has the six leg lengths (an independent check:
    from the pose, not from the polynomial system)."""
    from screwkit.algebraic.solve import solve_all
    from screwkit.kinematics.graph.closure import graph_forward
    from screwkit.kinematics.modes.stewart import (
        pose_from_study,
        stewart_from_mechanism,
        stewart_start,
        stewart_system,
    )

    mech = sk.load_spec(EXAMPLES / "stewart_platform.toml").mechanism
    rig = stewart_from_mechanism(mech)
    X = np.array([[0.0] * 6, [0.004, -0.003, 0.002, 0.005, -0.001, 0.003]])
    lay = graph_layout(mech)
    followed = follow_drawn_mode(mech, lay, X)
    assert followed.mask.all()
    frames = graph_forward(mech, lay, followed.conf)
    body = lay.body_of[rig.platform]
    p = rig.parameters(X)
    sol = solve_all(stewart_system(), p, stewart_start())
    assert np.all(sol.found <= 40)
    for b in range(len(X)):
        R, t = pose_from_study(sol.x[(sol.instance == b) & sol.real].real)
        gap = np.abs(R - frames.R[b, body]).max(axis=(1, 2)) + np.abs(t - frames.p[b, body]).max(1)
        assert gap.min() <= 1e-9
        legs = np.einsum("nij,kj->nki", R, rig.top) + t[:, None] - rig.base
        L = np.sqrt(p[b, 36:])
        assert np.abs(np.linalg.norm(legs, axis=2) - L).max() <= 1e-10 * max(L)


def test_a_mechanism_that_is_not_a_stewart_platform_is_refused() -> None:
    from screwkit.kinematics.modes.stewart import stewart_from_mechanism

    with pytest.raises(CapabilityError, match="not a 6-6 Stewart"):
        stewart_from_mechanism(sk.load_spec(EXAMPLES / "watt_sixbar.toml").mechanism)


def test_equal_rows_are_solved_once_with_the_same_modes(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """A closed motion's first and last rows (both anchors of modes/along.py) are one homotopy:
    the batch holds each distinct row once, and each copy gets that row's modes."""
    import screwkit.kinematics.modes.every_mode as em

    mech = sk.load_spec(Path(__file__).parents[2] / "examples" / "mechanisms" /
                        "fourbar_graph.toml").mechanism
    X = np.array([[0.0], [0.3], [0.0], [0.3], [-0.2]])
    batches: list[int] = []
    solve = em.solve_all

    def counted(system, p, start):  # type: ignore[no-untyped-def]
        batches.append(len(np.atleast_1d(p)))
        return solve(system, p, start)

    monkeypatch.setattr(em, "solve_all", counted)
    got = every_mode(mech, X)
    assert batches == [3]
    alone = every_mode(mech, X[[0, 1, 4]])
    for k, j in enumerate([0, 1, 0, 1, 2]):
        assert np.array_equal(got.configurations[k].scalars, alone.configurations[j].scalars)
        assert got.found[k] == alone.found[j]
    assert np.array_equal(got.inputs, X) and all(c.size == 2 for c in got.configurations)


@pytest.mark.parametrize("twist", [0.0, 1e-5, 1e-3])
def test_a_7r_loop_with_a_nearly_parallel_pair_keeps_its_tracked_mode(twist: float) -> None:
    """A 7R loop with j2's axis ``twist`` rad from j1's: the 6R reading divides by each link's
    sin α, so before, the parallel pair raised an InputError ("use planar"), at 1e-5 every_mode
    had no mode and at 1e-3 it missed the tracked mode on one loop of two (found by a review
    probe). Such a loop now goes to the R/P/C axes formulation, which puts that link at the
    ground; a well-separated 7R loop stays on the 6R route."""
    from tests.kinematics.test_modes_rpc_loop import INPUT, _tracked

    from screwkit.kinematics.modes.rpc_loop import RPCLoop

    rng = np.random.default_rng(8)
    checked = 0
    for _ in range(6):
        mech = tilted(random_r_loop(rng, 7, [0]), 2, 1, twist)
        tracked = _tracked(mech, ["j0.theta"])
        if tracked is None:
            continue
        assert isinstance(closure_formulation(mech), RPCLoop)
        conf = every_mode(mech, [[INPUT]]).configurations[0]
        assert np.abs(wrapped(conf.scalars - tracked)).max(axis=1).min() <= 1e-9
        checked += 1
    assert checked >= 2
    assert not isinstance(closure_formulation(random_r_loop(np.random.default_rng(21), 7, [2])),
                          RPCLoop)

"""The RSSR island of issue 27 ("a two-sample RSSR island between anchors is missed"): an RSSR
(tests/modes_helpers.py's :data:`ISLAND_RSSR`) whose two modes exist only over 168.04° …
176.39°, shorter than the spacing of the loop solver's root-search anchors (15°) and of the
graph route's homotopy anchors (8 samples). The closed form and the graph route's every mode
must find the island whole: both modes at both of its samples, nothing elsewhere, its ends
where a point-to-circle distance test puts them."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.families import rssr

sys.path.insert(0, str(Path(__file__).parents[1]))
from modes_helpers import ISLAND_DEG, ISLAND_RSSR, ISLAND_SAMPLES, rssr_reach  # noqa: E402

THETA = np.radians(np.arange(0.0, 360.0, 5.0))


def _counts(motion) -> np.ndarray:  # type: ignore[no-untyped-def]
    return np.sum([md.assembles for md in motion.modes], axis=0)


def test_the_distance_test_puts_the_island_where_the_closed_form_does() -> None:
    fine = np.radians(np.arange(0.0, 360.0, 0.01))
    near, far = rssr_reach(ISLAND_RSSR, fine)
    d2 = ISLAND_RSSR[1]
    closes = (near <= d2) & (d2 <= far)
    ends = np.degrees(fine[closes][[0, -1]])
    assert np.abs(ends - ISLAND_DEG).max() <= 0.011
    assert np.count_nonzero(closes[1:] != closes[:-1]) == 2  # one island, no other interval
    assert ISLAND_DEG[1] - ISLAND_DEG[0] < 15.0  # shorter than the anchor spacing
    closed = solve_motion(rssr(*ISLAND_RSSR), fine[(fine > np.radians(160)) &
                                                    (fine < np.radians(185))], method="closed")
    on = _counts(closed) > 0
    assert np.abs(np.degrees(fine[(fine > np.radians(160)) & (fine < np.radians(185))][on][
        [0, -1]]) - ISLAND_DEG).max() <= 0.011


def test_the_closed_form_finds_the_island_whole() -> None:
    closed = solve_motion(rssr(*ISLAND_RSSR), THETA, method="closed")
    count = _counts(closed)
    assert np.flatnonzero(count).tolist() == list(ISLAND_SAMPLES)
    assert count[list(ISLAND_SAMPLES)].tolist() == [2, 2]
    for md in closed.modes:
        assert np.nanmax(md.closure_residual[md.assembles]) <= 1e-10


def test_the_graph_routes_every_mode_finds_the_island_whole() -> None:
    """The graph, drawn at 175° (the only way to draw it is on the island), turned once round
    backward from there: both modes at 175° and 170°, born and dead at the island's ends."""
    closed = solve_motion(rssr(*ISLAND_RSSR), THETA, method="closed")
    a, b = ISLAND_SAMPLES
    mech = mechanism_from_loop(closed, 0, b)
    X = -np.radians(np.arange(0.0, 360.0, 5.0))  # 175°, 170°, 165°, … , 180°
    motion = solve_mechanism(mech, X[:, None], every_mode=True)
    count = _counts(motion)
    assert np.flatnonzero(count).tolist() == [0, 1] and count[:2].tolist() == [2, 2]
    assert len(motion.modes) == 2
    folds = [float(e.split("= ")[1].split(" deg")[0]) for md in motion.modes
             for e in md.events if e.startswith(("dies at", "is born at"))]
    # both modes die at the island's start, 175° − 168.04° = 6.96° back from the drawing
    assert np.allclose(folds, -(np.degrees(THETA[b]) - ISLAND_DEG[0]), atol=0.011)
    # each closes
    for md in motion.modes:
        assert np.nanmax(md.closure_residual[md.assembles]) <= 1e-10


def test_the_graph_routes_every_mode_holds_a_re_entered_island_twice(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """Issue 27's re-entry: drawn at 170° and driven 5° … 365° from there (175° … 535°), the
    island is assembled at the first sample and again at 530° and 535°. Solved by the graph's
    closed forms (the RSS leg; the loop route, graph/loop_subchain.py, bypassed), every sample
    is held by as many modes as the point-to-circle distance test puts configurations there
    (2 strictly inside the island, 0 outside), the drawn mode stops at its first fold, and the
    drawn branches' second run is a mode of its own, born at the island's start one turn on,
    whose pose at 535° is the drawn mode's at 175° (the same branch, no switch)."""
    monkeypatch.setattr("screwkit.kinematics.graph.loop_subchain.loop_chain", lambda mech: None)
    closed = solve_motion(rssr(*ISLAND_RSSR), THETA, method="closed")
    a, _ = ISLAND_SAMPLES
    mech = mechanism_from_loop(closed, 0, a)  # drawn at 170°
    X = np.radians(np.arange(5.0, 366.0, 5.0))
    motion = solve_mechanism(mech, X[:, None], every_mode=True)
    assert motion.method == "graph (closed forms)"
    near, far = rssr_reach(ISLAND_RSSR, THETA[a] + X)
    d2 = ISLAND_RSSR[1]
    expected = np.where((near < d2) & (d2 < far), 2, 0)
    assert expected.tolist() == [2] + [0] * 70 + [2, 2]  # the island at 175°, 530°, 535°
    assert _counts(motion).tolist() == expected.tolist()
    drawn, other, again = motion.modes
    assert np.flatnonzero(drawn.assembles).tolist() == [0]
    assert np.flatnonzero(again.assembles).tolist() == [71, 72]
    assert again.index == 2 and "drawn branches again" in again.label
    born = [float(e.split("= ")[1].split(" deg")[0]) for e in again.events
            if e.startswith("is born at")]
    assert np.allclose(born, [ISLAND_DEG[0] + 360.0 - np.degrees(THETA[a])], atol=0.011)
    assert not [e for e in again.events if e.startswith("dies at")]
    # 535° is 175° one turn on: each branch's pose there is its pose at the first sample
    for md, first in ((again, drawn), (other, other)):
        assert np.abs(md.link_origin[72] - first.link_origin[0]).max() <= 1e-9
        assert np.abs(md.link_rotation[72] - first.link_rotation[0]).max() <= 1e-9
    assert np.abs(again.link_origin[72] - other.link_origin[72]).max() > 1e-3  # two branches
    for md in motion.modes:
        assert np.nanmax(md.closure_residual[md.assembles]) <= 1e-10
    assert motion.notes[-1].endswith("{0, 1, 2}")  # all meet at the island's folds


def test_the_loop_route_holds_a_re_entered_island_twice() -> None:
    """The same re-entry through the loop engine (the whole RSSR drawn as a graph is solved by
    its closed form, graph/loop_subchain.py): every sample is held by as many modes as the
    distance test puts configurations there, the drawn mode stops at its first fold, and the
    drawn loop mode's second run is a mode of its own whose pose at 535° is the drawn mode's
    at 175°."""
    closed = solve_motion(rssr(*ISLAND_RSSR), THETA, method="closed")
    a, _ = ISLAND_SAMPLES
    mech = mechanism_from_loop(closed, 0, a)
    X = np.radians(np.arange(5.0, 366.0, 5.0))
    motion = solve_mechanism(mech, X[:, None], every_mode=True)
    assert motion.method == "graph (loop, closed)"
    near, far = rssr_reach(ISLAND_RSSR, THETA[a] + X)
    d2 = ISLAND_RSSR[1]
    expected = np.where((near < d2) & (d2 < far), 2, 0)
    assert _counts(motion).tolist() == expected.tolist()
    drawn = motion.modes[0]
    again = [md for md in motion.modes if "drawn branches again" in md.label]
    assert len(again) == 1 and len(motion.modes) == 3
    assert np.flatnonzero(drawn.assembles).tolist() == [0]
    assert np.flatnonzero(again[0].assembles).tolist() == [71, 72]
    # the same configuration (joint centres, R axes; the rod between the balls may carry
    # another idle spin in a run of its own, so its frame is not compared)
    assert np.abs(again[0].joint_centres[72] - drawn.joint_centres[0]).max() <= 1e-9
    R = [0, 3]  # the R joints (a ball's reported axis turns with the rod's idle spin)
    assert np.abs(again[0].joint_axes[72, R] - drawn.joint_axes[0, R]).max() <= 1e-9
    for md in motion.modes:
        assert np.nanmax(md.closure_residual[md.assembles]) <= 1e-10


@pytest.mark.parametrize("route", ["closed forms", "loop"])
def test_every_mode_finds_an_island_inside_one_step(monkeypatch, route: str) -> None:  # type: ignore[no-untyped-def]
    """Drawn at 170° and driven 0°, 7°, 17°, … , 367° from there, the island comes back one
    turn on strictly inside the step from 357° to 367° (527° … 537°): no sample lies on it.
    The graph's closed forms (the RSS leg; the loop route bypassed) and the loop route (the
    RSSR's closed form, its two modes the leg's two branches) find it from the leg's
    discriminant (graph/step_folds.py): both branches as modes on no sample, each born and
    dying where the point-to-circle distance test (brentq on ``rssr_reach``) puts the island's
    ends, one circuit; the drawn mode and the other branch hold the first sample only."""
    from scipy.optimize import brentq

    if route == "closed forms":
        monkeypatch.setattr("screwkit.kinematics.graph.loop_subchain.loop_chain",
                            lambda mech: None)
    closed = solve_motion(rssr(*ISLAND_RSSR), THETA, method="closed")
    a, _ = ISLAND_SAMPLES
    mech = mechanism_from_loop(closed, 0, a)  # drawn at 170°
    X = np.radians(np.array([0.0, *np.arange(7.0, 368.0, 10.0)]))
    motion = solve_mechanism(mech, X[:, None], every_mode=True)
    assert motion.method == ("graph (closed forms)" if route == "closed forms"
                             else "graph (loop, closed)")
    d2 = ISLAND_RSSR[1]

    def inside(x: float) -> float:  # > 0 where the loop closes, x from the drawing (rad)
        near, far = rssr_reach(ISLAND_RSSR, np.array([THETA[a] + x]))
        return float(min(d2 - near[0], far[0] - d2))

    start = np.degrees(brentq(inside, X[-2], np.radians(362.0), xtol=1e-14))
    end = np.degrees(brentq(inside, np.radians(362.0), X[-1], xtol=1e-14))
    assert 357.0 < start < end < 367.0
    near, far = rssr_reach(ISLAND_RSSR, THETA[a] + X)
    assert not ((near < d2) & (d2 < far))[1:].any()  # no sample on it
    islands = [md for md in motion.modes if "island inside one sample step" in md.label]
    assert len(motion.modes) == 4 and len(islands) == 2
    for md in islands:
        assert not md.assembles.any()
        assert md.events[0].startswith(f"is born at input.theta = {start:.6g} deg")
        assert md.events[1].startswith(f"dies at input.theta = {end:.6g} deg")
    circuits = [n for n in motion.notes if n.startswith("circuits")]
    assert circuits[0].endswith("{0, 1}, {2, 3}")

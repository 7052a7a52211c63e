"""A gap inside one sample step on the homotopy route (issue 27, "a motion never switches mode
silently"; kinematics/modes/along.py): the six-bar of tests/graphs/test_step_folds.py (a
four-bar O–A–B–D whose crank cannot pass 177.04° … 182.96°, with an RRR dyad E–G–F from the
crank to the ground) solved by the homotopy at anchors with tracking between, called directly on
the graph. Checked against the closed-form sub-chain route's modes on the same samples (which
test_step_folds.py checks against the distance law) and the four-bar's distance law
|A − D| = b + c itself (crank angle by arccos): four modes per sample and no two at one
configuration (a backward track from a born mode used to cross the gap onto a mode that dies
there, six modes on two samples), the four deaths at the first fold and four births at the
second."""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
import pytest
from tests.graphs.test_step_folds import GAP, GAP_DRAWN, GAP_INPUTS, _crank_at, _sixbar

from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_layout
from screwkit.kinematics.modes.along import MATCH_TOLERANCE, ModesAlong, modes_along, pose_vectors
from screwkit.kinematics.modes.along_folds import Chain, fold_meetings, partner_folds, unshare

#: fold inputs to this (deg): bisection to 2⁻²⁶ of the 10° step is 1.5e-7°, and a branch
#: is reached by continuation to within ~FINE_HALF² of a fold, so 1e-5° is a wide margin that
#: still tells a located fold from a sample (5°–5.9° away)
FOLD_DEG = 1e-5


def _deg(x: np.ndarray) -> str:
    return repr(float(np.degrees(x[0])))


@dataclass(frozen=True)
class Gap:
    """The homotopy route's modes, their poses per sample, and the closed-form route's poses
    and where each of its modes assembles."""

    along: ModesAlong
    mine: list[np.ndarray]
    closed: list[np.ndarray]
    held: np.ndarray


def _solve(reverse: bool) -> Gap:
    """The homotopy route over GAP_INPUTS (``reverse``: in the other order), and the
    closed-form route's modes over the same samples (solved in increasing order: its drawn
    mode is followed from the drawing, which the gap would stop from reaching 345°)."""
    mech = _sixbar(*GAP, GAP_DRAWN)
    lay = graph_layout(mech)
    order = slice(None, None, -1 if reverse else 1)
    along = modes_along(mech, lay, GAP_INPUTS[order, None], _deg)
    closed = solve_mechanism(mech, GAP_INPUTS[:, None], every_mode=True)
    assert closed.method == "graph (closed forms)"
    return Gap(along, [pose_vectors(mech, lay, c) for c in along.configurations],
               [pose_vectors(mech, lay, md.conf)[order] for md in closed.modes],
               np.array([md.assembles[order] for md in closed.modes]))


@pytest.fixture(scope="module")
def gap() -> Gap:
    return _solve(False)


@pytest.fixture(scope="module")
def gap_reversed() -> Gap:
    """The same inputs in the other order: the forward tracks now reach the gap from above."""
    return _solve(True)


@pytest.fixture(params=["forward", "reversed"])
def either(request: pytest.FixtureRequest) -> tuple[Gap, bool]:
    return request.getfixturevalue("gap" if request.param == "forward" else "gap_reversed"), \
        request.param == "reversed"


def test_each_sample_has_the_closed_form_modes_once(either: tuple[Gap, bool]) -> None:
    gap = either[0]
    along, closed, held, mine = gap.along, gap.closed, gap.held, gap.mine
    masks = np.array(along.masks)
    assert masks.sum(axis=0).tolist() == held.sum(axis=0).tolist() == [4] * len(GAP_INPUTS)
    for n in range(len(GAP_INPUTS)):
        here = np.array([p[n] for p, m in zip(mine, masks, strict=True) if m[n]])
        theirs = np.array([p[n] for p, h in zip(closed, held, strict=True) if h[n]])
        gaps = np.abs(here[:, None] - theirs[None]).max(axis=2)
        # one to one: each along mode is one closed-form mode, none twice
        assert np.all(gaps.min(axis=1) <= 1e-8), n
        assert sorted(np.argmin(gaps, axis=1).tolist()) == list(range(len(theirs))), n


def test_the_folds_are_the_distance_law_s_and_every_event_is_true(
        either: tuple[Gap, bool]) -> None:
    along, reversed_ = either[0].along, either[1]
    a, b, c, d = GAP
    first = _crank_at(a, d, b + c) - GAP_DRAWN
    second = 360.0 - _crank_at(a, d, b + c) - GAP_DRAWN
    if reversed_:  # met from above: the modes die at the upper fold, are born at the lower
        first, second = second, first
    dies, born = [], []
    for mask, events in zip(along.masks, along.events, strict=True):
        assert not any("path jump" in e for e in events), events
        assert not any(e.startswith(("cut", "starts at")) for e in events), events
        for e in events:
            m = re.match(r"(is born|dies) at ([-\d.e]+):", e)
            if m:
                (born if m[1] == "is born" else dies).append(float(m[2]))
        # a mode that does not hold at the first (last) sample says where it is born (dies)
        assert mask[0] or any(e.startswith("is born") for e in events)
        assert mask[-1] or any(e.startswith("dies") for e in events)
    assert len(dies) == len(born) == 4
    assert np.abs(np.array(dies) - first).max() <= FOLD_DEG
    assert np.abs(np.array(born) - second).max() <= FOLD_DEG
    # the two four-bar branches meet at each fold, dyad branch by dyad branch
    assert len(along.meets) == 4


def _chains(along: ModesAlong) -> list[Chain]:
    return [Chain(c.scalars.copy(), c.spherical.copy(), m.copy(), list(e[:-1]), folds=list(f))
            for c, m, e, f in zip(along.configurations, along.masks, along.events, along.folds,
                                  strict=True)]


@pytest.mark.parametrize("leftward", [True, False])
def test_a_track_spliced_across_the_gap_is_cut_at_its_fold(gap: Gap, leftward: bool) -> None:
    """The shared-configuration check alone (along_folds.py ``unshare``), on the modes above
    with one made to jump across the gap as a tracker would: a mode born after the gap that
    runs on through it onto a dying mode's configurations (leftward: the backward track of
    the bug), or a dying mode that runs on onto a born mode's (rightward). The jumped one is
    cut where the two are one mode, at the distance law's fold, and the modes are the right
    ones again."""
    mech = _sixbar(*GAP, GAP_DRAWN)
    lay = graph_layout(mech)
    X = GAP_INPUTS[:, None]
    k = int(np.flatnonzero(GAP_INPUTS < np.radians(90.0))[-1])  # the gap is in k → k+1
    chains = _chains(gap.along)
    right = [c for c, ch in enumerate(chains) if ch.mask[k + 1]]
    left = [c for c, ch in enumerate(chains) if ch.mask[k]]
    # the dying mode nearest the born one across the gap (where a jump would land), or back
    src, dst = (right[0], left) if leftward else (left[0], right)
    edge, other = (k + 1, k) if leftward else (k, k + 1)
    near = min(dst, key=lambda c: float(np.abs(gap.mine[c][other] - gap.mine[src][edge]).max()))
    jumped = chains[src]
    rows = np.arange(0, k + 1) if leftward else np.arange(k + 1, X.shape[0])
    jumped.scalars[rows] = chains[near].scalars[rows]
    jumped.spherical[rows] = chains[near].spherical[rows]
    jumped.mask[rows] = True
    jumped.events[:] = [e for e in jumped.events if not e.startswith(("is born", "dies"))]
    jumped.folds[:] = []
    masks = np.array(gap.along.masks)
    assert np.array([c.mask for c in chains]).sum(axis=0).max() == 5  # counted twice
    assert unshare(mech, lay, X, chains, MATCH_TOLERANCE, _deg) == 1
    assert np.array_equal(np.array([c.mask for c in chains]), masks)
    a, b, c, d = GAP
    fold = 360.0 - _crank_at(a, d, b + c) - GAP_DRAWN if leftward else \
        _crank_at(a, d, b + c) - GAP_DRAWN
    m = re.match(r"(is born|dies) at ([-\d.e]+): it (starts|stops) assembling there",
                 jumped.events[-1])
    assert m and m[1] == ("is born" if leftward else "dies"), jumped.events
    assert abs(float(m[2]) - fold) <= FOLD_DEG
    assert f"it landed on another mode's configuration at {_deg(X[other])}" in jumped.events[-1]
    assert len(jumped.folds) == 1


def test_a_track_that_takes_a_lone_mode_across_the_gap_is_split_at_its_fold(gap: Gap) -> None:
    """A dying mode's track run on across the gap onto a born mode that no other track holds
    (no two modes share a configuration, so ``unshare`` sees nothing): the born mode's partner
    then meets no mode at its fold, and ``partner_folds`` splits the track there, at the
    distance law's two folds, giving the right modes again."""
    mech = _sixbar(*GAP, GAP_DRAWN)
    lay = graph_layout(mech)
    X = GAP_INPUTS[:, None]
    k = int(np.flatnonzero(GAP_INPUTS < np.radians(90.0))[-1])
    chains = _chains(gap.along)
    right = [c for c, ch in enumerate(chains) if ch.mask[k + 1]]
    left = [c for c, ch in enumerate(chains) if ch.mask[k]]
    src = left[0]
    near = min(right, key=lambda c: float(np.abs(gap.mine[c][k + 1] - gap.mine[src][k]).max()))
    jumped, taken = chains[src], chains[near]
    rows = np.arange(k + 1, X.shape[0])
    jumped.scalars[rows], jumped.spherical[rows] = taken.scalars[rows], taken.spherical[rows]
    jumped.mask[rows] = True
    jumped.events[:], jumped.folds[:] = [], []
    del chains[near]
    assert unshare(mech, lay, X, chains, MATCH_TOLERANCE, _deg) == 0
    assert partner_folds(mech, lay, X, chains, _deg) == 1
    masks = sorted(tuple(c.mask.tolist()) for c in chains)
    assert masks == sorted(tuple(m.tolist()) for m in gap.along.masks)
    a, b, c, d = GAP
    first = _crank_at(a, d, b + c) - GAP_DRAWN
    second = 360.0 - _crank_at(a, d, b + c) - GAP_DRAWN
    dies = re.match(r"dies at ([-\d.e]+): it stops assembling there", jumped.events[-1])
    born = re.match(r"is born at ([-\d.e]+): it starts assembling there", chains[-1].events[0])
    assert dies and born, (jumped.events, chains[-1].events)
    assert abs(float(dies[1]) - first) <= FOLD_DEG and abs(float(born[1]) - second) <= FOLD_DEG
    # every fold is met by another mode's again
    assert len(fold_meetings(mech, lay, [c.folds for c in chains])) == 4

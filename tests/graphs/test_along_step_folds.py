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

from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_layout
from screwkit.kinematics.modes.along import ModesAlong, modes_along, pose_vectors
from tests.graphs.test_step_folds import GAP, GAP_DRAWN, GAP_INPUTS, _crank_at, _sixbar

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


@pytest.fixture(scope="module")
def gap() -> Gap:
    mech = _sixbar(*GAP, GAP_DRAWN)
    lay = graph_layout(mech)
    X = GAP_INPUTS[:, None]
    along = modes_along(mech, lay, X, _deg)
    closed = solve_mechanism(mech, X, every_mode=True)
    assert closed.method == "graph (closed forms)"
    return Gap(along, [pose_vectors(mech, lay, c) for c in along.configurations],
               [pose_vectors(mech, lay, md.conf) for md in closed.modes],
               np.array([md.assembles for md in closed.modes]))


def test_each_sample_has_the_closed_form_modes_once(gap: Gap) -> None:
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


def test_the_folds_are_the_distance_law_s_and_every_event_is_true(gap: Gap) -> None:
    along = gap.along
    a, b, c, d = GAP
    first = _crank_at(a, d, b + c) - GAP_DRAWN
    second = 360.0 - _crank_at(a, d, b + c) - GAP_DRAWN
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

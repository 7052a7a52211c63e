"""The drawn mode of a single loop drawn as a graph, from the closed form's branches alone
(issue 26 speed: graph/loop_motion.py ``drawn_branch`` builds only the drawn mode's positions,
tracker/mode_frames.py ``mode_poses``): the same numbers as solving every loop mode first,
checked field by field against that route and against ``solve_motion``'s own modes."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest

import screwkit as sk
from screwkit.kinematics.closed_forms.closed_form_motion import ALL
from screwkit.kinematics.graph import loop_motion, solve_mechanism
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.kinematics.registry import family_of
from screwkit.kinematics.tracker.loop import layout
from screwkit.kinematics.tracker.mode_frames import mode_poses

#: an RSRC with four assembly modes over a turn of the crank, two of them folding
#: (tests/graphs/test_loop_subchain.py)
RSRC4 = dict(d1=0.681, d2=2.147, d3=0.633, a=1.955, b=0.248, e=0.174, delta0=1.177,
             lambda0=0.273)
LOOPS = {
    "4R": lambda: sk.fourbar(a=4.0, d1=1.0, d2=3.5, d3=3.0),
    "RSRC": lambda: sk.rsrc(**RSRC4),
    "RSSR": lambda: sk.rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.3),
    "RCCC": lambda: sk.rccc((1.0, 1.5, 1.2, 1.4), (0.3, 0.5, -0.4, 0.6)),
    # a longer crank: the RSSR's two modes fold over a turn
    "RSSR folding": lambda: sk.rssr(2.0, 3.0, 2.0, 2.5, 1.0, 0.3),
}
X = np.radians(np.arange(0.0, 360.0, 4.0))


def _arrays(obj: Any, at: str, out: dict[str, Any]) -> dict[str, Any]:
    """Every array, string and number of a motion, by its path (the mechanism left out)."""
    if isinstance(obj, np.ndarray | str | int | float | bool) or obj is None:
        out[at] = obj
    elif isinstance(obj, dict) or hasattr(obj, "keys"):
        for k in list(obj.keys()):
            _arrays(obj[k], f"{at}[{k}]", out)
    elif isinstance(obj, tuple | list):
        for i, v in enumerate(obj):
            _arrays(v, f"{at}[{i}]", out)
    elif dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            if f.name != "mechanism":
                _arrays(getattr(obj, f.name), f"{at}.{f.name}", out)
    return out


def _same(a: Any, b: Any) -> list[str]:
    """The paths where two motions differ (arrays bit for bit, NaN equal to NaN)."""
    x, y = _arrays(a, "", {}), _arrays(b, "", {})
    bad = sorted(set(x) ^ set(y))
    for k in set(x) & set(y):
        u, v = x[k], y[k]
        if isinstance(u, np.ndarray):
            if not (isinstance(v, np.ndarray) and u.shape == v.shape and np.array_equal(
                    u, v, equal_nan=u.dtype.kind in "fc")):
                bad.append(k)
        elif u != v:
            bad.append(k)
    return bad


@pytest.mark.parametrize("name", list(LOOPS))
def test_a_closed_forms_branches_are_its_modes(name: str) -> None:
    """Per mode: the samples where it assembles, its configurations (on any slice of the
    sweep) and its positions from ``mode_poses`` are those of the closed form's Motion."""
    lk = LOOPS[name]()
    Xc = X[:, None]
    ones, zeros = np.ones_like(Xc), np.zeros_like(Xc)
    motion = sk.solve_motion(lk, X)
    branches = family_of(lk).closed_branches_for(lk)
    assert branches is not None
    br = branches(lk, Xc, ones, zeros)
    assert len(br.assembles) == len(motion.modes) >= 2
    lay = layout(lk)
    for m, md in enumerate(motion.modes):
        ok = br.assembles[m]
        assert np.array_equal(ok, md.assembles), m
        conf = br.configuration(m, ALL)
        if "RSSR" not in name:  # no rod (whose idle spin the mode holds): the configuration kept
            assert np.array_equal(conf.scalars[ok], md.conf.scalars[ok]), m
        part = slice(3, 7)
        np.testing.assert_array_equal(br.configuration(m, part).scalars, conf.scalars[part])
        poses = mode_poses(lk, lay, conf, ok, Xc)
        for field in ("link_rotation", "link_origin", "joint_centres", "joint_axes"):
            assert np.array_equal(getattr(poses, field), getattr(md, field), equal_nan=True), \
                (m, field)


def _graphs(name: str) -> list[tuple[Any, np.ndarray]]:
    """The loop drawn in each of its modes (at the mode's first assembling sample), with a
    sweep from there over more than a turn (so that folding modes stop and are reported)."""
    lk = LOOPS[name]()
    motion = sk.solve_motion(lk, X)
    out = []
    for m, md in enumerate(motion.modes):
        k0 = int(np.argmax(md.assembles))
        out.append((mechanism_from_loop(motion, m, k0), np.radians(np.arange(0.0, 400.0, 4.0))))
    return out


@pytest.mark.parametrize("name", list(LOOPS))
def test_the_drawn_mode_from_its_branch_is_the_every_mode_routes(
        name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The drawn-mode solve from the drawn branch alone gives every field, event and note of
    the route that solves every loop mode first (``drawn_branch`` off), bit for bit; and it is
    the route taken."""
    taken = []
    real = loop_motion.drawn_branch

    def spy(*args: Any) -> Any:
        found = real(*args)
        taken.append(found is not None)
        return found

    folds = 0
    for mech, x in _graphs(name):
        monkeypatch.setattr(loop_motion, "drawn_branch", spy)
        fast = solve_mechanism(mech, x, rates=1.3, accelerations=0.4)
        monkeypatch.setattr(loop_motion, "drawn_branch", lambda *args: None)
        slow = solve_mechanism(mech, x, rates=1.3, accelerations=0.4)
        assert fast.method == "graph (loop, closed)"
        assert _same(fast, slow) == []
        folds += not fast.modes[0].assembles.all()
    assert taken and all(taken)
    if name in ("RSRC", "RCCC", "RSSR folding"):  # drawn modes that fold: their events agree
        assert folds


@pytest.mark.parametrize("name", ["RSSR folding", "RCCC"])
def test_fold_counts_from_branches_are_the_closed_forms(name: str) -> None:
    """The count of real solutions the fold bisection uses, from the branches, is the count
    of the closed form's assembling modes at the same inputs, near folds too."""
    lk = LOOPS[name]()
    motion = sk.solve_motion(lk, X)
    births = [k for md in motion.modes for k in np.nonzero(np.diff(md.assembles))[0]]
    assert births
    x = np.concatenate([np.linspace(X[k], X[k + 1], 41) for k in births])[:, None]
    zeros = np.zeros_like(x)
    branches = family_of(lk).closed_branches_for(lk)
    closed = family_of(lk).closed_form_for(lk)
    assert branches is not None and closed is not None
    counts = np.sum(branches(lk, x, zeros, zeros).assembles, axis=0)
    expected = np.sum([md.assembles for md in closed(lk, x, zeros, zeros).modes], axis=0)
    np.testing.assert_array_equal(counts, expected)
    assert len(set(counts.tolist())) > 1

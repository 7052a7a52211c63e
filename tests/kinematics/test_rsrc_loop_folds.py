"""The single-loop engine's folds of the RSRC (``sk.solve_motion`` on the family's linkage, the
closed form's ``rsrc_motion``; issue 27: "births and deaths at folds are reported", "a motion
never switches mode silently"): every branch's event lies at its own root's fold, the branch it
meets there is named, and a branch matched across a step onto a root born inside that step says
so. The references are written independently of screwkit's closed form (tests/quartic_helpers.py:
the discriminant of the closure's quartic from np.roots, its zeros by brentq, each root tracked
on a 1e-4 rad grid; Bagci 1969 eqs. 3.58/3.59)."""

from __future__ import annotations

import re

import numpy as np

import screwkit as sk
from quartic_helpers import XQ, P, Q, X, track, zeros
from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_motion


def _zeros_by_step(x: np.ndarray, dims: dict[str, float]) -> dict[int, list[float]]:
    """The discriminant's zeros over the sweep ``x``, by the step k → k+1 they lie in."""
    out: dict[int, list[float]] = {}
    for z in zeros(x[0], x[-1], dims):
        out.setdefault(int(np.searchsorted(x, z) - 1), []).append(z)
    return out


def _at_deg(text: str) -> float:
    return float(re.search(r"input.theta = ([-\d.]+) deg", text)[1])  # type: ignore[index]


def test_two_pairs_born_inside_one_step_each_at_its_own_fold() -> None:
    """In the last 5° step two pairs are born 3.7° apart: modes 0, 1 at the first zero of the
    discriminant, 2, 3 at the second (each root tracked down from the sample after); every
    other event of the turn lies at a zero in its step, where its own root folds."""
    motion = sk.solve_motion(sk.rsrc(**P), X)
    assert motion.method == "closed" and len(motion.modes) == 4
    mot = rsrc_motion(RSRCDimensions(**P), X)
    assert np.all(mot.assembles.any(axis=0))  # modes are the columns
    k = X.size - 2
    folds = _zeros_by_step(X, P)
    assert len(folds[k]) == 2 and folds[k][1] - folds[k][0] > np.radians(3.0)
    last = {e.branch: e for e in mot.events if e.sample == k + 1}
    assert sorted(last) == [0, 1, 2, 3] and all(e.kind == "starts" for e in last.values())
    want = {0: folds[k][0], 1: folds[k][0], 2: folds[k][1], 3: folds[k][1]}
    for m, e in last.items():
        own = track(float(mot.phi0[k + 1, m]), X[k + 1], X[k], folds[k])
        assert own == want[m], m
        assert abs(e.theta0 - own) < 1e-9, m  # rad
    assert {m: e.partner for m, e in last.items()} == {0: 1, 1: 0, 2: 3, 3: 2}
    for e in mot.events:  # every event: at a zero in its step, its own root's, partner named
        z = folds[e.sample - 1]
        start = e.sample - 1 if e.kind == "stops" else e.sample
        end = X[e.sample] if e.kind == "stops" else X[e.sample - 1]
        assert abs(e.theta0 - track(float(mot.phi0[start, e.branch]), X[start], end, z)) < 1e-9
        assert e.partner is not None and any(
            f.partner == e.branch and f.sample == e.sample and f.theta0 == e.theta0
            for f in mot.events)
    # the modes' texts: each born at its own fold, the two that meet named
    for m, md in enumerate(motion.modes):
        text = md.events[-1]
        assert text.startswith("starts assembling"), m
        assert abs(_at_deg(text) - np.degrees(want[m])) < 1e-3, m  # printed to 6 digits
        pair = (0, 1) if m < 2 else (2, 3)
        assert f"modes {pair[0]} and {pair[1]} meet" in text, m


def test_no_mode_is_matched_onto_a_root_born_inside_a_step_silently() -> None:
    """On a 10° sweep whose count of roots is the same at both ends of the steps 14° → 24°
    (a root born and dying inside it) and 334° → 344° (two roots vanish and come back): every
    mode that assembles at both samples and whose root dies inside the step (tracked forward)
    stops there, and where its root at the sample after is born inside the step (tracked
    back) starts there, each to 1e-9 rad, its text saying its samples change root; a mode
    whose root crosses the step has no event there."""
    motion = sk.solve_motion(sk.rsrc(**Q), XQ)
    mot = rsrc_motion(RSRCDimensions(**Q), XQ)
    assert np.all(mot.assembles.any(axis=0)) and len(motion.modes) == 4
    count = mot.assembles.sum(axis=1)
    hidden = {k: z for k, z in _zeros_by_step(XQ, Q).items() if len(z) == 2}
    assert sorted(hidden) == [1, 33]
    switched = 0
    for k, z in hidden.items():
        assert count[k] == count[k + 1]
        for m in np.flatnonzero(mot.assembles[k] & mot.assembles[k + 1]):
            mine = {e.kind: e for e in mot.events if e.branch == m and e.sample == k + 1}
            dies = track(float(mot.phi0[k, m]), XQ[k], XQ[k + 1], z, Q)
            born = track(float(mot.phi0[k + 1, m]), XQ[k + 1], XQ[k], z, Q)
            assert (dies is None) == (born is None), (k, m)  # same root at both samples
            if dies is None:
                assert not mine, (k, m)
                continue
            assert born is not None
            switched += 1
            assert sorted(mine) == ["starts", "stops"], (k, m)
            assert abs(mine["stops"].theta0 - dies) < 1e-9, (k, m)
            assert abs(mine["starts"].theta0 - born) < 1e-9, (k, m)
            texts = {t.split(" ")[0]: _at_deg(t) for t in motion.modes[m].events
                     if "samples after this step are on" in t
                     and np.degrees(XQ[k]) < _at_deg(t) < np.degrees(XQ[k + 1])}
            assert texts.keys() == {"stops", "starts"}, (k, m)  # printed to 6 digits:
            assert abs(texts["stops"] - np.degrees(dies)) < 1e-3, (k, m)
            assert abs(texts["starts"] - np.degrees(born)) < 1e-3, (k, m)
    assert switched == 3  # the drawn mode at 14° → 24°, two modes across the gap

"""Folds of a four-mode loop (the RSRC quartic) attributed to the two modes that meet there
(graph/quartic_folds.py; issue 27: "births and deaths at folds are reported"): two different
pairs of modes born inside one sample step are each placed at their own fold, checked against
the quartic's discriminant located by a scalar root finder and against a fine-grid tracking of
each mode's root, both written here from Bagci 1969 eqs. 3.58/3.59."""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

import screwkit as sk
from loop_stage_helpers import knee
from quartic_helpers import XQ, P, Q, X, real_roots, track, zeros
from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions
from screwkit.kinematics.closed_forms.rsrc.positions import quartic_discriminant, rsrc_positions
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.kinematics.graph.loop_subchain import loop_chain
from screwkit.kinematics.graph.motion import MechanismMode
from screwkit.kinematics.graph.quartic_folds import quartic_folds
from screwkit.kinematics.graph.subchains import decompose
from screwkit.model.mechanism import Body, Mechanism, MechanismJoint


def _folds_in_last_step() -> list[float]:
    return zeros(X[-2], X[-1])


def _births(events: list[str], after: float, meet: str) -> dict[tuple[int, int], float]:
    """The births after ``after`` (deg) in ``events``: (the two modes that meet) → input."""
    out = {}
    for ev in events:
        hit = re.search(r"is born at .*input.theta = ([\d.]+) deg: .*folds \(" + meet +
                        r" (\d) and (\d) meet\)", ev)
        if hit and float(hit[1]) > after:
            out[(int(hit[2]), int(hit[3]))] = float(hit[1])
    return out


def test_two_pairs_born_inside_one_step_are_each_placed_at_their_own_fold() -> None:
    lk = sk.rsrc(**P)
    motion = sk.solve_motion(lk, X)
    k = X.size - 2  # the last step, 413.5° → 418.5° (53.5° → 58.5° a turn on)
    assert all(not md.assembles[k] and md.assembles[k + 1] for md in motion.modes)
    # the independent folds: the discriminant's zeros inside the step (fine grid, then brentq)
    folds = _folds_in_last_step()
    assert len(folds) == 2 and folds[1] - folds[0] > np.radians(3.0)
    # which fold each mode's root is born at, by tracking it down from the sample after
    own = {m: track(float(md.variables["phi0"][k + 1]), X[k + 1], X[k], folds)
           for m, md in enumerate(motion.modes)}
    assert own == {0: folds[0], 1: folds[0], 2: folds[1], 3: folds[1]}
    mech = mechanism_from_loop(motion, 0, 0)
    chain = loop_chain(mech)
    assert chain is not None
    found = {f.mode: f for f in quartic_folds(chain, chain.loop_inputs(X[:, None] - X[0]))
             if f.k == k}
    assert sorted(found) == [0, 1, 2, 3]
    for m, f in found.items():
        assert not f.dies
        assert abs(X[k] + f.t * (X[k + 1] - X[k]) - own[m]) < 1e-9, m  # rad
    assert {m: found[m].partner for m in found} == {0: 1, 1: 0, 2: 3, 3: 2}
    # the graph's modes report it: each born at its own fold, the partner named
    g = solve_mechanism(mech, X - X[0], every_mode=True)
    births = _births([e for md in g.modes for e in md.events], np.degrees(X[k] - X[0]),
                     "loop modes")
    assert births.keys() == {(0, 1), (2, 3)}
    assert abs(births[(0, 1)] - np.degrees(folds[0] - X[0])) < 1e-3  # printed to 6 digits
    assert abs(births[(2, 3)] - np.degrees(folds[1] - X[0])) < 1e-3


def test_a_loop_stage_places_each_pair_at_its_own_fold() -> None:
    """The same RSRC as a loop stage (graph/loop_stage.py), hung on a thigh that a hip joint
    turns (held still here): its modes are born at the same two folds, each pair at its own."""
    motion = sk.solve_motion(sk.rsrc(**P), X)
    loop = mechanism_from_loop(motion, 0, 0)
    on_thigh = tuple(replace(j, bodies=tuple("thigh" if b == "ground" else b for b in j.bodies))
                     for j in loop.joints)
    hip = MechanismJoint("hip", "R", ("ground", "thigh"), np.array([0.5, -2.0, 1.0]),
                         np.array([0.2, 0.3, 1.0]))
    mech = Mechanism("knee", (Body("thigh"), *loop.bodies), (hip, *on_thigh),
                     ("hip.theta", f"{loop.joints[0].name}.theta"))
    assert decompose(mech).loops[0].kind == "RSRC"
    g = solve_mechanism(mech, np.stack([np.zeros(X.size), X - X[0]], axis=1), every_mode=True)
    assert g.method == "graph (closed forms)"
    folds = _folds_in_last_step()
    births = _births([e for md in g.modes for e in md.events], np.degrees(X[-2] - X[0]),
                     "its modes")
    assert births.keys() == {(0, 1), (2, 3)}
    assert abs(births[(0, 1)] - np.degrees(folds[0] - X[0])) < 1e-3
    assert abs(births[(2, 3)] - np.degrees(folds[1] - X[0])) < 1e-3


def _loop_mode(label: str) -> int:
    hit = re.match(r"loop mode (\d)", label)
    return 0 if label == "drawn" else int(hit[1]) if hit else -1


def _at(event: str) -> float:
    return float(event.split(" deg")[0].split("= ")[-1])


def test_two_folds_of_a_four_mode_loop_inside_one_step_cut_its_modes() -> None:
    """The gap: the two loop modes whose roots vanish between the samples (by a fine-grid
    tracking) each die at the first zero of the discriminant and come back as modes of their
    own at the second; the island: the root on no sample is a mode born and dying at the two
    zeros, and the drawn mode, which rsrc_motion's samples match across the step to a root
    born inside it, dies at its own fold and its run after is a mode born at the other."""
    lk = sk.rsrc(**Q)
    motion = sk.solve_motion(lk, XQ)
    mech = mechanism_from_loop(motion, 0, 0)
    g = solve_mechanism(mech, XQ - XQ[0], every_mode=True)
    deg = np.degrees(XQ - XQ[0])
    for k in (1, 33):  # 14° → 24° and 334° → 344°
        z = zeros(XQ[k], XQ[k + 1], Q)
        assert len(z) == 2, k
        zg = np.degrees(np.array(z) - XQ[0])
        counts = [real_roots(t, Q).size for t in (XQ[k], 0.5 * (z[0] + z[1]), XQ[k + 1])]
        inside = [e for md in g.modes for e in md.events if "two folds between the samples at "
                  f"input.theta = {deg[k]:g} deg" in e]
        assert inside and all(min(abs(_at(e) - zg)) < 1e-3 for e in inside), k
        # every mode at sample k whose root dies inside the step, and every one at k+1 whose
        # root is born inside it, is reported so at the discriminant's zero it meets
        for m, md in enumerate(motion.modes):
            for n, end, word in ((k, XQ[k + 1], "dies"), (k + 1, XQ[k], "is born")):
                if not md.assembles[n]:
                    continue
                f = track(float(md.variables["phi0"][n]), XQ[n], end, z, Q)
                mine = [_at(e) for gm in g.modes if _loop_mode(gm.label) == m and
                        gm.assembles[n] for e in gm.events if e.startswith(word) and e in inside]
                if f is None:
                    assert not mine, (k, m, word)
                else:
                    assert len(mine) == 1 and abs(mine[0] - np.degrees(f - XQ[0])) < 1e-3, \
                        (k, m, word)
        islands = [md for md in g.modes if "an island inside one sample step" in md.label
                   and any(e in inside for e in md.events)]
        if counts[1] > counts[0]:  # 14° → 24°: one root on no sample, born and dying there
            assert counts == [2, 4, 2] and len(islands) == 1
            assert not islands[0].assembles.any()
            assert [_at(e) for e in islands[0].events] == pytest.approx(list(zg), abs=1e-3)
        else:  # 334° → 344°: a gap of two modes, no island
            assert counts == [2, 0, 2] and not islands
    drawn = g.modes[0]
    assert drawn.assembles.sum() == 2 and "the first of two folds" not in drawn.events[1]


def test_the_discriminant_s_sign_is_the_count_and_its_zeros_are_the_folds() -> None:
    """``quartic_discriminant`` (its invariants' form) against the real roots' count on a
    0.1° grid (positive: four or none, negative: two) and against the zeros of the discriminant
    built here from the roots of the closure's quartic (np.roots), by brentq, to 1e-10 rad."""
    for dims in (P, Q):
        d = RSRCDimensions(**dims)
        th = np.radians(np.arange(0.0, 360.0, 0.1))
        D = quartic_discriminant(d, th)
        n = rsrc_positions(d, th).n_assemblies
        assert np.all(np.where(D > 0, n % 4 == 0, n == 2))
        change = np.flatnonzero(np.sign(D[:-1]) != np.sign(D[1:]))
        assert change.size >= 4
        for i in change:
            mine = brentq(lambda t, d=d: float(quartic_discriminant(d, t)[0]), th[i], th[i + 1],
                          xtol=1e-15)
            ref = zeros(th[i], th[i + 1], dims)
            assert len(ref) == 1 and abs(mine - ref[0]) < 1e-10


def _theta(event: str) -> float:
    """The input angle (deg) an event is at."""
    hit = re.search(r" at .*?input\.theta = (-?[\d.]+) deg", event)
    assert hit, event
    return float(hit[1])


def _inside(modes: Iterable[MechanismMode], lo: float, hi: float) -> list[tuple[str, float]]:
    """Every birth and death strictly between ``lo`` and ``hi`` (deg) as (word, input)."""
    return sorted((e.split(" at ")[0], _theta(e)) for md in modes for e in md.events
                  if e.startswith(("dies", "is born")) and lo < _theta(e) < hi)


def test_a_loop_stage_cuts_its_modes_at_two_folds_inside_one_step() -> None:
    """The four-mode RSRC of the test above as a loop stage on a thigh (graph/loop_stage.py):
    the gap (334° → 344°) cuts the loop modes whose roots vanish, the island (14° → 24°) is a
    mode on no sample, and the drawn mode stops at its own fold inside the first step. Checked
    against the zeros of the discriminant (brentq), against the single loop's answer
    (graph/quartic_steps.py) and against a fine sweep from the drawing to each step's end
    (0.05°: no two folds inside one step there), to 1e-3° (events printed to 6 digits)."""
    motion = sk.solve_motion(sk.rsrc(**Q), XQ)
    loop = mechanism_from_loop(motion, 0, 0)
    mech = knee(loop)
    g = solve_mechanism(mech, np.stack([np.zeros(XQ.size), XQ - XQ[0]], axis=1),
                        every_mode=True)
    single = solve_mechanism(loop, XQ - XQ[0], every_mode=True)
    assert g.method == "graph (closed forms)"
    for k in (1, 33):
        zg = np.degrees(np.array(zeros(XQ[k], XQ[k + 1], Q)) - XQ[0])
        lo, hi = np.degrees(XQ[k] - XQ[0]), np.degrees(XQ[k + 1] - XQ[0])
        mine = _inside(g.modes, lo, hi)
        assert mine and all(min(abs(t - zg)) < 1e-3 for _, t in mine), k
        ref = _inside(single.modes, lo, hi)
        assert [w for w, _ in mine] == [w for w, _ in ref], k
        assert [t for _, t in mine] == pytest.approx([t for _, t in ref], abs=1e-3), k
        fine = np.radians(np.arange(0.0, hi + 1e-9, 0.05))
        gf = solve_mechanism(mech, np.stack([np.zeros(fine.size), fine], axis=1),
                             every_mode=True)
        # the fine sweep's births and deaths are at the same places, its modes that pass the
        # whole step are as many as those that assemble at both samples, and its modes inside
        # the step alone are the islands
        ends = sorted({t for _, t in _inside(gf.modes, lo, hi)})
        assert len(ends) == 2 and ends == pytest.approx(sorted({t for _, t in mine}), abs=1e-3)
        i, j = np.searchsorted(fine, np.radians([lo, hi]) - 1e-9)
        assert [md.assembles[i:j + 1].all() for md in gf.modes].count(True) == \
            [md.assembles[[k, k + 1]].all() for md in g.modes].count(True), k
        alone = [md for md in gf.modes if md.assembles.any()
                 and np.flatnonzero(md.assembles)[0] > i and np.flatnonzero(md.assembles)[-1] < j]
        islands = [md for md in g.modes if "an island inside one sample step" in md.label
                   and lo < _theta(md.events[0]) < hi]
        if k == 1:  # one root on no sample, born and dying at the two zeros
            assert len(islands) == len(alone) == 1 and not islands[0].assembles.any()
            assert [_theta(e) for e in islands[0].events] == pytest.approx(list(zg), abs=1e-3)
        else:
            assert not islands and not alone
    # the drawn mode stops at its own fold inside the first step, as the single loop's
    assert g.modes[0].assembles.sum() == single.modes[0].assembles.sum() == 2
    assert len(g.modes) == len(single.modes)


def _with_leg(loop: Mechanism) -> Mechanism:
    """The loop's coupler carrying an RSS leg: an arm on an R joint, a long S–S tie rod to the
    ground (both branches assemble over most of the turn)."""
    on = [j.at for j in loop.joints if "coupler" in j.bodies]
    K = np.mean(on, axis=0) + np.array([0.3, 0.2, 0.1])
    u = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    v = np.cross(u, [1.0, 0.0, 0.0])
    T = K + 0.6 * v / np.linalg.norm(v)
    z = np.array([0.0, 0.0, 1.0])
    joints = (MechanismJoint("K", "R", ("coupler", "arm"), K, u),
              MechanismJoint("T", "S", ("arm", "tie"), T, z),
              MechanismJoint("G", "S", ("tie", "ground"), T + 8.0 * z, z))
    return Mechanism("leg", (*loop.bodies, Body("arm"), Body("tie")), (*loop.joints, *joints),
                     loop.inputs)


def _stage_mode(label: str) -> int:
    hit = re.search(r"RSRC loop \S+ mode (\d)", label)
    return 0 if label == "drawn" else int(hit[1]) if hit else -1


def test_a_leg_hung_on_the_loop_stage_is_cut_with_its_loop_mode() -> None:
    """The four-mode RSRC carrying an RSS leg: in the 14° → 24° step, where the single loop's
    drawn mode dies at the discriminant's second zero and its run after is born at the first
    (a root on no sample between), each leg branch on that loop mode is cut the same way, at
    the same zeros (brentq, to 1e-3°); a mode that passes the step whole is on a loop mode that
    passes it in the single loop; the island is one mode of the loop, its leg not placed."""
    motion = sk.solve_motion(sk.rsrc(**Q), XQ)
    loop = mechanism_from_loop(motion, 0, 0)
    g = solve_mechanism(_with_leg(loop), XQ - XQ[0], every_mode=True)
    single = solve_mechanism(loop, XQ - XQ[0], every_mode=True)
    assert g.method == "graph (closed forms)"
    k = 1
    zg = np.degrees(np.array(zeros(XQ[k], XQ[k + 1], Q)) - XQ[0])
    lo, hi = np.degrees(XQ[k] - XQ[0]), np.degrees(XQ[k + 1] - XQ[0])
    passing = {_loop_mode(md.label) for md in single.modes if md.assembles[k:k + 2].all()}
    legs = [md for md in g.modes if "island" not in md.label]
    assert {_stage_mode(md.label) for md in legs if md.assembles[k:k + 2].all()} <= passing
    assert 0 not in passing
    on_drawn = [md for md in legs if _stage_mode(md.label) == 0 and
                (md.assembles[k] or md.assembles[k + 1])]
    assert len(on_drawn) == 4  # two leg branches, each before and after the cut
    mine = _inside(legs, lo, hi)
    ref = _inside([md for md in single.modes if "island" not in md.label], lo, hi)
    assert [w for w, _ in mine] == ["dies", "dies", "is born", "is born"]
    assert [t for _, t in mine] == pytest.approx([zg[1], zg[1], zg[0], zg[0]], abs=1e-3)
    assert mine == [r for r in ref for _ in range(2)]  # the single loop's, once per leg branch
    islands = [md for md in g.modes if "island" in md.label]
    assert len(islands) == 1 and "not placed" in islands[0].label
    assert [_theta(e) for e in islands[0].events] == pytest.approx(list(zg), abs=1e-3)

"""Folds and islands inside one sample step on the homotopy route (issue 27; modes/planar_folds.py,
modes/step_islands.py): every fold of a planar mechanism's input as the critical points of its
projection, and the island modes between two folds inside one step.

Checked against things independent of the critical-point system: the distance law of a
four-bar's dyad (|A − D| = b ± c, crank angle by arccos) and of an RRR dyad from the crank to the
ground (|E − F| = g₁ ± g₂), on random mechanisms; the closed-form sub-chain route's island modes
(graph/step_folds.py) on the ISLAND six-bar of tests/graphs/test_step_folds.py; the homotopy
route's own births and deaths (bisection of the tracked modes) on the Stephenson III six-bar;
the critical points' count at two random kernel scalings h and by monodromy from one of them."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from tests.graphs.test_step_folds import (
    ISLAND_DRAWN,
    ISLAND_INPUTS,
    _crank_at,
    _island_dims,
    _sixbar,
    _with_dyad,
)

import screwkit as sk
from screwkit.algebraic.monodromy import MonodromyOptions
from screwkit.algebraic.solve import StartSolutions
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_layout
from screwkit.kinematics.modes import step_islands as step_islands_module
from screwkit.kinematics.modes.along import ModesAlong, modes_along, pose_vectors
from screwkit.kinematics.modes.along_folds import Chain
from screwkit.kinematics.modes.every_mode import every_mode
from screwkit.kinematics.modes.planar import planar_formulation
from screwkit.kinematics.modes.planar_folds import input_folds
from screwkit.kinematics.modes.starts import start_solutions
from screwkit.kinematics.modes.step_islands import fold_values, unreported
from screwkit.model.mechanism import Mechanism

EXAMPLES = Path(__file__).parents[2] / "examples" / "mechanisms"
#: fold inputs agree to this (rad): the critical points are Newton-converged, the distance
#: law exact; the task's bar is 1e-8
FOLD_RAD = 1e-9


def _law(r1: float, r2: float, lo: float, hi: float) -> np.ndarray:
    """Angles φ (one turn) where |r1 e^{iφ} − r2| is ``lo`` or ``hi`` (law of cosines)."""
    out = []
    for dist in (lo, hi):
        cos = (r1 * r1 + r2 * r2 - dist * dist) / (2 * r1 * r2)
        if abs(cos) <= 1.0:
            out += [np.arccos(cos), -np.arccos(cos)]
    return np.array(out)


def _distance_law_folds(a: float, b: float, c: float, d: float, rE: float, F: np.ndarray,
                        g1: float, g2: float, drawn: float) -> np.ndarray:
    """Every fold input (from the drawing, one turn) of :func:`_with_dyad` where the other
    sub-chain assembles, each twice (the other sub-chain's two branches), sorted."""
    def fourbar_ok(theta: np.ndarray) -> np.ndarray:
        r = np.abs(a * np.exp(1j * theta) - d)
        return (r >= abs(b - c)) & (r <= b + c)

    argF = np.angle(F[0] + 1j * F[1])
    def dyad_ok(theta: np.ndarray) -> np.ndarray:
        r = np.abs(rE * np.exp(1j * (theta + 1.0)) - (F[0] + 1j * F[1]))
        return (r >= abs(g1 - g2)) & (r <= g1 + g2)

    crank = _law(a, d, abs(b - c), b + c)
    crank = crank[dyad_ok(crank)]
    dyad = _law(rE, float(np.hypot(*F)), abs(g1 - g2), g1 + g2) + argF - 1.0
    dyad = dyad[fourbar_ok(dyad)]
    folds = np.mod(np.concatenate([crank, dyad]) - drawn, 2 * np.pi)
    return np.sort(np.repeat(folds, 2))


def _random_sixbar(seed: int) -> tuple[Mechanism, tuple]:
    """A random four-bar with a dyad whose folds are real in both sub-chains, drawn at a
    crank angle where both assemble."""
    rng = np.random.default_rng(seed)
    F = np.array([-2.0, -3.0])
    while True:
        a, d = 1.0, rng.uniform(2.0, 3.5)
        b, c = rng.uniform(1.0, 3.5), rng.uniform(0.8, 2.5)
        rE = rng.uniform(0.2, 0.6)
        g = rng.uniform(np.hypot(*F) - 0.8 * rE, np.hypot(*F) + 0.8 * rE)
        g1 = rng.uniform(0.45, 0.55) * g
        g2 = g - g1
        for drawn in rng.uniform(0.0, 2 * np.pi, 50):
            rA = abs(a * np.exp(1j * drawn) - d)
            rG = abs(rE * np.exp(1j * (drawn + 1.0)) - (F[0] + 1j * F[1]))
            if abs(b - c) + 0.05 < rA < b + c - 0.05 and abs(g1 - g2) + 0.02 < rG < g - 0.02:
                dims = (a, b, c, d, rE, F, g1, g2, float(drawn))
                return _with_dyad(*dims), dims


def _circular_gap(got: np.ndarray, want: np.ndarray) -> float:
    diff = np.mod(got - want + np.pi, 2 * np.pi) - np.pi
    return float(np.abs(diff).max(initial=0.0))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_sixbars_folds_are_the_distance_laws(seed: int) -> None:
    mech, dims = _random_sixbar(seed)
    want = _distance_law_folds(*dims)
    assert want.size >= 4  # both sub-chains fold somewhere the other assembles
    folds = input_folds(planar_formulation(mech), [0.0])
    got = np.sort(np.mod(folds.inputs, 2 * np.pi))
    assert got.size == want.size and folds.certified.all() and folds.singular == 0
    assert _circular_gap(got, want) <= FOLD_RAD


@pytest.mark.parametrize("seed", [3, 4, 5])
def test_random_fourbars_folds_are_the_distance_law(seed: int) -> None:
    _, (a, b, c, d, _, _, _, _, drawn) = _random_sixbar(seed)
    six = _sixbar(a, b, c, d, np.degrees(drawn))
    mech = Mechanism("four-bar", six.bodies[:3], six.joints[:4], ("O.theta",))
    folds = input_folds(planar_formulation(mech), [0.0])
    want = np.sort(np.mod(_law(a, d, abs(b - c), b + c) - drawn, 2 * np.pi))
    got = np.sort(np.mod(folds.inputs, 2 * np.pi))
    assert got.size == want.size and folds.certified.all()
    assert _circular_gap(got, want) <= FOLD_RAD


def test_the_count_of_critical_points_is_stable() -> None:
    """Two random kernel scalings h give the same critical points, every generic one ending
    finite (none failed or at infinity); monodromy finds as many generic ones as the
    total-degree start set holds. The four-bar's and the dyad's blocks of ∂F/∂x are apart, so
    the critical points are two components (the kernel v in one block, 8 each) that no
    monodromy loop joins: it starts from one solution of each."""
    mech = _sixbar(*_island_dims(), ISLAND_DRAWN)
    form = planar_formulation(mech)
    one, two = input_folds(form, [0.0]), input_folds(form, [0.0], seed=5)
    assert one.found == two.found == one.generic_count == 16
    assert one.failed == one.at_infinity == two.failed == two.at_infinity == 0
    assert one.inputs.size == two.inputs.size == 8
    assert np.abs(one.inputs - two.inputs).max() <= 1e-10
    system = form.fold_system()
    start = start_solutions(system)
    assert start.generic_count == 16 and start.how_found.startswith("total-degree")
    v = np.abs(start.x[:, 6:])  # (vB, vG): B and G are the unknown joints
    fourbar = v[:, 2:].max(axis=1) <= 1e-9 * v[:, :2].max(axis=1)
    dyad = v[:, :2].max(axis=1) <= 1e-9 * v[:, 2:].max(axis=1)
    assert fourbar.sum() == dyad.sum() == 8
    seeds = start.x[[int(np.argmax(fourbar)), int(np.argmax(dyad))]]
    again = StartSolutions.by_monodromy(system, start.p, seeds,
                                        MonodromyOptions(stale_loops=9, seed=1))
    assert again.generic_count == start.generic_count
    # the Stephenson III six-bar's critical points are one component: monodromy from one
    # start solution stabilises at the total-degree start's 24
    six = planar_formulation(sk.load_spec(EXAMPLES / "stephenson3_sixbar.toml").mechanism)
    system = six.fold_system()
    start = start_solutions(system)
    assert start.generic_count == 24
    again = StartSolutions.by_monodromy(system, start.p, start.x[:1],
                                        MonodromyOptions(stale_loops=9, seed=1))
    assert again.generic_count == 24


def _fmt(x: np.ndarray) -> str:
    return repr(float(np.degrees(x[0])))


def test_the_island_sixbar_on_the_homotopy_route_has_the_closed_form_islands() -> None:
    """The ISLAND six-bar's mirror span lies inside the step 180° → 190° of input: the
    homotopy route finds its four modes on no sample, each born and dying at the distance
    law's folds and at the closed-form route's (graph/step_folds.py)."""
    a, b, c, d = _island_dims()
    mech = _sixbar(a, b, c, d, ISLAND_DRAWN)
    lay = graph_layout(mech)
    along = modes_along(mech, lay, ISLAND_INPUTS[:, None], _fmt)
    born = 360.0 - _crank_at(a, d, b + c) - ISLAND_DRAWN
    dies = 360.0 - _crank_at(a, d, abs(b - c)) - ISLAND_DRAWN
    assert len(along.islands) == 4 and len(along.masks) == 8
    closed = solve_mechanism(mech, ISLAND_INPUTS[:, None], every_mode=True)
    theirs = [md for md in closed.modes if "island inside one sample step" in md.label]
    assert len(theirs) == 4
    for k in along.islands:
        assert not along.masks[k].any()
        events = along.events[k]
        got = [re.match(r"(is born|dies) at ([-\d.e]+): it (starts|stops) assembling there \(a "
                        r"fold: a critical point", e) for e in events[:2]]
        assert got[0] and got[0][1] == "is born" and got[1] and got[1][1] == "dies", events
        assert abs(np.radians(float(got[0][2]) - born)) <= FOLD_RAD
        assert abs(np.radians(float(got[1][2]) - dies)) <= FOLD_RAD
        assert "an island inside one sample step" in events[2]
        assert [x for x, _ in along.folds[k]][0][0] == pytest.approx(np.radians(born), abs=1e-12)
    for md in theirs:  # the closed-form route's (printed to 6 digits) agree
        assert md.events[0].startswith(f"is born at O.theta = {born:.6g} deg")
        assert md.events[1].startswith(f"dies at O.theta = {dies:.6g} deg")
    # the four are distinct modes, two meeting at each fold (the four-bar's branches)
    islands = set(along.islands)
    meets = [m for m in along.meets if set(m) <= islands]
    assert len(meets) == 2 and len({k for m in meets for k in m}) == 4
    # every fold inside the steps (3°, 181°, 187°) is reported; without the island modes, or
    # without the modes dying at 3°, the note names what no mode reports
    folds = fold_values(mech, ISLAND_INPUTS[:, None])
    chains = [Chain(c.scalars, c.spherical, m, list(e), folds=list(f)) for c, m, e, f in
              zip(along.configurations, along.masks, along.events, along.folds, strict=True)]
    assert unreported(ISLAND_INPUTS[:, None], folds, chains, _fmt)[0].startswith(
        "every one of the 3 fold input(s)")
    without = unreported(ISLAND_INPUTS[:, None], folds,
                         [ch for k, ch in enumerate(chains) if k not in islands], _fmt)[0]
    named = re.search(r"\(([-\d.e]+); ([-\d.e]+)\)", without)
    assert without.startswith("2 of the 3 fold input(s)") and named, without
    assert np.radians(np.array([float(named[1]), float(named[2])]) - [born, dies]) == \
        pytest.approx([0.0, 0.0], abs=1e-8)
    early = unreported(ISLAND_INPUTS[:, None], folds, [chains[k] for k in islands], _fmt)[0]
    assert early.startswith("1 of the 3 fold input(s) inside the motion's steps are no "
                            "reported mode's birth or death (3.0")


def test_the_island_modes_are_reported_by_solve_mechanism_on_the_homotopy_route(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The same six-bar with its closed-form decomposition withheld (graph/motion.py then
    takes the homotopy route): eight modes, four labelled islands on no sample."""
    from screwkit.kinematics.graph import motion as motion_module
    from screwkit.kinematics.graph.subchains import Decomposition

    mech = _sixbar(*_island_dims(), ISLAND_DRAWN)
    monkeypatch.setattr(motion_module, "decompose", lambda m: Decomposition(
        (), tuple(b.name for b in m.bodies), ()))
    got = solve_mechanism(mech, ISLAND_INPUTS[:, None], every_mode=True)
    assert got.method == "graph (homotopy at anchors, tracking between)"
    islands = [md for md in got.modes if "island inside one sample step" in md.label]
    assert len(got.modes) == 8 and len(islands) == 4
    assert all(not md.assembles.any() for md in islands)


def test_the_stephenson_sixbar_is_unchanged_and_its_folds_are_the_critical_points(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """No step of the Stephenson III motion holds two folds and every run of samples between
    folds holds an anchor: its modes, events and folds are those found without the fold
    search (as before it), and the births and deaths the anchored tracking locates by
    bisection are critical points of the input."""
    mech = sk.load_spec(EXAMPLES / "stephenson3_sixbar.toml").mechanism
    lay = graph_layout(mech)
    X = np.arange(np.radians(180.0), np.radians(300.0) + 1e-9, np.radians(6.0))[:, None]
    got = modes_along(mech, lay, X, _fmt)
    monkeypatch.setattr(step_islands_module, "fold_values", lambda m, x: (-1, None, "off"))
    before = modes_along(mech, lay, X, _fmt)
    assert "0 step(s) hold two or more" in got.notes[-2] and "not searched" in before.notes[-1]
    assert got.notes[-1] == ("every one of the 2 fold input(s) inside the motion's steps is a "
                             "birth or death of the modes reported")
    assert got.notes[1:-2] == before.notes[1:-1] and "every run of samples" in got.notes[0]
    assert got.events == before.events and got.islands == before.islands == ()
    assert all(np.array_equal(m, n) for m, n in zip(got.masks, before.masks, strict=True))
    assert [[x for x, _ in f] for f in got.folds] == [[x for x, _ in f] for f in before.folds]
    folds = input_folds(planar_formulation(mech), X[0])
    located = [float(x[0]) for fs in got.folds for x, _ in fs]
    assert len(located) == 4 and folds.inputs.size == 2
    for x in located:  # bisection to 2⁻²⁶ of a 6° step, reached by continuation
        assert np.abs(folds.inputs - x).min() <= 1e-6


def test_an_island_on_samples_between_two_anchors_is_found_from_the_folds() -> None:
    """The ISLAND six-bar sampled every 0.9° from 151.2°: the anchors (every eighth sample)
    fall at 180° and 187.2°, around the mirror span 181° … 187° that holds six samples, and
    no mode lives at any anchor, so no track meets it. The homotopy at a sample of the run
    between its folds finds its four modes, each on those six samples, one to one with the
    homotopy solved anew at every sample (none elsewhere), born and dying at the distance
    law's folds."""
    a, b, c, d = _island_dims()
    mech = _sixbar(a, b, c, d, ISLAND_DRAWN)
    lay = graph_layout(mech)
    X = np.radians(np.arange(151.2, 220.0, 0.9))[:, None]
    along = modes_along(mech, lay, X, _fmt)
    assert np.degrees(X[along.anchors[4:6], 0]) == pytest.approx([180.0, 187.2])
    born = 360.0 - _crank_at(a, d, b + c) - ISLAND_DRAWN
    dies = 360.0 - _crank_at(a, d, abs(b - c)) - ISLAND_DRAWN
    inside = (np.degrees(X[:, 0]) > born) & (np.degrees(X[:, 0]) < dies)
    assert inside.sum() == 6 and len(along.masks) == 4
    every = every_mode(mech, X)
    assert [c.size for c in every.configurations] == (4 * inside).tolist()
    for m, events in zip(along.masks, along.events, strict=True):
        assert np.array_equal(m, inside)
        got = [re.match(r"(is born|dies) at ([-\d.e]+):", e) for e in events[:2]]
        assert got[0] and got[1] and got[0][1] == "is born" and got[1][1] == "dies"
        assert abs(np.radians(float(got[0][2]) - born)) <= FOLD_RAD
        assert abs(np.radians(float(got[1][2]) - dies)) <= FOLD_RAD
        assert "alone in a run of samples between two fold inputs" in events[1]
    mine = [pose_vectors(mech, lay, c) for c in along.configurations]
    for n in np.flatnonzero(inside):
        theirs = pose_vectors(mech, lay, every.configurations[n])
        gaps = np.abs(np.array([p[n] for p in mine])[:, None] - theirs[None]).max(axis=2)
        assert sorted(np.argmin(gaps, axis=1).tolist()) == [0, 1, 2, 3]
        assert gaps.min(axis=1).max() <= 1e-8


def test_steps_and_runs_between_folds_in_either_order_and_across_a_turn() -> None:
    """The bookkeeping of modes/step_islands.py on hand-made inputs: fold inputs given within
    one turn of the first sample are found in every turn, in sample order."""
    from screwkit.kinematics.modes.step_islands import folds_in_steps, run_samples

    r = np.radians
    vals = r(np.array([5.0, 7.0, 355.0]))
    up = folds_in_steps(r(np.array([0.0, 10.0, 20.0])), vals)
    assert len(up) == 1 and up[0][0] == 0 and np.degrees(up[0][1]) == pytest.approx([5, 7])
    down = folds_in_steps(r(np.array([20.0, 10.0, 0.0])), vals)
    assert len(down) == 1 and down[0][0] == 1 and np.degrees(down[0][1]) == pytest.approx([7, 5])
    turn = folds_in_steps(r(np.array([350.0, 365.0])), r(np.array([352.0, 362.0])))
    assert np.degrees(turn[0][1]) == pytest.approx([352, 362])
    assert folds_in_steps(r(np.array([0.0, 6.0, 10.0])), vals) == []  # one fold per step
    x = r(np.arange(0.0, 100.0, 1.0))
    folds = r(np.array([10.5, 20.5]))
    assert run_samples(x, folds, np.arange(0, 100, 8)).tolist() == []
    assert run_samples(x, folds, np.array([0, 99])).tolist() == [15]
    assert run_samples(x + 2 * np.pi, folds, np.array([0, 99])).tolist() == [15]


def test_the_island_inside_one_step_met_from_above() -> None:
    """The ISLAND six-bar's inputs in the other order: the island modes are born at the upper
    fold (187°) and die at the lower (181°)."""
    a, b, c, d = _island_dims()
    mech = _sixbar(a, b, c, d, ISLAND_DRAWN)
    along = modes_along(mech, graph_layout(mech), ISLAND_INPUTS[::-1, None], _fmt)
    upper = 360.0 - _crank_at(a, d, abs(b - c)) - ISLAND_DRAWN
    lower = 360.0 - _crank_at(a, d, b + c) - ISLAND_DRAWN
    assert len(along.islands) == 4
    for k in along.islands:
        born = re.match(r"is born at ([-\d.e]+):", along.events[k][0])
        dies = re.match(r"dies at ([-\d.e]+):", along.events[k][1])
        assert born and dies, along.events[k]
        assert abs(np.radians(float(born[1]) - upper)) <= FOLD_RAD
        assert abs(np.radians(float(dies[1]) - lower)) <= FOLD_RAD


def _stephenson(seed: int) -> Mechanism:
    """The bundled Stephenson III six-bar with every joint moved by ~4 mm (its drawing is its
    geometry, so it still closes there): a random non-decomposable planar six-bar."""
    from dataclasses import replace

    base = sk.load_spec(EXAMPLES / "stephenson3_sixbar.toml").mechanism
    rng = np.random.default_rng(seed)
    return replace(base, joints=tuple(
        replace(j, at=j.at + np.array([*rng.normal(0.0, 0.004, 2), 0.0])) for j in base.joints))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_stephenson_sixbars_folds_are_where_the_closure_jacobian_drops_rank(
        seed: int) -> None:
    """At each critical point the graph tracker's own closure (graph_forward, not the
    polynomial system) holds to 1e-10 and its Jacobian in the passive joints, by central
    differences, has lost a rank (σ_min/σ_max ≤ 1e-6); the homotopy's real-mode count at
    1e-2 rad on either side (less where another fold is nearer) differs by two; every generic
    path ends finite."""
    from screwkit.kinematics.graph.closure import graph_forward

    mech = _stephenson(seed)
    form = planar_formulation(mech)
    folds = input_folds(form, [0.0])
    assert folds.failed == folds.at_infinity == folds.singular == 0
    assert folds.found == folds.generic_count and folds.inputs.size >= 2
    assert folds.certified.all()
    lay = graph_layout(mech)
    cols = [lay.scalar_col[f] for f in lay.passive]
    gap = np.diff(folds.inputs)  # (sorted) a fold's sides stop short of its neighbours
    off = np.minimum(1e-2, 0.4 * np.minimum(np.r_[np.inf, gap], np.r_[gap, np.inf]))
    side = every_mode(mech, np.concatenate([folds.inputs - off, folds.inputs + off])[:, None])
    counts = np.array([c.size for c in side.configurations]).reshape(2, -1)
    assert np.all(np.abs(counts[0] - counts[1]) == 2), counts
    for t, xy in zip(folds.inputs, folds.points, strict=True):
        conf, _ = form.configuration(xy[None, :], [t])
        assert np.abs(graph_forward(mech, lay, conf).residual).max() <= 1e-10 * mech.length_scale
        h = 1e-6
        jac = []
        for col in cols:
            plus, minus = conf.scalars.copy(), conf.scalars.copy()
            plus[0, col] += h
            minus[0, col] -= h
            rp = graph_forward(mech, lay, type(conf)(plus, conf.spherical)).residual
            rm = graph_forward(mech, lay, type(conf)(minus, conf.spherical)).residual
            jac.append(((rp - rm) / (2 * h)).reshape(-1))
        sv = np.linalg.svd(np.array(jac).T, compute_uv=False)
        assert sv[-1] <= 1e-6 * sv[0], sv


def test_an_s_bend_inside_one_step_of_a_random_stephenson_sixbar() -> None:
    """A random Stephenson III six-bar whose curve bends back twice within 0.49° (folds at
    -18.730° and -18.236°), inside the step -20° → -18°: one mode dies at the upper fold,
    another is born at the lower, and the piece between them (no sample on it) is a mode of
    its own that meets both. At the step's middle the modes that live there are as many as a
    fresh homotopy solve finds."""
    mech = _stephenson(3)
    lay = graph_layout(mech)
    X = np.radians(np.arange(-60.0, 20.01, 2.0))[:, None]
    along = modes_along(mech, lay, X, _fmt)
    folds = input_folds(planar_formulation(mech), [0.0]).inputs
    lower, upper = folds[(folds > np.radians(-20.0)) & (folds < np.radians(-18.0))]
    assert np.degrees(upper - lower) == pytest.approx(0.494, abs=1e-3)
    assert len(along.islands) == 1
    (k,) = along.islands
    (born, _), (dies, _) = along.folds[k]
    assert [born[0], dies[0]] == pytest.approx([lower, upper], abs=1e-12)
    assert {m for pair in along.meets for m in pair if k in pair} == {k, *(
        m for m in range(len(along.masks)) if m != k and any(
            abs(x[0] - v) <= 1e-6 for x, _ in along.folds[m] for v in (lower, upper)))}
    assert sum(1 for pair in along.meets if k in pair) == 2
    middle = 0.5 * (lower + upper)
    alive = [m for m in range(len(along.masks)) if m == k or _holds(along, m, middle, X)]
    assert len(alive) == every_mode(mech, [[middle]]).configurations[0].size == 4
    assert along.notes[-1].startswith("every one of the")


def _holds(along: ModesAlong, m: int, x: float, X: np.ndarray) -> bool:
    """Whether mode m lives at input x between two samples: it holds at a neighbouring sample
    and no birth or death of it lies between that sample and x."""
    k = int(np.searchsorted(X[:, 0], x)) - 1
    ends = [f[0][0] for f in along.folds[m]]
    left = along.masks[m][k] and not any(X[k, 0] < e < x for e in ends)
    right = along.masks[m][k + 1] and not any(x < e < X[k + 1, 0] for e in ends)
    return bool(left or right)


def test_a_fold_search_the_formulation_cannot_write_becomes_the_note(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Where the formulation cannot write its input's circles (placed_circles raises a
    CapabilityError), the fold search is not taken and says why in the note, and the motion
    is solved as without it. Before, fold_values asked for the critical-point system (to count
    its paths) outside its try, so the error ended the whole every-mode motion (found by a
    review: the error path had no test)."""
    from screwkit.errors import CapabilityError
    from screwkit.kinematics.modes import planar_folds

    def refuse(*args: object, **kwargs: object) -> None:
        raise CapabilityError("the joints placed by input O.theta do not move on circles")

    mech = _sixbar(1.0, 3.0, 2.0, 3.5, 30.0)
    X = np.radians(np.arange(30.0, 60.0, 10.0))[:, None]
    monkeypatch.setattr(planar_folds, "placed_circles", refuse)
    j, vals, note = fold_values(mech, X)
    assert j == 0 and vals is None and "do not move on circles" in note
    got = modes_along(mech, graph_layout(mech), X, _fmt)
    assert any("not searched as critical points" in n and "circles" in n for n in got.notes)
    assert len(got.masks) >= 1 and all(m.any() for m in got.masks)

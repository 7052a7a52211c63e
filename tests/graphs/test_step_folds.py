"""Folds hidden inside one sample step of a closed-form mode (issue 27; graph/step_folds.py,
graph/closed_modes.py's ``held_modes``): a four-bar's dyad A–B–D whose discriminant is positive
at both ends of a step and negative in between (the crank cannot pass: the drawn mode dies and
the same branches are born again inside the step) and one negative at both ends and positive in
between (an island of modes on no sample), each with an RRR dyad E–G–F from the crank to the
ground that assembles at every crank angle (two loops: the closed-form sub-chain route). The
folds are checked against the four-bar's distance law |A − D| = b + c or |b − c| (crank angle
by arccos, no library code) and against the same mechanism on a grid fine enough to put samples
inside the gap or island (there the folds are found between samples that differ)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closed_modes import branch_combinations, every_mode
from screwkit.kinematics.graph.closure import graph_forward, graph_layout, loop_residuals
from screwkit.kinematics.graph.motion import MechanismMotion
from screwkit.kinematics.graph.subchains import decompose
from screwkit.model.mechanism import Body, Mechanism, MechanismJoint

Z = np.array([0.0, 0.0, 1.0])
#: crank a, coupler b, rocker c, frame d: |A − D| exceeds b + c only within 177.04° … 182.96°
#: of crank angle (a gap of 5.9°), sampled every 10° with samples at 175° and 185°
GAP = (1.0, 2.5, 1.499, 3.0)
#: crank angle at the drawing for GAP, and the inputs (from the drawing, rad)
GAP_DRAWN = 90.0
GAP_INPUTS = np.radians(np.arange(-5.0, 355.0, 10.0))
#: the ISLAND four-bar assembles only within 85° … 91° of crank angle and its mirror, 269° …
#: 275°: drawn at 88°, sampled every 10° of input, the mirror lies within 180° … 190° of input
ISLAND_SPAN = (85.0, 91.0)
ISLAND_DRAWN = 88.0
ISLAND_INPUTS = np.radians(np.arange(0.0, 360.0, 10.0))


def _joint(name: str, a: str, b: str, at: np.ndarray) -> MechanismJoint:
    return MechanismJoint(name, "R", (a, b), np.array([*at, 0.0]), Z)


def _meet(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float) -> np.ndarray:
    """The meeting point of two circles to the left of c1 → c2."""
    w = c2 - c1
    f = float(np.hypot(*w))
    along = (f ** 2 + r1 ** 2 - r2 ** 2) / (2 * f)
    return c1 + along * w / f + np.sqrt(r1 ** 2 - along ** 2) * np.array([-w[1], w[0]]) / f


def _with_dyad(a: float, b: float, c: float, d: float, rE: float, F: np.ndarray, g1: float,
               g2: float, drawn: float) -> Mechanism:
    """A four-bar O–A–B–D (crank a at O, rocker c pivoted at (d, 0)) with an RRR dyad
    E–G–F (E on the crank at radius rE, one radian ahead of A; F on the ground), drawn at
    crank angle ``drawn`` (rad)."""
    A = a * np.array([np.cos(drawn), np.sin(drawn)])
    D = np.array([d, 0.0])
    E = rE * np.array([np.cos(drawn + 1.0), np.sin(drawn + 1.0)])
    return Mechanism("four-bar with a dyad", tuple(Body(n) for n in ("crank", "coupler",
                                                                    "rocker", "b3", "b4")),
                     (_joint("O", "ground", "crank", np.zeros(2)),
                      _joint("A", "crank", "coupler", A),
                      _joint("B", "coupler", "rocker", _meet(A, b, D, c)),
                      _joint("D", "rocker", "ground", D),
                      _joint("E", "crank", "b3", E), _joint("G", "b3", "b4", _meet(E, g1, F, g2)),
                      _joint("F", "b4", "ground", F)), ("O.theta",))


def _sixbar(a: float, b: float, c: float, d: float, drawn: float) -> Mechanism:
    """The four-bar O–A–B–D (crank a at O, rocker c pivoted at (d, 0)) drawn at crank angle
    ``drawn`` (deg), and a dyad E–G–F from the crank to the ground (E 0.3 a from O: it
    assembles at every crank angle)."""
    return _with_dyad(a, b, c, d, 0.3 * a, np.array([-2.0, -3.0]), 3.0, 2.5, np.radians(drawn))


def _island_dims() -> tuple[float, float, float, float]:
    """b ± c = |A − D| at the span's ends (a = 1, d = 3)."""
    a, d = 1.0, 3.0
    lo, hi = (np.sqrt(a * a + d * d - 2 * a * d * np.cos(np.radians(s))) for s in ISLAND_SPAN)
    return a, 0.5 * (lo + hi), 0.5 * (hi - lo), d


def _crank_at(a: float, d: float, distance: float) -> float:
    """The crank angle in (0°, 180°) where |A − D| = ``distance`` (law of cosines)."""
    return float(np.degrees(np.arccos((a * a + d * d - distance ** 2) / (2 * a * d))))


def _folds(motion: MechanismMotion) -> list[tuple[int, str, str]]:
    """Every mode's fold events as (mode, "dies"/"is born", input text)."""
    out = []
    for i, md in enumerate(motion.modes):
        for e in md.events:
            for what in ("dies at ", "is born at "):
                if e.startswith(what):
                    out.append((i, what.strip()[:-3], e[len(what):].split(":")[0]))
    return out


def _closes(mech: Mechanism, motion: MechanismMotion) -> None:
    lay = graph_layout(mech)
    for md in motion.modes:
        idx = np.flatnonzero(md.assembles)
        if idx.size:
            conf = md.conf.take(idx)
            fr = graph_forward(mech, lay, conf)
            assert np.abs(loop_residuals(mech, lay, conf, fr.R, fr.p)).max() <= 1e-10


def _pairs(mech: Mechanism, X: np.ndarray) -> list[tuple[float, float, bool]]:
    """The hidden fold pairs of every branch combination, as input values (rad)."""
    from screwkit.kinematics.graph.closed_modes import held_modes

    lay, dec = graph_layout(mech), decompose(mech)
    em = every_mode(mech, lay, dec, X)
    M, N = em.count, X.shape[0]
    held = held_modes(mech, lay, dec, X, branch_combinations(dec), em.assembles(N),
                      em.placement.discriminant.reshape(M, N, -1), True)
    return [(float(X[p.k, 0] + p.t[0] * (X[p.k + 1, 0] - X[p.k, 0])),
             float(X[p.k, 0] + p.t[1] * (X[p.k + 1, 0] - X[p.k, 0])), p.gap)
            for p in held.pairs]


@pytest.mark.parametrize(("example", "span"), [("watt_sixbar", 400.0), ("jansen_leg", 400.0),
                                               ("double_wishbone", 20.0)])
def test_the_slopes_discriminants_are_the_placements(example: str, span: float) -> None:
    """The discriminants the fold search's slopes take alone (dyads.discriminants: the last
    RRR dyads not posed) are the full placement's, bit for bit, on every branch combination
    (RRR dyads; RSS and S–S legs, placed in full), over inputs ± ``span`` (deg)."""
    from screwkit.io import load_spec
    from screwkit.kinematics.graph.dyads import discriminants, place

    root = Path(__file__).resolve().parents[2]
    mech = load_spec(root / "examples" / "mechanisms" / f"{example}.toml").mechanism
    lay, dec = graph_layout(mech), decompose(mech)
    assert dec.complete and not dec.loops
    X = np.radians(np.linspace(-span, span, 97))[:, None]
    for signs in branch_combinations(dec):
        S = np.repeat(signs[None], X.shape[0], axis=0)
        np.testing.assert_array_equal(discriminants(mech, lay, dec, X, S),
                                      place(mech, lay, dec, X, S).discriminant)


def test_a_gap_inside_one_step_ends_the_drawn_mode() -> None:
    """The crank cannot turn through 177.04° … 182.96°: the drawn mode stops at the first fold
    (it used to run on through the step silently, a switch of mode), and the drawn branches
    after the gap are a mode of their own, born at the second fold."""
    a, b, c, d = GAP
    mech = _sixbar(*GAP, GAP_DRAWN)
    X = GAP_INPUTS[:, None]
    first = _crank_at(a, d, b + c) - GAP_DRAWN  # input at the first fold (deg)
    second = 360.0 - _crank_at(a, d, b + c) - GAP_DRAWN
    k = int(np.flatnonzero(np.degrees(GAP_INPUTS) < first)[-1])
    assert np.degrees(GAP_INPUTS[k + 1]) > second  # both folds inside one step
    for every in (False, True):
        motion = solve_mechanism(mech, X, every_mode=every)
        assert motion.method == "graph (closed forms)"
        drawn = motion.modes[0]
        assert drawn.assembles[:k + 1].all() and not drawn.assembles[k + 1:].any()
        assert f"dies at O.theta = {first:.6g} deg: the RRR dyad A–B–D folds" in drawn.events[1]
        assert "the first of two folds between the samples" in drawn.events[1]
    assert len(motion.modes) == 8  # each of the 4 combinations before and after the gap
    again = motion.modes[-1]
    assert "the drawn branches again" in again.label
    assert again.assembles[k + 1:].all() and not again.assembles[:k + 1].any()
    assert again.events[0].startswith(f"is born at O.theta = {second:.6g} deg")
    # per sample, as many modes as the four-bar's two branches times the dyad's two
    assert np.sum([md.assembles for md in motion.modes], axis=0).tolist() == [4] * X.shape[0]
    # the two four-bar branches meet at each fold: the drawn mode with the other four-bar
    # branch before the gap, the drawn branches again with it after the gap
    circuits = motion.notes[1].split(": ")[1]
    assert circuits.count("{") == 4 and "{0, 3}" in circuits
    _closes(mech, motion)
    # the folds to 1e-12 rad of the distance law's
    pairs = _pairs(mech, X)
    assert len(pairs) == 4 and all(p[2] for p in pairs)
    for lo, hi, _ in pairs:
        assert abs(np.degrees(lo) - first) <= 1e-10 and abs(np.degrees(hi) - second) <= 1e-10


def test_an_island_inside_one_step_is_a_mode_on_no_sample() -> None:
    """The four-bar's mirror span, 269° … 275° of crank angle, lies inside the step from
    input 180° to 190°: each of its four branch combinations is a mode on no sample, born and
    dying at the distance law's folds, two by two in one circuit."""
    a, b, c, d = _island_dims()
    mech = _sixbar(a, b, c, d, ISLAND_DRAWN)
    X = ISLAND_INPUTS[:, None]
    motion = solve_mechanism(mech, X, every_mode=True)
    born = 360.0 - _crank_at(a, d, b + c) - ISLAND_DRAWN
    dies = 360.0 - _crank_at(a, d, abs(b - c)) - ISLAND_DRAWN
    assert abs(born - 181.0) <= 1e-9 and abs(dies - 187.0) <= 1e-9
    islands = [md for md in motion.modes if "island inside one sample step" in md.label]
    assert len(motion.modes) == 8 and len(islands) == 4
    for md in islands:
        assert not md.assembles.any()
        assert md.events[0].startswith(f"is born at O.theta = {born:.6g} deg: the RRR dyad "
                                       "A–B–D folds")
        assert md.events[1].startswith(f"dies at O.theta = {dies:.6g} deg")
    circuits = motion.notes[1].split(": ")[1]
    assert "{4, 6}" in circuits and "{5, 7}" in circuits
    pairs = _pairs(mech, X)
    assert len(pairs) == 4 and not any(p[2] for p in pairs)
    for lo, hi, _ in pairs:
        assert abs(np.degrees(lo) - born) <= 1e-10 and abs(np.degrees(hi) - dies) <= 1e-10


@pytest.mark.parametrize("case", ["gap", "island"])
def test_a_fine_grid_puts_samples_inside_and_finds_the_same_folds(case: str) -> None:
    """On a 0.25° grid the gap and the island hold samples, and their folds are found between
    samples that differ (graph/closed_modes.py's ``fold_inputs``): the same inputs as the coarse
    grid's hidden pairs (to the 6 digits of the events), the same modes' branches."""
    if case == "gap":
        mech, coarse = _sixbar(*GAP, GAP_DRAWN), GAP_INPUTS
    else:
        mech, coarse = _sixbar(*_island_dims(), ISLAND_DRAWN), ISLAND_INPUTS
    fine = np.radians(np.arange(np.degrees(coarse[0]), np.degrees(coarse[-1]) + 1e-9, 0.25))
    folds_c = _folds(solve_mechanism(mech, coarse[:, None], every_mode=True))
    folds_f = _folds(solve_mechanism(mech, fine[:, None], every_mode=True))
    assert sorted({(w, x) for _, w, x in folds_c}) == sorted({(w, x) for _, w, x in folds_f})
    assert len(folds_c) == len(folds_f)


def test_a_dip_that_stays_positive_is_no_fold() -> None:
    """b + c a little above the largest |A − D|: the discriminant has a minimum inside the
    step, positive: no fold, four modes over every sample."""
    a, b, c, d = GAP
    mech = _sixbar(a, b, c + 0.002, d, GAP_DRAWN)
    motion = solve_mechanism(mech, GAP_INPUTS[:, None], every_mode=True)
    assert len(motion.modes) == 4 and not _folds(motion)
    assert all(md.assembles.all() for md in motion.modes)


def _spec(mech: Mechanism, path: Path) -> Path:
    lines = ['[mechanism]\nname = "island"\n\n[units]\nlength = "m"\nangle = "deg"\n']
    lines += [f'[[bodies]]\nname = "{b.name}"\n' for b in mech.bodies]
    for j in mech.joints:
        lines.append(f'[[joints]]\nname = "{j.name}"\nkind = "R"\nbetween = ["{j.bodies[0]}", '
                     f'"{j.bodies[1]}"]\nat = [{", ".join(repr(float(v)) for v in j.at)}]\n'
                     f'axis = [0.0, 0.0, 1.0]\n' + ("input = true\n" if j.name == "O" else ""))
    lines.append("[motion]\nstart = 0\nstop = 350\nstep = 10\n")
    path.write_text("\n".join(lines))
    return path


def test_the_cli_lists_the_island_modes_with_their_folds(tmp_path: Path) -> None:
    from screwkit.cli.main import app

    spec = _spec(_sixbar(*_island_dims(), ISLAND_DRAWN), tmp_path / "island.toml")
    runner = CliRunner()
    out = runner.invoke(app, ["analyze", str(spec)], env={"COLUMNS": "200"})
    assert out.exit_code == 0, out.output
    assert out.output.count("island inside one sample step") == 4
    assert out.output.count("is born at O.theta = 181 deg") == 4
    doc = json.loads(runner.invoke(app, ["analyze", str(spec), "--json"]).output)
    islands = [m for m in doc["modes"] if "island" in m["label"]]
    assert len(islands) == 4
    assert all(m["events"][1].startswith("dies at O.theta = 187 deg") for m in islands)


def _fourbar(a: float, b: float, c: float, d: float, drawn: float) -> Mechanism:
    """The four-bar of :func:`_sixbar` alone: one loop, solved by the loop engine (its family's
    closed form, graph/loop_motion.py)."""
    six = _sixbar(a, b, c, d, drawn)
    return Mechanism("four-bar", six.bodies[:3], six.joints[:4], ("O.theta",))


def test_the_single_loop_route_ends_the_drawn_mode_at_a_gap_inside_one_step() -> None:
    """The same gap on the four-bar alone (the loop route): the drawn mode stops at the first
    fold, both loop modes are cut there and come back at the second (four modes), the pieces
    that die together and those born together are circuits."""
    a, b, c, d = GAP
    mech = _fourbar(*GAP, GAP_DRAWN)
    X = GAP_INPUTS[:, None]
    first = _crank_at(a, d, b + c) - GAP_DRAWN
    second = 360.0 - _crank_at(a, d, b + c) - GAP_DRAWN
    k = int(np.flatnonzero(np.degrees(GAP_INPUTS) < first)[-1])
    drawn = solve_mechanism(mech, X).modes
    assert len(drawn) == 1 and np.flatnonzero(drawn[0].assembles).tolist() == list(range(k + 1))
    motion = solve_mechanism(mech, X, every_mode=True)
    assert motion.method == "graph (loop, closed)" and len(motion.modes) == 4
    for md in motion.modes:
        before = md.assembles[:k + 1].all() and not md.assembles[k + 1:].any()
        after = md.assembles[k + 1:].all() and not md.assembles[:k + 1].any()
        assert before or after
        fold = md.events[1] if md.label == "drawn" else md.events[0]
        assert fold.startswith(f"dies at O.theta = {first:.6g} deg: the loop folds" if before
                               else f"is born at O.theta = {second:.6g} deg: the loop folds")
    assert motion.notes[1].endswith(": {0, 2}, {1, 3}")
    assert np.sum([md.assembles for md in motion.modes], axis=0).tolist() == [2] * X.shape[0]
    _closes(mech, motion)


def test_the_single_loop_route_finds_an_island_inside_one_step() -> None:
    a, b, c, d = _island_dims()
    mech = _fourbar(a, b, c, d, ISLAND_DRAWN)
    motion = solve_mechanism(mech, ISLAND_INPUTS[:, None], every_mode=True)
    born = 360.0 - _crank_at(a, d, b + c) - ISLAND_DRAWN
    dies = 360.0 - _crank_at(a, d, abs(b - c)) - ISLAND_DRAWN
    islands = [md for md in motion.modes if "island inside one sample step" in md.label]
    assert len(motion.modes) == 4 and len(islands) == 2
    for md in islands:
        assert not md.assembles.any()
        assert md.events[0].startswith(f"is born at O.theta = {born:.6g} deg: the loop folds")
        assert md.events[1].startswith(f"dies at O.theta = {dies:.6g} deg: the loop folds")
    assert motion.notes[1].endswith(": {0, 1}, {2, 3}")

"""Every mode along the motion of a mechanism that does not decompose (issue 27,
kinematics/modes/along.py): the Stephenson III six-bar over a coarse crank range where two modes
are born and die. Each check is against something independent of the anchored tracking: the
loops' exact closure, the homotopy solved anew at every sample, the drawn-mode tracker alone, a
fine bisection of the homotopy's real-mode count, and the closed-form dyad modes of a 4R."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.motion import MechanismMotion
from screwkit.kinematics.modes.along import modes_along, pose_vectors
from screwkit.kinematics.modes.every_mode import every_mode
from screwkit.model.mechanism import Mechanism

EXAMPLES = Path(__file__).parents[2] / "examples" / "mechanisms"
STEP = np.radians(6.0)
X = np.arange(np.radians(180.0), np.radians(300.0) + 1e-9, STEP)[:, None]


@pytest.fixture(scope="module")
def six_bar() -> Mechanism:
    return sk.load_spec(EXAMPLES / "stephenson3_sixbar.toml").mechanism


@pytest.fixture(scope="module")
def motion(six_bar: Mechanism) -> MechanismMotion:
    return solve_mechanism(six_bar, X, every_mode=True)


def test_every_mode_closes_every_loop_at_every_sample(six_bar: Mechanism,
                                                      motion: MechanismMotion) -> None:
    lay = graph_layout(six_bar)
    assert len(motion.modes) == 4 and motion.modes[0].label == "drawn"
    for md in motion.modes:
        ok = np.asarray(md.assembles)
        residual = graph_forward(six_bar, lay, md.conf.take(np.flatnonzero(ok))).residual
        assert np.abs(residual).max() <= 1e-10 * six_bar.length_scale


def test_every_mode_is_continuous(six_bar: Mechanism, motion: MechanismMotion) -> None:
    lay = graph_layout(six_bar)
    for md in motion.modes:
        ok = np.asarray(md.assembles)
        both = ok[1:] & ok[:-1]
        change = np.abs(np.diff(pose_vectors(six_bar, lay, md.conf), axis=0)).max(axis=1)
        assert both.sum() >= 9
        assert change[both].max() <= 3 * STEP, md.label


def test_the_modes_at_every_sample_are_every_mode_there(six_bar: Mechanism,
                                                         motion: MechanismMotion) -> None:
    """At every sample (anchors and in between) the modes that assemble are, one to one, the
    real modes the homotopy finds when solved anew at that input."""
    lay = graph_layout(six_bar)
    fresh = every_mode(six_bar, X)
    counts = []
    for n in range(len(X)):
        here = [md for md in motion.modes if md.assembles[n]]
        mine = np.vstack([pose_vectors(six_bar, lay, md.conf.take(slice(n, n + 1)))
                          for md in here])
        theirs = pose_vectors(six_bar, lay, fresh.configurations[n])
        gap = np.abs(mine[:, None] - theirs[None]).max(axis=2)
        assert len(here) == len(theirs)
        assert np.all(gap.min(axis=1) <= 1e-8) and np.all(gap.min(axis=0) <= 1e-8)
        counts.append(len(here))
    assert set(counts) == {2, 4}


def test_the_drawn_mode_is_the_drawn_tracker_s(six_bar: Mechanism,
                                               motion: MechanismMotion) -> None:
    alone = solve_mechanism(six_bar, X)
    for name, values in alone.modes[0].variables.items():
        assert np.abs(motion.modes[0].variables[name] - values).max() <= 1e-10, name


def _fine_fold(mech: Mechanism, lo: float, hi: float) -> float:
    """Where the homotopy's count of real modes changes in [lo, hi], by bisection."""
    def count(x: float) -> int:
        return every_mode(mech, [[x]]).configurations[0].size

    c_lo = count(lo)
    for _ in range(24):
        mid = 0.5 * (lo + hi)
        if count(mid) == c_lo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def test_births_and_deaths_are_located(six_bar: Mechanism, motion: MechanismMotion) -> None:
    found = {"born": [], "dies": []}
    for md in motion.modes[2:]:
        for ev in md.events:
            m = re.match(r"(is born|dies) at Q3\.theta = ([-\d.]+) deg", ev)
            if m:
                found["born" if m[1] == "is born" else "dies"].append(np.radians(float(m[2])))
    assert len(found["born"]) == 2 and len(found["dies"]) == 2
    ok = np.array([any(md.assembles[n] for md in motion.modes[2:]) for n in range(len(X))])
    first, last = int(np.argmax(ok)), len(ok) - 1 - int(np.argmax(ok[::-1]))
    birth = _fine_fold(six_bar, float(X[first - 1, 0]), float(X[first, 0]))
    death = _fine_fold(six_bar, float(X[last, 0]), float(X[last + 1, 0]))
    assert np.abs(np.array(found["born"]) - birth).max() <= 1e-4
    assert np.abs(np.array(found["dies"]) - death).max() <= 1e-4


def test_a_fourbar_through_the_anchored_path_has_the_closed_form_modes() -> None:
    mech = sk.load_spec(EXAMPLES / "fourbar_graph.toml").mechanism
    lay = graph_layout(mech)
    Xf = np.radians(np.arange(0.0, 361.0, 15.0))[:, None]
    closed = solve_mechanism(mech, Xf, every_mode=True)
    assert closed.method == "graph (loop, closed)" and len(closed.modes) == 2
    along = modes_along(mech, lay, Xf, str)
    assert len(along.configurations) == 2 and all(m.all() for m in along.masks)
    for md in closed.modes:
        mine = pose_vectors(mech, lay, md.conf)
        gaps = [np.abs(pose_vectors(mech, lay, c) - mine).max() for c in along.configurations]
        assert min(gaps) <= 1e-9


def test_without_a_formulation_only_the_drawn_mode_with_the_reason() -> None:
    """The Delta robot with one plate ball moved 5 mm (its drawing still closes, but arm 1's
    rods are no parallelogram): no formulation takes it, so only the drawn mode, and why."""
    from dataclasses import replace

    mech = sk.load_spec(EXAMPLES / "delta_robot.toml").mechanism
    mech = replace(mech, joints=tuple(
        replace(j, at=j.at + np.array([0.0, 0.0, 0.005])) if j.name == "P1a" else j
        for j in mech.joints))
    m = solve_mechanism(mech, np.zeros((2, len(mech.inputs))), every_mode=True)
    assert len(m.modes) == 1
    assert "only the drawn mode" in m.notes[0] and "not a Delta robot" in m.notes[0]
    assert "parallelogram" in m.notes[0]


def test_a_mode_that_meets_no_anchor_mode_is_cut_not_switched(
        six_bar: Mechanism, monkeypatch: pytest.MonkeyPatch) -> None:
    """With a match tolerance nothing can meet, every tracked end is a path jump: each mode
    stops at its anchor with an event and the next anchor's modes start anew, so no mode runs
    through an anchor it was not matched at."""
    from screwkit.kinematics.modes import along

    monkeypatch.setattr(along, "MATCH_TOLERANCE", -1.0)
    lay = graph_layout(six_bar)
    Xs = X[:9]  # one segment: anchors at samples 0 and 8
    got = along.modes_along(six_bar, lay, Xs, str)
    assert list(got.anchors) == [0, 8]
    cut = [k for k, ev in enumerate(got.events) if any(e.startswith("cut after") for e in ev)]
    fresh = [k for k, ev in enumerate(got.events) if any("path jump was refused" in e
                                                           for e in ev)]
    assert len(cut) == len(fresh) == 2
    for k in cut:
        assert got.masks[k].tolist() == [True] + [False] * 8
    for k in fresh:
        assert got.masks[k].all()  # tracked back from the last anchor to the first


def test_analyze_lists_every_mode_with_its_certificate() -> None:
    from typer.testing import CliRunner

    from screwkit.cli.main import app

    r = CliRunner().invoke(app, ["analyze", str(EXAMPLES / "stephenson3_sixbar.toml")])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())  # however the terminal wraps it
    assert "note: every mode along the motion: the homotopy at 46 anchor" in text
    assert "generic count 6" in text and "certified by Smale's α-test" in text
    for k in range(4):
        assert f"assembly mode {k}" in text
    assert text.count("is born at Q3.theta = 205.8") == 2
    assert text.count("dies at Q3.theta = 280.3") == 2


def test_the_two_modes_born_at_one_fold_are_one_circuit(motion: MechanismMotion) -> None:
    """Modes 2 and 3 are born together and die together (the homotopy's real count changes
    by two there, test above): they meet at both folds, so they are one circuit, and the two
    modes that assemble throughout are circuits of their own."""
    circuits = [n for n in motion.notes if n.startswith("circuits")]
    assert circuits and circuits[0].endswith("{0}, {1}, {2, 3}")
    assert all(not np.asarray(md.assembles).all() for md in motion.modes[2:])
    assert all(np.asarray(md.assembles).all() for md in motion.modes[:2])


def test_a_birth_inside_one_long_step_is_located(six_bar: Mechanism) -> None:
    """Two samples 23° apart, the fold 5° after the first: the born modes are tracked back
    the whole way and the fold is still where the homotopy's count changes."""
    m = solve_mechanism(six_bar, [[3.5], [3.9]], every_mode=True)
    born = [float(re.match(r"is born at Q3\.theta = ([-\d.]+) deg", ev)[1])  # type: ignore[index]
            for md in m.modes[2:] for ev in md.events if ev.startswith("is born")]
    assert len(m.modes) == 4 and len(born) == 2
    assert np.abs(np.radians(born) - _fine_fold(six_bar, 3.5, 3.9)).max() <= 1e-4


def test_a_spatial_7r_loop_has_every_mode_at_every_sample() -> None:
    """A random 7R loop driven at one joint (16 complex solutions per input): at every sample
    each reported mode is one of a fresh homotopy solve's (none spurious, none jumped) and
    closes to 1e-10, and none is missing: this loop has islands (modes born and dying between
    two anchors), found from the folds of the modes they meet."""
    import sys

    sys.path.insert(0, str(Path(__file__).parents[1]))
    from modes_helpers import random_r_loop

    mech = random_r_loop(np.random.default_rng(5), 7, [2])
    lay = graph_layout(mech)
    Xs = np.linspace(0.0, 1.2, 25)[:, None]
    m = solve_mechanism(mech, Xs, every_mode=True)
    assert "generic count 16" in m.notes[0]
    fresh = every_mode(mech, Xs)
    for n in range(len(Xs)):
        here = [md for md in m.modes if md.assembles[n]]
        theirs = pose_vectors(mech, lay, fresh.configurations[n])
        for md in here:
            mine = pose_vectors(mech, lay, md.conf.take(slice(n, n + 1)))
            assert np.abs(theirs - mine).max(axis=1).min() <= 1e-8, (n, md.label)
            residual = graph_forward(mech, lay, md.conf.take(slice(n, n + 1))).residual
            assert np.abs(residual).max() <= 1e-10 * max(mech.length_scale, 1.0)
        assert len(here) == len(theirs), n
    assert any(n.startswith("the homotopy also at") for n in m.notes)

"""One engine for single loops (issue 27): the generic loop solver seeds its branches from every
real solution of the polynomial homotopy where a formulation fits the loop
(kinematics/tracker/algebraic_roots.py), and the three misses of the random-start root search
are found. Each is checked against the family's closed form, an independent solver, sample by
sample and variable by variable; every mode closes the loop's own chain to 1e-10."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from screwkit.io.spec import load_spec
from screwkit.kinematics.motion import Motion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.families import fourbar, rccc, rssr

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FIVE_DEG = np.radians(np.arange(0.0, 360.0, 5.0))


def counts(motion: Motion) -> np.ndarray:
    return np.sum([md.assembles for md in motion.modes], axis=0)


def assert_same_modes(generic: Motion, closed: Motion, tol: float = 1e-7) -> None:
    """At every sample, the same number of modes, and each closed-form mode is a generic mode
    there (every joint variable within ``tol``, angles modulo 2π)."""
    np.testing.assert_array_equal(counts(generic), counts(closed))
    for md in closed.modes:
        names = [n for n in md.variables if all(n in g.variables for g in generic.modes)]
        assert any(n.endswith(".s") for n in names) or len(names) >= 3
        for k in np.flatnonzero(md.assembles):
            want = np.array([md.variables[n][k] for n in names])
            best = np.inf
            for g in generic.modes:
                if not g.assembles[k]:
                    continue
                d = np.array([g.variables[n][k] for n in names]) - want
                d = np.where([n.endswith(".theta") or n.endswith(".phi") for n in names],
                             np.mod(d + np.pi, 2 * np.pi) - np.pi, d)
                best = min(best, float(np.abs(d).max()))
            assert best <= tol, (k, best)
    for g in generic.modes:
        assert np.nanmax(g.closure_residual) < 1e-10


def test_an_rccc_with_a_small_twist_has_both_closed_form_modes() -> None:
    # |α2| ≈ 0.09: from 140° to 185° the C3 slides run to many link lengths and the random
    # starts found no assembly there (samples 28–37 of this 5° sweep); the homotopy in
    # Plücker coordinates does not see the slides as unknowns
    lk = rccc((0.20781, 0.58492, 2.58333, 1.94884), (0.62614, -0.08763, 1.23703, -0.609),
              0.98127)
    closed = solve_motion(lk, FIVE_DEG, method="closed")
    generic = solve_motion(lk, FIVE_DEG, method="generic")
    assert counts(closed)[28:38].tolist() == [2] * 10
    longest = max(lk.parameters[f"a{i}"] for i in range(1, 5))
    far = max(float(np.nanmax(np.abs(md.variables["C3.s"][28:38]))) for md in closed.modes)
    assert far > 5.0 * longest
    assert_same_modes(generic, closed)
    assert "RCCC polynomial homotopy" in generic.solver
    assert any("certified" in n for n in generic.notes)


@pytest.mark.parametrize("degrees", [np.arange(-30.0, 31.0, 5.0),  # 0° is an anchor
                                     np.arange(-28.0, 29.0, 4.0)])  # 0° between anchors
def test_a_deltoid_at_its_continuum_has_no_mode_there(degrees: np.ndarray) -> None:
    # a kite 4R (frame = crank, coupler = rocker): with the crank on the frame the coupler and
    # rocker turn freely together, a curve of closures and no mode (the closed form's 0; the
    # random-start solver reported 3)
    lk = fourbar(1.0, 1.0, 2.0, 2.0)
    theta = np.radians(degrees)
    closed = solve_motion(lk, theta, method="closed")
    generic = solve_motion(lk, theta, method="generic")
    at = int(np.argmin(np.abs(degrees)))
    assert counts(closed)[at] == 0 and counts(generic)[at] == 0
    assert_same_modes(generic, closed)
    assert any("continuum" in n for n in generic.notes)


@pytest.mark.parametrize("samples", [72, 3600])
def test_an_rssr_island_between_anchors_is_found_whole(samples: int) -> None:
    # this RSSR assembles (in two modes) only from 197.25° to 202.25°, between two anchors of
    # the root search (every 15°): no search at an anchor sees it and no branch ends next to
    # it. The anchors' complex roots send the homotopy to every degree in between
    # (generic_motion.DENSE_SPAN); random starts found nothing ("does not close")
    lk = rssr(0.77516, 4.697, 1.90463, 1.75588, 1.52148, 0.79997, -0.88486)
    theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    closed = solve_motion(lk, theta, method="closed")
    on = np.flatnonzero(counts(closed))
    assert counts(closed).max() == 2
    assert np.all(np.degrees(theta[on]) > 195.0) and np.all(np.degrees(theta[on]) < 210.0)
    generic = solve_motion(lk, theta, method="generic")
    assert_same_modes(generic, closed, tol=1e-6)


def test_a_loop_without_a_formulation_says_it_used_random_starts() -> None:
    lk = load_spec(EXAMPLES / "rrsrr_loop.toml").linkage
    m = solve_motion(lk, np.radians(np.arange(0.0, 60.0, 10.0)), method="generic")
    assert "random starts" in m.solver
    assert any("cannot promise every mode" in n for n in m.notes)


def test_a_7r_loop_at_one_input_gets_every_root_newton_finds_and_closes() -> None:
    # the 6R route (a 7R loop driven at one joint: six free joints, 16 complex solutions): every
    # root that Newton from random starts finds is among the homotopy's, and each of those
    # closes the loop's own chain
    from screwkit.kinematics.tracker.algebraic_roots import algebraic_roots, loop_formulation
    from screwkit.kinematics.tracker.loop import closure_error, forward, layout
    from screwkit.kinematics.tracker.solve import find_assemblies
    from screwkit.model.joints import Joint
    from screwkit.model.linkage import Linkage

    rng = np.random.default_rng(5)
    lk = Linkage.from_hartenberg_denavit(
        "7R", [Joint(f"J{i + 1}", "R") for i in range(7)], list(rng.uniform(0.5, 2.0, 7)),
        list(rng.uniform(-1.2, 1.2, 7)), inputs=["J1.theta"])
    lay = layout(lk)
    lf = loop_formulation(lk, lay)
    assert lf is not None and lf.name == "6R"
    X = np.radians([[40.0], [200.0]])
    roots = algebraic_roots(lf, lk, lay, X)
    assert roots.generic_count == 16 and roots.complete.all()
    newton = find_assemblies(lk, X, starts=96, seed=1)
    asm = roots.assemblies
    for r in range(2):
        mine = asm.signature[r][asm.found[r]]
        theirs = newton.signature[r][newton.found[r]]
        assert len(mine) >= len(theirs) >= 2
        d = np.abs(theirs[:, None, :] - mine[None, :, :]).max(axis=-1).min(axis=1)
        assert d.max() < 1e-6
    fr = forward(lk, asm.conf.take(np.flatnonzero(asm.found.ravel())), lay, frames=False)
    assert np.abs(closure_error(fr.closure_R, fr.closure_p)).max() < 1e-10


def test_a_deltoid_solved_only_at_its_continuum_says_so() -> None:
    from screwkit.kinematics.motion import AssemblyError

    with pytest.raises(AssemblyError, match="closes only on continua"):
        solve_motion(fourbar(1.0, 1.0, 2.0, 2.0), np.array([0.0]), method="generic")

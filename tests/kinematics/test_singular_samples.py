"""Honest singularities: where the rate equations have no unique solution the sample is flagged
singular, gets no rates, and its mode says why (docs/kinematics.md, "Singular samples"); a
continuum of closed configurations at one input is one degenerate set, not many modes."""

import numpy as np
import pytest

from screwkit.dual import Dual, ScrewMatrix
from screwkit.io.spec import load_spec
from screwkit.kinematics.closed_forms.closed_form_motion import rsrc_dimensions
from screwkit.kinematics.closed_forms.rsrc import rsrc_motion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.kinematics.tracker.generic_motion import generic_motion
from screwkit.kinematics.tracker.loop import forward, layout
from screwkit.kinematics.tracker.rates import rate_equations
from screwkit.model import Joint, Linkage
from screwkit.model.families import fourbar
from screwkit.model.linkage import Link

deg = np.radians
EXAMPLES = __import__("pathlib").Path(__file__).resolve().parents[2] / "examples"

A1, AL1, AL2 = 1.0, deg(40), deg(70)
A2 = A1 * np.sin(AL2) / np.sin(AL1)  # Bennett's condition a/sin α equal for both pairs


def _no_rates(md, at):
    for table in (md.velocities, md.accelerations):
        for values in table.values():
            assert np.all(np.isnan(values[at]))
    for arr in (md.link_angular_velocity, md.link_origin_acceleration):
        assert np.all(np.isnan(arr[at]))


def test_a_rigid_bennett_closes_only_at_isolated_inputs_and_gives_no_rates_there():
    # the Bennett linkage with its length a1 = a3 made 2 % longer: a rigid structure that
    # closes only folded flat (θ1 = 0 or 180°), where the input cannot move it
    joints = [Joint(f"B{i + 1}", "R") for i in range(4)]
    lk = Linkage.from_hartenberg_denavit("rigid Bennett", joints, [1.02 * A1, A2, 1.02 * A1, A2],
                                         [AL1, AL2, AL1, AL2], inputs=["B1.theta"])
    m = generic_motion(lk, deg(np.arange(0.0, 360.0, 30.0)))
    closes = np.any([md.assembles for md in m.modes], axis=0)
    assert closes.tolist() == [k in (0, 6) for k in range(12)]
    for md in m.modes:
        at = md.assembles
        assert md.singular[at].all()
        _no_rates(md, at)
        assert any("locked" in e and "rigid" in e for e in md.events)
        # the flag matters: the least-squares rates would leave |J q̇| ~ 1e-3 (not a solution)
        lay = layout(lk)
        eq = rate_equations(lk, lay, forward(lk, md.conf.take(np.nonzero(at)[0]), lay))
        _, residual = eq.solve(np.ones((1, 1)), np.zeros((1, 6)), np.zeros((1, 0)),
                               minimum_norm=True)
        assert residual.min() > 1e-4


def test_an_underdriven_5r_is_one_degenerate_set_per_input_without_rates():
    # a planar 5R driven at one joint keeps a one-dimensional motion at every input
    joints = [Joint(f"J{i + 1}", "R") for i in range(5)]
    lk = Linkage.from_hartenberg_denavit("5R", joints, [1.0, 2.0, 2.5, 2.0, 3.0], [0.0] * 5,
                                         inputs=["J1.theta"])
    m = generic_motion(lk, deg(np.arange(0.0, 360.0, 30.0)))
    assert len(m.modes) == 1  # not one mode per point of the continuum
    md = m.modes[0]
    assert md.assembles.all() and md.singular.all()
    _no_rates(md, md.assembles)
    assert any("left free with the input fixed" in e and "dimension 1" in e for e in md.events)
    assert np.nanmax(md.closure_residual) < 1e-10


def test_a_continuum_at_one_input_is_one_set():
    # a Bennett linkage whose fourth link's twist is turned by an extra joint E (the input):
    # only at E = 0 is it a Bennett — a one-dimensional set of closures at that one input
    def X(alpha, a):
        return ScrewMatrix.rot_x(Dual(alpha, a))

    def Ry(t):
        c, s = np.cos(t), np.sin(t)
        return ScrewMatrix.from_rotation_translation(
            np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]), np.zeros(3))

    transforms = (X(AL1, A1), X(AL2, A2), X(AL1, A1), X(AL2 / 2, A2 / 2) @ Ry(np.pi / 2),
                  Ry(-np.pi / 2) @ X(AL2 / 2, A2 / 2))
    joints = tuple(Joint(f"B{i + 1}", "R") for i in range(4)) + (Joint("E", "R"),)
    lk = Linkage("Bennett with a twisting joint", joints, transforms,
                 tuple(Link(f"l{i}") for i in range(4)), ("E.theta",))
    m = generic_motion(lk, deg(np.arange(-30.0, 31.0, 10.0)))
    assert len(m.modes) == 1
    md = m.modes[0]
    assert md.assembles.tolist() == [False] * 3 + [True] + [False] * 3
    assert md.singular[3]
    assert any("dimension 1" in e for e in md.events)


@pytest.mark.parametrize("method", ["closed", "generic"])
def test_rsrc_dead_centre_sample_is_singular_in_both_modes(method):
    # Bagci's Example 4 RSRC: the input reaches a dead centre near 73.5° where both modes meet;
    # a sample placed exactly there (the closed form's bisected event) is singular
    s = load_spec(EXAMPLES / "bagci_example4.toml")
    dims, _ = rsrc_dimensions(s.linkage)
    stop = next(e.theta0 for e in rsrc_motion(dims, deg(np.arange(0.0, 360.0, 1.0))).events
                if e.kind == "stops")
    theta = np.concatenate([np.linspace(stop - deg(20), stop, 21), [stop + deg(0.5)]])
    m = solve_motion(s.linkage, theta, method=method)
    assert len(m.modes) == 2
    for md in m.modes:
        assert md.assembles[:21].all() and not md.assembles[21]
        assert md.singular[20] and not md.singular[:20].any()
        _no_rates(md, np.arange(22) == 20)
        assert np.isfinite(md.velocities["phi0"][:20]).all()
        assert any("dead centre" in e for e in md.events)


def test_branches_that_cross_are_followed_through_the_bifurcation():
    # a Grashof-neutral 4R (parallelogram): at θ0 = 0 the parallelogram and the
    # antiparallelogram branches cross; the sample there is singular (a bifurcation) and each
    # branch is followed through it along its own tangent
    lk = fourbar(2.0, 1.0, 2.0, 1.0)
    theta = deg(np.arange(-30.0, 31.0, 5.0))
    m = generic_motion(lk, theta)
    assert len(m.modes) == 2
    for md in m.modes:
        assert md.assembles.all()
        assert md.singular.tolist() == [k == 6 for k in range(13)]
        assert any("bifurcation" in e for e in md.events)
    phi = sorted((md.variables["output.theta"] for md in m.modes), key=lambda v: v[-1])
    # the parallelogram keeps φ0 = θ0 (output.theta = −θ0) through the crossing
    assert any(np.allclose(-v, theta, atol=1e-9) for v in phi)

"""Taylor coefficients of the loop closure (kinematics/tracker/loop_jets.py) against Bagci's exact
App. D coefficients of the RSRC, the motion's rate equations, and differences of the exact
second derivative; branch following against the closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

import screwkit as sk
from screwkit.io.spec import load_spec
from screwkit.kinematics.closed_forms.rsrc import (
    RSRCDimensions,
    rsrc_output_derivatives,
    rsrc_positions,
)
from screwkit.kinematics.tracker.loop_jets import close_loop, closure_error, follow, taylor_jets

EXAMPLES = "examples"
THETA = np.radians(np.arange(0.0, 360.0, 30.0))


def _fig7():
    s = load_spec(f"{EXAMPLES}/bagci_fig7_rsrc.toml")
    return s.linkage, RSRCDimensions(**s.linkage.parameters)


def test_jets_equal_bagci_exact_taylor_coefficients_to_seventh_order():
    linkage, dims = _fig7()
    motion = sk.solve_motion(linkage, THETA, method="closed")
    for md in motion.modes:
        jets = taylor_jets(linkage, md.conf, 7)
        assert jets.residual.max() < 1e-13
        ours = -jets.derivatives("output_C.theta")  # φ0 = −output_C.theta
        ref = rsrc_output_derivatives(dims, THETA, md.variables["phi0"], order=7)
        scale = np.abs(ref).max(axis=0)
        np.testing.assert_allclose(ours, ref, atol=1e-12 * scale.max(), rtol=1e-10)


@pytest.mark.parametrize("name", ["rssr_spatial", "rahman_cssp", "rccc_loop", "fourbar_dynamics"])
def test_first_two_orders_are_the_motions_rates(name):
    s = load_spec(f"{EXAMPLES}/{name}.toml")
    motion = sk.solve_motion(s.linkage, s.inputs[::3], rates=1.0, accelerations=0.0)
    scalar = [f for j in s.linkage.joints if j.kind != "S" for f in j.freedom_names()]
    for md in motion.modes:
        ok = md.assembles & ~md.singular
        jets = taylor_jets(s.linkage, md.conf.take(np.nonzero(ok)[0]), 2)
        for f in scalar:
            d = jets.derivatives(f)
            np.testing.assert_allclose(d[:, 0], md.velocities[f][ok], atol=1e-9)
            np.testing.assert_allclose(d[:, 1], md.accelerations[f][ok], atol=1e-8)


def test_third_derivative_equals_differences_of_the_exact_second():
    s = load_spec(f"{EXAMPLES}/rssr_spatial.toml")
    motion = sk.solve_motion(s.linkage, np.radians([20.0, 110.0, 250.0]))
    md = motion.modes[0]
    h = 1e-3
    for i, x in enumerate(motion.input_values):
        third = taylor_jets(s.linkage, md.conf.take(np.array([i])), 3).derivatives("output.theta")
        xs = x + h * np.arange(-2, 3)
        conf, ok = follow(s.linkage, md.conf.take(np.full(5, i)), np.full(5, x), xs)
        assert ok.all()
        second = taylor_jets(s.linkage, conf, 2).derivatives("output.theta")[:, 1]
        fd = (second[0] - 8 * second[1] + 8 * second[3] - second[4]) / (12 * h)
        assert third[0, 2] == pytest.approx(fd, abs=1e-9)


def test_follow_lands_on_the_closed_form_branch():
    linkage, dims = _fig7()
    motion = sk.solve_motion(linkage, THETA, method="closed")
    md = motion.modes[1]
    target = THETA + math.radians(17.0)
    conf, ok = follow(linkage, md.conf, THETA, target)
    assert ok.all() and closure_error(linkage, conf).max() < 1e-12
    phi = -conf.scalars[:, -2]
    pos = rsrc_positions(dims, target)
    gap = np.abs(np.remainder(pos.phi0 - phi[:, None] + np.pi, 2 * np.pi) - np.pi)
    assert np.nanmin(gap, axis=1).max() < 1e-10


def test_close_loop_closes_a_perturbed_configuration():
    linkage, _ = _fig7()
    md = sk.solve_motion(linkage, THETA, method="closed").modes[0]
    q = md.conf.scalars.copy()
    q[:, 2:] += 1e-3  # passive freedoms moved off the loop
    moved = type(md.conf)(q, md.conf.spherical)
    conf, ok = close_loop(linkage, moved)
    assert ok.all()
    np.testing.assert_allclose(conf.scalars[:, -2], md.conf.scalars[:, -2], atol=1e-9)

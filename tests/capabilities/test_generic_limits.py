"""Limit positions and dwell orders by the generic route (any output of any loop) against
Bagci's App. D closed form on the RSRC and the 4R, and against an independent re-solve on the
RSSR; the refusals say why."""

from __future__ import annotations

import math

import numpy as np
import pytest

import screwkit as sk
from screwkit.errors import UnknownNameError
from screwkit.io.spec import load_spec
from screwkit.kinematics.analysis.limit_positions import limit_positions
from screwkit.model.joints import Joint
from screwkit.model.linkage import Linkage

EXAMPLES = "examples"
TURN = np.radians(np.arange(0.0, 360.0, 2.0))


def _gap(a: float, b: float) -> float:
    return abs(math.remainder(a - b, 2 * math.pi))


@pytest.mark.parametrize("name", ["bagci_fig7_rsrc", "bagci_fig9_dwell",
                                  "bagci_fig10_double_crank", "bagci_example3_4r"])
def test_generic_route_finds_bagcis_limits(name):
    s = load_spec(f"{EXAMPLES}/{name}.toml")
    closed = limit_positions(s.linkage, 1e-4, method="closed")
    generic = limit_positions(sk.solve_motion(s.linkage, TURN), 1e-4, method="generic")
    assert closed.method == "closed" and generic.method == "generic"
    assert len(generic.limits) == len(closed.limits) > 0
    for lim in closed.limits:
        match = min((g for g in generic.limits if g.output == lim.output),
                    key=lambda g: _gap(g.input, lim.input) + _gap(g.value, lim.value))
        assert _gap(match.input, lim.input) < 1e-10
        assert _gap(match.value, lim.value) < 1e-10
        assert match.second_derivative == pytest.approx(lim.second_derivative, abs=1e-9)
        if lim.dwell_order is not None:
            assert match.dwell_order == lim.dwell_order
            np.testing.assert_allclose(match.derivatives, lim.derivatives, atol=1e-8)
        assert abs(match.derivatives[0]) < 1e-11  # a zero of d output / d input


@pytest.mark.parametrize(("name", "at", "tol", "order"),
                         [("bagci_fig9_dwell", 270.0, 1e-4, 3),
                          ("bagci_fig10_double_crank", 220.33, 1e-2, 2)])
def test_generic_dwell_orders_of_fig9_and_fig10(name, at, tol, order):
    s = load_spec(f"{EXAMPLES}/{name}.toml")
    x = [math.radians(at)]
    closed = limit_positions(s.linkage, tol, at=x, output="phi0", method="closed")
    generic = limit_positions(sk.solve_motion(s.linkage, TURN), tol, at=x, output="phi0",
                              method="generic")
    assert sorted(d.dwell_order for d in generic.dwells_at) == \
        sorted(d.dwell_order for d in closed.dwells_at)
    assert order in [d.dwell_order for d in generic.dwells_at]
    for d in closed.dwells_at:
        g = min(generic.dwells_at, key=lambda g: _gap(g.value, d.value))
        np.testing.assert_allclose(g.derivatives, d.derivatives, rtol=1e-8, atol=1e-10)


def test_rssr_limits_are_extrema_of_an_independent_resolve():
    s = load_spec(f"{EXAMPLES}/rssr_spatial.toml")
    result = limit_positions(sk.solve_motion(s.linkage, s.inputs), output="phi0")
    assert result.method == "generic" and len(result.limits) == 4
    h = 1e-4
    for lim in result.limits:
        assert lim.dwell_order == 1 and abs(lim.derivatives[0]) < 1e-11
        around = sk.solve_motion(s.linkage, lim.input + h * np.array([-1.0, 0.0, 1.0]),
                                 method="generic")
        y = [md.variables["phi0"] for md in around.modes if md.assembles.all()]
        here = min(y, key=lambda v: _gap(v[1], lim.value))
        assert _gap(here[1], lim.value) < 1e-9
        second = (here[0] - 2 * here[1] + here[2]) / h**2
        assert second == pytest.approx(lim.second_derivative, rel=1e-3)


def test_joint_freedom_outputs_and_translation_inputs():
    s = load_spec(f"{EXAMPLES}/rccc_loop.toml")
    motion = sk.solve_motion(s.linkage, s.inputs)
    result = limit_positions(motion)
    assert result.outputs == ("C4.theta", "C4.s")
    for lim in result.limits:
        assert abs(lim.derivatives[0]) < 1e-10
        assert lim.kind == ("translation" if lim.output == "C4.s" else "rotation")
    for md in motion.modes:  # one limit per sign change of the rate (a full-turn sweep)
        for name in result.outputs:
            rate = md.velocities[name]
            changes = int(np.sum(np.sign(rate) != np.sign(np.roll(rate, 1))))
            assert changes == sum(1 for x in result.limits
                                  if x.mode == md.index and x.output == name)


def test_a_loop_without_an_output_joint_says_why():
    joints = [Joint("a", "R"), Joint("b", "R"), Joint("c", "R"), Joint("d", "R")]
    lk = Linkage.from_hartenberg_denavit("mid", joints, [1.0, 3.0, 2.5, 3.0], [0.0] * 4,
                                         ["b.theta"])
    with pytest.raises(ValueError, match="not one of the two joints on the ground"):
        limit_positions(lk)
    with pytest.raises(UnknownNameError, match="no output variable 'phi0'"):
        limit_positions(lk, output="phi0")


def test_closed_route_only_for_what_app_d_covers():
    s = load_spec(f"{EXAMPLES}/rssr_spatial.toml")
    with pytest.raises(ValueError, match="no closed-form limits"):
        limit_positions(s.linkage, method="closed")


def test_a_limit_across_the_end_of_a_full_turn_is_found():
    """Example 3's 4R has a limit at θ0 = 7.37°: with the sweep 10° … 360° it lies between the
    last sample and the first one turned by 360° (the mode comes back to itself)."""
    s = load_spec(f"{EXAMPLES}/bagci_example3_4r.toml")
    closed = limit_positions(s.linkage, method="closed")
    sweep = np.radians(np.arange(10.0, 361.0, 10.0))
    generic = limit_positions(sk.solve_motion(s.linkage, sweep), method="generic")
    assert len(generic.limits) == len(closed.limits) == 2
    for lim in closed.limits:
        assert min(_gap(g.input, lim.input) for g in generic.limits) < 1e-10
    assert all(sweep[0] <= g.input < sweep[0] + 2 * math.pi for g in generic.limits)

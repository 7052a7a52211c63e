"""Plane 4R closed form (Bagci 1969 §3.4, Freudenstein) vs the RSRC special case and the loop."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from screwkit.kinematics.closed_forms.fourbar import fourbar, fourbar_positions, fourbar_rates
from screwkit.kinematics.closed_forms.rsrc import rsrc_positions, rsrc_rates

CRANK_ROCKER = fourbar(a=3.0, d1=1.0, d2=3.5, d3=2.0)


def loop_residual(dims, pos) -> float:
    """|P + d2 e^(i g) - O2| with P the crank tip and O2 the rocker tip (plane (Y, Z))."""
    th = pos.theta0[:, None]
    crank_tip = dims.d1 * np.exp(1j * th)
    rocker_tip = dims.a + dims.d3 * np.exp(1j * pos.phi0)
    res = np.abs(crank_tip + dims.d2 * np.exp(1j * pos.coupler_angle) - rocker_tip)
    return float(np.max(res[pos.assembles], initial=0.0))


def test_fourbar_rejects_bad_links() -> None:
    with pytest.raises(ValueError, match="coupler"):
        fourbar(a=1, d1=1, d2=0, d3=1)
    with pytest.raises(ValueError, match="frame"):
        fourbar(a=float("nan"), d1=1, d2=1, d3=1)
    with pytest.raises(ValueError, match="theta0"):
        fourbar_positions(CRANK_ROCKER, [[0.0]])


def test_grashof_types() -> None:
    assert CRANK_ROCKER.grashof_type == "crank-rocker"
    assert fourbar(a=1.0, d1=3.0, d2=3.5, d3=2.5).grashof_type == "double-crank"
    assert fourbar(a=3.0, d1=2.0, d2=1.0, d3=2.5).grashof_type == "double-rocker"
    assert fourbar(a=2.2, d1=2.0, d2=1.5, d3=1.8).grashof_type == "double-rocker"
    assert fourbar(a=3.0, d1=1.5, d2=2.5, d3=1.2).grashof_type == "triple-rocker"
    assert fourbar(a=2.0, d1=1.0, d2=2.0, d3=1.0).grashof_type == "change-point"


@pytest.mark.parametrize(
    "dims",
    [CRANK_ROCKER, fourbar(a=1.0, d1=3.0, d2=3.5, d3=2.5), fourbar(a=2.2, d1=2.0, d2=1.5, d3=1.8)],
)
def test_fourbar_equals_rsrc_special_case(dims) -> None:
    theta = np.linspace(-math.pi, math.pi, 1441)
    pos = fourbar_positions(dims, theta)
    ref = rsrc_positions(dims.as_rsrc(), theta)
    assert np.array_equal(pos.assembles, ref.assembles[:, :2])
    ok = pos.assembles
    diff = np.angle(np.exp(1j * (pos.phi0[ok] - ref.phi0[:, :2][ok])))
    assert np.max(np.abs(diff)) < 1e-12
    np.testing.assert_allclose(pos.chi0[ok], ref.chi0[:, :2][ok], atol=1e-12)
    assert np.all(ref.S[:, :2][ok] == 0.0)  # b = e = 0, lambda0 = 0
    assert loop_residual(dims, pos) < 1e-12
    rates = fourbar_rates(dims, pos, 1.7, -0.3)
    ref_rates = rsrc_rates(dims.as_rsrc(), ref, 1.7, -0.3)
    v = rates.valid & ref_rates.valid[:, :2]
    np.testing.assert_allclose(rates.phi0_dot[v], ref_rates.phi0_dot[:, :2][v], rtol=1e-9,
                               atol=1e-10)
    np.testing.assert_allclose(rates.phi0_ddot[v], ref_rates.phi0_ddot[:, :2][v], rtol=1e-8,
                               atol=1e-9)
    # coupler angle = phi0 - chi0
    np.testing.assert_allclose(rates.coupler_angle_dot[v],
                               (ref_rates.phi0_dot - ref_rates.chi0_dot)[:, :2][v], rtol=1e-9,
                               atol=1e-10)
    np.testing.assert_allclose(rates.coupler_angle_ddot[v],
                               (ref_rates.phi0_ddot - ref_rates.chi0_ddot)[:, :2][v], rtol=1e-8,
                               atol=1e-9)


def test_mode_signs_and_nan_policy() -> None:
    pos = fourbar_positions(fourbar(a=2.2, d1=2.0, d2=1.5, d3=1.8), np.linspace(0, 6.28, 500))
    assert (~pos.assembles).any() and pos.assembles.any()
    for arr in (pos.phi0, pos.chi0, pos.coupler_angle):
        assert np.array_equal(np.isnan(arr), ~pos.assembles)
    assert np.all(pos.chi0[pos.assembles[:, 0], 0] <= 0)
    assert np.all(pos.chi0[pos.assembles[:, 1], 1] >= 0)


def test_rates_match_finite_differences() -> None:
    """5-point differences, h = 1e-3 (errors ~1e-12 and ~1e-10): bound 1e-7."""
    h = 1e-3
    theta = 0.9 + h * np.arange(-2, 3)
    pos = fourbar_positions(CRANK_ROCKER, theta)
    rates = fourbar_rates(CRANK_ROCKER, pos)
    for col in (0, 1):
        for angle, dot, ddot in ((pos.phi0, rates.phi0_dot, rates.phi0_ddot),
                                 (pos.coupler_angle, rates.coupler_angle_dot,
                                  rates.coupler_angle_ddot)):
            f = np.unwrap(angle[:, col])
            first = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h)
            second = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
            assert dot[2, col] == pytest.approx(first, abs=1e-7)
            assert ddot[2, col] == pytest.approx(second, abs=1e-6)


def test_dead_centre_is_locked() -> None:
    """Double rocker at a crank limit: coupler and rocker in line, sin chi0 = 0."""
    dims = fourbar(a=2.2, d1=2.0, d2=1.5, d3=1.8)
    # |O1 - O3| = d2 + d3 at the limit: 2.2^2 + 4 - 8.8 cos th = 3.3^2
    theta = math.acos((2.2**2 + 2.0**2 - 3.3**2) / (2 * 2.2 * 2.0))
    pos = fourbar_positions(dims, [theta])
    assert pos.assembles[0].all()
    rates = fourbar_rates(dims, pos)
    assert rates.locked[0].all() and np.all(np.isnan(rates.phi0_dot[0]))


@settings(derandomize=True, max_examples=50, deadline=None)
@given(st.floats(0.3, 4.0), st.floats(0.3, 4.0), st.floats(0.3, 4.0), st.floats(0.3, 4.0),
       st.lists(st.floats(-math.pi, math.pi), min_size=1, max_size=6))
def test_property_loop_closes(a: float, d1: float, d2: float, d3: float,
                              theta: list[float]) -> None:
    dims = fourbar(a=a, d1=d1, d2=d2, d3=d3)
    pos = fourbar_positions(dims, theta)
    assert loop_residual(dims, pos) < 1e-10 * (a + d1 + d2 + d3)


def test_output_angles_equal_fourbar_positions():
    from screwkit.kinematics.closed_forms.fourbar import fourbar_output_angles

    for dims in (fourbar(3.0, 1.0, 3.5, 2.0), fourbar(2.0, 1.8, 2.2, 1.5), fourbar(1.0, 3.0, 3.0, 1.0)):
        th = np.linspace(0.0, 2 * np.pi, 2001)
        p = fourbar_positions(dims, th).phi0
        q = fourbar_output_angles(dims, th)
        assert (np.isnan(p) == np.isnan(q)).all()
        diff = np.angle(np.exp(1j * (q[~np.isnan(q)] - p[~np.isnan(p)])))  # ±π are one angle
        assert np.max(np.abs(diff)) < 1e-13

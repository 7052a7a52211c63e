"""CSSP closed form over random dimensions: loop closure, both roots, exact derivatives checked by
complex step and high-order finite differences, rod angular motion, angle-rate consistency."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from screwkit.kinematics.closed_forms.cssp import (
    CSSPDimensions,
    assembly_discriminant,
    cssp_motion,
    cssp_positions,
    slider_and_rod,
)

SETTINGS = settings(derandomize=True, max_examples=60, deadline=None)
H = 1e-30  # complex step: no subtractive cancellation, so any tiny step is exact to round-off


@st.composite
def assembled_cases(draw: st.DrawFn) -> dict[str, Any]:
    """Random CSSP built to assemble at θ0 with s4 = s4_0 (a2 := |P − D1|), plus random rates
    and crank angles near θ0; mode chosen to match the root s4_0 lies on."""
    a1 = draw(st.floats(0.02, 1.0))
    a4 = draw(st.floats(-1.0, 1.0))
    alpha4 = draw(st.floats(0.0, 2 * np.pi))
    s1 = draw(st.floats(-0.5, 0.5))
    theta0 = draw(st.floats(-np.pi, np.pi))
    s4_0 = draw(st.floats(-3.0, 3.0))
    pin = np.array([a1 * np.cos(theta0), a1 * np.sin(theta0), s1])
    ball = np.array([-a4, -s4_0 * np.sin(alpha4), -s4_0 * np.cos(alpha4)])
    a2 = float(np.linalg.norm(ball - pin))
    assume(a2 > 1e-2)
    dims = CSSPDimensions(a1=a1, a2=a2, a4=a4, alpha4=alpha4, s1=s1)
    b = a1 * np.sin(theta0) * np.sin(alpha4) + s1 * np.cos(alpha4)
    mode = 1 if s4_0 + b >= 0 else -1
    offsets = np.array([draw(st.floats(-0.05, 0.05)) for _ in range(6)])
    theta = theta0 + offsets
    disc = assembly_discriminant(dims, theta)
    # stay clear of branch points, where the rates are unbounded and ill-conditioned
    assume(np.all(disc > 1e-3 * (a1 + a2 + abs(a4) + abs(s1)) ** 2))
    rates = {
        "theta1_dot": draw(_rate(50.0)),
        "theta1_ddot": draw(_rate(500.0)),
        "s1_dot": draw(_rate(1.0)),
        "s1_ddot": draw(_rate(10.0)),
    }
    return {"dims": dims, "mode": mode, "theta": theta, "rates": rates}


def _rate(limit: float) -> st.SearchStrategy[float]:
    """0 or a magnitude in [1e-3, 1]·limit (no subnormals: the complex step would underflow)."""
    magnitude = st.floats(1e-3 * limit, limit)
    return st.one_of(st.just(0.0), magnitude, magnitude.map(lambda x: -x))


def _scale(x: np.ndarray) -> float:
    return float(np.max(np.abs(x))) + 1e-300


def natural_scales(case: dict[str, Any]) -> dict[str, float]:
    """Size of positions, velocities and accelerations of the case (m, m/s, m/s²), for
    absolute tolerances that do not collapse when a rate happens to vanish."""
    dims, r = case["dims"], case["rates"]
    size = dims.a1 + dims.a2 + abs(dims.a4) + abs(dims.s1)
    vel = size * abs(r["theta1_dot"]) + abs(r["s1_dot"])
    acc = size * (r["theta1_dot"] ** 2 + abs(r["theta1_ddot"])) + abs(r["s1_ddot"]) + vel**2 / size
    return {"pos": size, "vel": vel + 1e-300, "acc": acc + 1e-300}


@SETTINGS
@given(assembled_cases())
def test_closure_and_both_roots(case: dict[str, Any]) -> None:
    dims, theta = case["dims"], case["theta"]
    size = dims.a1 + dims.a2 + abs(dims.a4) + abs(dims.s1)
    plus = cssp_positions(dims, theta, root=1)
    minus = cssp_positions(dims, theta, root=-1)
    for pos in (plus, minus):
        assert np.all(pos.assembles)
        np.testing.assert_array_less(pos.loop_closure_gap, 1e-12 * size)
        np.testing.assert_allclose(np.linalg.norm(pos.rod_direction, axis=-1), 1.0, atol=1e-12)
    # Vieta: s4⁺ + s4⁻ = −2b, s4⁺ s4⁻ = c
    sa, ca = np.sin(dims.alpha4), np.cos(dims.alpha4)
    b = dims.a1 * np.sin(theta) * sa + dims.s1 * ca
    c = dims.a4**2 + 2 * dims.a1 * dims.a4 * np.cos(theta) + dims.a1**2 + dims.s1**2 - dims.a2**2
    np.testing.assert_allclose(plus.s4 + minus.s4, -2 * b, rtol=0, atol=1e-13 * size)
    np.testing.assert_allclose(plus.s4 * minus.s4, c, rtol=0, atol=1e-13 * size**2)
    assert np.all(plus.s4 >= minus.s4)


@SETTINGS
@given(assembled_cases())
def test_rates_equal_complex_step_derivatives(case: dict[str, Any]) -> None:
    """First derivatives: complex step on the positions along θ1(t), s1(t). Second derivatives:
    complex step on the (independently checked) first derivatives."""
    dims, mode, theta, r = case["dims"], case["mode"], case["theta"], case["rates"]
    motion = cssp_motion(dims, theta, root=mode, **r)
    n = theta.shape[0]
    w, wd, s1d, s1dd = (
        np.full(n, r[k]) for k in ("theta1_dot", "theta1_ddot", "s1_dot", "s1_ddot")
    )
    s1 = np.full(n, dims.s1)
    t = 1j * H
    # along the path θ1(t) = θ1 + θ̇1 t + ½θ̈1 t², s1(t) likewise
    stepped = slider_and_rod(
        dims,
        theta + w * t + 0.5 * wd * t**2,
        w + wd * t,
        wd.astype(complex),
        s1 + s1d * t + 0.5 * s1dd * t**2,
        s1d + s1dd * t,
        s1dd.astype(complex),
        mode,
    )
    pairs = [
        ("s4", "s4_dot"),
        ("s4_dot", "s4_ddot"),
        ("rod_direction", "rod_direction_dot"),
        ("rod_direction_dot", "rod_direction_ddot"),
        ("slider_ball", "slider_ball_velocity"),
        ("slider_ball_velocity", "slider_ball_acceleration"),
        ("crank_pin", "crank_pin_velocity"),
        ("crank_pin_velocity", "crank_pin_acceleration"),
    ]
    nat = natural_scales(case)
    for value, rate in pairs:
        expected = stepped[value].imag / H
        got = getattr(motion, rate)
        scale = nat["acc" if rate.endswith(("ddot", "acceleration")) else "vel"]
        if rate.startswith("rod_direction"):
            scale /= dims.a2
        # 1e-10: the rates divide by s4 + b = ±√(b² − c); the strategy keeps |s4 + b| above
        # 3 % of the mechanism size, so round-off is amplified by at most ~30 (and ~30² for s̈4)
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-10 * scale, err_msg=rate)


@SETTINGS
@given(assembled_cases())
def test_rod_angular_motion_has_no_spin_and_moves_u(case: dict[str, Any]) -> None:
    dims, mode, theta, r = case["dims"], case["mode"], case["theta"], case["rates"]
    m = cssp_motion(dims, theta, root=mode, **r)
    u, ud, udd = m.rod_direction, m.rod_direction_dot, m.rod_direction_ddot
    w, a = m.rod_angular_velocity, m.rod_angular_acceleration
    nat = natural_scales(case)
    sw, sa = nat["vel"] / dims.a2, nat["acc"] / dims.a2
    np.testing.assert_allclose(np.einsum("ni,ni->n", w, u), 0.0, atol=1e-12 * sw)
    np.testing.assert_allclose(np.cross(w, u), ud, rtol=0, atol=1e-12 * sw)
    np.testing.assert_allclose(
        np.cross(a, u) + np.cross(w, np.cross(w, u)), udd, rtol=0, atol=1e-12 * sa
    )


@SETTINGS
@given(assembled_cases())
def test_angle_rates_reproduce_rod_direction_rates(case: dict[str, Any]) -> None:
    """u = (cη2 cφ, cη2 sφ, −sη2) with φ = θ1 + θ2, and X(α4)·u = (cθ3 cη3, cθ3 sη3, sθ3):
    the chain rule with the reported angle rates must give the (complex-step checked) u̇, ü."""
    dims, mode, theta, r = case["dims"], case["mode"], case["theta"], case["rates"]
    m = cssp_motion(dims, theta, root=mode, **r)
    assume(np.all(m.rod_angles_defined) and np.all(m.slider_angles_defined))
    rot4 = np.array(
        [
            [1.0, 0.0, 0.0],
            [0.0, np.cos(dims.alpha4), -np.sin(dims.alpha4)],
            [0.0, np.sin(dims.alpha4), np.cos(dims.alpha4)],
        ]
    )
    rod = (
        m.theta1 + m.theta2,
        m.theta1_dot + m.theta2_dot,
        m.theta1_ddot + m.theta2_ddot,
        -m.eta2,
        -m.eta2_dot,
        -m.eta2_ddot,
    )
    slider = (m.eta3, m.eta3_dot, m.eta3_ddot, m.theta3, m.theta3_dot, m.theta3_ddot)
    frames = [(rod, np.eye(3)), (slider, rot4)]
    for (az, az_d, az_dd, el, el_d, el_dd), rot in frames:
        ce, se, ca, sa = np.cos(el), np.sin(el), np.cos(az), np.sin(az)
        v = np.stack([ce * ca, ce * sa, se], axis=-1)
        dv_del = np.stack([-se * ca, -se * sa, ce], axis=-1)
        dv_daz = np.stack([-ce * sa, ce * ca, np.zeros_like(ce)], axis=-1)
        vd = dv_del * el_d[:, None] + dv_daz * az_d[:, None]
        # second derivative of v(el, az) along the path
        d2_elel = -v
        d2_azaz = np.stack([-ce * ca, -ce * sa, np.zeros_like(ce)], axis=-1)
        d2_elaz = np.stack([se * sa, -se * ca, np.zeros_like(ce)], axis=-1)
        vdd = (
            dv_del * el_dd[:, None]
            + dv_daz * az_dd[:, None]
            + d2_elel * (el_d**2)[:, None]
            + d2_azaz * (az_d**2)[:, None]
            + 2 * d2_elaz * (el_d * az_d)[:, None]
        )
        np.testing.assert_allclose(v, m.rod_direction @ rot.T, rtol=0, atol=1e-14)
        ud, udd = m.rod_direction_dot @ rot.T, m.rod_direction_ddot @ rot.T
        # the angle rates divide by cos(elevation); allow that amplification of round-off
        amp = 1.0 / float(np.min(ce))
        nat = natural_scales(case)
        sv, sa = nat["vel"] / dims.a2, nat["acc"] / dims.a2
        np.testing.assert_allclose(vd, ud, rtol=0, atol=1e-11 * amp * sv)
        np.testing.assert_allclose(vdd, udd, rtol=0, atol=1e-11 * amp**3 * sa)


def _central_difference(f: np.ndarray, h: float, order: int) -> np.ndarray:
    """8th-order central difference of samples f(t0 + k h), k = −4..4, along axis 0."""
    weights = {
        1: np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280]),
        2: np.array(
            [-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560]
        ),
    }[order]
    return np.tensordot(weights, f, axes=(0, 0)) / h**order


@pytest.mark.parametrize("mode", [1, -1])
def test_angle_rates_against_finite_differences(mode: int) -> None:
    """Rahman's example with a driven s1 and crank acceleration; angles sampled along the
    motion and differentiated by 8th-order central differences (truncation ~h⁸)."""
    dims = CSSPDimensions(a1=0.0508, a2=0.2032, a4=0.0254, alpha4=np.radians(250.0), s1=0.01)
    w0, wd, s1d, s1dd = 3.0, 2.0, 0.02, -0.1
    t0 = np.linspace(0.0, 2.0, 7)
    h = 1e-3
    ks = np.arange(-4, 5)
    t = t0[None, :] + ks[:, None] * h  # (9, 7)
    theta = w0 * t + 0.5 * wd * t**2
    s1 = dims.s1 + s1d * t + 0.5 * s1dd * t**2
    pos = cssp_positions(dims, theta.ravel(), root=mode, s1=s1.ravel())
    motion = cssp_motion(
        dims,
        w0 * t0 + 0.5 * wd * t0**2,
        w0 + wd * t0,
        wd,
        root=mode,
        s1=dims.s1 + s1d * t0 + 0.5 * s1dd * t0**2,
        s1_dot=s1d + s1dd * t0,
        s1_ddot=s1dd,
    )
    for name in ("theta2", "eta2", "theta3", "eta3", "s4"):
        samples = np.unwrap(getattr(pos, name).reshape(9, 7), axis=0)
        for order, suffix in ((1, "_dot"), (2, "_ddot")):
            fd = _central_difference(samples, h, order)
            exact = getattr(motion, name + suffix)
            # FD round-off ~eps/h^order: 1e-13/1e-3 and 1e-16/1e-6 → 1e-10 relative is safe
            np.testing.assert_allclose(
                fd, exact, rtol=0, atol=1e-8 * _scale(exact), err_msg=name + suffix
            )

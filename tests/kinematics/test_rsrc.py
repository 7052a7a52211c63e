"""RSRC closed form (Bagci 1969, Ch. III, App. C, App. D) checked against independent paths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from screwkit.kinematics.closed_forms.quartic import (
    real_quartic_roots,
    real_roots_of_trig_quadratic,
)
from screwkit.kinematics.closed_forms.rsrc import (
    RSRCDimensions,
    RSRCPositions,
    dwell_order,
    rsrc_coupler_point,
    rsrc_dwell_order,
    rsrc_kinematics,
    rsrc_motion,
    rsrc_output_derivatives,
    rsrc_positions,
    rsrc_rates,
    rsrc_rotation_limits,
    rsrc_translation_limits,
)

DEG = math.pi / 180.0

# Reference mechanisms of SPEC §3.6 (Bagci Fig. 7/8, 9, 10), inches and radians
FIG7 = RSRCDimensions(d1=2, d2=4.5, d3=3, a=3, b=3, e=1, delta0=18 * DEG, lambda0=60 * DEG)
FIG9 = RSRCDimensions(d1=2, d2=4, d3=2.925, a=2.75, b=4.6156, e=0, delta0=0, lambda0=60 * DEG)
FIG10 = RSRCDimensions(d1=2, d2=1.7, d3=1.5, a=0.75, b=0.4, e=0, delta0=0, lambda0=60 * DEG)


# ------------------------------------------------------------------ independent reference paths


def rot_x(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    z, o = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1),
                     np.stack([z, s, c], -1)], -2)


def rot_y(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    z, o = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1),
                     np.stack([-s, z, c], -1)], -2)


def master_loop(dims: RSRCDimensions, phi: np.ndarray, s: np.ndarray, chi: np.ndarray):
    """Sphere centre and coupler frame B from the output side (SPEC §3.1 master position loop)."""
    e1, e2 = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    lam = np.full_like(phi, dims.lambda0)
    dlt = np.full_like(phi, -dims.delta0)
    a_mat = rot_y(lam) @ rot_x(phi)
    b_mat = a_mat @ rot_y(dlt) @ rot_x(-chi)
    o3 = np.array([dims.b, dims.a, 0.0])
    centre = (o3 - s[..., None] * (rot_y(lam) @ e1) + dims.d3 * (a_mat @ e2)
              + dims.e * (b_mat @ e1) - dims.d2 * (b_mat @ e2))
    return centre, b_mat


def closure_error(dims: RSRCDimensions, pos: RSRCPositions) -> float:
    """Largest relative distance between the sphere centre from both sides of the loop."""
    ok = pos.assembles
    theta = np.broadcast_to(pos.theta0[:, None], ok.shape)[ok]
    centre, _ = master_loop(dims, pos.phi0[ok], pos.S[ok], pos.chi0[ok])
    input_side = np.stack([0 * theta, dims.d1 * np.cos(theta), dims.d1 * np.sin(theta)], -1)
    return float(np.max(np.linalg.norm(centre - input_side, axis=-1), initial=0.0)
                 / dims.length_scale)


def follow(dims: RSRCDimensions, theta: float, phi: float, offsets: np.ndarray,
           column: int | None = None):
    """(phi, chi, S) of the root nearest to ``phi`` at theta + offsets (small offsets), or of a
    fixed column (delta0 = +-pi/2, whose chi0-sign pairs share phi0)."""
    pos = rsrc_positions(dims, theta + offsets)
    dist = np.abs(np.angle(np.exp(1j * (np.nan_to_num(pos.phi0, nan=1e9) - phi))))
    dist = np.where(pos.assembles, dist, np.inf)
    j = np.argmin(dist, axis=1) if column is None else np.full(offsets.size, column)
    rows = np.arange(offsets.size)
    return np.unwrap(pos.phi0[rows, j]), np.unwrap(pos.chi0[rows, j]), pos.S[rows, j]


def five_point(values: np.ndarray, h: float) -> tuple[float, float]:
    """First and second derivative from samples at -2h..2h (errors O(h^4))."""
    fm2, fm1, f0, f1, f2 = values
    first = (fm2 - 8 * fm1 + 8 * f1 - f2) / (12 * h)
    second = (-fm2 + 16 * fm1 - 30 * f0 + 16 * f1 - f2) / (12 * h * h)
    return first, second


# ------------------------------------------------------------------ dimensions and inputs


def test_dimensions_reject_bad_values() -> None:
    with pytest.raises(ValueError, match="d1"):
        RSRCDimensions(d1=0, d2=1, d3=1, a=1, b=0, e=0, delta0=0, lambda0=0)
    with pytest.raises(ValueError, match="d2"):
        RSRCDimensions(d1=1, d2=-1, d3=1, a=1, b=0, e=0, delta0=0, lambda0=0)
    with pytest.raises(ValueError, match="d3"):
        RSRCDimensions(d1=1, d2=1, d3=-1, a=1, b=0, e=0, delta0=0, lambda0=0)
    with pytest.raises(ValueError, match="finite"):
        RSRCDimensions(d1=1, d2=1, d3=1, a=float("nan"), b=0, e=0, delta0=0, lambda0=0)


def test_positions_reject_bad_input_angles() -> None:
    with pytest.raises(ValueError, match=r"theta0\[1\]"):
        rsrc_positions(FIG7, [0.0, float("inf")])
    with pytest.raises(ValueError, match="1-D"):
        rsrc_positions(FIG7, np.zeros((2, 2)))
    with pytest.raises(ValueError, match="theta0_dot"):
        rsrc_rates(FIG7, rsrc_positions(FIG7, [0.0, 1.0]), np.zeros(3))


# ------------------------------------------------------------------ Fig. 7/8 worked values


def test_fig7_worked_values_at_100_degrees() -> None:
    """SPEC §3.6 table, 6 digits (theta0-dot = 1, theta0-ddot = 0)."""
    pos, rates = rsrc_kinematics(FIG7, [100 * DEG])
    assert pos.n_assemblies[0] == 2
    # label 2 = larger tan(phi0/2) = root A, label 1 = root B
    root_a = dict(phi=119.797172, chi=52.545308, S=3.052906, dphi=0.402247, dchi=0.649163,
                  dS=-0.849736, ddphi=0.310773, ddchi=0.104496, ddS=-1.328912)
    root_b = dict(phi=-81.030575, chi=-64.626507, S=5.413226, dphi=-0.759859, dS=0.075582,
                  ddphi=0.629419, ddS=-2.148684)
    for col, ref in ((1, root_a), (0, root_b)):
        got = dict(phi=pos.phi0[0, col] / DEG, chi=pos.chi0[0, col] / DEG, S=pos.S[0, col],
                   dphi=rates.phi0_dot[0, col], dchi=rates.chi0_dot[0, col],
                   dS=rates.S_dot[0, col], ddphi=rates.phi0_ddot[0, col],
                   ddchi=rates.chi0_ddot[0, col], ddS=rates.S_ddot[0, col])
        for key, value in ref.items():
            assert got[key] == pytest.approx(value, abs=1.5e-6), key


def test_fig7_two_real_roots_at_every_input_angle() -> None:
    pos = rsrc_positions(FIG7, np.radians(np.arange(0, 360, 5.0)))
    assert np.all(pos.n_assemblies == 2)


# ------------------------------------------------------------------ loop closure


SPECIAL_MECHANISMS = {
    "general": FIG7,
    "delta0_n_pi": FIG9,
    "delta0_pi": RSRCDimensions(d1=2, d2=4, d3=2.925, a=2.75, b=4.6, e=0.7, delta0=math.pi,
                                lambda0=60 * DEG),
    "delta0_half_pi": RSRCDimensions(d1=1.5, d2=3.0, d3=0.5, a=2.0, b=1.0, e=0.4,
                                     delta0=math.pi / 2, lambda0=40 * DEG),
    "delta0_minus_half_pi": RSRCDimensions(d1=1.5, d2=3.0, d3=0.5, a=2.0, b=1.0, e=0.4,
                                           delta0=-math.pi / 2, lambda0=40 * DEG),
    "planar": RSRCDimensions(d1=1, d2=3.5, d3=2, a=3, b=0, e=0, delta0=0, lambda0=0),
}


@pytest.mark.parametrize("name", sorted(SPECIAL_MECHANISMS))
def test_master_loop_closes(name: str) -> None:
    dims = SPECIAL_MECHANISMS[name]
    pos = rsrc_positions(dims, np.linspace(-math.pi, math.pi, 721))
    assert pos.assembles.any()
    assert closure_error(dims, pos) < 1e-10
    # NaN exactly where the mask says
    for arr in (pos.phi0, pos.chi0, pos.S):
        assert np.array_equal(np.isnan(arr), ~pos.assembles)


def test_half_pi_returns_both_chi_signs_with_both_translations() -> None:
    dims = SPECIAL_MECHANISMS["delta0_half_pi"]
    pos = rsrc_positions(dims, np.linspace(0, 2 * math.pi, 91))
    both = pos.assembles[:, 0] & pos.assembles[:, 2]
    assert both.any()
    np.testing.assert_allclose(pos.phi0[both, 0], pos.phi0[both, 2])
    np.testing.assert_allclose(pos.chi0[both, 0], -pos.chi0[both, 2])
    assert np.all(pos.chi0[both, 0] >= 0)
    # S = ... - d2 sin(delta0) sin(chi0): the two modes differ by 2 d2 sin(chi0)
    np.testing.assert_allclose(pos.S[both, 2] - pos.S[both, 0],
                               2 * dims.d2 * np.sin(pos.chi0[both, 0]), atol=1e-12)


def test_delta0_n_pi_labels_follow_program_a() -> None:
    """Program A/C: tan(phi0/2) = (-BO +- sqrt(AO^2 + BO^2 - CO^2))/(CO - AO), label 1 = '+'."""
    for dims in (FIG9, SPECIAL_MECHANISMS["delta0_pi"], FIG10):
        theta = np.radians(np.arange(0.5, 360, 7.0))
        pos = rsrc_positions(dims, theta)
        m0 = dims.b * math.sin(dims.lambda0) - dims.d1 * math.cos(dims.lambda0) * np.sin(theta)
        n0 = dims.a - dims.d1 * np.cos(theta)
        ao, bo = 2 * dims.d3 * n0, 2 * dims.d3 * m0
        co = dims.d3**2 - dims.d2**2 + n0**2 + m0**2
        radi = ao**2 + bo**2 - co**2
        ok = radi > 1e-9
        for col, sign in ((0, 1.0), (1, -1.0)):
            phi = 2 * np.arctan((-bo[ok] + sign * np.sqrt(radi[ok])) / (co[ok] - ao[ok]))
            diff = np.angle(np.exp(1j * (pos.phi0[ok, col] - phi)))
            assert np.max(np.abs(diff)) < 1e-9
        assert np.array_equal(pos.assembles[:, 0], ok)
        # cos(delta0) > 0: label 1 has sin(chi0) <= 0 (SPEC §3.4 "robust definition")
        sign_cd = math.copysign(1.0, math.cos(dims.delta0))
        assert np.all(sign_cd * pos.chi0[ok, 0] <= 1e-12)


def test_delta0_half_pi_labels_follow_program_a() -> None:
    """Eq. 3.76 in program form: t = (-N0 +- sqrt(N0^2 + M0^2 - e^2 sin^2 delta0))/(M0 - e sin delta0)."""
    dims = SPECIAL_MECHANISMS["delta0_half_pi"]
    theta = np.radians(np.arange(0.5, 360, 7.0))
    pos = rsrc_positions(dims, theta)
    m0 = dims.b * math.sin(dims.lambda0) - dims.d1 * math.cos(dims.lambda0) * np.sin(theta)
    n0 = dims.a - dims.d1 * np.cos(theta)
    es = dims.e * math.sin(dims.delta0)
    for col, sign in ((0, 1.0), (1, -1.0)):
        ok = pos.assembles[:, col]
        phi = 2 * np.arctan((-n0 + sign * np.sqrt(n0**2 + m0**2 - es**2)) / (m0 - es))
        diff = np.angle(np.exp(1j * (pos.phi0[ok, col] - phi[ok])))
        assert ok.any() and np.max(np.abs(diff)) < 1e-9


def test_root_at_phi_equal_pi_where_the_quartic_leading_coefficient_vanishes() -> None:
    """A4 = -K - F3 = 0 means phi0 = pi solves (3.62): choose d2 so that it does at theta0 = 0.4."""
    base = FIG7
    theta = 0.4
    m0 = base.b * math.sin(base.lambda0) - base.d1 * math.cos(base.lambda0) * math.sin(theta)
    n0 = base.a - base.d1 * math.cos(theta)
    sd, cd = math.sin(base.delta0), math.cos(base.delta0)
    w1 = -n0 + base.d3  # at phi0 = pi
    w2 = m0 - base.e * sd
    d2 = math.sqrt(w1**2 + (w2 / cd) ** 2)
    dims = RSRCDimensions(d1=base.d1, d2=d2, d3=base.d3, a=base.a, b=base.b, e=base.e,
                          delta0=base.delta0, lambda0=base.lambda0)
    pos = rsrc_positions(dims, [theta])
    phis = pos.phi0[0, pos.assembles[0]]
    assert np.min(np.abs(np.abs(phis) - math.pi)) < 1e-12
    assert closure_error(dims, pos) < 1e-12


FOUR_ROOTS = RSRCDimensions(d1=2.9, d2=3.6, d3=1.5, a=-1.9, b=-0.6, e=0.0, delta0=1.2,
                            lambda0=0.8)


def test_four_real_inversions_are_labelled_by_ascending_tan_half_phi() -> None:
    """Up to 4 geometric inversions (§3.4); labels 1..4 = ascending tan(phi0/2)."""
    theta = np.radians(np.arange(130.0, 175.0, 5.0))
    pos = rsrc_positions(FOUR_ROOTS, theta)
    assert np.all(pos.n_assemblies == 4)
    assert np.all(np.diff(np.tan(pos.phi0 / 2), axis=1) > 0)
    assert closure_error(FOUR_ROOTS, pos) < 1e-10
    assert pos.inversion_label[0].tolist() == [1, 2, 3, 4]
    # rotation limits: up to 8 in general (App. D); this one has several on 4 branches
    limits = rsrc_rotation_limits(FOUR_ROOTS)
    assert 1 <= len(limits) <= 8
    for lim in limits:
        q4, q5, *_ = q_terms(FOUR_ROOTS, lim.theta0, lim.phi0, lim.chi0)
        assert abs(q4) < 1e-10 * FOUR_ROOTS.length_scale**2


# ------------------------------------------------------------------ velocities, accelerations


@pytest.mark.parametrize("name", ["general", "delta0_n_pi", "delta0_half_pi", "planar"])
def test_rates_match_finite_differences(name: str) -> None:
    """(3.77)-(3.82) vs 5-point differences of the closed-form positions along each root.

    Step h = 1e-3: truncation ~h^4 f^(5) ~ 1e-12, rounding ~ eps/h ~ 1e-13 (first derivative) and
    eps/h^2 ~ 1e-10 (second), so 1e-7 is a safe bound that still catches any sign error.
    """
    dims = SPECIAL_MECHANISMS[name]
    h = 1e-3
    offsets = h * np.arange(-2, 3)
    checked = 0
    for theta in np.radians([17.0, 100.0, 200.0, 290.0]):
        pos = rsrc_positions(dims, [theta])
        rates = rsrc_rates(dims, pos)
        for col in np.flatnonzero(rates.valid[0]):
            fixed = int(col) if name == "delta0_half_pi" else None
            phi_s, chi_s, s_s = follow(dims, theta, pos.phi0[0, col], offsets, fixed)
            for samples, dot, ddot in ((phi_s, rates.phi0_dot, rates.phi0_ddot),
                                       (chi_s, rates.chi0_dot, rates.chi0_ddot),
                                       (s_s, rates.S_dot, rates.S_ddot)):
                first, second = five_point(samples, h)
                assert dot[0, col] == pytest.approx(first, abs=1e-7)
                assert ddot[0, col] == pytest.approx(second, abs=1e-6)
            checked += 1
    assert checked >= 4


def test_rates_scale_with_input_speed_and_acceleration() -> None:
    """phi0' = phi_theta th', phi0'' = phi_thth th'^2 + phi_theta th''; likewise chi0 and S."""
    theta = np.radians(np.arange(0, 360, 10.0))
    pos = rsrc_positions(FIG7, theta)
    unit = rsrc_rates(FIG7, pos)
    td = np.linspace(-2.0, 3.0, theta.size)
    tdd = np.linspace(1.5, -0.5, theta.size)
    rates = rsrc_rates(FIG7, pos, td, tdd)
    ok = unit.valid
    for first, second, f1, f2 in ((rates.phi0_dot, rates.phi0_ddot, unit.phi0_dot,
                                   unit.phi0_ddot),
                                  (rates.chi0_dot, rates.chi0_ddot, unit.chi0_dot,
                                   unit.chi0_ddot),
                                  (rates.S_dot, rates.S_ddot, unit.S_dot, unit.S_ddot)):
        np.testing.assert_allclose(first[ok], (f1 * td[:, None])[ok], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(
            second[ok], (f2 * td[:, None] ** 2 + f1 * tdd[:, None])[ok], rtol=1e-11, atol=1e-11
        )


def test_kinematics_equals_positions_then_rates() -> None:
    theta = np.linspace(0, 2 * math.pi, 50)
    pos, rates = rsrc_kinematics(FIG7, theta, 1.3, -0.4)
    ref = rsrc_rates(FIG7, rsrc_positions(FIG7, theta), 1.3, -0.4)
    for name in ("phi0_dot", "chi0_dot", "S_dot", "phi0_ddot", "chi0_ddot", "S_ddot"):
        np.testing.assert_allclose(getattr(rates, name), getattr(ref, name), rtol=1e-10,
                                   atol=1e-12, equal_nan=True)


CHI_CROSSING = RSRCDimensions(d1=1.5, d2=2.8, d3=2.0, a=-0.6, b=0.7, e=-1.0, delta0=0.9,
                              lambda0=-0.1)


def test_chi_rates_through_sin_chi_zero() -> None:
    """(3.78) divides by sin chi0; where chi0 crosses 0 the W2 form takes over (SPEC §3.5)."""
    dims = CHI_CROSSING
    motion = rsrc_motion(dims, np.linspace(0, 2 * math.pi, 2001))
    chi = motion.chi0[:, 1]
    crossings = np.flatnonzero(np.abs(np.diff(np.sign(chi))) == 2)
    crossings = [k for k in crossings if motion.assembles[k:k + 2, 1].all() and abs(chi[k]) < 0.1]
    assert crossings, "this mechanism's second branch has chi0 crossing zero"
    k = crossings[0]
    # the root of chi0 on that branch, by bisection on the closed form
    lo, hi = motion.theta0[k], motion.theta0[k + 1]
    phi_guess = motion.phi0[k, 1]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        _, chi_mid, _ = follow(dims, mid, phi_guess, np.zeros(1))
        if np.sign(chi_mid[0]) == np.sign(chi[k]):
            lo = mid
        else:
            hi = mid
    theta = 0.5 * (lo + hi)
    pos = rsrc_positions(dims, [theta])
    dist = np.abs(np.angle(np.exp(1j * (np.nan_to_num(pos.phi0[0], nan=1e9) - phi_guess))))
    col = int(np.argmin(dist))
    assert abs(pos.chi0[0, col]) < 1e-12
    rates = rsrc_rates(dims, pos)
    assert rates.valid[0, col]
    h = 1e-3
    _, chi_s, _ = follow(dims, theta, pos.phi0[0, col], h * np.arange(-2, 3))
    first, second = five_point(chi_s, h)
    assert rates.chi0_dot[0, col] == pytest.approx(first, abs=1e-7)
    assert rates.chi0_ddot[0, col] == pytest.approx(second, abs=1e-6)


def test_locked_configuration_is_reported_not_divided() -> None:
    """At a branch end (limit of the input, Q5 = 0) the rates are masked as locked."""
    dims = RSRCDimensions(d1=2.0, d2=2.2, d3=1.2, a=2.5, b=0.3, e=0.2, delta0=25 * DEG,
                          lambda0=30 * DEG)
    motion = rsrc_motion(dims, np.linspace(0, 2 * math.pi, 721))
    stops = [ev for ev in motion.events if ev.kind == "stops"]
    assert stops
    pos = rsrc_positions(dims, [stops[0].theta0])
    rates = rsrc_rates(dims, pos)
    assert rates.locked[0].any()
    locked = rates.locked[0]
    assert np.all(np.isnan(rates.phi0_dot[0, locked]))
    assert not np.any(rates.valid[0, locked])


# ------------------------------------------------------------------ coupler point (App. C)


def test_coupler_point_matches_coupler_frame() -> None:
    theta = np.radians(np.arange(0, 360, 15.0))
    pos = rsrc_positions(FIG7, theta)
    f, g, h = 0.7, -0.4, 1.1
    cp = rsrc_coupler_point(FIG7, pos, f, g, h)
    ok = pos.assembles
    centre, b_mat = master_loop(FIG7, pos.phi0[ok], pos.S[ok], pos.chi0[ok])
    expected = centre + b_mat @ np.array([f, g, h])
    np.testing.assert_allclose(cp.global_xyz[ok], expected, atol=1e-12)
    # explicit (C.2)-(C.4), typed from the spec
    d = FIG7
    sl, cl, sd, cd = (math.sin(d.lambda0), math.cos(d.lambda0), math.sin(d.delta0),
                      math.cos(d.delta0))
    sp, cpv = np.sin(pos.phi0[ok]), np.cos(pos.phi0[ok])
    sc, cc = np.sin(pos.chi0[ok]), np.cos(pos.chi0[ok])
    s = pos.S[ok]
    xp = (d.b - s * cl + d.d3 * sl * sp + (d.d2 - g) * (sc * (sl * cd * cpv - sd * cl) - sl * sp * cc)
          + (d.e + f) * (cl * cd + sl * sd * cpv) + h * (sl * sp * sc + cc * (sl * cd * cpv - sd * cl)))
    yp = (d.a + d.d3 * cpv - (d.d2 - g) * (cpv * cc + cd * sp * sc) - (d.e + f) * sd * sp
          + h * (cpv * sc - cd * sp * cc))
    zp = (s * sl + d.d3 * cl * sp + (d.d2 - g) * (sc * (sl * sd + cl * cd * cpv) - cl * sp * cc)
          + (d.e + f) * (cl * sd * cpv - sl * cd) + h * (cc * (cl * cd * cpv + sl * sd) + cl * sp * sc))
    np.testing.assert_allclose(cp.global_xyz[ok], np.stack([xp, yp, zp], -1), atol=1e-12)


def test_coupler_point_origin_is_the_sphere_centre() -> None:
    theta = np.radians(np.arange(0, 360, 30.0))
    pos = rsrc_positions(FIG7, theta)
    cp = rsrc_coupler_point(FIG7, pos, 0.0, 0.0, 0.0)
    ok = pos.assembles
    expected = np.stack([0 * theta, 2 * np.cos(theta), 2 * np.sin(theta)], -1)
    np.testing.assert_allclose(cp.global_xyz[ok], np.broadcast_to(expected[:, None], (12, 4, 3))[ok],
                               atol=1e-12)


# ------------------------------------------------------------------ motion and branches


def test_motion_tracks_two_continuous_branches_of_fig7() -> None:
    theta = np.linspace(0, 2 * math.pi, 721)
    motion = rsrc_motion(FIG7, theta)
    assert motion.events == ()
    assert np.all(motion.assembles[:, :2]) and not motion.assembles[:, 2:].any()
    steps = np.abs(np.diff(motion.phi0[:, :2], axis=0))
    assert steps.max() < 5 * DEG  # unwrapped and continuous
    # each branch comes back to itself after a revolution (rotation limits on both: rockers)
    np.testing.assert_allclose(motion.phi0[-1, :2], motion.phi0[0, :2], atol=1e-9)


def test_motion_reports_where_branches_stop() -> None:
    """A Grashof double-rocker plane 4R: the crank has dead-centre limits on both sides."""
    dims = RSRCDimensions(d1=2.0, d2=1.5, d3=1.8, a=2.2, b=0, e=0, delta0=0, lambda0=0)
    theta = np.linspace(-math.pi, math.pi, 1441)
    motion = rsrc_motion(dims, theta)
    kinds = sorted(ev.kind for ev in motion.events)
    assert kinds.count("stops") >= 2 and kinds.count("starts") >= 2
    for ev in motion.events:
        # crank tip at distance d2 + d3 or |d2 - d3| from the output pivot: a dead centre
        r = math.hypot(dims.a - dims.d1 * math.cos(ev.theta0), dims.d1 * math.sin(ev.theta0))
        assert min(abs(r - (dims.d2 + dims.d3)), abs(r - abs(dims.d2 - dims.d3))) < 1e-9
        inside = ev.theta0 - 1e-7 if ev.kind == "stops" else ev.theta0 + 1e-7
        outside = ev.theta0 + 1e-7 if ev.kind == "stops" else ev.theta0 - 1e-7
        assert rsrc_positions(dims, [inside]).n_assemblies[0] == 2
        assert rsrc_positions(dims, [outside]).n_assemblies[0] == 0


# ------------------------------------------------------------------ limits and dwells (App. D)


def q_terms(dims: RSRCDimensions, theta: float, phi: float, chi: float):
    """Q4, Q5, M2, L2 typed from SPEC §3.5 (independent of the library's rate code)."""
    sl, cl = math.sin(dims.lambda0), math.cos(dims.lambda0)
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    m0 = dims.b * sl - dims.d1 * cl * math.sin(theta)
    n0 = dims.a - dims.d1 * math.cos(theta)
    sp, cp = math.sin(phi), math.cos(phi)
    w1 = m0 * sp + n0 * cp + dims.d3
    w2 = n0 * sp - m0 * cp - dims.e * sd
    m1, m2 = n0 * cp + m0 * sp, m0 * cp - n0 * sp
    l1 = math.sin(theta) * sp + cl * math.cos(theta) * cp
    l2 = math.sin(theta) * cp - cl * sp * math.cos(theta)
    return w2 * l1 + cd**2 * w1 * l2, w2 * m1 + cd**2 * w1 * m2, m2, l2, m0, n0


def test_rotation_limits_are_ellipse_tangencies() -> None:
    limits = rsrc_rotation_limits(FIG7)
    assert len(limits) == 4
    scale = FIG7.length_scale**2
    for lim in limits:
        q4, q5, *_ = q_terms(FIG7, lim.theta0, lim.phi0, lim.chi0)
        assert abs(q4) < 1e-12 * scale and abs(q5) > 1e-3 * scale  # eq. D.1
        # eq. D.4a: normal slopes of the input-crank ellipse and of the coupler ellipse agree
        sp, cp = math.sin(lim.phi0), math.cos(lim.phi0)
        c2 = math.cos(FIG7.delta0) ** 2
        _, _, _, _, m0, n0 = q_terms(FIG7, lim.theta0, lim.phi0, lim.chi0)
        w1 = m0 * sp + n0 * cp + FIG7.d3
        w2 = n0 * sp - m0 * cp - FIG7.e * math.sin(FIG7.delta0)
        lhs = math.atan(math.tan(lim.theta0) / math.cos(FIG7.lambda0))
        rhs = math.atan(-(w2 * cp - w1 * c2 * sp) / (w2 * sp + w1 * c2 * cp))
        assert abs(math.remainder(lhs - rhs, math.pi)) < 1e-9
        # and phi0 is stationary there
        phi_s, _, _ = follow(FIG7, lim.theta0, lim.phi0, 1e-4 * np.array([-1.0, 1.0]))
        assert abs(phi_s[1] - phi_s[0]) < 1e-7


def test_translation_limits_satisfy_corrected_d3() -> None:
    """sin d0 (M2 Q4 - L2 Q5) = sin l0 cos th0 tan chi0 Q5 (SPEC §10, corrected D.3)."""
    limits = rsrc_translation_limits(FIG7)
    assert len(limits) == 4
    for lim in limits:
        q4, q5, m2, l2, _, _ = q_terms(FIG7, lim.theta0, lim.phi0, lim.chi0)
        lhs = math.sin(FIG7.delta0) * (m2 * q4 - l2 * q5)
        rhs = math.sin(FIG7.lambda0) * math.cos(lim.theta0) * math.tan(lim.chi0) * q5
        assert abs(lhs - rhs) < 1e-10 * FIG7.length_scale**3
        _, _, s_s = follow(FIG7, lim.theta0, lim.phi0, 1e-4 * np.array([-1.0, 1.0]))
        assert abs(s_s[1] - s_s[0]) < 1e-7


def test_translation_limits_of_delta0_zero_are_at_plus_minus_90() -> None:
    """Eq. 3.60a: S = C1 + d1 sin(lambda0) sin(theta0) on every branch (and Fig. 9: the limits of
    rotation and translation coincide at 90 and 270 deg)."""
    limits = rsrc_translation_limits(FIG9)
    assert {round(lim.theta0 / DEG, 9) for lim in limits} == {90.0, 270.0}
    rot = rsrc_rotation_limits(FIG9)
    assert min(abs(lim.theta0 - math.pi / 2) for lim in rot) < 0.01


def test_fig9_third_order_dwell_at_270() -> None:
    """SPEC §3.6: phi' = -4.4e-5, phi'' = 1.6e-5, phi''' ~ 2e-6 with the printed (rounded)
    dimensions, so the dwell holds to ~1e-4 and the fourth derivative is O(1)."""
    pos = rsrc_positions(FIG9, [270 * DEG])
    phi = pos.phi0[0, 1]  # negative radical = label 2
    assert phi / DEG == pytest.approx(-160.066, abs=5e-4)
    order, derivs = rsrc_dwell_order(FIG9, [270 * DEG], [phi], tol=1e-4, max_order=5)
    assert order[0] == 3
    assert derivs[0, 0] == pytest.approx(-4.4e-5, abs=1e-6)
    assert derivs[0, 1] == pytest.approx(1.6e-5, abs=1e-6)
    assert abs(derivs[0, 3]) > 0.1


def test_fig10_second_order_dwell_near_220_33() -> None:
    """SPEC §3.6: at 220.33 deg phi' ~ 0.007, phi'' ~ -0.0007, phi''' ~ 1.78; phi'' = 0 at
    220.351 deg (the printed dimensions are rounded)."""
    pos = rsrc_positions(FIG10, [220.33 * DEG])
    phi = pos.phi0[0, 1]
    assert phi / DEG == pytest.approx(161.452, abs=5e-4)
    order, derivs = rsrc_dwell_order(FIG10, [220.33 * DEG], [phi], tol=1e-2)
    assert order[0] == 2
    assert derivs[0, 2] == pytest.approx(1.78, abs=0.01)
    # phi'' changes sign at 220.351 deg
    theta = np.radians([220.350, 220.352])
    p = rsrc_positions(FIG10, theta)
    d = rsrc_output_derivatives(FIG10, theta, p.phi0[:, 1], order=2)
    assert d[0, 1] * d[1, 1] < 0


def test_output_derivatives_match_rates_and_finite_differences() -> None:
    theta = np.radians([30.0, 140.0, 250.0])
    pos = rsrc_positions(FIG7, theta)
    rates = rsrc_rates(FIG7, pos)
    for col in (0, 1):
        d = rsrc_output_derivatives(FIG7, theta, pos.phi0[:, col], order=4)
        np.testing.assert_allclose(d[:, 0], rates.phi0_dot[:, col], rtol=1e-11, atol=1e-12)
        np.testing.assert_allclose(d[:, 1], rates.phi0_ddot[:, col], rtol=1e-10, atol=1e-11)
        # third derivative: 5-point central difference of the (exact) second derivative
        h = 1e-3
        for i, th in enumerate(theta):
            phi_s, _, _ = follow(FIG7, th, pos.phi0[i, col], h * np.arange(-2, 3))
            second = rsrc_output_derivatives(FIG7, th + h * np.arange(-2, 3), phi_s, order=2)[:, 1]
            third, _ = five_point(second, h)
            assert d[i, 2] == pytest.approx(third, abs=1e-8)


def test_output_derivatives_reject_a_point_off_the_loop() -> None:
    with pytest.raises(ValueError, match="does not close"):
        rsrc_output_derivatives(FIG7, [1.0], [0.123])


def test_dwell_order_counts_leading_zeros() -> None:
    d = np.array([[0.0, 1e-9, 0.5, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
    assert dwell_order(d, 1e-6).tolist() == [2, 0, 4]


# ------------------------------------------------------------------ the quartic helper


def test_quartic_roots_of_random_real_polynomials() -> None:
    rng = np.random.default_rng(7)
    roots = np.sort(rng.uniform(-5, 5, size=(500, 4)), axis=1)
    sep = np.min(np.diff(roots, axis=1), axis=1)
    roots = roots[sep > 1e-2]  # well-separated: Ferrari + one Newton step is exact to rounding
    coeffs = np.array([np.poly(r) for r in roots])
    t, ok = real_quartic_roots(coeffs[:, 1], coeffs[:, 2], coeffs[:, 3], coeffs[:, 4])
    assert ok.all()
    np.testing.assert_allclose(np.sort(t, axis=1), roots, atol=1e-9)


def test_quartic_biquadratic_and_complex_cases() -> None:
    # (t^2 - 1)(t^2 - 4): q = 0, resolvent root m = 0
    t, ok = real_quartic_roots(0.0, -5.0, 0.0, 4.0)
    np.testing.assert_allclose(np.sort(t[ok]), [-2, -1, 1, 2], atol=1e-14)
    # (t^2 + 1)(t^2 + 4): no real roots
    _, ok = real_quartic_roots(0.0, 5.0, 0.0, 4.0)
    assert not ok.any()
    # (t - 1)^2 (t^2 + 1): a double root, reported twice
    c = np.poly([1, 1, 1j, -1j]).real
    t, ok = real_quartic_roots(c[1], c[2], c[3], c[4])
    assert ok.sum() == 2 and np.allclose(t[ok], 1.0, atol=1e-7)


def test_trig_quadratic_pure_sin_2phi() -> None:
    """P = sin 2phi vanishes at all four multiples of pi/2 (the six-origin choice handles it)."""
    phi, ok = real_roots_of_trig_quadratic(0.0, 0.0, 0.0, 0.0, 1.0)
    np.testing.assert_allclose(phi[0], [-math.pi / 2, 0.0, math.pi / 2, math.pi], atol=1e-14)
    phi, ok = real_roots_of_trig_quadratic(0.0, 0.0, 0.0, 0.0, 0.0)
    assert not ok.any()


# ------------------------------------------------------------------ property tests


lengths = st.floats(0.2, 5.0)
angles = st.floats(-math.pi, math.pi)


@st.composite
def mechanisms(draw: st.DrawFn) -> RSRCDimensions:
    return RSRCDimensions(
        d1=draw(lengths), d2=draw(lengths), d3=draw(lengths), a=draw(st.floats(-5.0, 5.0)),
        b=draw(st.floats(-3.0, 3.0)), e=draw(st.floats(-2.0, 2.0)), delta0=draw(angles),
        lambda0=draw(angles),
    )


@settings(derandomize=True, max_examples=60, deadline=None)
@given(mechanisms(), st.lists(angles, min_size=1, max_size=8))
def test_property_every_root_closes_the_loop(dims: RSRCDimensions, theta: list[float]) -> None:
    pos = rsrc_positions(dims, theta)
    assert closure_error(dims, pos) < 1e-10
    # the count agrees with an independent sign-change scan of (3.62) over a fine phi grid
    # (skipped near double roots, where a grid cannot see the pair)
    grid = np.linspace(-math.pi, math.pi, 20001)
    for k, th in enumerate(theta):
        m0 = dims.b * math.sin(dims.lambda0) - dims.d1 * math.cos(dims.lambda0) * math.sin(th)
        n0 = dims.a - dims.d1 * math.cos(th)
        cd2 = math.cos(dims.delta0) ** 2
        w1 = m0 * np.sin(grid) + n0 * np.cos(grid) + dims.d3
        w2 = n0 * np.sin(grid) - m0 * np.cos(grid) - dims.e * math.sin(dims.delta0)
        g = cd2 * w1**2 + w2**2 - cd2 * dims.d2**2
        if np.min(np.abs(g)) < 1e-6 * dims.length_scale**2 or dims.special_case != "general":
            continue
        changes = int(np.count_nonzero(np.sign(g[1:]) != np.sign(g[:-1])))
        assert changes == pos.n_assemblies[k]


@settings(derandomize=True, max_examples=40, deadline=None)
@given(mechanisms(), angles)
def test_property_rates_match_finite_differences(dims: RSRCDimensions, theta: float) -> None:
    """Tolerance 1e-5 relative to the rate size: random mechanisms come near locks, where the
    difference quotient (h = 1e-4, error ~ h^2 phi''') loses accuracy; a sign error would be O(1)."""
    pos = rsrc_positions(dims, [theta])
    rates = rsrc_rates(dims, pos)
    h = 1e-4
    scale = dims.length_scale**2
    for col in np.flatnonzero(rates.valid[0]):
        _, q5, *_ = q_terms(dims, theta, pos.phi0[0, col], pos.chi0[0, col])
        if abs(q5) < 1e-2 * scale or abs(math.sin(pos.chi0[0, col])) < 1e-2:
            continue  # near a lock or a chi0 crossing of a random mechanism: FD is unreliable
        phi_s, chi_s, s_s = follow(dims, theta, pos.phi0[0, col], h * np.array([-1.0, 1.0]))
        for samples, dot in ((phi_s, rates.phi0_dot), (chi_s, rates.chi0_dot), (s_s, rates.S_dot)):
            fd = (samples[1] - samples[0]) / (2 * h)
            assert dot[0, col] == pytest.approx(fd, rel=1e-5, abs=1e-5 * (1 + abs(fd)))

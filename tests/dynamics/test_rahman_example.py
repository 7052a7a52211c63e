"""Rahman's (1996) CSSP example (examples/rahman_cssp.toml) with correct physics.

* physical laws: shaking force = −dP/dt, shaking moment about O = −dH_O/dt, input power =
  dKE/dt, from the link kinematics alone (spectral derivatives over one periodic turn);
* second method: the closed-form path (cssp_mode_motion) equals the generic solver's motion;
* independent anchors: the shaking force and the input torque at a few angles from a
  hand-coded slider crank (own quadratic for s4, finite differences, Σ m a_cm, energy rate).

The seed's Tables 5.3–5.7 are not targets here (they are wrong, see
validation/rahman1996/dynamics.md).
"""

from pathlib import Path

import numpy as np
import pytest

from screwkit.dynamics import inverse_dynamics
from screwkit.io.spec import load_spec
from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "rahman_cssp.toml"


@pytest.fixture(scope="module")
def example():
    spec = load_spec(EXAMPLE)
    return spec.linkage, float(spec.speed)


def _spectral_derivative(values, period):
    n = values.shape[0]
    k = np.fft.fftfreq(n, d=period / n) * 2 * np.pi
    k[n // 2] = 0.0
    shape = (-1,) + (1,) * (values.ndim - 1)
    return np.real(np.fft.ifft(1j * k.reshape(shape) * np.fft.fft(values, axis=0), axis=0))


def test_momentum_and_energy_balances(example):
    lk, omega = example
    n = 512
    theta = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    mode = cssp_mode_motion(lk, theta, omega, 0.0)
    dyn = inverse_dynamics(lk, mode)
    P = np.zeros((n, 3))
    H = np.zeros((n, 3))
    KE = np.zeros(n)
    for l, link in enumerate(lk.links):
        mp = link.mass
        R = mode.link_rotation[:, l]
        w = mode.link_angular_velocity[:, l]
        rc = R @ mp.com
        pc = mode.link_origin[:, l] + rc
        vc = mode.link_origin_velocity[:, l] + np.cross(w, rc)
        Iw = np.einsum("nij,jk,nlk,nl->ni", R, mp.inertia, R, w)
        P += mp.mass * vc
        H += mp.mass * np.cross(pc, vc) + Iw
        KE += 0.5 * mp.mass * np.sum(vc**2, axis=1) + 0.5 * np.sum(w * Iw, axis=1)
    # the signals are trigonometric-polynomial-like and smooth: 512 spectral samples resolve
    # them to round-off (measured 1e-13 of the peak); 1e-9 leaves room for the platform
    force = dyn.shaking_force
    np.testing.assert_allclose(force, -omega * _spectral_derivative(P, 2 * np.pi),
                               atol=1e-9 * np.abs(force).max())
    moment = dyn.shaking_moment
    np.testing.assert_allclose(moment, -omega * _spectral_derivative(H, 2 * np.pi),
                               atol=1e-9 * np.abs(moment).max())
    power = dyn.efforts["crank.theta"] * omega
    np.testing.assert_allclose(power, omega * _spectral_derivative(KE, 2 * np.pi),
                               atol=1e-9 * np.abs(power).max())
    # the axisymmetric rod's free spin carries no load
    assert np.max(dyn.relative_residual) < 1e-12


def test_closed_form_path_equals_generic_path(example):
    lk, omega = example
    theta = np.radians(np.arange(0.0, 360.0, 30.0))
    fast = cssp_mode_motion(lk, theta, omega, 0.0)
    m = motion(lk, theta, omega, 0.0)
    s4 = fast.variables["slider.s"]
    (slow,) = [md for md in m.modes if np.allclose(md.variables["slider.s"], s4, atol=1e-12)]
    a, b = inverse_dynamics(lk, fast), inverse_dynamics(lk, slow)
    scale = b.residual_scale  # largest joint load (N, and N·m / length scale)
    ell = lk.length_scale
    # both exact: agreement to round-off of the largest load
    np.testing.assert_allclose(a.shaking_force, b.shaking_force, atol=1e-10 * scale)
    np.testing.assert_allclose(a.shaking_moment, b.shaking_moment, atol=1e-10 * scale * ell)
    np.testing.assert_allclose(a.efforts["crank.theta"], b.efforts["crank.theta"],
                               atol=1e-10 * scale * ell)
    for joint in a.reactions:
        np.testing.assert_allclose(a.reactions[joint]["force"], b.reactions[joint]["force"],
                                   atol=1e-10 * scale)
        np.testing.assert_allclose(a.reactions[joint]["moment"], b.reactions[joint]["moment"],
                                   atol=1e-10 * scale * ell)


# --- a hand-coded slider crank (no screwkit kinematics) --------------------------------------
INCH = 0.0254
A1, A2, A4, S1 = 2 * INCH, 8 * INCH, 1 * INCH, 0.4 * INCH
ALPHA4 = np.radians(250.0)
K4 = np.array([0.0, np.sin(ALPHA4), np.cos(ALPHA4)])


def _points(theta):
    """Crank pin, slider ball (the larger root of |P − pin| = a2, the seed's branch)."""
    pin = np.array([A1 * np.cos(theta), A1 * np.sin(theta), S1])
    # P = −a4 i − s k4: |P − pin|² = s² + 2 s (k4·pin) + |a4 i + pin|² = a2²
    corner = np.array([A4, 0.0, 0.0]) + pin
    s = max(np.roots([1.0, 2 * K4 @ pin, corner @ corner - A2**2]).real)
    return pin, np.array([-A4, 0.0, 0.0]) - s * K4


def _derivatives(f, theta, h=1e-3):
    """First and second θ-derivatives by 5-point central differences (error ~h⁴ f⁽⁵⁾)."""
    f2, f1, f0, g1, g2 = (f(theta + k * h) for k in (-2, -1, 0, 1, 2))
    first = (f2 - 8 * f1 + 8 * g1 - g2) / (12 * h)
    second = (-f2 + 16 * f1 - 30 * f0 + 16 * g1 - g2) / (12 * h**2)
    return first, second


@pytest.mark.parametrize("theta_deg", [0.0, 90.0, 217.0])
def test_shaking_force_and_input_torque_anchors(example, theta_deg):
    lk, omega = example
    m_crank, m_rod, m_slider = (link.mass.mass for link in lk.links)
    i_crank_z = lk.links[0].mass.inertia[2, 2]
    i_rod_t = lk.links[1].mass.inertia[1, 1]  # about a transverse axis through the CoM
    theta = np.radians(theta_deg)

    def centres(th):
        pin, ball = _points(th)
        crank_com = np.array([0.5 * A1 * np.cos(th), 0.5 * A1 * np.sin(th), S1])
        return np.stack([crank_com, 0.5 * (pin + ball), ball])  # CoMs: mid-crank, mid-rod, ball

    masses = np.array([m_crank, m_rod, m_slider])
    _, d2 = _derivatives(centres, theta)
    shaking = -(masses[:, None] * omega**2 * d2).sum(axis=0)  # −Σ m a_cm at constant ω

    def kinetic_energy(th):
        d1, _ = _derivatives(centres, th)
        v = omega * d1
        u_dot = omega * _derivatives(lambda t: np.subtract(*_points(t)[::-1]) / A2, th)[0]
        # zero-spin rod: |ω_rod| = |u̇|; the crank turns about z at ω
        return (0.5 * masses @ np.sum(v**2, axis=1) + 0.5 * i_crank_z * omega**2
                + 0.5 * i_rod_t * u_dot @ u_dot)

    torque = _derivatives(kinetic_energy, theta)[0]  # T ω = dKE/dt = ω dKE/dθ

    dyn = inverse_dynamics(lk, cssp_mode_motion(lk, [theta], omega, 0.0))
    # finite differences of the hand-coded kinematics carry ~1e-9 relative error (h = 1e-3,
    # fifth derivatives of order 1), nested once for the energy: 1e-6 is a safe, meaningful bound
    np.testing.assert_allclose(dyn.shaking_force[0], shaking, rtol=0,
                               atol=1e-7 * np.linalg.norm(shaking))
    assert dyn.efforts["crank.theta"][0] == pytest.approx(torque, rel=1e-6, abs=1e-6 * 400.0)

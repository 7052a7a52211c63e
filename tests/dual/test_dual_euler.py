"""Dual Euler angles z–x–z (Bagci eqs. 2.12–2.16, verified convention: φ, ψ about z, θ about x),
both directions, against dual atan2 of the dual matrix elements and scipy's 'ZXZ', and the
degenerate rule at θ0 = 0 and π."""

from __future__ import annotations

import numpy as np
import pytest
from dual_strategies import SETTINGS, assert_screw_close, cases, random_screw, rng_for
from hypothesis import given
from scipy.spatial.transform import Rotation

import screwkit.dual as sd
from screwkit.dual import Dual, ScrewMatrix


@SETTINGS
@given(cases)
def test_matrix_to_euler_to_matrix(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    S = random_screw(rng_for(seed), shape)
    e = sd.dual_euler_from_screw_matrix(S)
    assert e.theta.shape == shape
    # Near-singular samples have ψ1 ∝ 1/sin θ0; random rotations keep sin θ0 ≳ 1e-3.
    assert_screw_close(e.as_screw_matrix(), S, atol=1e-10)
    assert np.all((e.theta.real >= 0) & (e.theta.real <= np.pi))
    # Real parts are scipy's intrinsic Z-X-Z angles.
    ref = Rotation.from_matrix(S.real.reshape(-1, 3, 3)).as_euler("ZXZ").reshape(*shape, 3)
    np.testing.assert_allclose(np.stack([e.phi.real, e.theta.real, e.psi.real], -1), ref, atol=1e-9)


@SETTINGS
@given(cases)
def test_euler_to_matrix_to_euler(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    phi = Dual(rng.uniform(-3.1, 3.1, size=shape), rng.normal(size=shape))
    theta = Dual(rng.uniform(0.05, 3.09, size=shape), rng.normal(size=shape))
    psi = Dual(rng.uniform(-3.1, 3.1, size=shape), rng.normal(size=shape))
    S = sd.screw_matrix_from_dual_euler(phi, theta, psi)
    e = sd.dual_euler_from_screw_matrix(S)
    for got, want in ((e.phi, phi), (e.theta, theta), (e.psi, psi)):
        np.testing.assert_allclose(got.real, want.real, atol=1e-12)
        # dual parts carry 1/sin θ0 ≤ 1/sin 0.05 ≈ 20 times the rounding
        np.testing.assert_allclose(got.dual, want.dual, atol=1e-11)


@SETTINGS
@given(cases)
def test_bagci_formulas_equal_dual_atan2(case: tuple[tuple[int, ...], int]) -> None:
    """Eqs. 2.14–2.16 against the dual extension of the real extraction formulas, applied to the
    dual matrix elements: φ̂ = atan2(R̂13, −R̂23), ψ̂ = atan2(R̂31, R̂32),
    θ̂ = atan2(√(R̂13² + R̂23²), R̂33)."""
    shape, seed = case
    S = random_screw(rng_for(seed), shape)
    e = sd.dual_euler_from_screw_matrix(S)

    def el(i: int, j: int) -> Dual:
        return Dual(S.real[..., i, j], S.dual[..., i, j])

    phi = sd.atan2(el(0, 2), -el(1, 2))
    psi = sd.atan2(el(2, 0), el(2, 1))
    theta = sd.atan2(sd.sqrt(el(0, 2) ** 2 + el(1, 2) ** 2), el(2, 2))
    for got, want in ((e.phi, phi), (e.theta, theta), (e.psi, psi)):
        np.testing.assert_allclose(got.real, want.real, atol=1e-12)
        np.testing.assert_allclose(got.dual, want.dual, atol=1e-9)  # 1/sin θ0 as above


def test_bagci_translation_formulas_explicitly() -> None:
    """θ1 = X cos φ0 + Y sin φ0; ψ1 = (X sin φ0 − Y cos φ0)/sin θ0; φ1 = Z − ψ1 cos θ0."""
    phi0, theta0, psi0 = 0.4, 1.1, -2.0
    X, Y, Z = 1.5, -0.5, 2.0
    R = Rotation.from_euler("ZXZ", [phi0, theta0, psi0]).as_matrix()
    e = sd.dual_euler_from_screw_matrix(ScrewMatrix.from_rotation_translation(R, [X, Y, Z]))
    psi1 = (X * np.sin(phi0) - Y * np.cos(phi0)) / np.sin(theta0)
    assert e.theta.dual == pytest.approx(X * np.cos(phi0) + Y * np.sin(phi0), abs=1e-13)
    assert e.psi.dual == pytest.approx(psi1, abs=1e-13)
    assert e.phi.dual == pytest.approx(Z - psi1 * np.cos(theta0), abs=1e-13)


@pytest.mark.parametrize("theta0", [0.0, np.pi])
@pytest.mark.parametrize("translation", [[1.0, 2.0, -0.5], [0.0, 0.0, 3.0], [-2.0, 0.0, 0.0]])
def test_degenerate_rule(theta0: float, translation: list[float]) -> None:
    gamma = 0.7
    R = ScrewMatrix.rot_z(gamma).real @ ScrewMatrix.rot_x(theta0).real
    S = ScrewMatrix.from_rotation_translation(R, translation)
    e = sd.dual_euler_from_screw_matrix(S)
    X, Y, Z = translation
    assert e.theta.real == theta0
    assert e.psi.dual == 0.0  # the whole z translation goes to φ̂
    assert e.phi.dual == pytest.approx(Z, abs=1e-14)
    if np.hypot(X, Y) > 0:
        assert e.phi.real == pytest.approx(np.arctan2(Y, X), abs=1e-14)
        assert e.theta.dual == pytest.approx(np.hypot(X, Y), abs=1e-14)
    else:
        assert e.psi.real == 0.0 and e.phi.real == pytest.approx(gamma, abs=1e-14)
        assert e.theta.dual == 0.0
    assert_screw_close(e.as_screw_matrix(), S, atol=1e-13)


def test_euler_error_path() -> None:
    with pytest.raises(ValueError, match="not skew-symmetric"):
        sd.dual_euler_from_screw_matrix(ScrewMatrix(np.eye(3), np.eye(3)))

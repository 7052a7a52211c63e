"""Screw parameters of a displacement (Bagci SPEC §2.6): round trips, the defining geometric
properties of the axis, Bagci's dual-trace formulas, and the degenerate cases."""

from __future__ import annotations

import numpy as np
import pytest
from dual_strategies import SETTINGS, assert_screw_close, cases, random_screw, rng_for
from hypothesis import given
from scipy.spatial.transform import Rotation

import screwkit.dual as sd
from screwkit.dual import Dual, DualVector, ScrewMatrix, ScrewParameters, vee


@SETTINGS
@given(cases)
def test_round_trip_and_axis_geometry(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    S = random_screw(rng_for(seed), shape)
    p = sd.screw_parameters_from_screw_matrix(S)
    assert p.shape == shape
    assert_screw_close(p.as_screw_matrix(), S, atol=1e-11)
    u, c = p.axis_direction, p.axis_point
    np.testing.assert_allclose(np.linalg.norm(u, axis=-1), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.sum(c * u, axis=-1), 0.0, atol=1e-11)  # nearest the origin
    assert np.all((p.angle >= 0) & (p.angle <= np.pi))
    # Every point of the axis slides along it by s (the defining property of the screw).
    for lam in (-2.0, 0.0, 3.0):
        x = c + lam * u
        np.testing.assert_allclose(
            S.transform_points(x), x + p.translation[..., None] * u, atol=1e-10
        )
    # The axis line is fixed by the screw matrix: T̂ û = û.
    line = p.axis_line
    moved = S @ line
    np.testing.assert_allclose(moved.real, line.real, atol=1e-12)
    np.testing.assert_allclose(moved.dual, line.dual, atol=1e-10)
    np.testing.assert_allclose(p.pitch, p.translation / p.angle, rtol=1e-15)


@SETTINGS
@given(cases)
def test_bagci_dual_trace_formulas(case: tuple[tuple[int, ...], int]) -> None:
    """Bagci SPEC §2.6: cos θ̂ = (tr Â − 1)/2 and Û = vee(Â − Âᵀ)/(2 sin θ̂) (dual)."""
    shape, seed = case
    S = random_screw(rng_for(seed), shape)
    p = sd.screw_parameters_from_screw_matrix(S)
    cos_t = sd.cos(p.dual_angle)
    np.testing.assert_allclose(
        cos_t.real, (np.trace(S.real, axis1=-2, axis2=-1) - 1) / 2, atol=1e-13
    )
    np.testing.assert_allclose(cos_t.dual, np.trace(S.dual, axis1=-2, axis2=-1) / 2, atol=1e-12)
    two_sin = 2.0 * sd.sin(p.dual_angle)
    w_real = vee(S.real - np.swapaxes(S.real, -1, -2))
    w_dual = vee(S.dual - np.swapaxes(S.dual, -1, -2))
    u_hat = DualVector(w_real, w_dual).scale(1.0 / two_sin)
    # 1/sin θ̂ amplifies rounding where θ is near 0 or π; random rotations keep sin θ ≳ 1e-3.
    np.testing.assert_allclose(u_hat.real, p.axis_line.real, atol=1e-9)
    np.testing.assert_allclose(u_hat.dual, p.axis_line.dual, atol=1e-8)


def test_identity() -> None:
    p = sd.screw_parameters_from_screw_matrix(ScrewMatrix.identity())
    assert p.angle == 0.0 and p.translation == 0.0 and p.pitch == 0.0
    np.testing.assert_array_equal(p.axis_direction, [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(p.axis_point, [0.0, 0.0, 0.0])
    assert not p.is_pure_translation
    assert_screw_close(p.as_screw_matrix(), ScrewMatrix.identity(), atol=0)


def test_pure_translation_has_infinite_pitch() -> None:
    t = np.array([[1.0, -2.0, 2.0], [0.0, 0.0, -5.0]])
    S = ScrewMatrix.translation_only(t)
    p = sd.screw_parameters_from_screw_matrix(S)
    np.testing.assert_array_equal(p.angle, 0.0)
    np.testing.assert_allclose(p.translation, [3.0, 5.0])
    np.testing.assert_allclose(p.axis_direction, t / [[3.0], [5.0]])
    assert np.all(np.isposinf(p.pitch))
    assert np.all(p.is_pure_translation)
    assert_screw_close(p.as_screw_matrix(), S, atol=1e-15)


@pytest.mark.parametrize(
    "axis", [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [1.0, 1.0, -1.0], [-0.3, 0.2, -0.9]]
)
def test_half_turn(axis: list[float]) -> None:
    u = np.array(axis) / np.linalg.norm(axis)
    c = np.cross(u, [0.3, -0.7, 1.1])  # a point with c·u = 0
    R = Rotation.from_rotvec(np.pi * u).as_matrix()
    for s in (0.0, 0.8, -1.3):
        S = ScrewMatrix.from_rotation_translation(R, c - R @ c + s * u)
        p = sd.screw_parameters_from_screw_matrix(S)
        assert p.angle == pytest.approx(np.pi, abs=1e-12)
        sign = 1.0 if u[np.argmax(np.abs(u))] > 0 else -1.0  # documented rule
        np.testing.assert_allclose(p.axis_direction, sign * u, atol=1e-12)
        assert p.translation == pytest.approx(sign * s, abs=1e-12)
        np.testing.assert_allclose(p.axis_point, c, atol=1e-12)
        assert_screw_close(p.as_screw_matrix(), S, atol=1e-12)


def test_small_rotation_is_still_a_rotation() -> None:
    # θ = 1e-6 about z through (0, 1, 0): far above angle_tol, the axis is recovered
    S = sd.screw_matrix_about_line(
        DualVector.line([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), Dual(1e-6, 0.25)
    )
    p = sd.screw_parameters_from_screw_matrix(S)
    assert p.angle == pytest.approx(1e-6, rel=1e-9)
    # c = ½ cot(θ/2) u × d: relative error ~ eps/θ ≈ 1e-10.
    np.testing.assert_allclose(p.axis_point, [0.0, 1.0, 0.0], atol=1e-8)
    assert p.translation == pytest.approx(0.25, abs=1e-12)


@SETTINGS
@given(cases)
def test_screw_about_line_matches_elementary_rotations(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    angle = Dual(rng.uniform(-3, 3, size=shape), rng.normal(size=shape))
    for axis in range(3):
        line = DualVector.line(np.zeros(3), np.eye(3)[axis])
        assert_screw_close(
            sd.screw_matrix_about_line(line, angle), ScrewMatrix.about_axis(angle, axis), atol=1e-13
        )
    # About a line through c: conjugation by the translation to c.
    c = rng.normal(size=(*shape, 3))
    u = rng.normal(size=(*shape, 3))
    line = DualVector.line(c, u)
    params = ScrewParameters(line.real, c, angle.real, angle.dual)
    A = sd.screw_matrix_about_line(line, angle)
    assert_screw_close(A, params.as_screw_matrix(), atol=1e-12)
    to_c = ScrewMatrix.translation_only(c)
    R = Rotation.from_rotvec(angle.real[..., None] * line.real).as_matrix()
    expected = (
        to_c
        @ ScrewMatrix.from_rotation_translation(R, angle.dual[..., None] * line.real)
        @ to_c.inverse()
    )
    assert_screw_close(A, expected, atol=1e-12)


def test_screw_parameter_error_paths() -> None:
    with pytest.raises(ValueError, match="axis_direction must be a unit vector"):
        ScrewParameters([1.0, 1.0, 0.0], [0.0, 0.0, 0.0], 1.0, 0.0)
    with pytest.raises(ValueError, match="angle contains NaN"):
        ScrewParameters([1.0, 0.0, 0.0], [0.0, 0.0, 0.0], np.nan, 0.0)
    with pytest.raises(ValueError, match="not orthogonal"):
        sd.screw_parameters_from_screw_matrix(ScrewMatrix(2.0 * np.eye(3)))

"""Dual vectors and Plücker lines: products, norms, the dual angle between two lines and their
common normal, each against a direct geometric computation (closest points of two lines)."""

from __future__ import annotations

import numpy as np
import pytest
from dual_strategies import SETTINGS, cases, random_line_parts, random_screw, rng_for
from hypothesis import given

import screwkit.dual as sd
from screwkit.dual import Dual, DualVector, common_normal, dual_angle


def closest_points(pa, ua, pb, ub):  # type: ignore[no-untyped-def]
    """Feet of the common normal by least squares on pa + s ua = pb + t ub (no dual numbers)."""
    A = np.stack([ua, -ub], axis=-1)  # (..., 3, 2)
    rhs = (pb - pa)[..., None]
    st = np.linalg.solve(np.swapaxes(A, -1, -2) @ A, np.swapaxes(A, -1, -2) @ rhs)[..., 0]
    return pa + st[..., :1] * ua, pb + st[..., 1:] * ub


@SETTINGS
@given(cases)
def test_line_is_unit_and_its_point_is_nearest_origin(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    p, u = random_line_parts(rng, shape)
    line = DualVector.line(p, u)
    sd.check_unit_line(line.direction, line.moment, tol=1e-12)
    c = line.point()
    # c is on the line (c − p ∥ u) and perpendicular to it.
    np.testing.assert_allclose(np.cross(c - p, line.real), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.sum(c * line.real, axis=-1), 0.0, atol=1e-12)


@SETTINGS
@given(cases)
def test_dual_angle_matches_closest_points(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    pa, ua = random_line_parts(rng, shape)
    pb, ub = random_line_parts(rng, shape)
    a, b = DualVector.line(pa, ua), DualVector.line(pb, ub)
    got = dual_angle(a, b)
    fa, fb = closest_points(pa, a.real, pb, b.real)
    n = np.cross(a.real, b.real)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    expected_twist = np.arccos(np.clip(np.sum(a.real * b.real, axis=-1), -1, 1))
    expected_distance = np.sum((fb - fa) * n, axis=-1)  # signed along n = a × b
    # arccos loses digits near 0 and π; random lines are rarely there: 1e-9.
    np.testing.assert_allclose(got.real, expected_twist, atol=1e-9)
    np.testing.assert_allclose(got.dual, expected_distance, atol=1e-9)
    # Bagci A.19: â·b̂ = cos φ̂ (both parts).
    c = a.dot(b)
    cos_phi = sd.cos(got)
    np.testing.assert_allclose(c.real, cos_phi.real, atol=1e-12)
    np.testing.assert_allclose(c.dual, cos_phi.dual, atol=1e-10)


def test_dual_angle_sign_convention() -> None:
    # a: the x axis; b: parallel to y, lifted to z = h. n = a × b = +z, so d = +h.
    a = DualVector.line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    for h in (2.5, -1.5):
        b = DualVector.line([7.0, 3.0, h], [0.0, 1.0, 0.0])
        phi = dual_angle(a, b)
        assert phi.real == pytest.approx(np.pi / 2, abs=1e-15)
        assert phi.dual == pytest.approx(h, abs=1e-14)
    # Swapping the lines flips n, so the sign of d is kept; reversing b flips n and d.
    b = DualVector.line([7.0, 3.0, 2.5], [0.0, 1.0, 0.0])
    assert dual_angle(b, a).dual == pytest.approx(2.5, abs=1e-14)
    assert dual_angle(a, -b).dual == pytest.approx(-2.5, abs=1e-14)
    assert dual_angle(a, -b).real == pytest.approx(np.pi / 2, abs=1e-15)


def test_parallel_lines() -> None:
    a = DualVector.line([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    b = DualVector.line([3.0, 4.0, -2.0], [0.0, 0.0, -2.0])
    phi = dual_angle(a, b)
    assert phi.real == pytest.approx(np.pi)
    assert phi.dual == pytest.approx(5.0)
    n = common_normal(a, b)
    np.testing.assert_allclose(n.real, [0.6, 0.8, 0.0], atol=1e-15)
    np.testing.assert_allclose(n.point(), [0.0, 0.0, 0.0], atol=1e-15)


@SETTINGS
@given(cases)
def test_dual_angle_is_invariant_under_displacement(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    a = DualVector.line(*random_line_parts(rng, shape))
    b = DualVector.line(*random_line_parts(rng, shape))
    T = random_screw(rng, shape)
    before, after = dual_angle(a, b), dual_angle(T @ a, T @ b)
    np.testing.assert_allclose(after.real, before.real, atol=1e-9)  # see arccos note above
    np.testing.assert_allclose(after.dual, before.dual, atol=1e-9)


@SETTINGS
@given(cases)
def test_common_normal(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    pa, ua = random_line_parts(rng, shape)
    pb, ub = random_line_parts(rng, shape)
    a, b = DualVector.line(pa, ua), DualVector.line(pb, ub)
    n = common_normal(a, b)
    fa, fb = closest_points(pa, a.real, pb, b.real)
    sd.check_unit_line(n.real, n.dual, tol=1e-12)
    # Through both feet, perpendicular to both lines.
    for foot in (fa, fb):
        np.testing.assert_allclose(np.cross(foot, n.real), n.dual, atol=1e-9)
    np.testing.assert_allclose(np.sum(n.real * a.real, axis=-1), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.sum(n.real * b.real, axis=-1), 0.0, atol=1e-12)
    # Bagci A.21–A.22: â × b̂ = sin φ̂ n̂, i.e. n̂ is the dual normalisation of â × b̂.
    via_dual = a.cross(b).normalized()
    np.testing.assert_allclose(via_dual.real, n.real, atol=1e-9)
    np.testing.assert_allclose(via_dual.dual, n.dual, atol=1e-9)
    sin_phi = sd.sin(dual_angle(a, b))
    scaled = n.scale(sin_phi)
    cross = a.cross(b)
    np.testing.assert_allclose(scaled.real, cross.real, atol=1e-12)
    np.testing.assert_allclose(scaled.dual, cross.dual, atol=1e-9)


@SETTINGS
@given(cases)
def test_norm_and_normalisation(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    v = DualVector(rng.normal(size=(*shape, 3)), rng.normal(size=(*shape, 3)))
    n = v.norm()
    # |v̂|² = v̂·v̂ (dual).
    sq = v.dot(v)
    np.testing.assert_allclose((n * n).real, sq.real, rtol=1e-13)
    np.testing.assert_allclose((n * n).dual, sq.dual, rtol=1e-12, atol=1e-13)
    u = v.normalized()
    sd.check_unit_line(u.real, u.dual, tol=1e-12)
    back = u.scale(n)
    np.testing.assert_allclose(back.real, v.real, atol=1e-12)
    np.testing.assert_allclose(back.dual, v.dual, atol=1e-12)


@SETTINGS
@given(cases)
def test_screw_matrix_moves_lines_like_points(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    p, u = random_line_parts(rng, shape)
    T = random_screw(rng, shape)
    moved = T @ DualVector.line(p, u)
    expected = DualVector.line(T.transform_points(p), np.einsum("...ij,...j->...i", T.real, u))
    np.testing.assert_allclose(moved.real, expected.real, atol=1e-12)
    np.testing.assert_allclose(moved.dual, expected.dual, atol=1e-11)


def test_products_against_definitions() -> None:
    a = DualVector([1.0, 2.0, 3.0], [0.5, -1.0, 2.0])
    b = DualVector([-2.0, 0.5, 1.0], [1.0, 1.0, -3.0])
    d = a.dot(b)
    assert d.real == pytest.approx(-2 + 1 + 3)
    assert d.dual == pytest.approx((1 * 1 + 2 * 1 + 3 * -3) + (0.5 * -2 + -1 * 0.5 + 2 * 1))
    c = a.cross(b)
    np.testing.assert_allclose(c.dual, np.cross(a.real, b.dual) + np.cross(a.dual, b.real))
    s = a.scale(Dual(2.0, 3.0))
    np.testing.assert_allclose(s.dual, 2.0 * a.dual + 3.0 * a.real)


def test_vector_error_paths() -> None:
    with pytest.raises(ValueError, match=r"trailing shape \(3,\)"):
        DualVector(np.zeros((2, 4)))
    with pytest.raises(ValueError, match=r"non-zero direction.*\(1,\)"):
        DualVector.line(np.zeros((2, 3)), np.array([[1.0, 0, 0], [0, 0, 0]]))
    with pytest.raises(ValueError, match="NaN or inf"):
        DualVector.line([0.0, np.nan, 0.0], [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="zero real part"):
        DualVector([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]).norm()
    a = DualVector.line([1.0, 2.0, 3.0], [1.0, 1.0, 0.0])
    b = DualVector.line([2.0, 3.0, 3.0], [-2.0, -2.0, 0.0])
    with pytest.raises(ValueError, match="coincident"):
        common_normal(a, b)
    with pytest.raises(ValueError, match="not a line"):
        sd.check_unit_line([1.0, 0.0, 0.0], [1.0, 0.0, 0.0])

"""The shared spatial toolbox (skew, cross, elementary rotations, angle wrapping) against numpy's
cross product, scipy's rotations and the complex-exponential wrap."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from screwkit.dual.spatial import (
    MATVEC_FROM,
    cross,
    elementary_rotation,
    matvec,
    rot_x,
    rot_y,
    rot_z,
    skew,
    vee,
    wrap_angle,
    wrap_angle_near,
)

SHAPES = [(), (7,), (4, 5)]


@pytest.mark.parametrize("shape", SHAPES)
def test_skew_and_cross_match_numpy_cross(shape: tuple[int, ...]) -> None:
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=(*shape, 3)), rng.normal(size=(*shape, 3))
    expected = np.cross(a, b)
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", skew(a), b), expected,
                               rtol=0, atol=1e-14)
    np.testing.assert_allclose(cross(a, b), expected, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(vee(skew(a)), a)
    np.testing.assert_array_equal(skew(a), -np.swapaxes(skew(a), -1, -2))


def test_matvec_is_numpys_stacked_product_bit_for_bit() -> None:
    """One BLAS product on the stacked rows gives each matrix's product exactly as numpy's
    matmul does (the graph closed forms rely on it for unchanged results), on contiguous
    stacks, on slices of a pose array (each body's rotations), on a broadcast ground, and on
    transposed views (left to numpy)."""
    rng = np.random.default_rng(4)
    x = rng.normal(size=3)
    poses = rng.normal(size=(3 * MATVEC_FROM, 5, 3, 3))
    for R in (poses[:, 0].copy(), poses[:, 3], np.swapaxes(poses[:, 2], -1, -2),
              poses.reshape(-1, 3, 3)[::3], np.broadcast_to(np.eye(3), (MATVEC_FROM, 3, 3)),
              rng.normal(size=(4, MATVEC_FROM, 3, 3)), rng.normal(size=(5, 3, 3)),
              rng.normal(size=(3, 3)) * 1e12):
        np.testing.assert_array_equal(matvec(R, x), R @ x)
    assert matvec(np.zeros((0, 3, 3)), x).shape == (0, 3)


@pytest.mark.parametrize("shape", SHAPES)
def test_elementary_rotations_match_scipy(shape: tuple[int, ...]) -> None:
    rng = np.random.default_rng(2)
    angle = rng.uniform(-7.0, 7.0, size=shape)
    for fn, axis in ((rot_x, "x"), (rot_y, "y"), (rot_z, "z")):
        expected = Rotation.from_euler(axis, angle.reshape(-1, 1)).as_matrix().reshape(*shape, 3, 3)
        np.testing.assert_allclose(fn(angle), expected, rtol=0, atol=1e-15)


def test_elementary_rotation_rejects_an_unknown_axis() -> None:
    with pytest.raises(ValueError, match="axis must be 0"):
        elementary_rotation(np.ones(2), np.zeros(2), 3)


def test_wrap_angle_range_and_boundaries() -> None:
    rng = np.random.default_rng(3)
    x = rng.uniform(-50.0, 50.0, size=10_000)
    w = wrap_angle(x)
    assert np.all((w > -np.pi) & (w <= np.pi))
    np.testing.assert_allclose(np.exp(1j * w), np.exp(1j * x), rtol=0, atol=1e-12)
    np.testing.assert_allclose(w, np.angle(np.exp(1j * x)), rtol=0, atol=1e-12)
    # the convention (-pi, pi]: both ends map to +pi
    assert wrap_angle(np.pi) == np.pi
    assert wrap_angle(-np.pi) == np.pi
    assert wrap_angle(3 * np.pi) == np.pi


def test_wrap_angle_near_equals_wrap_angle_within_three_pi() -> None:
    rng = np.random.default_rng(4)
    x = np.concatenate([rng.uniform(-3 * np.pi, 3 * np.pi, size=10_000),
                        [np.pi, -np.pi, 3 * np.pi, -3 * np.pi + 1e-12, 0.0]])
    near = wrap_angle_near(x)
    assert np.all((near > -np.pi) & (near <= np.pi))
    np.testing.assert_allclose(near, wrap_angle(x), rtol=0, atol=1e-14)

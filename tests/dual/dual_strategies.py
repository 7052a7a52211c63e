"""Shared hypothesis settings and random generators for the tests of screwkit.dual.

Random inputs are drawn from a numpy generator seeded by hypothesis, so every example is a
whole batch (shapes (), (5,), (2, 3)) and the run is deterministic (derandomize=True).
"""

from __future__ import annotations

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from screwkit.dual import Dual, ScrewMatrix

SETTINGS = settings(derandomize=True, max_examples=20, deadline=None)

BATCH_SHAPES = [(), (5,), (2, 3)]
batch_shapes = st.sampled_from(BATCH_SHAPES)
seeds = st.integers(min_value=0, max_value=2**32 - 1)
cases = st.tuples(batch_shapes, seeds)


def rng_for(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def random_rotation(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    """Uniform random rotation matrices (scipy, independent of screwkit), shape (*shape, 3, 3)."""
    n = int(np.prod(shape)) if shape else 1
    R = Rotation.random(n, rng=rng).as_matrix()
    return R.reshape(*shape, 3, 3)


def random_translation(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    return rng.normal(scale=2.0, size=(*shape, 3))


def random_screw(rng: np.random.Generator, shape: tuple[int, ...]) -> ScrewMatrix:
    return ScrewMatrix.from_rotation_translation(
        random_rotation(rng, shape), random_translation(rng, shape)
    )


def random_dual(rng: np.random.Generator, shape: tuple[int, ...], scale: float = 2.0) -> Dual:
    return Dual(rng.normal(scale=scale, size=shape), rng.normal(scale=scale, size=shape))


def random_line_parts(
    rng: np.random.Generator, shape: tuple[int, ...]
) -> tuple[np.ndarray, np.ndarray]:
    """(point, direction) of random lines."""
    return rng.normal(size=(*shape, 3)), rng.normal(size=(*shape, 3))


def assert_screw_close(a: ScrewMatrix, b: ScrewMatrix, atol: float = 1e-10) -> None:
    np.testing.assert_allclose(a.real, b.real, atol=atol, rtol=0)
    np.testing.assert_allclose(a.dual, b.dual, atol=atol, rtol=0)

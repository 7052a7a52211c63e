"""Dense evaluation of quadric homotopies (screwkit.algebraic.quadrics) against the sparse term
table of PolynomialSystem: values, both derivatives, the σ-coefficients, and whole tracks."""

from __future__ import annotations

import numpy as np
import pytest

from homotopy_helpers import dense_family, univariate
from screwkit.algebraic.path import Homotopy
from screwkit.algebraic.quadrics import DenseQuadrics, dense_quadrics_apply
from screwkit.algebraic.solve import StartSolutions
from screwkit.algebraic.track import TrackOptions, track_parameter_homotopy
from screwkit.kinematics.modes.loop6r import loop6r_system
from screwkit.kinematics.modes.stewart import stewart_system


def _complex(rng: np.random.Generator, *shape: int) -> np.ndarray:
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


def test_which_systems_are_quadrics():
    assert dense_quadrics_apply(stewart_system().homogenized())
    assert dense_quadrics_apply(loop6r_system().homogenized())
    assert dense_quadrics_apply(dense_family(3).homogenized())
    assert not dense_quadrics_apply(univariate(4).homogenized())  # a quartic
    assert not dense_quadrics_apply(dense_family(2, degree=3).homogenized())


@pytest.mark.parametrize("name", ["stewart", "loop6r", "dense3"])
def test_dense_equals_sparse(name):
    """H, ∂H/∂y and ∂H/∂τ from the dense form agree with the sparse term table to rounding,
    at random complex points, σ and dσ/dτ, for paths of several instances (all rows and a
    subset), with parameters of degree up to 2 in the coefficients (σ² terms)."""
    system = {"stewart": stewart_system, "loop6r": loop6r_system,
              "dense3": lambda: dense_family(3)}[name]()
    hsys = system.homogenized()
    rng = np.random.default_rng(7)
    B, P = 3, 11
    p_start, direction = _complex(rng, B, system.k), _complex(rng, B, system.k)
    instance = rng.integers(0, B, P)
    dense = DenseQuadrics.build(hsys, p_start, direction)
    patch = _complex(rng, hsys.n)
    sparse = Homotopy(hsys, patch, p_start[instance], direction[instance])
    fast = Homotopy(hsys, patch, p_start[instance], direction[instance], dense, instance)
    y, sigma, dsigma = _complex(rng, P, hsys.n), _complex(rng, P), _complex(rng, P)
    for rows in (None, np.array([0, 4, 5, 9])):
        sub = slice(None) if rows is None else rows
        want = sparse.parts(y[sub], rows, sigma[sub], dsigma[sub])
        got = fast.parts(y[sub], rows, sigma[sub], dsigma[sub])
        for a, b in zip(want, got, strict=True):
            assert a is not None and b is not None
            assert np.abs(a - b).max() <= 1e-13 * np.abs(a).max()


def test_sigma_coefficients_reproduce_the_parameter_segment():
    """Σ σ^k Q_k at a real σ off the unit circle equals the coefficients evaluated at
    p_start + σ·d directly (the DFT interpolation is exact for degree ≤ K − 1)."""
    system = stewart_system()
    hsys = system.homogenized()
    rng = np.random.default_rng(3)
    p0, d = _complex(rng, 1, system.k), _complex(rng, 1, system.k)
    dense = DenseQuadrics.build(hsys, p0, d)
    sigma = 0.37
    direct = DenseQuadrics.build(hsys, p0 + sigma * d, np.zeros_like(d))
    Q = dense.matrices(0)
    combined = sum(sigma**k * Q[k] for k in range(dense.K))
    at = direct.matrices(0)
    assert np.abs(combined - at[0]).max() <= 1e-12 * np.abs(at[0]).max()
    assert direct.K == dense.K == 3 and not np.any(at[1:])  # d = 0: no σ terms, exactly
    assert np.allclose(Q, Q.transpose(0, 1, 3, 2), rtol=0, atol=0)  # symmetric


def test_tracks_agree_with_the_sparse_evaluation():
    """Whole parameter homotopies (a batch of 3 instances of 3 dense quadrics, 8 paths each):
    the dense and sparse evaluations end at the same points with the same statuses."""
    system = dense_family(3)
    start = StartSolutions.by_total_degree(system, seed=2)
    assert start.generic_count == 8
    targets = np.random.default_rng(5).standard_normal((3, system.k))
    args = (system, start.p, np.repeat(targets, 8, axis=0), np.tile(start.x, (3, 1)))
    fast = track_parameter_homotopy(*args)
    slow = track_parameter_homotopy(*args, TrackOptions(dense=False))
    assert (fast.status == slow.status).all() and fast.counts()["regular"] == 24
    assert np.abs(fast.x - slow.x).max() <= 1e-10

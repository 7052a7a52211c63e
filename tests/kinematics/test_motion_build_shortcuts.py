"""The Motion build's shortcuts against the exact computations they stand in for: the rank
test's determinant bound (rates._sigma_ratio) and the first-order closure residual
(mode_frames.closure_residual)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from screwkit.kinematics.tracker.loop import closure_twist, rotation_matrix
from screwkit.kinematics.tracker.mode_frames import closure_residual
from screwkit.kinematics.tracker.rates import SINGULAR_RTOL, _sigma_ratio


def _jacobians(rng, n, k, m, weakest):
    """Random k×m matrices with σ_min/σ_max = ``weakest`` (n of them)."""
    U = np.linalg.qr(rng.normal(size=(n, k, k)))[0][:, :, :m]
    V = np.linalg.qr(rng.normal(size=(n, m, m)))[0]
    s = np.exp(rng.uniform(np.log(weakest)[:, None], 0.0, (n, m)))
    s[:, 0], s[np.arange(n), 1 + rng.integers(0, m - 1, n)] = 1.0, weakest
    return np.einsum("nij,nj,nkj->nik", U, s, V)


@settings(max_examples=20, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**32 - 1), k=st.integers(3, 7), extra=st.integers(0, 2))
def test_the_determinant_bound_gives_the_rank_test_s_answer(seed, k, extra):
    rng = np.random.default_rng(seed)
    m = max(2, k - extra)
    # σ ratios on both sides of the threshold, down to 1e-9 and up to 1
    weakest = 10.0 ** rng.uniform(-9.0, 0.0, 400)
    weakest[:20] = SINGULAR_RTOL * rng.uniform(0.5, 2.0, 20)
    J = _jacobians(rng, 400, k, m, weakest)
    exact = _sigma_ratio(J, True)
    # (through JᵀJ the ratio is known to ~1e-8 absolute: √ of round-off)
    np.testing.assert_allclose(exact, weakest, rtol=1e-6, atol=1e-7)
    fast = _sigma_ratio(J, False)
    computed = np.isfinite(fast)
    np.testing.assert_array_equal(fast[computed], exact[computed])
    # where it is not computed the ratio is certainly above the threshold
    assert np.all(exact[~computed] > SINGULAR_RTOL)
    np.testing.assert_array_equal(fast < SINGULAR_RTOL, exact < SINGULAR_RTOL)
    assert computed.mean() < 0.9  # the shortcut does skip most well-conditioned samples


def test_the_first_order_closure_residual_is_the_exact_one_where_it_matters():
    rng = np.random.default_rng(3)
    rows = np.array([1, 1, 1, 0.5, 0.5, 0.5])
    size = 10.0 ** rng.uniform(-16, 0.5, 2000)
    w = rng.normal(size=(2000, 3))
    w *= (size / np.linalg.norm(w, axis=1))[:, None]
    w[:10] *= np.pi / np.linalg.norm(w[:10], axis=1)[:, None]  # half turns
    R, p = rotation_matrix(w), rng.normal(size=(2000, 3)) * size[:, None]
    exact = np.max(np.abs(closure_twist(R, p) * rows), axis=-1)
    got = closure_residual(R, p, rows)
    np.testing.assert_allclose(got, exact, rtol=2e-6, atol=1e-300)
    assert np.all(got[:10] > 1.5)  # a half turn is never mistaken for closure

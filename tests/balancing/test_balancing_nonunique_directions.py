"""Non-unique balancing optima are reported in a canonical basis: the basis depends only on the
space of directions, and Rahman's example gives the expected two directions."""

from __future__ import annotations

import numpy as np

from screwkit.pipeline import balance_from_spec


def test_canonical_basis_depends_only_on_the_space():
    from screwkit.balancing.problem import canonical_basis

    rng = np.random.default_rng(3)
    space = np.linalg.qr(rng.normal(size=(6, 3)))[0]
    first = canonical_basis(space)
    for _ in range(5):
        rot = np.linalg.qr(rng.normal(size=(3, 3)))[0]  # another orthonormal basis, any signs
        # the basis is rebuilt by elimination: agreement to round-off of a 6x3 elimination
        np.testing.assert_allclose(canonical_basis(space @ rot), first, atol=1e-12)
    # same space, unit columns, leading entries positive
    np.testing.assert_allclose(np.linalg.norm(first, axis=0), 1.0, atol=1e-12)
    proj = space @ space.T
    np.testing.assert_allclose(proj @ first, first, atol=1e-12)
    lead = [col[np.flatnonzero(np.abs(col) > 1e-12)[0]] for col in first.T]
    assert all(v > 0 for v in lead)


def test_rahman_directions_are_canonical(rahman):
    spec, mode = rahman
    res = balance_from_spec(spec, mode_motion=mode)
    h = np.sqrt(0.5)
    got = [{k: round(v, 12) for k, v in d.direction.items()} for d in res.directions]
    assert got == [{"crank.m1": round(h, 12), "crank.m3": round(-h, 12)},
                   {"crank.m2": round(h, 12), "crank.m3": round(-h, 12)}]

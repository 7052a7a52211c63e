"""Smale's α-test: true roots certified, far points refused, the certified radius holds the
root, real and non-real roots told apart, and overlapping certified balls merged."""

from __future__ import annotations

import numpy as np

from screwkit.algebraic.certify import ALPHA_0, certify, distinct
from screwkit.algebraic.polynomial import Poly, compile_system


def _circle_parabola():
    # x² + y² = 1 and x = 2y² − 1/2: y² = (x + 1/2)/2, so x² + x/2 − 3/4 = 0,
    # x = (−1/2 ± √13/2)/2: x₊ = 0.6514 gives two real points, x₋ = −1.1514 two complex ones
    x, y = Poly.variable(0), Poly.variable(1)
    system = compile_system([x * x + y * y - 1, x - 2 * y * y + 0.5], ["x", "y"])
    xp, xm = (-0.5 + np.sqrt(13) / 2) / 2, (-0.5 - np.sqrt(13) / 2) / 2
    yp, ym = np.sqrt((xp + 0.5) / 2), np.sqrt(complex((xm + 0.5) / 2))
    roots = np.array([[xp, yp], [xp, -yp], [xm, ym], [xm, -ym]], dtype=complex)
    return system, roots


def test_true_roots_are_certified_and_real_ones_told_from_complex():
    system, roots = _circle_parabola()
    cert = certify(system, roots, np.zeros(0))
    assert cert.certified.all() and (cert.alpha < 1e-10).all()
    assert cert.real.tolist() == [True, True, False, False]
    assert cert.not_real.tolist() == [False, False, True, True]


def test_a_point_far_from_every_root_is_refused():
    system, _ = _circle_parabola()
    cert = certify(system, np.array([[3.0, 2.0], [0.2, 0.1]], dtype=complex), np.zeros(0))
    assert not cert.certified.any() and (cert.alpha > ALPHA_0).all()


def test_the_certified_radius_contains_the_root():
    system, roots = _circle_parabola()
    rng = np.random.default_rng(0)
    for scale in (1e-8, 1e-5, 1e-3):
        moved = roots + scale * (rng.standard_normal(roots.shape)
                                 + 1j * rng.standard_normal(roots.shape))
        cert = certify(system, moved, np.zeros(0))
        assert cert.certified.all()
        distance = np.linalg.norm(moved - roots, axis=1)
        assert (distance <= cert.radius).all()  # ‖x − ξ‖ ≤ 2β (BCSS 1998, ch. 8, Thm 2)
        assert (cert.radius < 20 * scale).all()


def test_a_real_root_seen_with_a_small_imaginary_part_is_still_certified_real():
    system, roots = _circle_parabola()
    cert = certify(system, roots[:2] + 1e-9j, np.zeros(0))
    assert cert.real.all()
    # the same system with a complex coefficient is not real: no real certificate at all
    x, y = Poly.variable(0), Poly.variable(1)
    skew = compile_system([x * x + y * y - 1, x - 2 * y * y + (0.5 + 1e-3j)], ["x", "y"])
    assert not certify(skew, roots[:2], np.zeros(0)).real.any()


def test_overlapping_certified_balls_count_once():
    system, roots = _circle_parabola()
    points = np.vstack([roots, roots[0] + 1e-13, roots[2] - 1e-13j])
    cert = certify(system, points, np.zeros(0))
    label = distinct(points, cert.radius, np.zeros(len(points), dtype=np.intp))
    assert label.tolist() == [0, 1, 2, 3, 0, 2]
    # in different groups (instances) the same point is not a duplicate
    groups = np.array([0, 0, 0, 0, 1, 1])
    assert distinct(points, cert.radius, groups).tolist() == [0, 1, 2, 3, 4, 5]


def test_the_fast_bounds_are_on_the_safe_side_of_the_svd_ones():
    """``fast=True`` bounds 2-norms by Frobenius norms: α, β and γ are never smaller than the
    SVD route's (and at most √n · (1 + round-off) larger in γ), so it certifies no point the
    SVD route refuses; near the roots both certify."""
    system, roots = _circle_parabola()
    rng = np.random.default_rng(3)
    points = np.concatenate([roots + 1e-6 * rng.normal(size=roots.shape),
                             roots + 0.2 * rng.normal(size=roots.shape)])
    exact, fast = certify(system, points, np.zeros(0)), certify(system, points, np.zeros(0),
                                                                 fast=True)
    for name in ("alpha", "beta", "gamma"):
        assert (getattr(fast, name) >= getattr(exact, name) * (1 - 1e-12)).all(), name
    assert (fast.gamma <= exact.gamma * np.sqrt(2) * (1 + 1e-9)).all()
    assert not (fast.certified & ~exact.certified).any()
    assert fast.certified[:4].all() and exact.certified[:4].all()
    assert np.allclose(fast.newton, exact.newton, rtol=1e-12, atol=1e-14)

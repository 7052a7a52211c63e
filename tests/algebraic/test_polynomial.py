"""PolynomialSystem evaluation: values and both Jacobians against central differences, the
directional parameter derivative against ∂F/∂p·dp, and the homogenised system against
h^d·F(x/h)."""

from __future__ import annotations

import numpy as np

from homotopy_helpers import dense_family
from screwkit.algebraic.polynomial import Poly, compile_system


def _system():
    x, y, z, a, b = (Poly.variable(i) for i in range(5))
    return compile_system([x * x * y + a * z - 3 + b * b * x, y**3 - a * b + 2j * x * z,
                           z * z + x - b * y * a * x], ["x", "y", "z"], ["a", "b"])


def test_jacobians_match_central_differences():
    system = _system()
    rng = np.random.default_rng(1)
    x = rng.standard_normal((4, 3)) + 1j * rng.standard_normal((4, 3))
    p = rng.standard_normal((4, 2)) + 1j * rng.standard_normal((4, 2))
    F, Jx, Jp = system.evaluate(x, p)
    h = 1e-6
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        diff = (system.evaluate(x + e, p)[0] - system.evaluate(x - e, p)[0]) / (2 * h)
        assert np.abs(diff - Jx[:, :, i]).max() < 1e-8
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        diff = (system.evaluate(x, p + e)[0] - system.evaluate(x, p - e)[0]) / (2 * h)
        assert np.abs(diff - Jp[:, :, j]).max() < 1e-8
    # a hand value: F_0 = x²y + a z − 3 + b² x
    X, Y, Z = x[0]
    A, B = p[0]
    assert abs(F[0, 0] - (X * X * Y + A * Z - 3 + B * B * X)) < 1e-13


def test_directional_derivative_is_jp_times_direction():
    system = dense_family(3)
    rng = np.random.default_rng(2)
    x = rng.standard_normal((5, 3)) + 1j * rng.standard_normal((5, 3))
    p = rng.standard_normal((5, system.k)) + 1j * rng.standard_normal((5, system.k))
    dp = rng.standard_normal((5, system.k))
    F, Jx, Jp = system.evaluate(x, p)
    F2, Jx2, Fdp = system.evaluate_directional(x, p, dp)
    assert np.allclose(F, F2) and np.allclose(Jx, Jx2)
    assert np.abs(Fdp - np.einsum("bij,bj->bi", Jp, dp)).max() < 1e-12


def test_homogenised_system_is_h_to_the_degree_times_f():
    system = _system()
    hom = system.homogenized()
    rng = np.random.default_rng(3)
    x = rng.standard_normal((4, 3)) + 1j * rng.standard_normal((4, 3))
    h = rng.standard_normal(4) + 1j * rng.standard_normal(4)
    p = rng.standard_normal(2)
    F, _, _ = system.evaluate(x, p, want_jp=False)
    Fh, _, _ = hom.evaluate(np.column_stack([h, x * h[:, None]]), p, want_jp=False)
    assert hom.variables[0] == "h" and hom.n == 4 and hom.size == 3
    assert np.abs(Fh - F * h[:, None] ** np.array(system.degrees)).max() < 1e-12


def test_coefficients_at_rebuild_the_values():
    system = _system()
    rng = np.random.default_rng(4)
    p = rng.standard_normal((2, 2))
    x = rng.standard_normal(3) + 1j * rng.standard_normal(3)
    eq, exps, coef = system.coefficients_at(p)
    monomial = np.prod(x[None, :] ** exps, axis=1)
    for b in range(2):
        rebuilt = np.bincount(eq, weights=(coef[b] * monomial).real, minlength=3) + 1j * \
            np.bincount(eq, weights=(coef[b] * monomial).imag, minlength=3)
        F, _, _ = system.evaluate(x[None], p[b], want_jp=False)
        assert np.abs(rebuilt - F[0]).max() < 1e-12

"""Polynomial systems shared by the tests of screwkit.algebraic (tests/algebraic)."""

from __future__ import annotations

import itertools

import numpy as np

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system


def univariate(degree: int) -> PolynomialSystem:
    """x^d + c_{d−1}x^{d−1} + … + c_0 with the coefficients c as parameters."""
    x = Poly.variable(0)
    f = x**degree + sum((Poly.variable(1 + i) * x**i for i in range(degree)), Poly.constant(0))
    return compile_system([f], ["x"], [f"c{i}" for i in range(degree)])


def univariate_start(degree: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Generic complex coefficients with known roots: (c (degree,), roots (degree, 1))."""
    rng = np.random.default_rng(seed)
    roots = rng.standard_normal(degree) + 1j * rng.standard_normal(degree)
    return np.poly(roots)[::-1][:degree], roots[:, None]


def monomials(n: int, degree: int) -> list[tuple[int, ...]]:
    return [m for m in itertools.product(range(degree + 1), repeat=n) if sum(m) <= degree]


def dense_family(n: int, degree: int = 2) -> PolynomialSystem:
    """n dense equations of total degree ``degree`` in n unknowns, every coefficient a
    parameter (equation i's coefficient of monomial j is parameter i·len(monomials) + j)."""
    xs = [Poly.variable(i) for i in range(n)]
    mons = monomials(n, degree)
    equations = []
    for i in range(n):
        f = Poly.constant(0)
        for j, m in enumerate(mons):
            term = Poly.variable(n + i * len(mons) + j)
            for v, e in enumerate(m):
                term = term * xs[v] ** e
            f = f + term
        equations.append(f)
    return compile_system(equations, [f"x{i}" for i in range(n)],
                          [f"c{i}" for i in range(n * len(mons))])


def dense_system(n: int, degree: int, seed: int) -> PolynomialSystem:
    """A dense system with random real coefficients and no parameters."""
    rng = np.random.default_rng(seed)
    xs = [Poly.variable(i) for i in range(n)]
    equations = []
    for _ in range(n):
        f = Poly.constant(0)
        for m in monomials(n, degree):
            term = Poly.constant(float(rng.standard_normal()))
            for v, e in enumerate(m):
                term = term * xs[v] ** e
            f = f + term
        equations.append(f)
    return compile_system(equations, [f"x{i}" for i in range(n)])


def generic_point(system: PolynomialSystem, n_monomials: int,
                  seed: int) -> tuple[np.ndarray, np.ndarray]:
    """For a :func:`dense_family`: a random complex x0 and random complex coefficients p0
    whose constant terms are shifted so that F(x0; p0) = 0."""
    rng = np.random.default_rng(seed)
    x0 = rng.standard_normal(system.n) + 1j * rng.standard_normal(system.n)
    p0 = rng.standard_normal(system.k) + 1j * rng.standard_normal(system.k)
    F, _, _ = system.evaluate(x0[None], p0, want_jp=False)
    p0[np.arange(system.n) * n_monomials] -= F[0]  # monomial 0 is the constant
    return p0, x0

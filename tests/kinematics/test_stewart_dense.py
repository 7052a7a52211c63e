"""The Stewart–Gough route's dense quadrics (modes/stewart_solve.py's ``dense_quadrics``) against
the term table of modes/stewart.py's system (a second evaluation of the same equations), and
the dense Newton polish and fast α-test (modes/eigen_first.py, algebraic/compiled.py) against
the term table's, compiled and in numpy."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from screwkit.algebraic import compiled
from screwkit.algebraic.certify import bombieri_weyl_norm, certify, term_magnitude
from screwkit.kinematics.modes import eigen_first
from screwkit.kinematics.modes.stewart import random_stewart, stewart_system
from screwkit.kinematics.modes.stewart_solve import dense_quadrics, stewart_route
from screwkit.kinematics.modes.stewart_template import template_solve


def _instances(B: int, seed: int) -> np.ndarray:
    p, _ = random_stewart(np.random.default_rng(seed), B)
    p = p.astype(complex)
    p[-1] += 0.3j * np.random.default_rng(seed + 1).standard_normal(42)  # one complex instance
    return p


@pytest.mark.parametrize("kernel", [True, False], ids=["compiled", "numpy"])
def test_the_dense_quadrics_are_the_term_tables_equations(kernel: bool, monkeypatch) -> None:
    """F, ∂F/∂x from zᵀ Q z and 2 (Q z)[:n] equal the term table's at random complex points;
    |z|ᵀ |Q| |z| equals its Σ|terms| (the α-test's rounding scale) to rounding; from the
    compiled kernel (modes/stewart_kernels.py, where numba is there) and the numpy route."""
    monkeypatch.setattr(compiled, "AVAILABLE", kernel)
    system = stewart_system()
    p = _instances(4, 3)
    rng = np.random.default_rng(1)
    x = rng.standard_normal((4, 8)) + 1j * rng.standard_normal((4, 8))
    F, J, _ = system.evaluate(x, p, want_jp=False)
    Q, Qabs = dense_quadrics(p)
    assert np.allclose(Q, np.swapaxes(Q, -1, -2), rtol=0, atol=0)
    z = np.concatenate([x, np.ones((4, 1))], axis=1)
    Fd = np.einsum("pijk,pj,pk->pi", Q, z, z)
    Jd = 2.0 * np.einsum("pijk,pk->pij", Q, z)[:, :, :8]
    assert np.abs(Fd - F).max() <= 1e-13 * np.abs(F).max()
    assert np.abs(Jd - J).max() <= 1e-13 * np.abs(J).max()
    az = np.abs(z)
    mag = np.einsum("pijk,pj,pk->pi", Qabs.real, az, az)
    table = term_magnitude(system, x, p)
    assert np.allclose(mag, table, rtol=1e-13, atol=0)
    assert (Qabs.imag == 0).all() and (Qabs.real >= 0).all()


def _template_points(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x, _ = template_solve(p)
    inst = np.repeat(np.arange(len(p)), x.shape[1])
    return x.reshape(-1, 8), inst


def test_the_dense_polish_equals_the_term_tables(monkeypatch) -> None:
    """The dense Newton steps (compiled and numpy) reach the term table's points."""
    system = stewart_system()
    p = _instances(3, 5)
    x, inst = _template_points(p)
    Q, _ = dense_quadrics(p)
    table = eigen_first.newton(system, x, p[inst], 6)
    dense = eigen_first.newton_dense(Q, inst, x, 6)
    with monkeypatch.context() as m:
        m.setattr(compiled, "AVAILABLE", False)
        numpy_dense = eigen_first.newton_dense(Q, inst, x, 6)
    scale = 1.0 + np.abs(table).max(axis=1)
    for got in (dense, numpy_dense):
        assert (np.abs(got - table).max(axis=1) <= 1e-9 * scale).all()
    # the polish moved the points: the test is not comparing the raw points with themselves
    assert (np.abs(table - x).max(axis=1) > 1e-14 * scale).any()


def test_the_dense_alpha_test_equals_the_term_tables() -> None:
    """The fast α-test from the quadrics gives the term table's certificates: the same
    verdicts, the same γ (‖f‖ and the bound are shared), β and α to rounding."""
    system = stewart_system()
    p = _instances(3, 7)
    x, inst = _template_points(p)
    Q, Qabs = dense_quadrics(p)
    x = eigen_first.newton_dense(Q, inst, x, 6)
    x = np.concatenate([x, x[:1] + 1e-3, np.zeros((1, 8))])  # one not certified, one singular
    inst = np.concatenate([inst, inst[:2]])
    norm_f = bombieri_weyl_norm(system, p)[inst]
    old = certify(system, x, p[inst], fast=True, norm_f=norm_f)
    new = certify(system, x, p[inst], fast=True, norm_f=norm_f, dense=(Q, Qabs, inst))
    assert old.certified[:-2].mean() > 0.9 and not old.certified[-2:].any()
    for name in ("certified", "real", "not_real"):
        assert np.array_equal(getattr(new, name), getattr(old, name)), name
    good = old.certified
    assert np.allclose(new.gamma[good], old.gamma[good], rtol=1e-9, atol=0)
    # β = ‖J⁻¹F‖ at a polished point is round-off of F, so it (and α = βγ) differ between the
    # two evaluation orders at the percent level; the verdicts above are identical
    for name in ("alpha", "beta"):
        assert np.allclose(getattr(new, name)[good], getattr(old, name)[good], rtol=1e-2,
                           atol=0), name
        assert np.array_equal(np.isinf(getattr(new, name)), np.isinf(getattr(old, name)))
    assert np.allclose(new.terms, old.terms, rtol=1e-12, atol=0)
    assert np.allclose(new.newton[good], old.newton[good], rtol=0, atol=1e-12)


def test_the_route_with_and_without_the_quadrics_finds_the_same() -> None:
    """The whole eigen route with the dense evaluation and with the term table: the same
    routes, points (to round-off), certified and real counts."""
    p = _instances(12, 11)
    route = stewart_route()
    a = eigen_first.solve_eigen_first(dataclasses.replace(route, quadrics=None), p)
    b = eigen_first.solve_eigen_first(route, p)
    assert a.route == b.route and np.array_equal(a.instance, b.instance)
    assert np.array_equal(a.found, b.found) and np.array_equal(a.real_count, b.real_count)
    assert b.certified.sum() >= a.certified.sum() and a.certified.mean() > 0.95
    assert np.array_equal(a.certified_real_count, b.certified_real_count)
    for i in range(len(p)):
        xa, xb = a.x[a.instance == i], b.x[b.instance == i]
        d = np.abs(xa[:, None] - xb[None]).max(axis=2) / (1.0 + np.abs(xa).max(axis=1))[:, None]
        assert d.min(axis=1).max() <= 1e-10 and d.min(axis=0).max() <= 1e-10


def test_a_batchs_quadric_matrices_in_threads_are_each_instances(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A batch's quadric matrices made in parts on three threads are, bit for bit, each
    instance's made alone."""
    from screwkit.kinematics.modes import stewart_solve

    monkeypatch.setattr(stewart_solve, "THREADS", 3)
    p, _ = random_stewart(np.random.default_rng(52), 100)
    p = p.real.astype(complex)
    Q, Qabs = stewart_solve.dense_quadrics(p)
    for b in (0, 33, 34, 66, 67, 99):
        one, one_abs = stewart_solve.dense_quadrics(p[b:b + 1])
        assert np.array_equal(Q[b], one[0]) and np.array_equal(Qabs[b], one_abs[0]), b

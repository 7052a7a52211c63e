"""The multi-homogeneous homotopy (algebraic/multi_homogeneous.py): its Bézout number equals a
brute-force expansion of Π_i Σ_j d_ij·α_j; the linear-product start system has exactly that
many distinct solutions, each a zero of it; on a generalised eigenvalue problem (bilinear in
(λ, v)) it tracks n paths against the total degree's 2^n and finds the same finite solutions,
which are numpy's eigenvalues; on a planar six-bar in isotropic coordinates it tracks 6 paths
against 16 and finds the total-degree homotopy's solutions."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from screwkit.algebraic.multi_homogeneous import (
    Grouping,
    LinearProduct,
    mhom_bezout_of,
    multi_homogeneous_bezout,
    solve_multi_homogeneous,
)
from screwkit.algebraic.polynomial import Poly, compile_system
from screwkit.algebraic.total_degree import bezout_number, solve_total_degree
from screwkit.errors import InputError
from screwkit.io.mechanism_spec import graph_spec_from_data
from screwkit.io.toml_file import read_toml
from screwkit.kinematics.modes.planar import planar_formulation

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


def _brute_force_bezout(degrees: np.ndarray, sizes: list[int]) -> int:
    """The coefficient of Π α_j^(n_j) in Π_i Σ_j d_ij α_j, by expanding every product."""
    total = 0
    for pick in itertools.product(range(len(sizes)), repeat=len(degrees)):
        if [pick.count(j) for j in range(len(sizes))] == sizes:
            total += int(np.prod([degrees[i, j] for i, j in enumerate(pick)]))
    return total


def test_the_bezout_number_equals_the_expanded_coefficient():
    rng = np.random.default_rng(3)
    for _ in range(20):
        sizes = [int(s) for s in rng.integers(1, 3, size=rng.integers(2, 4))]
        degrees = rng.integers(0, 3, size=(sum(sizes), len(sizes)))
        assert multi_homogeneous_bezout(degrees, sizes) == _brute_force_bezout(degrees, sizes)


def test_the_linear_product_system_has_exactly_bezout_many_distinct_zeros():
    rng = np.random.default_rng(5)
    groups = ((0, 2), (1,), (3,))
    degrees = np.array([[1, 1, 0], [2, 0, 1], [1, 2, 1], [0, 1, 2]])
    product = LinearProduct.random(groups, degrees, rng)
    u = product.solutions()
    assert len(u) == multi_homogeneous_bezout(degrees, [2, 1, 1]) == 15
    system = compile_system(product.polys(), [f"u{i}" for i in range(4)])
    F, _, _ = system.evaluate(u, np.zeros(0))
    assert np.abs(F).max() < 1e-10
    gaps = np.abs(u[:, None] - u[None]).max(axis=2) + np.eye(len(u))
    assert gaps.min() > 1e-6


def _eigen_system(n: int, seed: int):
    """(A − λB)v = 0 with the patch c·v = 1: n+1 equations in (λ, v), A, B as parameters."""
    rng = np.random.default_rng(seed)
    A, B, c = rng.standard_normal((n, n)), rng.standard_normal((n, n)), rng.standard_normal(n)
    lam, v = Poly.variable(0), [Poly.variable(1 + i) for i in range(n)]
    a = [[Poly.variable(n + 1 + n * i + j) for j in range(n)] for i in range(n)]
    eqs = [sum((a[i][j] * v[j] - B[i, j] * lam * v[j] for j in range(n)), Poly())
           for i in range(n)]
    eqs.append(sum((c[j] * v[j] for j in range(n)), Poly()) - 1)
    system = compile_system(eqs, ["lam", *(f"v{i}" for i in range(n))],
                            [f"a{i}{j}" for i in range(n) for j in range(n)])
    return system, A, B


def test_a_bilinear_eigenvalue_system_tracks_fewer_paths_and_finds_the_same_solutions():
    n = 5
    system, A, B = _eigen_system(n, 11)
    grouping = Grouping(((0,), tuple(range(1, n + 1))))
    assert mhom_bezout_of(system, grouping) == n < bezout_number(system) == 2 ** n
    p = A.reshape(-1).astype(complex)
    mh = solve_multi_homogeneous(system, p, grouping)
    td = solve_total_degree(system, p)
    assert len(mh.result.status) == n and len(td.status) == 2 ** n
    ours = mh.result.x[mh.result.regular]
    theirs = td.x[td.regular]
    eig = np.linalg.eigvals(np.linalg.solve(B, A))
    assert len(ours) == len(theirs) == n
    _same_points(ours[:, :1], eig[:, None], 1e-9)
    _same_points(theirs, ours, 1e-8)


def _same_points(a: np.ndarray, b: np.ndarray, tol: float) -> None:
    """a and b hold the same points (rows), one to one, within tol relative."""
    gap = np.abs(a[:, None] - b[None]).max(axis=2)
    assert (gap.min(axis=1) <= tol * (1 + np.abs(b).max())).all(), gap.min(axis=1)
    assert len(set(gap.argmin(axis=1).tolist())) == len(a) == len(b)


def test_a_planar_six_bar_in_isotropic_coordinates_tracks_six_paths_not_sixteen():
    path = EXAMPLES / "stephenson3_sixbar.toml"
    form = planar_formulation(graph_spec_from_data(read_toml(path), path).mechanism)
    grouping = form.grouping
    assert mhom_bezout_of(form.system, grouping) == 6 < bezout_number(form.system) == 16
    rng = np.random.default_rng(2)
    p = rng.standard_normal(form.system.k) + 1j * rng.standard_normal(form.system.k)
    mh = solve_multi_homogeneous(form.system, p, grouping, seed=1)
    td = solve_total_degree(form.system, p, seed=1)
    ours, theirs = mh.result.x[mh.result.regular], td.x[td.regular]
    assert len(mh.result.status) == 6 and len(ours) == len(theirs) == 6
    _same_points(ours, theirs, 1e-8)
    F, _, _ = form.system.evaluate(ours, p, want_jp=False)
    assert np.abs(F).max() < 1e-9


def test_a_bad_grouping_is_refused():
    system, _, _ = _eigen_system(3, 1)
    with pytest.raises(InputError, match="split the 4 unknowns"):
        mhom_bezout_of(system, Grouping(((0, 1), (1, 2, 3))))
    x0 = Poly.variable(0)
    lacking = compile_system([x0 - 1, x0 * x0 + 2], ["x0", "x1"])  # x1 in no equation
    with pytest.raises(InputError, match="no solutions to track"):
        solve_multi_homogeneous(lacking, np.zeros(0), Grouping(((0,), (1,))))
    with pytest.raises(InputError, match="invertible"):
        mhom_bezout_of(system, Grouping(((0,), (1, 2, 3)), np.zeros((4, 4))))

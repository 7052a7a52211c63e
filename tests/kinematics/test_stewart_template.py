"""Stewart–Gough forward kinematics by the elimination template (modes/stewart_template.py,
modes/stewart_solve.py), checked against the parameter homotopy (a second method) and the leg
lengths of every real pose (‖R b_i + t − a_i‖ from the pose, not from the polynomial system).

``SCREWKIT_MODES_INSTANCES`` sets the number of random instances (default 200).
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from screwkit.algebraic.solve import Solutions, solve_all
from screwkit.errors import InputError
from screwkit.kinematics.modes import eigen_first, stewart_solve, stewart_sparse, stewart_template
from screwkit.kinematics.modes import stewart_template_data as data
from screwkit.kinematics.modes.stewart import (
    leg_lengths,
    pose_from_study,
    random_stewart,
    stewart_start,
    stewart_system,
)
from screwkit.kinematics.modes.stewart_solve import HOMOTOPY, TEMPLATE, solve_stewart
from screwkit.kinematics.modes.stewart_template import (
    UNKNOWNS,
    action_matrices,
    coefficients,
    monomials,
    template_solve,
)

INSTANCES = int(os.environ.get("SCREWKIT_MODES_INSTANCES", "200"))
#: solutions of the two routes agree to this, relative to 1 + the largest coordinate
MATCH = 1e-8
#: every real pose's leg lengths are the instance's to this (unit-scale platforms)
CLOSE = 1e-10


def _matched(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance from a point of either set to the nearest of the other."""
    if len(a) == 0 or len(b) == 0:
        return 0.0 if len(a) == len(b) else np.inf
    d = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2) / (
        1.0 + np.maximum(np.abs(a).max(axis=1)[:, None], np.abs(b).max(axis=1)[None, :]))
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


def _legs_close(sol: Solutions, p: np.ndarray) -> float:
    R, t = pose_from_study(sol.x[sol.real].real.astype(complex))
    inst = sol.instance[sol.real]
    L = leg_lengths(R.real, t.real, p[inst, :18].real.reshape(-1, 6, 3),
                    p[inst, 18:36].real.reshape(-1, 6, 3))
    return float(np.abs(L - np.sqrt(p[inst, 36:].real)).max(initial=0.0))


def test_the_template_gives_the_homotopys_40_on_random_platforms() -> None:
    p, z = random_stewart(np.random.default_rng(31), INSTANCES)
    p = p.real
    sol = solve_stewart(p)
    by_template = np.array([r == TEMPLATE for r in sol.route])
    assert by_template.mean() >= 0.95, f"{(~by_template).sum()} by the homotopy"
    assert np.mean(sol.found == 40) >= 0.99, np.flatnonzero(sol.found != 40)
    assert sol.certified_real[sol.real].mean() >= 0.99
    assert _legs_close(sol, p) <= CLOSE
    hom = solve_all(stewart_system(), p, stewart_start())
    # every real pose is certified that the homotopy's route certifies (a pose that neither
    # certifies is ill-conditioned at double precision: α ≈ 1e2)
    assert np.all(sol.certified_real_count >= hom.certified_real_count)
    for b in range(INSTANCES):  # every homotopy pose is found, and the drawn one
        assert np.abs(sol.of(b) - z[b].real).max(axis=1).min() <= MATCH, b
        if hom.found[b] == 40 and sol.found[b] == 40:
            assert _matched(sol.of(b), hom.of(b)) <= MATCH, b
        else:  # the template may find poses the homotopy misses, never the reverse
            h = hom.of(b)
            d = np.abs(h[:, None] - sol.of(b)[None]).max(axis=2).min(axis=1)
            assert np.all(d <= MATCH * (1 + np.abs(h).max(axis=1))), b


@pytest.mark.parametrize(("sparse", "median", "share"), [(False, 1e-6, 0.9), (True, 1e-5, 0.75)])
def test_the_template_points_are_the_homotopys_before_any_polish(
        monkeypatch: pytest.MonkeyPatch, sparse: bool, median: float, share: float) -> None:
    """The raw eigenvector points (no Newton step) are the homotopy's 40: by the LAPACK route
    at the median within 1e-6 (relative), nine in ten within 1e-3 (the block-triangular solve
    pivots within blocks only, so a few arrive further off and are brought in by the polish);
    by the sparse route (fixed pivots, modes/stewart_sparse.py; measured on these 20: median
    4e-6, 80% within 1e-3) within 1e-5 and three in four within 1e-3: the elimination itself is
    right, not only the polish."""
    if sparse and not stewart_sparse.AVAILABLE:
        pytest.skip("the sparse route needs numba")
    monkeypatch.setattr(stewart_sparse, "AVAILABLE", sparse)
    p, _ = random_stewart(np.random.default_rng(32), 20)
    p = p.real.astype(complex)
    pts, keys = template_solve(p)
    hom = solve_all(stewart_system(), p, stewart_start())
    assert np.all(hom.found == 40) and np.all(np.isfinite(pts))
    gap = np.concatenate([
        (np.abs(pts[b][:, None] - hom.of(b)[None]).max(axis=2)
         / (1.0 + np.abs(pts[b]).max(axis=1))[:, None]).min(axis=1) for b in range(20)])
    assert np.median(gap) <= median and np.mean(gap <= 1e-3) >= share, np.sort(gap)[-10:]
    for b in range(20):  # a real instance's ξ1 come in exact conjugate pairs
        assert np.array_equal(np.sort_complex(keys[b]), np.sort_complex(keys[b].conj()))


def test_a_complex_instance_has_its_40_too() -> None:
    p, z = random_stewart(np.random.default_rng(33), 10, complex_values=True)
    sol = solve_stewart(p)
    assert sum(r == TEMPLATE for r in sol.route) >= 9 and np.all(sol.found == 40)
    hom = solve_all(stewart_system(), p, stewart_start())
    for b in range(10):
        assert np.abs(sol.of(b) - z[b]).max(axis=1).min() <= MATCH
        assert _matched(sol.of(b), hom.of(b)) <= MATCH


def test_another_chart_gives_the_same_points() -> None:
    """Eliminated in two affine charts, the 40 points agree once polished (Newton)."""
    p, _ = random_stewart(np.random.default_rng(34), 3)
    p = p.astype(complex)
    a, _ = template_solve(p, 0)
    b, _ = template_solve(p, 1)
    for k in range(3):
        pk = np.repeat(p[k:k + 1], 40, axis=0)
        a[k] = eigen_first.newton(stewart_system(), a[k], pk, 8)
        b[k] = eigen_first.newton(stewart_system(), b[k], pk, 8)
        assert _matched(a[k], b[k]) <= MATCH


def test_what_the_template_cannot_settle_goes_to_the_homotopy() -> None:
    """An eigen solver that gives nothing usable (NaN points): every instance is solved by the
    homotopy, with its 40."""
    def nothing(targets: np.ndarray, label: int) -> tuple[np.ndarray, np.ndarray]:
        shape = (len(targets), 40)
        return np.full(shape + (8,), np.nan, dtype=complex), np.full(shape, np.nan, dtype=complex)

    route = eigen_first.EigenRoute(stewart_system(), 40, nothing, (0,), stewart_start,
                                   TEMPLATE, HOMOTOPY)
    p, _ = random_stewart(np.random.default_rng(35), 3)
    sol = eigen_first.solve_eigen_first(route, p.real.astype(complex))
    assert sol.route == (HOMOTOPY,) * 3 and np.all(sol.found == 40)
    assert _legs_close(sol, p.real) <= CLOSE


def test_a_batch_gives_what_each_instance_gives_alone() -> None:
    p, _ = random_stewart(np.random.default_rng(36), 5)
    p = p.real
    batch = solve_stewart(p)
    for b in range(len(p)):
        alone = solve_stewart(p[b])
        assert alone.found[0] == batch.found[b] and alone.route[0] == batch.route[b]
        assert _matched(alone.of(0), batch.of(b)) <= 1e-12


def test_the_template_layout_is_square_and_its_basis_holds_the_unknowns() -> None:
    mono = monomials(data.DEGREE)
    rows = np.asarray(data.ROWS).reshape(-1, 2)
    assert len(rows) == len(data.SQUARE) and len(data.BASIS) == 40
    basis = {mono[i] for i in data.BASIS}
    assert all(tuple(int(j == k) for j in range(UNKNOWNS)) in basis for k in range(-1, UNKNOWNS))
    moved = {tuple(a + (j == data.ACTION) for j, a in enumerate(e)) for e in basis}
    assert moved - basis == {mono[i] for i in data.SQUARE[data.KEPT:]}


def test_bad_parameters_are_refused() -> None:
    with pytest.raises(InputError):
        solve_stewart(np.zeros(41))
    with pytest.raises(InputError):
        solve_stewart(np.full(42, np.nan))


def test_a_point_that_arrives_far_off_is_polished_to_round_off() -> None:
    """Instance 334 of the benchmark's seed: one eigenvector point arrives far from any pose
    (its first Newton step is ~70) and wanders before converging; it must still end at
    round-off, not merely inside its certified ball (its legs were 3e-5 off with 12 steps)."""
    p, _ = random_stewart(np.random.default_rng(0), 1000)
    sol = solve_stewart(p[334].real)
    assert sol.route == (TEMPLATE,) and sol.found[0] == 40
    assert sol.certified_real_count[0] == sol.real_count[0] == 4
    assert _legs_close(sol, p[334:335].real) <= CLOSE


def _dense_action_matrix(p: np.ndarray) -> tuple[np.ndarray, float]:
    """The action matrix of one instance from the whole 526 × 526 square matrix, built here
    from the template's rows (each equation's coefficients times its multiplier) and solved
    by one dense LU: the route the block solve replaces; and that matrix's condition number."""
    mono = monomials(data.DEGREE)
    square = {mono[i]: c for c, i in enumerate(data.SQUARE)}
    basis = {mono[i]: c for c, i in enumerate(data.BASIS)}
    pairs = [tuple(int(v == i) + int(v == k) for v in range(1, UNKNOWNS + 1))
             for i in range(8) for k in range(i, 8)]
    coef = coefficients(p[None].astype(complex))[0].real
    rows = np.asarray(data.ROWS).reshape(-1, 2)
    M, Bm = np.zeros((len(rows), len(square))), np.zeros((len(rows), len(basis)))
    for r, (eq, mult) in enumerate(rows):
        for t, e in enumerate(pairs):
            at = tuple(a + b for a, b in zip(e, mono[mult], strict=True))
            if at in square:
                M[r, square[at]] += coef[eq, t]
            elif at in basis:
                Bm[r, basis[at]] += coef[eq, t]
    X = np.linalg.solve(M, -Bm)
    A = np.zeros((40, 40))
    for i, e in enumerate(mono[j] for j in data.BASIS):
        up = tuple(a + (j == data.ACTION) for j, a in enumerate(e))
        if up in basis:
            A[i, basis[up]] = 1.0
        else:
            A[i] = X[square[up]]
    return A, float(np.linalg.cond(M))


def test_the_block_solve_gives_the_dense_solves_action_matrix() -> None:
    """The block-triangular solve (the last block for its one R row alone, by a transposed
    solve) gives the action matrix of one dense solve of the whole square matrix, to the
    square matrix's conditioning: within 100 ε cond (a backward-stable solve's forward error;
    cond is 1e6..1e10 here)."""
    p, _ = random_stewart(np.random.default_rng(37), 6)
    p = p.real
    A, good = action_matrices(p.astype(complex))
    assert good.all() and A.dtype == np.float64
    for b in range(len(p)):
        D, cond = _dense_action_matrix(p[b])
        eps = np.finfo(float).eps
        assert np.linalg.norm(A[b] - D) <= 100 * eps * cond * np.linalg.norm(D), (b, cond)


def test_threads_change_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    """A batch split over threads gives bit for bit the points and keys of one thread, and of
    each instance alone (the chunks and their arithmetic are the same)."""
    p, _ = random_stewart(np.random.default_rng(38), 3 * stewart_template.CHUNK + 3)
    p = p.real.astype(complex)
    monkeypatch.setattr(stewart_template, "THREADS", 1)
    one = template_solve(p)
    monkeypatch.setattr(stewart_template, "THREADS", 3)
    three = template_solve(p)
    for a, b in zip(one, three, strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    alone = template_solve(p[-1:])
    assert np.array_equal(alone[0][0], three[0][-1]) and np.array_equal(alone[1][0], three[1][-1])


def test_a_real_instance_in_a_batch_with_complex_ones_is_eliminated_as_alone() -> None:
    """Real arithmetic for a real instance (exact conjugate pairs, which eigen_first's pairing
    relies on) whatever else its chunk holds: bit for bit what it gives alone."""
    p, _ = random_stewart(np.random.default_rng(39), 6)
    q, _ = random_stewart(np.random.default_rng(40), 3, complex_values=True)
    mixed = np.concatenate([p.real.astype(complex)[:3], q, p.real.astype(complex)[3:]])
    pts, keys = template_solve(mixed)
    for b in range(len(mixed)):
        alone = template_solve(mixed[b:b + 1])
        assert np.array_equal(alone[0][0], pts[b]) and np.array_equal(alone[1][0], keys[b]), b
    for b in (0, 1, 2, 6, 7, 8):
        assert np.array_equal(np.sort_complex(keys[b]), np.sort_complex(keys[b].conj()))


def test_blas_runs_one_thread_inside_a_batch(monkeypatch: pytest.MonkeyPatch) -> None:
    """While a batch is eliminated (in threads of its own), BLAS's threads are held at one, and
    released after (else OpenBLAS's threads and the batch's share the same cores)."""
    from threadpoolctl import threadpool_info, threadpool_limits

    seen: list[int] = []
    inner = stewart_template.action_matrices

    def spy(*args: object, **kwargs: object) -> object:
        seen.extend(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")
        return inner(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(stewart_template, "action_matrices", spy)
    monkeypatch.setattr(stewart_template, "THREADS", 2)
    p, _ = random_stewart(np.random.default_rng(46), 2 * stewart_template.CHUNK + 1)
    with threadpool_limits(2, user_api="blas"):
        template_solve(p.real.astype(complex))
        after = [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    assert seen and set(seen) == {1}
    assert set(after) == {2}


def test_the_polish_and_alpha_test_in_threads_change_nothing(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A batch's points polished and certified over threads (contiguous parts, each part's
    kernel point by point) give bit for bit the points, certificates and verdicts of one
    thread; the parts really ran apart (the first polish in three even parts; a pool runs
    parts this small on one thread or more as they come, larger ones side by side)."""
    import dataclasses

    p, _ = random_stewart(np.random.default_rng(41), 8)
    p = p.real.astype(complex)
    route = eigen_first.EigenRoute(stewart_system(), 40, template_solve, (0, 1, 2),
                                   stewart_start, TEMPLATE, HOMOTOPY, 6,
                                   stewart_solve.dense_quadrics)
    one = eigen_first.solve_eigen_first(route, p)
    monkeypatch.setattr(eigen_first, "THREAD_POINTS", 8)
    seen: list[int] = []
    inner = eigen_first.newton_dense

    def spy(Q: np.ndarray, inst: np.ndarray, x: np.ndarray, steps: int) -> np.ndarray:
        seen.append(len(x))
        return inner(Q, inst, x, steps)

    monkeypatch.setattr(eigen_first, "newton_dense", spy)
    three = eigen_first.solve_eigen_first(dataclasses.replace(route, threads=3), p)
    first = seen[:3]
    assert len(seen) >= 3 and max(first) - min(first) <= 1, seen
    assert np.array_equal(one.x, three.x) and np.array_equal(one.instance, three.instance)
    assert one.route == three.route and np.all(one.found == 40)
    for name in ("certified", "real", "alpha", "beta", "gamma"):
        assert np.array_equal(getattr(one, name), getattr(three, name)), name


def test_a_batch_in_parts_on_threads_changes_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    """A batch solved in parts side by side (each part's elimination, polish, α-test and
    distinctness test on one thread: eigen_first.eigen_route_in_parts) gives bit for bit the
    points, certificates, verdicts and routes of the batch in one part; the parts start at
    whole chunks of the template and really ran as parts (the eliminator called once per part
    and chart, on one thread)."""
    import dataclasses
    from functools import partial

    from threadpoolctl import threadpool_info, threadpool_limits

    p, _ = random_stewart(np.random.default_rng(47), 5 * stewart_template.CHUNK + 5)
    p = p.real.astype(complex)
    route = eigen_first.EigenRoute(stewart_system(), 40, template_solve, (0, 1, 2),
                                   stewart_start, TEMPLATE, HOMOTOPY, 6,
                                   stewart_solve.dense_quadrics)
    one = eigen_first.solve_eigen_first(route, p)
    monkeypatch.setattr(eigen_first, "PART_INSTANCES", 16)
    calls: list[tuple[int, int | None]] = []
    blas: list[int] = []

    def alone(t: np.ndarray, label: int, threads: int | None = None) -> object:
        calls.append((len(t), threads))
        blas.extend(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")
        return template_solve(t, label, threads)

    parts = dataclasses.replace(route, threads=2, eliminate_alone=partial(alone, threads=1),
                                part_step=stewart_template.CHUNK)
    # BLAS held at one thread around the parts, not by each part's own limit (a limit is
    # process-wide: the parts' own would restore each other's counts; found as 1e-13
    # differences in one run of three with BLAS at two threads)
    with threadpool_limits(2, user_api="blas"):
        two = eigen_first.solve_eigen_first(parts, p)
    assert blas and set(blas) == {1}
    first = sorted(n for n, _ in calls)[-2:]
    assert sum(first) == len(p) and any(n % stewart_template.CHUNK == 0 for n in first)
    assert {t for _, t in calls} == {1}
    assert np.array_equal(one.x, two.x) and np.array_equal(one.instance, two.instance)
    assert one.route == two.route and one.how_found == two.how_found
    for name in ("found", "certified", "real", "alpha", "beta", "gamma", "radius"):
        assert np.array_equal(getattr(one, name), getattr(two, name)), name


def test_duplicates_are_sought_among_the_homotopys_points_alone(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """With one instance of a batch left to the homotopy, the duplicate labels passed to
    collect_solutions (the homotopy's points tested among themselves, the eigen route's taken
    as distinct) give the Solutions of the whole duplicate test over every point."""
    import dataclasses

    p, _ = random_stewart(np.random.default_rng(53), 3)
    p = p.real.astype(complex)

    def eliminate(t: np.ndarray, label: int, threads: int | None = None) -> tuple:
        x, key = stewart_solve.eliminate_pass(t, label, threads)
        first = np.all(t == p[0], axis=1)
        x[first], key[first] = np.nan, np.nan  # instance 0: unsettled in every pass
        return x, key

    route = dataclasses.replace(stewart_solve.stewart_route(), eliminate=eliminate,
                                eliminate_alone=None)
    inner = eigen_first.collect_solutions
    checked: list[int] = []

    def both(*args: object) -> Solutions:
        given = inner(*args)
        whole = inner(*args[:-1], None)
        for name in ("x", "instance", "certified", "real", "found", "real_count", "residual",
                     "multiplicity"):
            np.testing.assert_array_equal(getattr(given, name), getattr(whole, name))
        checked.append(len(given.x))
        return given

    monkeypatch.setattr(eigen_first, "collect_solutions", both)
    sol = eigen_first.solve_eigen_first(route, p)
    assert checked and sol.route == (HOMOTOPY, TEMPLATE, TEMPLATE)
    assert np.all(sol.found == 40)

"""The Stewart template's sparse elimination with a fixed pivot sequence
(modes/stewart_sparse.py), checked against a dense LU with partial pivoting of the whole
526 × 526 template (another method), against the block-triangular LAPACK route end to end, and
for its fallback.

``SCREWKIT_MODES_INSTANCES`` sets the number of random instances (default 200).
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from screwkit.algebraic import compiled
from screwkit.errors import InputError
from screwkit.kinematics.modes import stewart_sparse, stewart_template
from screwkit.kinematics.modes import stewart_template_data as data
from screwkit.kinematics.modes.stewart import random_stewart
from screwkit.kinematics.modes.stewart_solve import TEMPLATE, solve_stewart

pytestmark = pytest.mark.skipif(not compiled.AVAILABLE, reason="the sparse route needs numba")

INSTANCES = int(os.environ.get("SCREWKIT_MODES_INSTANCES", "200"))
#: polished points of the two routes agree to this, relative to 1 + the largest coordinate
MATCH = 1e-8


def _coefficients(seed: int, count: int) -> np.ndarray:
    p, _ = random_stewart(np.random.default_rng(seed), count)
    return stewart_template.coefficients(p.real.astype(complex)).real.reshape(count, -1)


def _dense_r_rows(c: np.ndarray) -> np.ndarray:
    """X_R by LAPACK's dense LU (partial pivoting) of the whole square template."""
    lay = stewart_template.layout()
    n, m = len(data.SQUARE), len(data.BASIS)
    out = []
    for row in c:
        A = np.zeros(n * n)
        A[lay["sq_dst"]] = row[lay["sq_src"]]
        rhs = np.zeros(n * m)
        rhs[lay["b_dst"]] = row[lay["b_src"]]
        out.append(np.linalg.solve(A.reshape(n, n), -rhs.reshape(n, m))[lay["r_pos"]])
    return np.array(out)


def _sparse_groups(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The sizes of the groups the sparse kernel gets from now on (stewart_sparse.r_rows)."""
    groups: list[int] = []
    inner = stewart_sparse.r_rows

    def spy(c: np.ndarray, work: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
        groups.append(len(c))
        return inner(c, work)

    monkeypatch.setattr(stewart_sparse, "r_rows", spy)
    return groups


def _matched(a: np.ndarray, b: np.ndarray) -> float:
    d = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2) / (
        1.0 + np.maximum(np.abs(a).max(axis=1)[:, None], np.abs(b).max(axis=1)[None, :]))
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


def test_the_schedule_eliminates_every_e_column_once() -> None:
    plan = stewart_sparse.schedule()
    lay = stewart_template.layout()
    n, m = len(data.SQUARE), len(data.BASIS)
    e_cols = np.setdiff1d(np.arange(n), lay["r_pos"])
    assert np.array_equal(np.sort(plan["pivot_col"]), e_cols)
    assert plan["left"] == len(lay["r_pos"]) == n - len(e_cols)
    assert len(plan["init_ptr"]) == n + 1 and plan["columns"] == n + m
    # every step reaches only rows after its own, in increasing order
    for t in range(n):
        steps = plan["upd_step"][plan["upd_ptr"][t]:plan["upd_ptr"][t + 1]]
        assert np.all(np.diff(steps.astype(int)) > 0) and np.all(steps < min(t, len(e_cols)))


def test_the_r_rows_are_a_dense_lus() -> None:
    """Most instances' R rows equal the dense partial-pivoting LU's closely; the fixed pivots
    lose digits on some (module docstring), which the polish and the α-test absorb."""
    c = _coefficients(41, 100)
    X, ok = stewart_sparse.r_rows(c)
    ref = _dense_r_rows(c)
    assert ok.all()
    err = np.abs(X - ref).max(axis=(1, 2)) / np.abs(ref).max(axis=(1, 2))
    assert np.median(err) <= 1e-5 and np.mean(err <= 1e-3) >= 0.95, np.sort(err)[-5:]


def test_a_lane_gives_the_same_whatever_its_group() -> None:
    """An instance's arithmetic is the same in any group (the lanes are independent)."""
    c = _coefficients(42, 12)
    X, _ = stewart_sparse.r_rows(c)
    for b in (0, 5, 11):
        alone, _ = stewart_sparse.r_rows(c[b:b + 1])
        np.testing.assert_array_equal(alone[0], X[b])


def test_work_arrays_kept_from_call_to_call_change_nothing() -> None:
    """The kernel's work arrays start on a cache line and, kept from call to call (one
    thread's, as the template keeps them), give each call's rows bit for bit as fresh ones do,
    after a call whose instances were not finite too (the accumulator is left zero)."""
    w = stewart_sparse.aligned_zeros((566, stewart_sparse.GROUP))
    assert w.ctypes.data % stewart_sparse.ALIGN == 0 and not w.any()
    c = _coefficients(49, 40)
    bad = c[:16].copy()
    bad[:, ::7] = np.nan
    work: dict = {}
    stewart_sparse.r_rows(bad, work)
    for s in (0, 16, 20):
        kept, ok_kept = stewart_sparse.r_rows(c[s:s + 20], work)
        fresh, ok_fresh = stewart_sparse.r_rows(c[s:s + 20])
        assert ok_kept.all() and np.array_equal(ok_kept, ok_fresh)
        np.testing.assert_array_equal(kept, fresh)


def test_the_sparse_route_gives_the_lapack_routes_poses(monkeypatch: pytest.MonkeyPatch) -> None:
    p, _ = random_stewart(np.random.default_rng(43), INSTANCES)
    p = p.real
    sparse = solve_stewart(p)
    monkeypatch.setattr(stewart_sparse, "AVAILABLE", False)
    lapack = solve_stewart(p)
    assert np.array_equal(sparse.found, lapack.found) and np.all(sparse.found == 40)
    assert sparse.route == lapack.route == (TEMPLATE,) * INSTANCES
    assert int(sparse.certified.sum()) == int(lapack.certified.sum())
    assert np.array_equal(sparse.real, lapack.real)
    for b in range(INSTANCES):
        assert _matched(sparse.of(b), lapack.of(b)) <= MATCH, b


def test_an_instance_failing_the_check_is_solved_by_lapack(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """With the growth bound at 0 every instance fails the check: the action matrices are the
    LAPACK route's, bit for bit; with one instance's coefficients not finite, only it fails."""
    p, _ = random_stewart(np.random.default_rng(44), stewart_sparse.GROUP)
    p = p.real.astype(complex)
    calls = _sparse_groups(monkeypatch)
    monkeypatch.setattr(stewart_sparse, "AVAILABLE", False)
    ref, good_ref = stewart_template.action_matrices(p)
    monkeypatch.setattr(stewart_sparse, "AVAILABLE", True)
    monkeypatch.setattr(stewart_sparse, "GROWTH", 0.0)
    forced, good = stewart_template.action_matrices(p)
    assert calls == [stewart_sparse.GROUP]  # (a whole group: the sparse route ran, and failed)
    assert good.all() and good_ref.all()
    np.testing.assert_array_equal(forced, ref)
    monkeypatch.setattr(stewart_sparse, "GROWTH", 1e12)
    c = _coefficients(44, 9)
    c[3, 0] = np.inf
    _, ok = stewart_sparse.r_rows(c)
    assert not ok[3] and ok[np.arange(9) != 3].all()


def test_the_vector_kernel_is_the_plain_one_bit_for_bit() -> None:
    from screwkit.kinematics.modes import stewart_sparse_kernels as kernels

    plan = stewart_sparse.schedule()
    G = kernels.LANES
    c = _coefficients(45, G)
    outs = []
    for kernel in (kernels.eliminate, kernels.eliminate_vector):
        w, U = np.zeros((plan["columns"], G)), np.zeros((len(plan["u_col"]), G))
        out = np.zeros((plan["left"], plan["out_col"].shape[1], G))
        big = np.zeros(G)
        kernel(np.ascontiguousarray(c.T), plan["init_ptr"], plan["init_col"], plan["init_src"],
               plan["upd_ptr"], plan["upd_step"], plan["pivot_col"], plan["u_ptr"],
               plan["u_col"], plan["out_col"], w, U, out, big)
        assert np.all(w == 0.0) and np.isfinite(out).all()
        outs.append((out, big))
    np.testing.assert_array_equal(outs[0][0], outs[1][0])
    np.testing.assert_array_equal(outs[0][1], outs[1][1])


def test_a_mixed_batch_gives_each_instance_its_poses(monkeypatch: pytest.MonkeyPatch) -> None:
    """A batch of real and complex instances: a chunk of real ones alone takes the sparse
    route, a chunk with complex ones the LAPACK route (complex arithmetic for those, real for
    the real ones); every instance's poses are the ones it has in a batch of its own kind, the
    real ones' conjugate pairs exact."""
    G = stewart_sparse.GROUP
    p, _ = random_stewart(np.random.default_rng(47), 2 * G)
    q, _ = random_stewart(np.random.default_rng(48), 3, complex_values=True)
    real = p.real.astype(complex)
    mixed = np.concatenate([real[:G], q[:1], real[G:], q[1:]])
    where_real = np.r_[0:G, G + 1:2 * G + 1]
    where_complex = (G, 2 * G + 1, 2 * G + 2)
    inner = stewart_sparse.r_rows
    groups = _sparse_groups(monkeypatch)
    sol = solve_stewart(mixed)
    assert groups == [G]  # the first chunk, real only; the others hold complex instances
    monkeypatch.setattr(stewart_sparse, "r_rows", inner)
    alone_real, alone_complex = solve_stewart(real), solve_stewart(q)
    assert np.all(sol.found == 40) and sol.route == (TEMPLATE,) * len(mixed)
    for k, b in enumerate(where_real):
        x = sol.of(int(b))
        assert _matched(x, alone_real.of(k)) <= MATCH and _matched(x, x.conj()) <= MATCH, b
    for k, b in enumerate(where_complex):
        assert _matched(sol.of(b), alone_complex.of(k)) <= MATCH, b


def test_the_routes_of_template_solve(monkeypatch: pytest.MonkeyPatch) -> None:
    """``route="sparse"``: a whole group of real instances gets the points of the default
    route bit for bit, a short group of at least FEWEST the sparse route too (the default
    route gives it LAPACK's), a lone instance NaN points (the LAPACK pass after it solves
    them), and so does a growth-check reject; ``route="lapack"``: each instance's points as
    alone, bit for bit (the LAPACK route's arithmetic is the instance's own); an unknown
    route is refused."""
    G = stewart_sparse.GROUP
    p, _ = random_stewart(np.random.default_rng(50), G + 3)
    p = p.real.astype(complex)
    either, keys = stewart_template.template_solve(p, 1)
    sparse, sparse_keys = stewart_template.template_solve(p, 1, route="sparse")
    assert np.isfinite(sparse[:G]).all()
    np.testing.assert_array_equal(sparse[:G], either[:G])
    np.testing.assert_array_equal(sparse_keys[:G], keys[:G])
    assert 2 <= stewart_sparse.FEWEST <= 3 and np.isfinite(sparse[G:]).all()
    short = stewart_template.template_solve(p[G:], 1, route="sparse")[0]
    np.testing.assert_array_equal(sparse[G:], short)  # (a short group of its own)
    assert not np.array_equal(short, either[G:])  # (the default route: LAPACK's)
    lone, lone_keys = stewart_template.template_solve(p[:1], 1, route="sparse")
    assert np.isnan(lone).all() and np.isnan(lone_keys).all()
    lapack, _ = stewart_template.template_solve(p, 1, route="lapack")
    for b in (0, G - 1, G + 2):
        alone, _ = stewart_template.template_solve(p[b:b + 1], 1)
        np.testing.assert_array_equal(lapack[b], alone[0])
    assert not np.array_equal(lapack[:G], sparse[:G])  # (two eliminations: it ran LAPACK)
    monkeypatch.setattr(stewart_sparse, "GROWTH", 0.0)  # every instance a reject
    rejected, _ = stewart_template.template_solve(p[:G], 1, route="sparse")
    assert np.isnan(rejected).all()
    with pytest.raises(InputError, match="route must be one of"):
        stewart_template.template_solve(p, 0, route="fast")


def test_the_passes_take_only_what_the_pass_before_left(monkeypatch: pytest.MonkeyPatch) -> None:
    """A batch's template passes in turn (stewart_solve.PASSES: chart 0, then chart 1 by the
    sparse route, then charts 1 and 2 by LAPACK): chart 0 leaves some instances unsettled,
    exactly those go to chart 1's sparse route, which settles some of them, and only the rest
    go on; every instance ends with its 40 poses by the template."""
    import dataclasses
    import threading
    from functools import partial

    from screwkit.kinematics.modes import eigen_first, stewart_solve

    p, _ = random_stewart(np.random.default_rng(51), 10 * stewart_sparse.GROUP)
    p = p.real.astype(complex)
    seen: dict[int, int] = {}
    sparse_in: dict[int, int] = {}  # instances the sparse kernel got, per pass
    inner = stewart_sparse.r_rows
    now = threading.local()  # the pass each part's thread is in (the parts run side by side)
    lock = threading.Lock()

    def sparse(c: np.ndarray, work: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
        label = getattr(now, "label", -1)  # (-1: the template's own threads, outside parts)
        with lock:
            sparse_in[label] = sparse_in.get(label, 0) + len(c)
        return inner(c, work)

    def spy(t: np.ndarray, label: int, threads: int | None = None) -> tuple:
        with lock:
            seen[label] = seen.get(label, 0) + len(t)
        now.label = label
        return stewart_solve.eliminate_pass(t, label, threads)

    monkeypatch.setattr(stewart_sparse, "r_rows", sparse)

    route = dataclasses.replace(stewart_solve.stewart_route(), eliminate=spy,
                                eliminate_alone=partial(spy, threads=1))
    _, _, first, _ = eigen_first.eigen_route(dataclasses.replace(route, labels=(0,)), p)
    _, _, second, _ = eigen_first.eigen_route(dataclasses.replace(route, labels=(0, 1)), p)
    seen.clear()
    sparse_in.clear()
    sol = eigen_first.solve_eigen_first(route, p)
    left = int((~first).sum())
    assert left >= 1 and seen[0] == len(p) and seen[1] == left
    # the sparse kernel ran in passes 0 and 1 (pass 1's own instances; a group of fewer than
    # FEWEST goes to LAPACK) and never in the LAPACK passes
    assert sparse_in.get(0, 0) >= len(p) and 0 < sparse_in.get(1, 0) <= left
    assert not sparse_in.get(2) and not sparse_in.get(3)
    assert int((~second).sum()) < left and seen.get(2, 0) == int((~second).sum())
    assert np.all(sol.found == 40) and sol.route == (TEMPLATE,) * len(p)
    assert stewart_solve.PASSES[1] == (1, "sparse")

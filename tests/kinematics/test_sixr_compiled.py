"""The compiled 6R elimination (modes/sixr_compiled.py, numba), Newton polish and fast α-test
(algebraic/compiled.py) against the numpy route (modes/sixr_elimination.py,
modes/loop6r_solve.py, algebraic/certify.py): the same method, so the same 16 solutions after the polish, the
same routes, counts and certificates, on random loops and arms (every real solution closing by
the arm's product-of-exponentials forward kinematics, a check outside both routes).

``SCREWKIT_MODES_INSTANCES`` sets the number of random instances (default 200).
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from screwkit.algebraic import compiled
from screwkit.kinematics.modes import sixr_compiled
from screwkit.kinematics.modes.arm6r import arm6r_instance, arm_forward
from screwkit.kinematics.modes.loop6r import random_loop6r
from screwkit.kinematics.modes.loop6r_solve import ELIMINATION, solve_loop6r
from screwkit.kinematics.modes.sixr_elimination import eliminate

INSTANCES = int(os.environ.get("SCREWKIT_MODES_INSTANCES", "200"))
#: certified solutions of the two routes agree to this (relative to 1 + the largest
#: coordinate): both are Newton-polished to round-off on the same system
SAME_CERTIFIED = 1e-10
#: and every solution to this (an uncertified one, ill-conditioned, is only converged: a
#: Newton step below 1e-8 relative, modes/loop6r_solve.py CONVERGED)
SAME = 1e-8
#: every real solution's forward kinematics gives the target back to this (unit-scale arms)
CLOSE = 1e-10


def test_numba_is_there_for_the_tests() -> None:
    """numba is in the dev extra: without it the comparisons below compare the numpy route
    with itself."""
    assert compiled.AVAILABLE and sixr_compiled.AVAILABLE


def _numpy_route(monkeypatch: pytest.MonkeyPatch, params: np.ndarray):  # type: ignore[no-untyped-def]
    with monkeypatch.context() as m:
        m.setattr(sixr_compiled, "AVAILABLE", False)
        m.setattr(compiled, "AVAILABLE", False)  # the polish and the α-test too
        return solve_loop6r(params)


def _nearest(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each point of a (m, n), the relative distance to the nearest point of b."""
    d = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2) / (
        1.0 + np.maximum(np.abs(a).max(axis=1)[:, None], np.abs(b).max(axis=1)[None, :]))
    return np.asarray(d.min(axis=1))


def test_the_compiled_route_gives_the_numpy_routes_16(monkeypatch: pytest.MonkeyPatch) -> None:
    p, x = random_loop6r(np.random.default_rng(40), INSTANCES)
    p = p.real
    old, new = _numpy_route(monkeypatch, p), solve_loop6r(p)
    assert new.route == old.route and new.route.count(ELIMINATION) >= 0.99 * INSTANCES
    assert (new.found == 16).mean() >= 0.99
    assert np.array_equal(new.found, old.found) and np.array_equal(new.real_count, old.real_count)
    # the certified count may differ by a few points: a polished point's β is round-off, so a
    # point at the α threshold can fall either side with another summation order
    assert abs(int(new.certified.sum()) - int(old.certified.sum())) <= 0.01 * len(new.x)
    for b in range(INSTANCES):
        a, c = new.of(b), old.of(b)
        gap = _nearest(a, c)
        cert = new.certified[new.instance == b]
        assert max(gap.max(), _nearest(c, a).max()) <= SAME, b
        assert gap[cert].max(initial=0.0) <= SAME_CERTIFIED, (b, gap[cert].max())
        assert np.abs(a - x[b].real).max(axis=1).min() <= SAME  # the drawn configuration
    assert new.residual.max() <= 1e-10


def test_every_real_solution_closes_the_arm() -> None:
    rng = np.random.default_rng(41)
    arms, params = [], []
    for _ in range(INSTANCES):
        C, U = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
        U /= np.linalg.norm(U, axis=1)[:, None]
        home = (np.eye(3), rng.normal(size=3))
        target = arm_forward(C, U, home, rng.uniform(-np.pi, np.pi, 6))
        inst = arm6r_instance(C, U, home, target)
        arms.append((C, U, home, target, inst))
        params.append(inst.params)
    sol = solve_loop6r(np.array(params))
    assert sol.route.count(ELIMINATION) >= 0.99 * INSTANCES and (sol.found == 16).mean() >= 0.99
    worst = 0.0
    for b, (C, U, home, (Rt, pt), inst) in enumerate(arms):
        for q in inst.joint_values(sol.x[(sol.instance == b) & sol.real]):
            R, t = arm_forward(C, U, home, q)
            worst = max(worst, float(np.abs(R - Rt).max() + np.abs(t - pt).max()))
    assert worst <= CLOSE, worst


@pytest.mark.parametrize("shift", range(6))
def test_the_unpolished_roots_agree_in_every_labelling(shift: int) -> None:
    """Before the polish: the same x3 roots (matched; LAPACK may order them differently when
    the companion matrices differ by round-off) for most instances to round-off, the same
    instances failed (z1 = z6: no Denavit–Hartenberg chain), and a degenerate twist (cos α1
    = 1) alike."""
    p, _ = random_loop6r(np.random.default_rng(42 + shift), 60)
    p = p.real.copy()
    p[1, 3:6] = p[1, 0:3]
    p[2, 6] = 1.0
    a, b = eliminate(p, shift, compiled=False), eliminate(p, shift)
    fail_a, fail_b = np.isnan(a[0]).any(axis=(1, 2)), np.isnan(b[0]).any(axis=(1, 2))
    assert np.array_equal(fail_a, fail_b) and fail_a[1]
    gaps = np.array([_nearest(a[1][i][:, None], b[1][i][:, None]).max() for i in
                     np.flatnonzero(~fail_a)])
    assert np.median(gaps) <= 1e-12 and (gaps <= 1e-8).mean() >= 0.95
    # cond of the leading matrix, on the random ones (with cos α1 = 1 the θ1θ2 products'
    # coefficients lose rank: the null space, hence Σ, is then any basis of a larger space)
    assert np.allclose(a[2][3:], b[2][3:], rtol=1e-6)


def test_complex_parameters_take_the_numpy_route() -> None:
    p, _ = random_loop6r(np.random.default_rng(48), 3, complex_values=True)
    a, b = eliminate(p, 0, compiled=False), eliminate(p, 0)
    assert np.array_equal(a[1], b[1]) and np.array_equal(a[0], b[0])


def test_the_compiled_verdict_is_the_pairwise_rule(monkeypatch: pytest.MonkeyPatch) -> None:
    """sixr_compiled.settled (the distinctness test, with its shortcut on the first
    coordinate) against the rule written out in numpy: every pair of an instance's points
    apart by more than the sum of their radii, each point certified or converged and finite,
    m points; on points with close first coordinates, near twins, large radii and NaN; the
    same on threads (parts of whole instances)."""
    rng = np.random.default_rng(5)
    B, m, n = 300, 12, 4
    xs = rng.normal(size=(B * m, n)) + 1j * rng.normal(size=(B * m, n))
    xs[1::m, 0] = xs[0::m, 0] + 1e-13  # first coordinates equal to round-off, others apart
    xs[3::7 * m] = xs[2::7 * m] + 1e-9  # near twins
    xs[5::11 * m, 0] = xs[4::11 * m, 0].conj()
    xs[6::13 * m] = np.nan
    newton = xs + rng.normal(size=xs.shape) * 10.0 ** rng.integers(-12, -6, size=(B * m, 1))
    certified = rng.random(B * m) < 0.9
    radius = 10.0 ** rng.uniform(-12, 0.2, size=B * m)
    finite = np.isfinite(xs).all(axis=1)
    inst = np.repeat(np.arange(B), m)
    inst = inst[inst != 7]  # an instance short of m
    keep = np.repeat(np.arange(B), m) != 7
    xs, newton, certified, radius, finite = (a[keep] for a in (xs, newton, certified,
                                                               radius, finite))
    got = sixr_compiled.settled(xs, inst, finite, newton, certified, radius, B, m, 1e-8, 1e-6)
    scale = 1.0 + np.abs(xs).max(axis=1)
    with np.errstate(invalid="ignore"):
        near = np.abs(xs - newton).max(axis=1) <= 1e-8 * scale
    good = (certified | near) & finite
    r = np.where(certified, radius, 1e-6 * scale)
    want = np.zeros(B, dtype=bool)
    for b in range(B):
        i = np.flatnonzero(inst == b)
        if len(i) != m or not good[i].all():
            continue
        gap = np.linalg.norm(xs[i][:, None] - xs[i][None], axis=-1)
        with np.errstate(invalid="ignore"):
            apart = gap > r[i][:, None] + r[i][None]
        want[b] = apart[np.triu_indices(m, 1)].all()
    assert 0.2 < want.mean() < 0.9  # both verdicts occur
    np.testing.assert_array_equal(got, want)
    monkeypatch.setattr(sixr_compiled, "SETTLED_POINTS", 500)  # 7 parts cut inside instances
    threaded = sixr_compiled.settled(xs, inst, finite, newton, certified, radius, B, m, 1e-8,
                                     1e-6, threads=7)
    np.testing.assert_array_equal(threaded, want)

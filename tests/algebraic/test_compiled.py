"""The compiled step loop (screwkit.algebraic.compiled, numba) against the numpy route of
screwkit.algebraic.path: the same algorithm, so the same statuses, steps and end points (to
the Newton polish's accuracy) on random Stewart–Gough and 6R instances and through the Cauchy
endgame; and the numpy route when numba is absent."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from screwkit.algebraic import compiled
from screwkit.algebraic.polynomial import Poly, compile_system
from screwkit.algebraic.solve import StartSolutions, solve_all
from screwkit.algebraic.track import PathStatus, TrackOptions, track_parameter_homotopy
from screwkit.kinematics.modes.loop6r import loop6r_start, loop6r_system, random_loop6r
from screwkit.kinematics.modes.stewart import random_stewart, stewart_start, stewart_system

NUMPY = TrackOptions(compiled=False)


def test_numba_is_there_for_the_tests():
    """numba is in the dev extra: without it every comparison below would compare the numpy
    route with itself."""
    assert compiled.AVAILABLE


def _both(system, start, targets):
    m = start.generic_count
    args = (system, start.p, np.repeat(targets, m, axis=0), np.tile(start.x, (len(targets), 1)))
    instance = np.repeat(np.arange(len(targets)), m)
    return (track_parameter_homotopy(*args, TrackOptions(), instance=instance),
            track_parameter_homotopy(*args, NUMPY, instance=instance))


@pytest.mark.parametrize("family", ["stewart", "loop6r"])
def test_compiled_and_numpy_routes_agree(family):
    """Random instances (3 Stewart–Gough platforms, 40 paths each; 3 6R loops, 16 each): equal
    statuses path by path, end points equal to 1e-10, every path regular; equal step counts
    but for a step whose error lies within rounding of a tolerance, which the two routes'
    different order of arithmetic may accept on one and reject on the other (seen: 2 of 120
    Stewart paths one step apart, with the start solutions of a fresh monodromy run)."""
    if family == "stewart":
        system, start = stewart_system(), stewart_start()
        targets = random_stewart(np.random.default_rng(11), 3)[0]
    else:
        system, start = loop6r_system(), loop6r_start()
        targets = random_loop6r(np.random.default_rng(11), 3)[0].real
    fast, slow = _both(system, start, targets)
    assert (fast.status == slow.status).all()
    assert (fast.steps != slow.steps).mean() <= 0.05
    assert np.abs(fast.steps - slow.steps).max() <= 3
    assert fast.counts()["regular"] == 3 * start.generic_count
    assert np.abs(fast.x - slow.x).max() <= 1e-10 * (1 + np.abs(slow.x).max())


def test_solve_all_agrees_on_the_solutions():
    """The front door on one Stewart instance: the same 40 solutions, certified alike."""
    system, start = stewart_system(), stewart_start()
    target = random_stewart(np.random.default_rng(0), 1)[0][0]
    fast, slow = solve_all(system, target, start), solve_all(system, target, start, NUMPY)
    assert fast.found[0] == slow.found[0] == 40
    assert (fast.certified == slow.certified).all() and (fast.real == slow.real).all()
    assert np.abs(fast.x - slow.x).max() <= 1e-10 * (1 + np.abs(slow.x).max())


def test_singular_ends_through_the_endgame_agree():
    """x0² = a, x1² + x0·x1 = b (quadrics) at a = 0, b = 1: x0 = 0 is a double root, so all
    four paths go through the Cauchy endgame (the circle σ = 1 − r·e^{iτ} runs compiled) and
    end singular with winding number 2 at x = (0, ±1); both routes alike."""

    x0, x1, a, b = (Poly.variable(i) for i in range(4))
    system = compile_system([x0 * x0 - a, x1 * x1 + x0 * x1 - b], ["x0", "x1"], ["a", "b"])
    start = StartSolutions.by_total_degree(system, seed=3)
    assert start.generic_count == 4
    fast, slow = _both(system, start, np.array([[0.0, 1.0]]))
    assert (fast.status == PathStatus.SINGULAR).all() and (slow.status == fast.status).all()
    assert (fast.winding == 2).all() and (slow.winding == 2).all()
    # near a singular end the rounding of the two routes steers the step sizes a little
    # apart (a few steps of ~380); the Cauchy integral's end points agree all the same
    assert np.abs(fast.steps - slow.steps).max() <= 0.05 * slow.steps.min()
    assert np.abs(fast.x - slow.x).max() <= 1e-10
    assert np.allclose(np.sort(fast.x[:, 1].real), [-1, -1, 1, 1], atol=1e-8)
    assert np.abs(fast.x[:, 0]).max() <= 1e-8


def test_without_numba_the_numpy_route_runs():
    """SCREWKIT_NO_NUMBA stands for an install without the fast extra: the module says it is
    not available and the tracker solves the 6R loop all the same (16 regular ends)."""
    code = ("import numpy as np\n"
            "from screwkit.algebraic import compiled\n"
            "from screwkit.algebraic.solve import solve_all\n"
            "from screwkit.kinematics.modes.loop6r import loop6r_start, loop6r_system, "
            "random_loop6r\n"
            "p = random_loop6r(np.random.default_rng(2), 1)[0].real\n"
            "s = solve_all(loop6r_system(), p[0], loop6r_start())\n"
            "print(compiled.AVAILABLE, int(s.found[0]), int(s.failed[0]))\n")
    src = str(Path(compiled.__file__).resolve().parents[2])
    env = {**os.environ, "SCREWKIT_NO_NUMBA": "1",
           "PYTHONPATH": os.pathsep.join([src, os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True, timeout=300)
    assert out.stdout.split() == ["False", "16", "0"]


def test_the_endgame_stops_a_path_at_its_step_budget():
    """The double root above takes a few hundred endgame steps per path; with a budget of 60
    every path stops inside the endgame and is reported failed (not singular, not a mode),
    having taken at most the budget plus one circle segment's steps there."""
    x0, x1, a, b = (Poly.variable(i) for i in range(4))
    system = compile_system([x0 * x0 - a, x1 * x1 + x0 * x1 - b], ["x0", "x1"], ["a", "b"])
    start = StartSolutions.by_total_degree(system, seed=3)
    args = (system, start.p, np.array([0.0, 1.0]), start.x)
    full = track_parameter_homotopy(*args)
    capped = track_parameter_homotopy(*args, TrackOptions(endgame_max_steps=60))
    assert (full.status == PathStatus.SINGULAR).all()
    assert (capped.status == PathStatus.FAILED).all()
    assert (capped.steps < full.steps).all()


@pytest.mark.parametrize("family", ["stewart", "loop6r", "cubic"])
def test_compiled_term_evaluation_matches_numpy(family, monkeypatch):
    """F and ∂F/∂x of the term table, compiled (numba, one point and term at a time) and by
    numpy (powers, prefix and suffix products, sparse sums), at random complex points and
    parameters: equal to 1e-13 of the largest entry; ∂F/∂x also against central differences
    of the compiled F (to 1e-6: the differences' own truncation error)."""
    rng = np.random.default_rng(3)
    if family == "stewart":
        system = stewart_system()
    elif family == "loop6r":
        system = loop6r_system()
    else:  # powers up to 3 and terms mixing unknowns with parameters
        x0, x1, a, b = (Poly.variable(i) for i in range(4))
        system = compile_system([x0 ** 3 * a - x1 * b + 2, x0 * x1 ** 2 * b ** 2 + a * x1 - 1],
                                ["x0", "x1"], ["a", "b"])
    x = rng.standard_normal((7, system.n)) + 1j * rng.standard_normal((7, system.n))
    p = rng.standard_normal((7, system.k)) + 1j * rng.standard_normal((7, system.k))
    monkeypatch.setattr(compiled, "AVAILABLE", True)
    F, J, _ = system.evaluate(x, p, want_jp=False)
    monkeypatch.setattr(compiled, "AVAILABLE", False)
    F_np, J_np, _ = system.evaluate(x, p, want_jp=False)
    assert np.abs(F - F_np).max() <= 1e-13 * np.abs(F_np).max()
    assert np.abs(J - J_np).max() <= 1e-13 * np.abs(J_np).max()
    monkeypatch.setattr(compiled, "AVAILABLE", True)
    step = 1e-5
    for j in range(system.n):
        e = np.zeros(system.n)
        e[j] = step
        Fp, _, _ = system.evaluate(x + e, p, want_jp=False)
        Fm, _, _ = system.evaluate(x - e, p, want_jp=False)
        assert np.abs((Fp - Fm) / (2 * step) - J[:, :, j]).max() <= 1e-6 * np.abs(J).max()


def _moved_6r_points(rng: np.random.Generator):
    """Points near the 16 solutions of random real 6R loops (the eigen route's, moved by
    1e-6..1e-3), a non-finite point and one where ∂F/∂x is exactly singular (the origin: every
    term of every equation's Jacobian row vanishes but the parameters')."""
    from screwkit.kinematics.modes.sixr_elimination import eliminate

    p, _ = random_loop6r(rng, 6)
    x = eliminate(p.real)[0].reshape(-1, 12)
    x = x + 10.0 ** rng.uniform(-6, -3, (len(x), 1)) * rng.standard_normal(x.shape)
    x = np.concatenate([x, np.full((1, 12), np.nan), np.zeros((1, 12))])
    return x, np.repeat(p, 16, axis=0)[np.r_[np.arange(len(x) - 2), 0, 0]]


def test_the_compiled_polish_and_alpha_test_equal_the_numpy_route(monkeypatch):
    """compiled.newton_terms and compiled.alpha_test (the fast α-test) against the numpy
    route: the same polished points, the same certificates."""
    from screwkit.algebraic.certify import certify
    from screwkit.kinematics.modes import eigen_first

    system = loop6r_system()
    x, p = _moved_6r_points(np.random.default_rng(7))

    def both(fn):
        new = fn()
        with monkeypatch.context() as m:
            m.setattr(compiled, "AVAILABLE", False)
            return new, fn()

    new_x, old_x = both(lambda: eigen_first.newton(system, x, p, 3))
    # a singular ∂F/∂x (the last point): the compiled polish leaves the point where it is
    # (the numpy route takes a pseudo-inverse step there)
    assert np.array_equal(new_x[-1], x[-1])
    ok = np.isfinite(old_x[:-1]).all(axis=1)
    assert np.array_equal(ok, np.isfinite(new_x[:-1]).all(axis=1)) and not ok[-1]
    scale = 1.0 + np.abs(old_x[:-1][ok]).max(axis=1)
    assert (np.abs(new_x[:-1][ok] - old_x[:-1][ok]).max(axis=1) <= 1e-12 * scale).all()
    assert not certify(system, new_x[-1:], p[-1:], fast=True).certified[0]
    new, old = both(lambda: certify(system, new_x[:-1], p[:-1], fast=True))
    assert np.array_equal(new.certified, old.certified) and new.certified[:-1].mean() > 0.9
    assert not new.certified[-1]
    assert np.array_equal(new.real, old.real) and np.array_equal(new.not_real, old.not_real)
    good = old.certified
    for name in ("alpha", "beta", "gamma"):
        assert np.array_equal(np.isinf(getattr(new, name)), np.isinf(getattr(old, name))), name
    # γ is a function of the point: the same to round-off. β is the Newton step's length at
    # a converged point, i.e. the round-off of F itself (up to 4e-13 apart here, 1e-4
    # relative, from the two routes' summation orders; a fresh numba compile and a cached
    # one differ there too), so it is compared absolutely, and α = βγ with it
    gamma = old.gamma[good]
    assert np.allclose(new.gamma[good], gamma, rtol=1e-12, atol=0.0)
    noise = 1e-11 * (1.0 + np.abs(new_x[:-1][good]).max(axis=1))
    assert (np.abs(new.beta[good] - old.beta[good]) <= noise + 1e-6 * old.beta[good]).all()
    assert (np.abs(new.alpha[good] - old.alpha[good])
            <= gamma * noise + 1e-6 * old.alpha[good]).all()
    assert np.allclose(new.terms, old.terms, rtol=1e-12, equal_nan=True)
    assert np.allclose(new.newton[good], old.newton[good], rtol=0, atol=1e-12)


@pytest.mark.parametrize("family", ["stewart", "loop6r"])
def test_the_compiled_bombieri_weyl_norm_equals_the_numpy_one(monkeypatch, family):
    from screwkit.algebraic.certify import bombieri_weyl_norm

    system = stewart_system() if family == "stewart" else loop6r_system()
    rng = np.random.default_rng(8)
    p = rng.standard_normal((5, system.k)) + 1j * rng.standard_normal((5, system.k))
    p[0] = p[0].real
    new = bombieri_weyl_norm(system, p)
    with monkeypatch.context() as m:
        m.setattr(compiled, "AVAILABLE", False)
        old = bombieri_weyl_norm(system, p)
    assert np.allclose(new, old, rtol=1e-13, atol=0) and (old > 0).all()


def test_a_track_spread_over_threads_is_the_same_bit_for_bit(monkeypatch):
    """The compiled track of many paths runs in interleaved parts on a pool of threads (each
    path on its own in the kernel): the same end points, statuses and step counts bit for bit
    as on one thread; the parts really went to the pool, and a track called from another
    thread stays on it (no pool inside a pool)."""
    import threading

    from screwkit.algebraic.blas import one_blas_thread

    system, start = stewart_system(), stewart_start()
    p, _ = random_stewart(np.random.default_rng(61), 2)
    inst = np.repeat(np.arange(2), len(start.x))

    def solve():
        # BLAS at one thread for both runs (its thread count changes the polish's rounding;
        # the compiled tracks hold it there themselves when they spread over threads)
        with one_blas_thread():
            return track_parameter_homotopy(system, start.p, p[inst],
                                            np.tile(start.x, (2, 1)), instance=inst)

    monkeypatch.setattr(compiled, "THREADS", 1)
    one = solve()
    monkeypatch.setattr(compiled, "THREADS", 2)
    handed: list[int] = []
    inner = compiled._pool

    class Spy:
        def submit(self, fn, rows):
            handed.append(len(rows))
            return inner().submit(fn, rows)

    monkeypatch.setattr(compiled, "_pool", lambda: Spy())
    two = solve()
    assert len(handed) >= 2 and sum(handed) >= len(inst)  # (the anchors' paths, in parts)
    for name in ("x", "y", "status", "condition", "winding", "steps"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name), err_msg=name)
    handed.clear()
    box = []
    worker = threading.Thread(target=lambda: box.append(solve()))
    worker.start()
    worker.join()
    assert not handed and np.array_equal(box[0].y, one.y, equal_nan=True)

"""The parameter-homotopy tracker: univariate targets against numpy.roots, a batch against
one-at-a-time, a double root through the endgame, a path to infinity, path-jump handling and
bad input."""

from __future__ import annotations

import numpy as np
import pytest

from homotopy_helpers import univariate, univariate_start
from screwkit.algebraic.polynomial import Poly, compile_system
from screwkit.algebraic.track import PathStatus, TrackOptions, track_parameter_homotopy
from screwkit.errors import InputError


def _matches(found: np.ndarray, expected: np.ndarray, tol: float) -> bool:
    """Every expected root has a found one within tol (relative), one to one."""
    found = list(found)
    for root in expected:
        gaps = [abs(f - root) for f in found]
        best = int(np.argmin(gaps))
        if gaps[best] > tol * (1 + abs(root)):
            return False
        found.pop(best)
    return True


@pytest.mark.parametrize("degree", [4, 5])
def test_univariate_roots_match_numpy(degree):
    system = univariate(degree)
    c0, roots0 = univariate_start(degree, seed=degree)
    rng = np.random.default_rng(10 + degree)
    for _ in range(5):
        target = rng.standard_normal(degree)
        result = track_parameter_homotopy(system, c0, target, roots0)
        assert result.counts()["regular"] == degree
        assert np.nanmax(result.residual) < 1e-12
        expected = np.roots(np.r_[1.0, target[::-1]])
        assert _matches(result.x[:, 0], expected, 1e-10)


def test_batch_of_targets_equals_one_at_a_time():
    system = univariate(4)
    c0, roots0 = univariate_start(4, seed=1)
    targets = np.random.default_rng(2).standard_normal((6, 4))
    batch = track_parameter_homotopy(system, c0, np.repeat(targets, 4, axis=0),
                                     np.tile(roots0, (6, 1)))
    groups = batch.instance.reshape(6, 4)
    assert (groups == groups[:, :1]).all() and len(set(groups[:, 0])) == 6
    chunked = track_parameter_homotopy(system, c0, np.repeat(targets, 4, axis=0),
                                       np.tile(roots0, (6, 1)), TrackOptions(chunk=5))
    assert np.abs(chunked.x - batch.x).max() < 1e-12
    assert (chunked.steps == batch.steps).all()
    for b, target in enumerate(targets):
        alone = track_parameter_homotopy(system, c0, target, roots0)
        assert np.abs(batch.x[4 * b: 4 * b + 4] - alone.x).max() < 1e-12
        assert (batch.status[4 * b: 4 * b + 4] == alone.status).all()


def test_double_root_is_singular_with_multiplicity_two():
    system = univariate(5)
    c0, roots0 = univariate_start(5, seed=0)
    target = np.poly([1.0, 1.0, 2.0, -1 + 1j, -1 - 1j])[::-1][:5].real
    result = track_parameter_homotopy(system, c0, target, roots0)
    singular = result.status == PathStatus.SINGULAR
    assert singular.sum() == 2
    assert (result.multiplicity[singular] == 2).all() and (result.winding[singular] == 2).all()
    assert np.abs(result.x[singular, 0] - 1.0).max() < 1e-8  # the Cauchy endgame's accuracy
    assert _matches(result.x[~singular, 0], np.array([2.0, -1 + 1j, -1 - 1j]), 1e-10)


def test_triple_root_has_multiplicity_and_winding_three():
    system = univariate(5)
    c0, roots0 = univariate_start(5, seed=0)
    target = np.poly([1.0, 1.0, 1.0, 2.0, -3.0])[::-1][:5].real
    result = track_parameter_homotopy(system, c0, target, roots0)
    singular = result.status == PathStatus.SINGULAR
    assert singular.sum() == 3
    assert (result.multiplicity[singular] == 3).all() and (result.winding[singular] == 3).all()
    assert np.abs(result.x[singular, 0] - 1.0).max() < 1e-8


def test_a_root_going_to_infinity_is_reported_at_infinity():
    # a·x² + b·x + c with a → 0: one root stays finite (−c/b), the other diverges
    x, a, b, c = (Poly.variable(i) for i in range(4))
    system = compile_system([a * x * x + b * x + c], ["x"], ["a", "b", "c"])
    p0 = np.array([1.0 + 0.5j, -0.3 + 1j, 0.7 - 0.2j])
    roots0 = np.roots(p0)[:, None]
    result = track_parameter_homotopy(system, p0, [0.0, 2.0, -3.0], roots0)
    assert sorted(result.status.tolist()) == [PathStatus.REGULAR, PathStatus.AT_INFINITY]
    assert abs(result.x[result.regular, 0][0] - 1.5) < 1e-12
    assert np.isnan(result.x[result.status == PathStatus.AT_INFINITY]).all()


def _quadratic():
    x, a, b, c = (Poly.variable(i) for i in range(4))
    return compile_system([a * x * x + b * x + c], ["x"], ["a", "b", "c"])


def _endgame_calls(monkeypatch) -> list[int]:
    """The number of paths of each call of the Cauchy endgame, recorded as the tracker runs."""
    import screwkit.algebraic.track as track_module

    calls: list[int] = []
    real = track_module.cauchy_endgame
    monkeypatch.setattr(track_module, "cauchy_endgame",
                        lambda hom, y, rows, options: calls.append(len(rows)) or real(
                            hom, y, rows, options))
    return calls


def test_a_regular_end_at_infinity_skips_the_endgame(monkeypatch):
    # at a = 0 the homogenised a·X² + b·X·h + c·h² is h·(b·X + c·h): its root h = 0 is
    # nonsingular (∂/∂h = b·X ≠ 0), so Newton converges there and the endgame is not needed
    calls = _endgame_calls(monkeypatch)
    p0 = np.array([1.0 + 0.5j, -0.3 + 1j, 0.7 - 0.2j])
    result = track_parameter_homotopy(_quadratic(), p0, [0.0, 2.0, -3.0], np.roots(p0)[:, None])
    assert calls == []
    gone = result.status == PathStatus.AT_INFINITY
    assert gone.sum() == 1 and result.winding[gone][0] == 1
    h, X = result.y[gone][0]
    assert abs(h) <= 1e-12 * abs(X)  # the point at infinity [h : X] = [0 : 1]
    assert abs(result.x[result.regular, 0][0] - 1.5) < 1e-12


def test_a_singular_end_at_infinity_still_goes_through_the_endgame(monkeypatch):
    # a = b = 0: c·h² has the double root h = 0; both paths (x ~ ±√(−c/a)) go to infinity
    # through it, which Newton cannot certify, so they are classified by the endgame
    calls = _endgame_calls(monkeypatch)
    p0 = np.array([1.0 + 0.5j, -0.3 + 1j, 0.7 - 0.2j])
    result = track_parameter_homotopy(_quadratic(), p0, [0.0, 0.0, -3.0], np.roots(p0)[:, None])
    assert sum(calls) == 2
    assert result.counts()["at_infinity"] == 2


def test_two_paths_on_one_regular_solution_are_retracked_then_failed():
    # the same start solution twice: both paths end at one regular solution, which a correct
    # tracking never gives; both are tracked again and, still together, marked failed
    system = univariate(3)
    c0, roots0 = univariate_start(3, seed=4)
    starts = np.vstack([roots0, roots0[:1]])
    result = track_parameter_homotopy(system, c0, [0.5, -1.0, 0.2], starts)
    assert result.retracked.tolist() == [True, False, False, True]
    assert result.status.tolist() == [PathStatus.FAILED, PathStatus.REGULAR,
                                      PathStatus.REGULAR, PathStatus.FAILED]
    off = track_parameter_homotopy(system, c0, [0.5, -1.0, 0.2], starts,
                                   TrackOptions(retrack=False))
    assert not off.retracked.any() and (off.status[[0, 3]] == PathStatus.FAILED).all()


def test_bad_shapes_are_refused_with_the_expected_shape():
    system = univariate(3)
    c0, roots0 = univariate_start(3)
    with pytest.raises(InputError, match=r"x_start must have shape \(paths, 1\)"):
        track_parameter_homotopy(system, c0, c0, roots0[:, 0])
    with pytest.raises(InputError, match=r"p_target must have shape \(3,\)"):
        track_parameter_homotopy(system, c0, [1.0, 2.0], roots0)
    with pytest.raises(InputError, match="p_start must be finite"):
        track_parameter_homotopy(system, [np.nan, 0, 0], c0, roots0)


def test_a_segment_through_a_double_root_fails_straight_and_is_detoured():
    """x⁴ + … from the roots ±1, ±2 to ±i, ±2 along a real segment: the roots ±1 meet at 0
    half-way (the segment crosses the discriminant), so the straight paths of those two fail.
    The detour through a random complex point tracks all four again and ends at every root,
    each once, against numpy.roots."""
    system = univariate(4)
    roots = np.array([1.0, -1.0, 2.0, -2.0])
    start = np.poly(roots)[::-1][:4]
    target = np.poly([1j, -1j, 2.0, -2.0])[::-1][:4].real
    straight = track_parameter_homotopy(system, start, target, roots[:, None],
                                        TrackOptions(detour=False))
    assert straight.counts()["failed"] == 2 and not straight.retracked.any()
    result = track_parameter_homotopy(system, start, target, roots[:, None])
    assert result.counts()["regular"] == 4 and result.retracked.all()
    expected = np.roots(np.r_[1.0, target[::-1]])
    assert _matches(result.x[:, 0], expected, 1e-10)


def _lose_path_zero(monkeypatch, first_end=None):
    """Make the first tracking pass report path 0 lost on its main leg (its step collapsed);
    with ``first_end`` the next pass (the retrack alone) ends path 0 there. Returns the
    list of the detour's calls."""
    import screwkit.algebraic.track as track_module

    run, detour, calls = track_module._run, track_module._detour, {"run": 0, "detour": 0}

    def lossy(system, hom, x, rows, options):
        out = run(system, hom, x, rows, options)
        calls["run"] += 1
        if calls["run"] == 1:
            out["status"][0], out["main_leg"][0] = PathStatus.FAILED, False
            out["y"][0] = np.nan
        elif calls["run"] == 2 and first_end is not None:
            out["y"][0] = first_end
        return out

    def counted(*args, **kwargs):
        calls["detour"] += 1
        return detour(*args, **kwargs)

    monkeypatch.setattr(track_module, "_run", lossy)
    monkeypatch.setattr(track_module, "_detour", counted)
    return calls


def test_a_path_lost_on_its_main_leg_is_tracked_again_alone(monkeypatch):
    """x⁴ + … from the roots ±1, ±2 to a random complex quartic (a generic segment): with
    path 0 reported lost on its main leg, it alone is tracked again (10× smaller steps) and
    ends where the untouched run ends it (1e-10); no detour; only it is marked retracked."""
    system = univariate(4)
    roots = np.array([1.0, -1.0, 2.0, -2.0])
    start = np.poly(roots)[::-1][:4]
    target = np.random.default_rng(4).normal(size=4) + 1j * np.random.default_rng(5).normal(
        size=4)
    clean = track_parameter_homotopy(system, start, target, roots[:, None])
    assert clean.counts()["regular"] == 4 and not clean.retracked.any()
    calls = _lose_path_zero(monkeypatch)
    result = track_parameter_homotopy(system, start, target, roots[:, None])
    assert calls == {"run": 2, "detour": 0}
    assert result.counts()["regular"] == 4
    assert result.retracked.tolist() == [True, False, False, False]
    assert np.abs(result.x - clean.x).max() <= 1e-10


def test_a_lost_path_retracked_onto_another_paths_end_sends_its_instance_round(monkeypatch):
    """The same, but the retrack alone ends path 0 where path 1 ends (a jump): that end is not
    kept, and the detour tracks all four again; every root once, against numpy.roots."""
    system = univariate(4)
    roots = np.array([1.0, -1.0, 2.0, -2.0])
    start = np.poly(roots)[::-1][:4]
    target = np.random.default_rng(4).normal(size=4) + 1j * np.random.default_rng(5).normal(
        size=4)
    clean = track_parameter_homotopy(system, start, target, roots[:, None])
    calls = _lose_path_zero(monkeypatch, first_end=clean.y[1])
    result = track_parameter_homotopy(system, start, target, roots[:, None])
    assert calls["detour"] == 1
    assert result.counts()["regular"] == 4 and result.retracked.all()
    expected = np.roots(np.r_[1.0, target[::-1]])
    assert _matches(result.x[:, 0], expected, 1e-10)


@pytest.mark.parametrize("compiled", [False, True])
def test_a_root_at_its_rounding_floor_needs_the_converged_option(compiled):
    """(x − p)(x − p − 10⁻⁴): the root x = p moves exactly as the predictor says, so Newton's
    first correction is pure rounding, ~10⁻¹¹ here (f' = 10⁻⁴ against terms of size 1), and
    the second is as large. With the contraction test (second ≤ first / 10) waived only below
    10⁻¹² (the tracker before), every step is rejected and the step collapses: the path
    fails. With the default ``converged`` (both corrections ≤ 10⁻⁹) those steps are accepted
    and the path arrives, regular, in a few steps (the trace test's far-out witnesses:
    algebraic/trace_test.py)."""
    from dataclasses import replace

    x, p = Poly.variable(0), Poly.variable(1)
    system = compile_system([(x - p) * (x - p - 1e-4)], ["x"], ["p"])
    options = replace(TrackOptions(), retrack=False, detour=False, compiled=compiled)
    assert options.converged == 1e-9
    start, target = np.array([0.3]), np.array([1.7 + 0.2j])
    if not compiled:  # the numpy route's rounding (the compiled kernel's last bits vary
        # with its compilation, so whether some step slips through there varies too: seen)
        strict = replace(options, converged=1e-12)
        stuck = track_parameter_homotopy(system, start, target, np.array([[0.3]]), strict)
        assert stuck.status[0] == PathStatus.FAILED and stuck.steps[0] > 100
    moved = track_parameter_homotopy(system, start, target, np.array([[0.3]]), options)
    assert moved.status[0] == PathStatus.REGULAR and moved.steps[0] < 20
    assert abs(moved.x[0, 0] - (1.7 + 0.2j)) < 1e-10  # its floor: ~u·|terms| / f' ≈ 1e-11

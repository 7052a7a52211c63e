"""The fold search between two samples (modes/along_folds.py ``fold_between``): σ²'s
extrapolated zero probed from both sides, bisection otherwise. Checked against the four-bar's
distance law (the crank angle where |A − D| = b + c, law of cosines), against plain bisection
(the same fold to the bracket's width), and for the reaches it takes."""

from __future__ import annotations

import numpy as np
import pytest
from tests.graphs.test_step_folds import GAP, GAP_DRAWN, _crank_at, _sixbar

from screwkit.kinematics.graph import follow
from screwkit.kinematics.graph.closure import graph_layout, zero_configuration
from screwkit.kinematics.modes import along_folds
from screwkit.kinematics.modes.along_folds import FOLD_STEPS, fold_between, fold_in_step


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    calls = [0]
    real = follow.reach

    def counted(*args: object, **kwargs: object) -> object:
        calls[0] += 1
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(along_folds, "reach", counted)
    return calls


def _gap_fold() -> float:
    """The crank angle (rad, from the drawing) where the GAP four-bar's drawn mode dies:
    |A − D| = b + c."""
    a, b, c, d = GAP
    return float(np.radians(_crank_at(a, d, b + c) - GAP_DRAWN))


@pytest.mark.parametrize("start_deg", [60.0, 80.0, 86.5])  # input (deg); the fold at 87.04°
def test_a_quadratic_fold_is_the_distance_laws_in_few_reaches(
        start_deg: float, monkeypatch: pytest.MonkeyPatch) -> None:
    mech = _sixbar(*GAP, GAP_DRAWN)
    lay = graph_layout(mech)
    fold = _gap_fold()
    x_from, x_to = np.radians([start_deg]), np.radians([100.0])
    conf = follow.reach(mech, lay, zero_configuration(lay), np.zeros(1), x_from)
    assert conf is not None
    calls = _counting(monkeypatch)
    at, near = fold_between(mech, lay, conf, x_from, x_to)
    width = 2.0 ** -FOLD_STEPS * float(x_to[0] - x_from[0])
    # the fold within the bracket's width (and the law's arccos is good to ~1e-8 rad there)
    assert abs(float(at[0]) - fold) <= width + 1e-7
    assert calls[0] <= 18, calls[0]  # bisection: 26
    # plain bisection of the same step (the probes off) ends at the same fold
    monkeypatch.setattr(along_folds, "FOLD_ROUNDS", 0)
    monkeypatch.setattr(along_folds, "HEAD_FOR_END", False)
    calls[0] = 0
    plain, _ = fold_between(mech, lay, conf, x_from, x_to)
    assert calls[0] == FOLD_STEPS
    assert abs(float(plain[0]) - float(at[0])) <= 2 * width


def test_a_step_with_no_fold_is_told_from_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """A step with no fold is crossed in 6 reaches (gaps to its end 1/2, 1/4, 1/16, 2⁻⁸,
    2⁻¹⁶, 2⁻²⁶), where bisection took 26; one with a fold still finds it."""
    mech = _sixbar(*GAP, GAP_DRAWN)
    lay = graph_layout(mech)
    x_from, x_to = np.zeros(1), np.array([np.radians(20.0)])
    calls = _counting(monkeypatch)
    assert fold_in_step(mech, lay, zero_configuration(lay), x_from, x_to) is None
    assert calls[0] == 6
    monkeypatch.setattr(along_folds, "HEAD_FOR_END", False)  # halvings: bisection's 26
    calls[0] = 0
    assert fold_in_step(mech, lay, zero_configuration(lay), x_from, x_to) is None
    assert calls[0] == FOLD_STEPS
    got = fold_in_step(mech, lay, zero_configuration(lay), x_from, np.radians([100.0]))
    assert got is not None and abs(float(got[0][0]) - _gap_fold()) <= 1e-7


@pytest.mark.parametrize(("law", "most"), [
    ("quadratic fold", 21), ("sigma linear", 29), ("sigma's zero off the stop", 29),
    ("quarter power", 29)])
def test_the_bracket_holds_on_model_branches(law: str, most: int,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """On model branches that stop at a random t* of the step (a reach succeeds exactly below
    it) with σ following a given law, every search ends with its last point reached below t*
    and the fold within 2⁻²⁶ of t*, every trial ahead of the last point reached, in at most
    ``most`` reaches (bisection: 26; a quadratic fold: σ ∝ √(t* − t); the first trials head
    for the step's end, so a stop in its last quarter can cost a reach more than bisection's
    first halvings would)."""
    rng = np.random.default_rng(7)
    monkeypatch.setattr(along_folds, "input_scale", lambda lay: np.ones(1))
    counts, calls = [], [0]
    for _ in range(300):
        stop = float(rng.uniform(0.01, 0.99))
        zero = {"quadratic fold": stop, "sigma linear": stop,
                "sigma's zero off the stop": stop + float(rng.uniform(-0.05, 0.05)),
                "quarter power": stop + float(rng.uniform(0.0, 0.01))}[law]
        power = {"quadratic fold": 0.5, "sigma linear": 1.0, "sigma's zero off the stop": 0.5,
                 "quarter power": 0.25}[law]
        calls[0] = 0

        def reach(mech: object, lay: object, conf: float, a: np.ndarray, b: np.ndarray,
                  smallest: float, stop: float = stop) -> float | None:
            calls[0] += 1
            assert float(b[0]) > float(a[0]) == conf
            return float(b[0]) if float(b[0]) < stop else None

        class Model:
            def sigma(self, t: float, zero: float = zero, power: float = power) -> np.ndarray:
                return np.array([abs(zero - t) ** power])

        monkeypatch.setattr(along_folds, "reach", reach)
        monkeypatch.setattr(along_folds, "graph_system", lambda mech, lay: Model())
        at, last = fold_between(None, None, 0.0, np.zeros(1), np.ones(1))  # type: ignore[arg-type]
        assert last < stop  # type: ignore[operator]
        assert abs(float(at[0]) - stop) <= 2.0 ** -FOLD_STEPS
        counts.append(calls[0])
    assert max(counts) <= most, (law, max(counts))

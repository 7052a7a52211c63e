"""The exact Jacobian (implicit-function theorem + complex step, App. E) against central
differences, on random general mechanisms and on a parameters-of-constraint problem."""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthesis_helpers import UNKNOWNS, generated_target, random_mechanism

from screwkit.synthesis.problem import (
    ConstraintConstruction,
    ConstraintPoint,
    RSRCSynthesisProblem,
)
from screwkit.synthesis.residuals import ResidualModel
from screwkit.synthesis.targets import ScrewTarget, library_function

THETA = np.radians(np.arange(0.0, 81.0, 10.0))


def _central(model: ResidualModel, x: np.ndarray, h: float) -> np.ndarray:
    cols = []
    for k in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[k] += h
        xm[k] -= h
        fp = model.evaluate(xp, jacobian=False, remember=False).residuals
        fm = model.evaluate(xm, jacobian=False, remember=False).residuals
        cols.append((fp - fm) / (2 * h))
    return np.stack(cols, axis=1)


@pytest.mark.parametrize("seed", range(6))
def test_jacobian_matches_central_differences(seed: int) -> None:
    rng = np.random.default_rng(seed)
    start, label = random_mechanism(rng, THETA)
    other, _ = random_mechanism(rng, THETA)  # a target this mechanism does not generate
    target = generated_target(other, label, THETA)
    problem = RSRCSynthesisProblem(target, start, UNKNOWNS, inversion=label, length_scale=1.0)
    model = ResidualModel(problem)
    ev = model.evaluate(problem.start_vector())
    assert ev.jacobian is not None
    fd = _central(model, problem.start_vector(), 1e-6)
    # central differences with h = 1e-6 are good to ~1e-9 relative here (truncation h^2 and
    # rounding 1e-16/h); the exact Jacobian must agree to that
    scale = np.max(np.abs(ev.jacobian))
    assert np.max(np.abs(fd - ev.jacobian)) <= 1e-7 * scale


def test_constraint_parameters_jacobian() -> None:
    d = math.radians
    target = ScrewTarget(library_function("power", amplitude=d(40), span=d(47.5)),
                         np.radians(np.arange(0.0, 48.0, 2.5)))
    construction = ConstraintConstruction(ConstraintPoint(0.0, "dwell"),
                                          ConstraintPoint(d(47.5), "free"))
    start = dict(d1=1.0, d2=3.7, e=0.0, b=0.0, delta0=0.0, lambda0=d(60), theta01=d(25),
                 q2=d(46))
    problem = RSRCSynthesisProblem(target, start, ("d1", "d2", "q2", "theta01", "lambda0"),
                                   input_direction=-1, construction=construction,
                                   length_scale=1.0)
    model = ResidualModel(problem)
    ev = model.evaluate(problem.start_vector())
    assert ev.jacobian is not None
    fd = _central(model, problem.start_vector(), 1e-6)
    assert np.max(np.abs(fd - ev.jacobian)) <= 1e-7 * np.max(np.abs(ev.jacobian))

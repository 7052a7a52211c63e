"""Shared helpers: random RSRC mechanisms and targets they generate exactly."""

from __future__ import annotations

import math

import numpy as np

from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_positions
from screwkit.synthesis.problem import RSRCSynthesisProblem
from screwkit.synthesis.targets import ScrewTarget, data_function

UNKNOWNS = ("e", "d1", "d2", "d3", "a", "b", "delta0", "theta01")


def random_mechanism(rng: np.random.Generator, theta: np.ndarray) -> tuple[dict[str, float], int]:
    """A random general RSRC (lengths ~1, delta0 != 0) that assembles at theta01 + theta on a
    branch with two real roots and no lock; returns (start dict, inversion label)."""
    while True:
        dims = dict(d1=rng.uniform(0.5, 1.5), d2=rng.uniform(2.0, 4.0), d3=rng.uniform(1.5, 3.0),
                    a=rng.uniform(1.5, 3.5), b=rng.uniform(-1.0, 2.0), e=rng.uniform(-1.0, 1.0),
                    delta0=rng.uniform(-0.5, 0.5), lambda0=rng.uniform(0.3, 1.2))
        theta01 = rng.uniform(0.0, 2 * math.pi)
        pos = rsrc_positions(RSRCDimensions(**dims), theta01 + theta)
        if pos.assembles[:, :2].all() and not pos.assembles[:, 2:].any():
            gap = np.abs(np.diff(pos.phi0[:, :2], axis=1))
            if gap.min() > 0.3:  # well away from a dead centre
                dims["theta01"] = theta01
                return dims, int(rng.integers(1, 3))


def generated_target(start: dict[str, float], label: int, theta: np.ndarray,
                     rotation: bool = True, translation: bool = True) -> ScrewTarget:
    """The screw the mechanism generates on its branch, as data at the design points."""
    from screwkit.synthesis.residuals import ResidualModel

    dummy = ScrewTarget(data_function(theta, np.zeros_like(theta)), theta)
    problem = RSRCSynthesisProblem(dummy, start, UNKNOWNS, inversion=label, length_scale=1.0)
    ev = ResidualModel(problem).evaluate(problem.start_vector(), jacobian=False)
    order = np.argsort(ev.theta)
    th = ev.theta[order]
    psi = np.unwrap(ev.phi - ev.phi[0])[order]
    s = (ev.S - ev.S[0])[order]
    return ScrewTarget(data_function(th, psi) if rotation else None,
                       theta if rotation else np.zeros(0),
                       data_function(th, s) if translation else None,
                       theta if translation else np.zeros(0))

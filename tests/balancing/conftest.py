"""Shared fixtures: Rahman's CSSP example (kinematics once per session) and the planar 4R
dynamics example with a [balancing] table of the test's choice."""

from __future__ import annotations

from functools import cache

import pytest
from balancing_examples import EXAMPLE


@cache
def _rahman() -> tuple:
    from screwkit.io.spec import load_spec
    from screwkit.kinematics.tracker.generic_motion import generic_motion as motion

    spec = load_spec(EXAMPLE)
    m = motion(spec.linkage, spec.inputs, spec.speed, spec.acceleration)
    return spec, m.modes[spec.mode]


@pytest.fixture(scope="session")
def rahman() -> tuple:
    return _rahman()

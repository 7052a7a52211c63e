"""Shared fixtures: Rahman's CSSP example (kinematics once per session)."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "rahman_cssp_balance.toml"


@cache
def _rahman() -> tuple:
    from screwkit.io.spec import load_spec
    from screwkit.kinematics.generic_motion import generic_motion as motion

    spec = load_spec(EXAMPLE)
    m = motion(spec.linkage, spec.inputs, spec.speed, spec.acceleration)
    return spec, m.modes[spec.mode]


@pytest.fixture(scope="session")
def rahman() -> tuple:
    return _rahman()

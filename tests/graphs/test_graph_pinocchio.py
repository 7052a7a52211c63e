"""The Stewart platform's leg forces against Pinocchio (validation/pinocchio/stewart.py, which
builds the platform in Pinocchio as six U–P legs and a free-flying platform closed by ball
constraints): the same body frames and the same forces, on the spec's motion and with drive
accelerations, to the script's tolerances."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import screwkit as sk

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "validation" / "pinocchio"))
import stewart  # noqa: E402


@pytest.mark.parametrize("run", range(len(stewart.RUNS)))
def test_stewart_leg_forces_equal_pinocchios(run: int) -> None:
    r = stewart.compare(sk.load_spec(stewart.SPEC), stewart.RUNS[run][1])
    assert r["samples"] == 41
    assert r["pose"] <= stewart.POSE_TOLERANCE
    assert r["leg force"] <= stewart.TOLERANCE
    assert r["largest leg force (N)"] > 1.0  # the forces are not trivially zero

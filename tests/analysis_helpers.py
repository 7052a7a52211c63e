"""The analysis document of a linkage through the front door (solve_motion + the io layer's
document), in the shape the analysis tests compare."""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.io.documents import analysis_document
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.linkage import Linkage


def analyze(linkage: Linkage, inputs: np.ndarray, speed: float = 1.0, acceleration: float = 0.0,
            coupler_point: tuple[float, float, float] | None = None,
            method: str = "auto") -> tuple[Motion, dict[str, Any]]:
    m = solve_motion(linkage, inputs, rates=speed, accelerations=acceleration, method=method)
    return m, analysis_document(m, coupler_point=coupler_point)


def mode_motion(linkage: Linkage, inputs: np.ndarray, speed: float, acceleration: float,
                mode: int = 0) -> ModeMotion:
    return solve_motion(linkage, inputs, rates=speed, accelerations=acceleration).mode(mode)

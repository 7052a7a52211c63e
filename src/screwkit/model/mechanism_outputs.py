"""Named outputs of a mechanism (the model side; kinematics/graph/outputs.py computes them):
the angle a body-fixed direction turns through about a world axis (camber, toe), and a point's
travel along a world direction (track change)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class BodyAngle:
    """The angle ``vector`` (fixed in ``body``, as drawn) turns through about world ``about``."""

    name: str
    body: str
    vector: Array
    about: Array

    kind = "angle"


@dataclass(frozen=True)
class PointTravel:
    """The travel of ``point`` (a ``[[points]]`` entry) along the world direction ``along``."""

    name: str
    point: str
    along: Array

    kind = "length"


Output = BodyAngle | PointTravel

"""Dimensions of Bagci's RSRC space four-bar and the checks of its input arrays (Bagci 1969, §3.1).

Parameter names are Bagci's (SPEC §3.1): input crank d1 about the X axis (input angle theta0,
measured from +Y), coupler d2, output crank d3, fixed link a (along +Y), offset b along the input
axis, offset e along the coupler-output revolute axis, skew angle delta0 between the output axis
and that revolute axis, skew angle lambda0 between the input and output axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError
from screwkit.messages import given

__all__ = [
    "SPECIAL_ANGLE_TOL",
    "RSRCDimensions",
    "SpecialCase",
    "check_input_angles",
    "check_input_rate",
]

FloatArray = NDArray[np.float64]

SpecialCase = Literal["general", "delta0_n_pi", "delta0_half_pi"]

#: |sin delta0| (resp. |cos delta0|) at or below this value selects the quadratic special case
#: delta0 = n pi (resp. delta0 = +-pi/2) of Bagci §3.4.  Program A branches on exact equality of
#: the angle in degrees; in radians the floating-point value of pi/2 needs a tolerance.
SPECIAL_ANGLE_TOL = 1e-12


@dataclass(frozen=True)
class RSRCDimensions:
    """Dimensions of an RSRC mechanism with Bagci's parameter names (Bagci 1969, §3.1, Fig. 5).

    Lengths in metres (any consistent unit works), angles in radians.

    Attributes
    ----------
    d1 : input crank length (input axis to sphere centre), > 0.
    d2 : coupler length (coupler revolute axis to sphere centre), > 0.
    d3 : output crank length (output axis to coupler revolute axis), >= 0.
    a : fixed-link length (common normal of the input and output axes, along +Y); any sign.
    b : offset of the input-crank plane from the fixed link along the input axis.
    e : offset along the coupler revolute axis from the foot of d3 to the foot of d2.
    delta0 : skew angle between the output axis and the coupler revolute axis.
    lambda0 : skew angle between the input axis and the output axis.
    """

    d1: float
    d2: float
    d3: float
    a: float
    b: float
    e: float
    delta0: float
    lambda0: float

    def __post_init__(self) -> None:
        for name in ("d1", "d2", "d3", "a", "b", "e", "delta0", "lambda0"):
            value = getattr(self, name)
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise InputError(
                    f"RSRCDimensions.{name} must be a real number, got {given(value)}"
                ) from None
            if not math.isfinite(number):
                raise InputError(f"RSRCDimensions.{name} must be finite, got {given(number)}")
            object.__setattr__(self, name, number)
        if self.d1 <= 0.0:
            raise InputError(
                f"RSRCDimensions.d1 (input crank) must be > 0, got {self.d1!r}; a zero crank "
                "leaves the input angle without effect"
            )
        if self.d2 <= 0.0:
            raise InputError(
                f"RSRCDimensions.d2 (coupler) must be > 0, got {self.d2!r}"
            )
        if self.d3 < 0.0:
            raise InputError(
                f"RSRCDimensions.d3 (output crank) must be >= 0, got {self.d3!r}; a negative "
                "crank is the same mechanism with phi0 shifted by pi, pass -d3 instead"
            )

    @property
    def special_case(self) -> SpecialCase:
        """Which closed form applies: the quartic, delta0 = n pi, or delta0 = +-pi/2 (§3.4)."""
        if abs(math.sin(self.delta0)) <= SPECIAL_ANGLE_TOL:
            return "delta0_n_pi"
        if abs(math.cos(self.delta0)) <= SPECIAL_ANGLE_TOL:
            return "delta0_half_pi"
        return "general"

    @property
    def length_scale(self) -> float:
        """Sum of the absolute lengths: the scale used by the relative tolerances."""
        return self.d1 + self.d2 + self.d3 + abs(self.a) + abs(self.b) + abs(self.e)

    @property
    def is_planar_fourbar(self) -> bool:
        """True for the plane 4R special case delta0 = lambda0 = 0, b = e = 0 (§3.4)."""
        return self.delta0 == 0.0 and self.lambda0 == 0.0 and self.b == 0.0 and self.e == 0.0


def check_input_angles(theta0: ArrayLike, name: str = "theta0") -> FloatArray:
    """Angles (radians) as a finite 1-D float array (a scalar becomes shape (1,)).

    Raises a ValueError naming ``name``, the offending shape or the first non-finite entry.
    """
    arr = np.asarray(theta0, dtype=np.float64)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1:
        raise InputError(
            f"{name} must be a scalar or a 1-D array of input angles (radians), got shape "
            f"{arr.shape}; flatten it first"
        )
    bad = ~np.isfinite(arr)
    if bad.any():
        index = int(np.flatnonzero(bad)[0])
        raise InputError(f"{name}[{index}] = {arr[index]!r} is not finite")
    return arr


def check_input_rate(value: ArrayLike, n: int, name: str) -> FloatArray:
    """A scalar or (n,) input rate (rad/s or rad/s^2) as a finite (n, 1) column."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise InputError(f"{name} must be a scalar or have shape ({n},), got shape {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        index = int(np.flatnonzero(bad)[0])
        raise InputError(f"{name}[{index}] = {arr[index]!r} is not finite")
    return arr[:, None]

"""Coupler-point coordinates of the RSRC in every assembly (Bagci 1969, App. C, eqs. C.2-C.7)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.rsrc.dimensions import RSRCDimensions
from screwkit.kinematics.closed_forms.rsrc.positions import RSRCPositions
from screwkit.messages import given

__all__ = ["RSRCCouplerPoint", "rsrc_coupler_point"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class RSRCCouplerPoint:
    """Coordinates of a coupler point (Bagci 1969, App. C, eqs. C.2-C.7).

    Attributes
    ----------
    global_xyz : (N, 4, 3) X_p, Y_p, Z_p in the fixed frame OXYZ.
    output_frame_xyz : (N, 4, 3) xi'_3p, eta'_3p, zeta'_3p in the output-axis frame O3 xi' eta'
        zeta' (origin (b, a, 0), xi' along the output axis (cos lambda0, 0, -sin lambda0), eta' = +Y).
    assembles : (N, 4) bool; NaN rows elsewhere.
    """

    global_xyz: FloatArray
    output_frame_xyz: FloatArray
    assembles: BoolArray


def rsrc_coupler_point(
    dims: RSRCDimensions, positions: RSRCPositions, f: float, g: float, h: float
) -> RSRCCouplerPoint:
    """Coupler point (f, g, h), given in the coupler frame at the sphere centre (App. C).

    The coupler frame is parallel to the frame O2''xi2''eta2''zeta2'' (x along the coupler
    revolute axis, y from the sphere centre towards the foot O2'' of d2 on that axis): the point
    is P = O1 + f B e1 + g B e2 + h B e3, B the coupler frame's rotation (SPEC §3.1, §9).  With f = g = h = 0 it is the sphere centre
    (0, d1 cos theta0, d1 sin theta0).  Explicit forms (C.2)-(C.4) and, with a = b = lambda0 = 0,
    (C.5)-(C.7).
    """
    for name, value in (("f", f), ("g", g), ("h", h)):
        if not math.isfinite(float(value)):
            raise InputError(f"coupler point coordinate {name} must be finite, got {given(value)}")
    f, g, h = float(f), float(g), float(h)
    sl, cl = math.sin(dims.lambda0), math.cos(dims.lambda0)
    sd, cd = math.sin(dims.delta0), math.cos(dims.delta0)
    sp, cp = np.sin(positions.phi0), np.cos(positions.phi0)
    sc, cc = np.sin(positions.chi0), np.cos(positions.chi0)
    s = positions.S
    dg = dims.d2 - g
    ef = dims.e + f
    # output-axis frame, eqs. C.5-C.7
    xi = -s - dg * sd * sc + ef * cd - h * sd * cc
    eta = (dims.d3 * cp - dg * (cp * cc + cd * sp * sc) - ef * sd * sp
           + h * (cp * sc - cd * sp * cc))
    zeta = (dims.d3 * sp + dg * (cd * cp * sc - sp * cc) + ef * sd * cp
            + h * (cd * cp * cc + sp * sc))
    # fixed frame: O3 + xi u3 + eta e2 + zeta (sin lambda0, 0, cos lambda0), equal to eqs. C.2-C.4
    x = dims.b + cl * xi + sl * zeta
    y = dims.a + eta
    z = -sl * xi + cl * zeta
    return RSRCCouplerPoint(
        np.stack([x, y, z], axis=-1), np.stack([xi, eta, zeta], axis=-1), positions.assembles
    )

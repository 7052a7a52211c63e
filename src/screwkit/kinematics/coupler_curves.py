"""Coupler points and their curves: the world path of a point fixed to any moving link
(Bagci 1969 App. C for the RSRC's coupler: P = O1 + f·B e1 + g·B e2 + h·B e3, with B the coupler
frame at the sphere centre; here for any link of any loop from its body frame)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from screwkit.errors import InputError
from screwkit.kinematics.loop import Array
from screwkit.kinematics.motion import ModeMotion


def coupler_point_path(mode: ModeMotion, point: ArrayLike, link: int = 1) -> Array:
    """(N, 3) world positions (m) of ``point`` (3,), given in the body frame of moving link
    ``link`` (0-based; link k lies between joints k and k+1, its frame is joint k's frame after
    the joint motion), over one mode; NaN where the mode does not assemble."""
    p = np.asarray(point, dtype=float)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise InputError(f"a coupler point is 3 finite coordinates in the link frame; got {point!r}")
    n_links = mode.link_rotation.shape[1]
    if not 0 <= link < n_links:
        raise InputError(f"link index {link} out of range: the loop has {n_links} moving links")
    R = mode.link_rotation[:, link]
    return np.asarray(mode.link_origin[:, link] + np.einsum("nij,j->ni", R, p))

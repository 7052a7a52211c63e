"""Coupler points and their curves: the world path of a point fixed to any moving link of any
loop (Bagci 1969 App. C for the RSRC's coupler: P = O1 + f·B e1 + g·B e2 + h·B e3, with B the
coupler frame at the sphere centre — the RSRC coupler's body frame is exactly that frame).

Link k (``linkage.links[k]``) lies between joints k and k+1; its body frame is joint k's frame
after the joint motion (docs/kinematics.md, "Link frames", gives every family's). A point on a
link between two ball joints must lie on the line of the two ball centres: such a link turns
freely about that line (an idle freedom no joint drives), so a point off the line has no defined
path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from screwkit.errors import InputError, expect_instance
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.kinematics.registry import coupler_link_index
from screwkit.kinematics.tracker.loop import Array
from screwkit.messages import given, shown, shown_values
from screwkit.model.linkage import Linkage

__all__ = ["CouplerPoint", "coupler_curves", "coupler_point", "coupler_point_path"]


@dataclass(frozen=True)
class CouplerPoint:
    """A point fixed to moving link ``link`` (an index into ``linkage.links``, whose name is
    ``link_name``), at ``point`` (m) in that link's body frame."""

    name: str
    link: int
    link_name: str
    point: tuple[float, float, float]


def idle_axis(linkage: Linkage, link: int) -> Array | None:
    """The direction, in link ``link``'s body frame, of the line of the two ball centres when the
    link lies between two spherical joints (it spins idly about that line); else None."""
    joints = linkage.joints
    if not (joints[link].kind == "S" and joints[link + 1].kind == "S"):
        return None
    t = linkage.link_transforms[link]
    centre = t.translation + t.real @ np.array([0.0, 0.0, joints[link + 1].offset])
    return np.asarray(centre / np.linalg.norm(centre))


def _point(point: ArrayLike) -> Array:
    """``point`` as floats; NaN for what is not numbers (the caller's message says what a
    point is)."""
    try:
        return np.asarray(point, dtype=float)
    except (TypeError, ValueError):
        return np.full(1, np.nan)


def coupler_point(linkage: Linkage, point: ArrayLike, link: str | None = None,
                  name: str = "coupler point") -> CouplerPoint:
    """A coupler point of ``linkage``: ``point`` (3 coordinates, m) in the body frame of the
    moving link called ``link`` (default: the family's coupler,
    :func:`~screwkit.kinematics.registry.coupler_link_index`). A ValueError says why a point
    has no defined path (module docstring)."""
    p = _point(point)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise InputError(f"a coupler point is 3 finite coordinates in the link frame; got {given(point)}")
    k = coupler_link_index(linkage, link)
    axis = idle_axis(linkage, k)
    if axis is not None:
        off = float(np.linalg.norm(np.cross(p, axis)))
        if off > 1e-9 * linkage.length_scale:
            j1, j2 = linkage.joints[k].name, linkage.joints[k + 1].name
            along = float(p @ axis)
            raise InputError(
                f"{linkage.name}: the {linkage.links[k].name} lies between the ball joints {j1} "
                f"and {j2}, so it turns freely about the line of their centres and only points on "
                f"that line have a defined path; this point is {shown(off, 'length')} off it (the "
                f"nearest point on it is {shown(along, 'length')} along the line from {j1}, "
                "direction "
                f"{shown_values(np.round(axis, 9))} in the link frame)")
    return CouplerPoint(name, k, linkage.links[k].name, (float(p[0]), float(p[1]), float(p[2])))


def coupler_point_path(mode: ModeMotion, point: ArrayLike, link: int = 1) -> Array:
    """(N, 3) world positions (m) of ``point`` (3,), given in the body frame of moving link
    ``link`` (0-based; link k lies between joints k and k+1, its frame is joint k's frame after
    the joint motion), over one mode; NaN where the mode does not assemble."""
    expect_instance(mode, ModeMotion, "coupler_point_path: mode",
                    "one mode of a solved motion (motion.mode(k))")
    p = _point(point)
    if isinstance(link, bool) or not isinstance(link, int | np.integer):
        raise InputError(f"coupler_point_path: link must be a moving link's index; got {link!r}")
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise InputError(f"a coupler point is 3 finite coordinates in the link frame; got {given(point)}")
    n_links = mode.link_rotation.shape[1]
    if not 0 <= link < n_links:
        raise InputError(f"link index {link} out of range: the loop has {n_links} moving links")
    R = mode.link_rotation[:, link]
    return np.asarray(mode.link_origin[:, link] + np.einsum("nij,j->ni", R, p))


def coupler_curves(motion: Motion, points: list[CouplerPoint]) -> list[dict[str, Array]]:
    """Per mode of ``motion``, the (N, 3) world path of every coupler point, by name: the
    coupler curves in 3-D (NaN where the mode does not assemble)."""
    return [{cp.name: coupler_point_path(md, cp.point, cp.link) for cp in points}
            for md in motion.modes]

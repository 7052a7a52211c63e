"""The constant geometry of each family's loop as plain arrays of its dimensions: the link
transforms L_k = (R_k, t_k) and the joint offsets, written with numpy operations only so that a
complex dimension goes through (complex-step derivatives of the loop closure with respect to a
dimension, :mod:`screwkit.synthesis.loop_route`). Each function reproduces the transforms of the
family's constructor in :mod:`screwkit.model.families` exactly (a test holds them together).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.model.linkage import Linkage

__all__ = ["LoopGeometry", "cssp_geometry", "fourbar_geometry", "geometry_of",
           "hartenberg_denavit_geometry", "rccc_geometry", "rsrc_geometry", "rssr_geometry"]

# columns e2, e3, e1: a frame whose z axis is the x axis of the frame it is expressed in
_P = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


@dataclass(frozen=True)
class LoopGeometry:
    """Link transforms (rotation (3, 3), translation (3,)) after each joint, and each joint's
    constant offset (a length along its axis; an angle for a P joint)."""

    rotations: tuple[Any, ...]
    translations: tuple[Any, ...]
    offsets: tuple[Any, ...]


# complex-safe elementary rotations (screwkit.dual.spatial's are float-only by design)
def _ry(a: Any) -> Any:
    c, s = np.cos(a), np.sin(a)
    z, o = 0 * c, 0 * c + 1
    return np.array([[c, z, s], [z, o, z], [-s, z, c]])


def _rx(a: Any) -> Any:
    c, s = np.cos(a), np.sin(a)
    z, o = 0 * c, 0 * c + 1
    return np.array([[o, z, z], [z, c, -s], [z, s, c]])


def _vec(*v: Any) -> Any:
    return np.array([0 * v[0] + x for x in v])


def rsrc_geometry(d1: Any, d2: Any, d3: Any, a: Any, b: Any, e: Any, delta0: Any,
                  lambda0: Any) -> LoopGeometry:
    """Bagci's RSRC (:func:`~screwkit.model.families.rsrc`)."""
    ry = _ry(lambda0)
    r4 = _P.T @ ry.T @ _P
    return LoopGeometry(
        (np.eye(3), _P, _P.T @ _ry(delta0) @ _P, r4),
        (_vec(d1, 0, 0), _vec(0, d2, 0), _vec(-d3, 0, -e), -(_P.T @ ry.T @ _vec(b, a, 0))),
        (0, 0, 0, 0))


def rssr_geometry(d1: Any, d2: Any, d3: Any, a: Any, b: Any, lambda0: Any,
                  output_offset: Any = 0.0) -> LoopGeometry:
    """The RSSR (:func:`~screwkit.model.families.rssr`)."""
    ry = _ry(lambda0)
    return LoopGeometry(
        (np.eye(3), np.eye(3), np.eye(3), _P.T @ ry.T @ _P),
        (_vec(d1, 0, 0), _vec(d2, 0, 0), _vec(-d3, 0, -output_offset),
         -(_P.T @ ry.T @ _vec(b, a, 0))),
        (0, 0, 0, 0))


def cssp_geometry(a1: Any, a2: Any, a4: Any, alpha4: Any, s1: Any = 0.0) -> LoopGeometry:
    """Rahman's CSSP with a constant crank offset s1 (:func:`~screwkit.model.families.cssp`)."""
    return LoopGeometry(
        (np.eye(3), np.eye(3), _rx(np.pi / 2), _rx(alpha4)),
        (_vec(a1, 0, 0), _vec(a2, 0, 0), _vec(0, 0, 0), _vec(a4, 0, 0)),
        (s1, 0, 0, 0))


def fourbar_geometry(a: Any, d1: Any, d2: Any, d3: Any) -> LoopGeometry:
    """The planar 4R (:func:`~screwkit.model.families.fourbar`)."""
    return LoopGeometry(
        (np.eye(3), np.eye(3), np.eye(3), np.diag([-1.0, -1.0, 1.0])),
        (_vec(d1, 0, 0), _vec(d2, 0, 0), _vec(d3, 0, 0), _vec(a, 0, 0)),
        (0, 0, 0, 0))


def hartenberg_denavit_geometry(lengths: Sequence[Any], twists: Sequence[Any],
                                offsets: Sequence[Any]) -> LoopGeometry:
    """A joint list: L_i = X(α_i + ε a_i) (Rahman eq. 2.2), joint offsets as given."""
    return LoopGeometry(tuple(_rx(t) for t in twists),
                        tuple(_vec(a, 0, 0) for a in lengths), tuple(offsets))


def rccc_geometry(a1: Any, a2: Any, a3: Any, a4: Any, alpha1: Any, alpha2: Any, alpha3: Any,
                  alpha4: Any, input_offset: Any = 0.0) -> LoopGeometry:
    """The RCCC (:func:`~screwkit.model.families.rccc`)."""
    return hartenberg_denavit_geometry((a1, a2, a3, a4), (alpha1, alpha2, alpha3, alpha4),
                                       (input_offset, 0, 0, 0))


def geometry_of(linkage: Linkage) -> LoopGeometry:
    """The geometry of a built linkage (real), read from its transforms and joints."""
    return LoopGeometry(tuple(np.asarray(t.real) for t in linkage.link_transforms),
                        tuple(np.asarray(t.translation) for t in linkage.link_transforms),
                        tuple(j.offset for j in linkage.joints))

"""Degenerate sets: a continuum of closed configurations at one input (a motion left free with
the input fixed) is one set, never many one-sample modes.

A root search started from many random points lands on many points of such a continuum. A root
is on a continuum when its passive Jacobian (with the zero-spin rows of S–S rods, so that an
idle spin is not a free motion) loses rank with the input in range and a step along the null
direction closes again a step away (:func:`~screwkit.kinematics.tracker.singularities.classify`, "free
motion"). All the roots on continua at one input are one degenerate set, of the largest
dimension found: it is seeded once, and not at all where a known branch is already on it. (Its
connected components are not told apart: the set is reported by one of its configurations,
flagged singular, with the dimension in the mode's events.)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import Configuration, Layout, forward
from screwkit.kinematics.tracker.rates import rate_equations
from screwkit.kinematics.tracker.singularities import classify
from screwkit.model.linkage import Linkage


def free_motion_dimension(linkage: Linkage, lay: Layout, conf: Configuration) -> NDArray[np.int_]:
    """The dimension of the continuum of closed configurations through each row of ``conf``
    at its (held) inputs: 0 for an isolated root."""
    out = np.zeros(conf.size, dtype=int)
    if conf.size == 0:
        return out
    eq = rate_equations(linkage, lay, forward(linkage, conf, lay))
    idx = np.nonzero(eq.rank_deficient)[0]
    if idx.size:
        sub = conf.take(idx)
        kinds, dims = classify(linkage, lay, sub, rate_equations(
            linkage, lay, forward(linkage, sub, lay)))
        out[idx] = [d if k == "free motion" else 0 for k, d in zip(kinds, dims, strict=True)]
    return out


def seeds_off_continua(linkage: Linkage, lay: Layout, known: Configuration,
                       roots: Configuration) -> NDArray[np.bool_]:
    """Which ``roots`` (all at one input) to keep as seeds of new branches: every isolated
    root, and one root on a continuum unless a ``known`` configuration is on one already."""
    on_free = free_motion_dimension(linkage, lay, roots) > 0
    keep = ~on_free
    if on_free.any() and not np.any(free_motion_dimension(linkage, lay, known) > 0):
        keep[int(np.argmax(on_free))] = True
    return keep


__all__ = ["free_motion_dimension", "seeds_off_continua"]

"""Folds of a loop whose positions are the real roots of the RSRC quartic, each attributed to
the two modes that meet there (issue 27: "births and deaths at folds are reported", "a motion
never switches mode silently").

The loop's modes are the branches of ``rsrc_motion`` that assemble somewhere over the rows, and
each one's fold is where its own root stops assembling, found by the one search the single-loop
engine uses too (kinematics/closed_forms/rsrc/folds.py's ``branch_folds``: the step cut into
sections, the roots matched section to section by ``rsrc_motion`` itself, to 2⁻⁵⁰ of the step;
its partner the branch whose own search ends at the same place). This module renumbers its
branches as the loop's modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.closed_forms.rsrc import rsrc_motion
from screwkit.kinematics.closed_forms.rsrc.folds import branch_folds
from screwkit.kinematics.graph.loop_subchain import LoopChain

Array = NDArray[np.float64]


@dataclass(frozen=True)
class QuarticFold:
    """Loop mode ``mode`` (``solve_motion``'s order: the quartic's branches that assemble
    somewhere over the rows) is born or dies (``dies``) between rows k and k+1 of the loop
    inputs, at the fraction ``t`` of that step; ``partner`` the loop mode that meets it there
    (None: a root that assembles at neither sample)."""

    mode: int
    k: int
    dies: bool
    t: float
    partner: int | None


def quartic_folds(chain: LoopChain, L: Array) -> list[QuarticFold]:
    """Every birth and death of the loop's modes between consecutive rows of the loop inputs
    ``L`` (K, 1), the rows its modes were solved on (module docstring)."""
    from screwkit.kinematics.closed_forms.closed_form_motion import rsrc_dimensions

    dims = rsrc_dimensions(chain.linkage)[0]
    mot = rsrc_motion(dims, L[:, 0], events=False)
    mode = np.cumsum(mot.assembles.any(axis=0)) - 1  # column → loop mode
    return [QuarticFold(int(mode[f.branch]), f.k, f.dies, f.t,
                        None if f.partner is None else int(mode[f.partner]))
            for f in branch_folds(dims, mot)]

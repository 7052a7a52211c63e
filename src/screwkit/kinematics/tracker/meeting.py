"""Whether a branch end has run onto another branch the continuation holds
(:mod:`screwkit.kinematics.tracker.continuation`): the same assembly, by signature (joint centres
and axes), at two samples or more."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import Configuration
from screwkit.kinematics.tracker.system import ClosureSystem
from screwkit.kinematics.tracker.tracks import Track


def joins_another(system: ClosureSystem, tracks: list[Track], met: dict[int, bool], track: int,
                  idx: NDArray[np.intp], conf: Configuration) -> bool:
    """Whether the newly reached samples ``idx`` of ``track`` are, at two of them or more,
    the configurations another track already holds: the front has run onto a known branch
    (a seed found again next to where a branch ended) and stops there; the two tracks are
    merged afterwards. Branches that cross meet at one sample only. A long chunk is
    compared at its first two and last two samples: a front that runs onto a branch
    stays on it to the chunk's end (where it left the branch again within the chunk, the
    merge removes the shared samples afterwards)."""
    if len(idx) < 2:
        idx, conf = idx[-1:], conf.take(np.arange(len(idx))[-1:])
    elif len(idx) > 4:
        ends = np.array([0, 1, len(idx) - 2, len(idx) - 1])
        idx, conf = idx[ends], conf.take(ends)
    others = [k for k, tr in enumerate(tracks) if k != track and tr.mask[idx].any()]
    if not others or len(idx) == 0:
        return False
    mine = system.signature(conf)
    for k in others:
        tr = tracks[k]
        held = np.nonzero(tr.mask[idx])[0]
        theirs = system.signature(Configuration(tr.scalars[idx[held]], tr.spherical[idx[held]]))
        same = np.max(np.abs(mine[held] - theirs), axis=1) < 1e-6
        if same.sum() >= min(2, len(idx)) and (same.sum() >= 2 or met[track]):
            return True
        if same.any():
            met[track] = True
    return False


__all__ = ["joins_another"]

"""A generic loop's motion after a small change of its dimensions, warm-started from the motion
of the loop before the change (the studio's live update, docs/studio.md "Speed").

The generic solver (:func:`~screwkit.kinematics.tracker.generic_motion.generic_motion`) finds
the assembly modes by root searches and follows them by continuation. When the dimensions move
a little, each mode's configuration at every sample moves a little too, so the new modes are
found faster by one batched Newton corrector on all N × modes samples at once, started from the
old configurations (:func:`~screwkit.kinematics.tracker.solve.correct`: minimum-norm
Gauss–Newton to round-off, with Deuflhard's contraction test, vectorised over the batch). The
result is kept only when it is provably the generic solver's answer:

1. every sample of every mode converges and contracts (a start outside its root's basin of
   quadratic convergence does not), to the round-off closure the generic solver's samples
   have (:func:`closed_as`), so the two agree to within that closure error over the passive
   Jacobian's smallest singular value;
2. no branch switch: each mode's joint centres and axes (its signature, the tracker's
   measure) move between neighbouring samples by at most :data:`STEP_GROWTH` times their
   move before the change, plus :data:`STEP_SLACK` (a jump to another branch at some samples
   is a step of the size of the distance between branches);
3. the modes stay distinct at every sample (two modes run onto one branch are not);
4. (:func:`same_modes_as_search`, which callers run after answering, as it costs about as
   much as the rest) the generic solver's own first root search — the same random starts at
   the same anchor samples (:func:`~screwkit.kinematics.tracker.generic_motion.anchor_samples`)
   — finds no root off these modes and each mode somewhere. Where every mode assembles over
   the whole sweep that search is the only place the generic solver finds modes (it searches
   again only where a branch ends), so the warm modes are then its modes.

Only motions whose every mode assembles at every sample with no singular sample (before and
after the change), of a loop
without S–S rods (whose idle spin the root search fixes at random), are warm-started; anything
else returns None and the caller solves anew. The modes are built, numbered and named exactly as
:func:`~screwkit.kinematics.solve_motion.solve_motion` builds a generic motion.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.kinematics.motion import Motion, as_input_array, per_sample
from screwkit.kinematics.registry import family_of
from screwkit.kinematics.solve_motion import with_seed_names
from screwkit.kinematics.tracker.branch_merge import SAME_ROOT
from screwkit.kinematics.tracker.generic_motion import (
    anchor_samples,
    root_search,
)
from screwkit.kinematics.tracker.loop import Array, Configuration, Layout, layout
from screwkit.kinematics.tracker.mode_frames import mode_from_configuration
from screwkit.kinematics.tracker.rates import spin_links
from screwkit.kinematics.tracker.solve import correct, signature
from screwkit.kinematics.tracker.system import FILL_TOL
from screwkit.model.linkage import Linkage

#: largest first Newton step from an old configuration (scaled freedoms: rad, and lengths / the
#: length scale); a larger change of the design is solved anew
REACH = 1.0
#: largest ratio of the second Newton step to the first (Deuflhard's contraction test)
CONTRACTION = 0.5
#: a mode's signature may move between neighbouring samples by this many times its move before
#: the change, plus STEP_SLACK (signature units: lengths / length scale, axis components)
STEP_GROWTH = 3.0
STEP_SLACK = 1e-6
#: signature distance below which two modes are the same configuration (the generic solver's
#: merge test, generic_motion.same_samples)
DISTINCT = 1e-5


def _warmable(previous: Motion, linkage: Linkage, X: Array) -> bool:
    """Whether ``previous`` can start the motion of ``linkage`` over ``X`` (module
    docstring): a generic motion of a loop with the same joints over the same inputs, every
    mode assembling at every sample, none singular, and no S–S rod; no closed form."""
    old = previous.linkage
    return (previous.method == "generic" and bool(previous.modes)
            and family_of(linkage).closed_form_for(linkage) is None
            and [(j.kind, j.name) for j in old.joints] == [(j.kind, j.name) for j in linkage.joints]
            and tuple(old.inputs) == tuple(linkage.inputs) and not spin_links(linkage)
            and previous.inputs.shape == X.shape and bool(np.array_equal(previous.inputs, X))
            and all(bool(np.all(md.assembles)) and not bool(np.any(md.singular))
                    for md in previous.modes))


def _steps(sig: Array) -> Array:
    """(M, N − 1) max-norm moves of each mode's signature (M, N, d) between neighbours."""
    return np.asarray(np.max(np.abs(np.diff(sig, axis=1)), axis=-1))


def warm_motion(linkage: Linkage, inputs: ArrayLike, previous: Motion, *,
                rates: ArrayLike = 1.0, accelerations: ArrayLike = 0.0) -> Motion | None:
    """The generic motion of ``linkage`` over ``inputs`` from ``previous`` (the motion of the
    same loop with other dimensions; module docstring, checks 1–3), or None where it cannot
    be warm-started or a check fails. Check 4 is :func:`same_modes_as_search`."""
    X = as_input_array(linkage, inputs, "inputs")
    if not _warmable(previous, linkage, X):
        return None
    N, M = X.shape[0], len(previous.modes)
    lay = layout(linkage)
    start = Configuration(np.concatenate([md.conf.scalars for md in previous.modes]),
                          np.concatenate([md.conf.spherical for md in previous.modes]))
    with np.errstate(all="ignore"):
        fixed = correct(linkage, start, lay, np.full(N * M, REACH), CONTRACTION)
    if not fixed.accepted.all():
        return None
    old_sig = signature(previous.linkage, start, layout(previous.linkage)).reshape(M, N, -1)
    sig = signature(linkage, fixed.conf, lay).reshape(M, N, -1)
    if not np.all(np.isfinite(sig)) or np.any(
            _steps(sig) > STEP_GROWTH * _steps(old_sig) + STEP_SLACK):
        return None
    for a in range(M):
        for b in range(a + 1, M):
            if np.any(np.max(np.abs(sig[a] - sig[b]), axis=-1) < DISTINCT):
                return None
    order = sorted(range(M), key=lambda m: tuple(np.round(sig[m, 0], 9).tolist()))
    Xd = per_sample(linkage, rates, "rates", X)
    Xdd = per_sample(linkage, accelerations, "accelerations", X)
    mask = np.ones(N, dtype=bool)
    modes = []
    closed = closed_as(previous)
    for k, m in enumerate(order):
        conf = fixed.conf.take(slice(m * N, (m + 1) * N))
        md = mode_from_configuration(linkage, lay, conf, mask.copy(), X, Xd, Xdd, [])
        if not np.all(md.closure_residual <= closed) or md.singular.any():
            return None  # not closed as well, or a singular sample (the solver's own care)
        modes.append(with_seed_names(linkage, replace(md, index=k, label=f"branch {k}")))
    return Motion(linkage, X, Xd, Xdd, tuple(modes), method="generic",
                  solver=previous.solver, notes=previous.notes)


def closed_as(previous: Motion) -> float:
    """The closure error a warm-started sample may have: what the generic solver's samples
    have — round-off (its fill's FILL_TOL, or the largest error among the samples of
    ``previous``, the same solver's motion at nearby dimensions, if more)."""
    worst = max(float(np.nanmax(md.closure_residual, initial=0.0)) for md in previous.modes)
    return max(FILL_TOL, worst)


def same_modes_as_search(motion: Motion, starts: int = 48, seed: int = 0) -> bool:
    """Check 4 of the module docstring: the generic solver's first root search (its starts
    and seed, at its anchor samples) on ``motion``'s loop finds every root on one of
    ``motion``'s modes (signature within the search's radius of the root, or SAME_ROOT) and
    each mode at some anchor."""
    linkage, X = motion.linkage, motion.inputs
    lay = layout(linkage)
    samples, asm = root_search(linkage, X, anchor_samples(linkage, X), starts, seed)
    modes = np.stack([_signature_at(linkage, lay, md.conf, samples) for md in motion.modes])
    seen = np.zeros(len(motion.modes), dtype=bool)
    for r in range(samples.size):
        found = np.nonzero(asm.found[r])[0]
        if found.size == 0:
            continue
        sig, radius = asm.signature[r][found], asm.radius[r][found]
        d = np.max(np.abs(sig[:, None, :] - modes[None, :, r, :]), axis=-1)  # (roots, modes)
        near = d < np.maximum(radius, SAME_ROOT)[:, None]
        if not near.any(axis=1).all():
            return False  # a root on no mode: a mode born with the change
        seen |= near.any(axis=0)
    return bool(seen.all())


def _signature_at(linkage: Linkage, lay: Layout, conf: Configuration,
                  samples: NDArray[np.intp]) -> Array:
    return signature(linkage, conf.take(samples), lay)


__all__ = ["closed_as", "same_modes_as_search", "warm_motion"]

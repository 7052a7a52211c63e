"""Branches found twice, or in pieces, made one (the generic loop solver's last step,
kinematics/tracker/generic_motion.py): tracks that are the same configuration wherever both
hold are merged, a turning point found alone at a dead centre joins the branches that meet
there, a lone end is attached to its branch, a singular closure beside a bifurcation is
dropped, and the branches are put in a fixed order (docs/kinematics.md, "The generic loop
solver")."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import Array, Configuration, Layout, forward
from screwkit.kinematics.tracker.rates import rate_equations
from screwkit.kinematics.tracker.solve import signature
from screwkit.kinematics.tracker.tracks import Track
from screwkit.model.linkage import Linkage

#: how far (signature units) two overlapping tracks may move between the samples where they
#: are compared first (:func:`same_samples`)
MERGE_MOVE = 0.25
SAME_ROOT = 1e-6  # signature distance (length-scale units) of two copies of one configuration


def track_signatures(linkage: Linkage, lay: Layout, tr: Track, samples: NDArray[np.intp]) -> Array:
    conf = Configuration(tr.scalars[samples], tr.spherical[samples])
    return signature(linkage, conf, lay)


def pair_ends(linkage: Linkage, lay: Layout, tracks: list[Track]) -> None:
    """Where two branches are born (or die) at the same sample next to a fold, their two
    roots there are close and the searches may hand each branch the other's: swap them when
    that makes both continuous with the neighbouring sample (the closed forms' pairing). Each
    mode then starts on its own branch, so the rates and the idle spin carried along it start
    right."""
    for step in (1, -1):  # births continue to k + 1, deaths come from k − 1
        for a_i, a in enumerate(tracks):
            for b in tracks[a_i + 1:]:
                both = a.mask & b.mask
                held = np.pad(a.mask | b.mask, 1)  # False beyond the sweep
                nxt = np.roll(np.pad(both, 1), -step)[1:-1]
                prev = np.roll(held, step)[1:-1]
                for kk in np.nonzero(both & nxt & ~prev)[0].tolist():
                    k, n = int(kk), int(kk) + step
                    sa, sb = track_signatures(linkage, lay, a, np.array([k, n]))
                    ta, tb = track_signatures(linkage, lay, b, np.array([k, n]))
                    kept = np.linalg.norm(sa - sb) + np.linalg.norm(ta - tb)
                    swapped = np.linalg.norm(sa - tb) + np.linalg.norm(ta - sb)
                    if swapped < kept:
                        held_a = (a.scalars[k].copy(), a.spherical[k].copy())
                        a.set_sample(k, b.scalars[k], b.spherical[k])
                        b.set_sample(k, *held_a)


def merge_duplicates(linkage: Linkage, lay: Layout, tracks: list[Track]) -> list[Track]:
    """Tracks that are the same configuration wherever both hold are one branch; a track that
    shares another's configuration at some samples only has jumped onto it there (near a fold
    both branches are close) and loses those samples. (Two branches that cross share one
    singular configuration; that sample is kept by both.)"""
    out: list[Track] = []
    for tr in tracks:
        for kept in out:
            both = np.nonzero(kept.mask & tr.mask)[0]
            if both.size == 0:
                continue
            same = same_samples(linkage, lay, kept, tr, both)
            if same.all():
                extra = tr.mask & ~kept.mask
                kept.scalars[extra] = tr.scalars[extra]
                kept.spherical[extra] = tr.spherical[extra]
                kept.mask |= tr.mask
                if kept.rates is not None and tr.rates is not None:
                    for name in ("qd", "qdd", "singular", "known"):
                        getattr(kept.rates, name)[extra] = getattr(tr.rates, name)[extra]
                break
            if same.sum() > 1:
                tr.mask[both[same]] = False
        else:
            if tr.mask.any():
                out.append(tr)
    return out


def same_samples(linkage: Linkage, lay: Layout, a: Track, b: Track,
                  both: NDArray[np.intp]) -> NDArray[np.bool_]:
    """Which of the samples ``both`` (held by tracks ``a`` and ``b``) are the same
    configuration in the two (signature distance below 1e-5). The signatures are compared first
    at samples chosen so that between two of them the two tracks' signatures together move at
    most :data:`MERGE_MOVE` (:func:`signature_moves`, a bound from their joint variables'
    steps; both sides of a gap are chosen too); in between, the tracks can meet only where the
    distance at either end is not more than that move — and only there is every sample
    compared."""
    n = both.size
    steps = signature_moves(linkage, lay, a, both) + signature_moves(linkage, lay, b, both)
    gap = ~np.isfinite(steps)
    moved = np.concatenate([[0.0], np.cumsum(np.where(gap, 0.0, steps))])
    bucket = np.floor(moved / MERGE_MOVE)
    chosen = np.zeros(n, dtype=bool)
    chosen[[0, -1]] = True
    chosen[1:] |= bucket[1:] != bucket[:-1]
    chosen[:-1] |= bucket[1:] != bucket[:-1]
    chosen[:-1] |= gap
    chosen[1:] |= gap
    pick = np.nonzero(chosen)[0]
    sa, sb = track_signatures(linkage, lay, a, both[pick]), track_signatures(linkage, lay, b, both[pick])
    d = np.max(np.abs(sa - sb), axis=1)
    same = np.zeros(n, dtype=bool)
    same[pick] = d < 1e-5
    if pick.size == n:
        return same
    span = moved[pick[1:]] - moved[pick[:-1]]
    contiguous = ~np.array([gap[i:j].any() for i, j in zip(pick[:-1], pick[1:], strict=True)]) \
        if gap.any() else np.ones(pick.size - 1, dtype=bool)
    apart = contiguous & (np.maximum(d[:-1], d[1:]) > span + 1e-5)
    look = np.zeros(n, dtype=bool)
    for j in np.nonzero(~apart)[0]:
        look[pick[j] + 1:pick[j + 1]] = True
    if look.any():
        idx = both[look]
        same[look] = np.max(np.abs(track_signatures(linkage, lay, a, idx)
                                   - track_signatures(linkage, lay, b, idx)), axis=1) < 1e-5
    return same


def signature_moves(linkage: Linkage, lay: Layout, tr: Track,
                     samples: NDArray[np.intp]) -> Array:
    """An upper bound (n − 1,) of how far the track's signature (max norm) moves between
    consecutive ``samples``: every freedom's step times how far it can move a joint centre or
    axis — a turn by δ moves a point at most δ times its distance from the axis, which is at most
    the loop's whole length (links, offsets, and the largest slide of every P, C and H joint
    over the samples; divided by the length scale), and an axis by δ; a slide moves points by
    its length. A ball joint's turn is bounded by
    the difference of its rotation matrices' first two columns: |ΔR e₀|² + |ΔR e₁|² =
    4 sin²(θ/2)(2 − n₀² − n₁²) ≥ 4 sin²(θ/2) for a turn θ about n, so θ ≤ (π/2)·√(that)."""
    L = linkage.length_scale
    lo, hi = int(samples[0]), int(samples[-1]) + 1  # steps between neighbours, by slices
    q = tr.scalars[lo:hi]
    held = q[samples - lo]  # the slides' extent over the samples held (not the NaN between)
    # every length along the chain: links, offsets, and the largest slide of each P, C and H
    # joint over these samples (a point's distance from an earlier axis includes them)
    reach = sum(float(np.linalg.norm(t)) for t in lay.link_translations)
    for i, joint in enumerate(linkage.joints):
        if joint.kind == "H":  # its slide is offset + pitch θ, and a turn also moves by pitch
            c = lay.scalar_col[lay.joint_of.index(i)]
            reach += float(np.max(np.abs(joint.offset + joint.pitch * held[:, c]))) \
                + abs(joint.pitch)
        elif joint.kind != "P":  # a P joint's offset is an angle
            reach += abs(joint.offset)
    for f, c in enumerate(lay.scalar_col):
        if lay.is_translation[f]:
            reach += float(np.max(np.abs(held[:, c])))
    lever = max(1.0, reach / L)
    dq = np.abs(q[1:] - q[:-1])
    turn = ~np.array([lay.is_translation[f] for f in range(len(lay.names))
                      if lay.scalar_col[f] >= 0], dtype=bool)
    dq[:, turn] = np.abs(np.pi - np.mod(np.pi - dq[:, turn], 2 * np.pi))
    dq[:, ~turn] /= L
    steps = dq.sum(axis=1)
    if lay.n_spherical:
        cols = tr.spherical[lo:hi, :, :, :2]
        d = cols[1:] - cols[:-1]
        steps += 0.5 * np.pi * np.sqrt(np.einsum("nsij,nsij->ns", d, d)).sum(axis=1)
    # between samples that are not neighbours (a gap) the bound is not known: infinite
    out = np.full(len(samples) - 1, np.inf)
    near = np.diff(samples) == 1
    out[near] = steps[samples[:-1][near] - lo]
    return np.asarray(lever * out)


def attach_turning_points(linkage: Linkage, lay: Layout, tracks: list[Track]) -> list[Track]:
    """A one-sample track at a singular configuration next to where other branches end is
    the turning point where they meet (a sample exactly at a dead centre, found by the root
    search there): it becomes the last sample of each of those branches, as the closed forms
    report it."""
    out = []
    for tr in tracks:
        held = np.nonzero(tr.mask)[0]
        if held.size != 1:
            out.append(tr)
            continue
        s = int(held[0])
        ends = [o for o in tracks if o is not tr and not o.mask[s] and (
            (s > 0 and o.mask[s - 1]) or (s + 1 < len(o.mask) and o.mask[s + 1]))]
        conf = Configuration(tr.scalars[held], tr.spherical[held])
        singular = rate_equations(linkage, lay, forward(linkage, conf, lay)).rank_deficient[0]
        if not ends or not singular:
            out.append(tr)
            continue
        for o in ends:
            o.set_sample(s, tr.scalars[s], tr.spherical[s])
    return out


def without_singular_shadows(linkage: Linkage, lay: Layout, tracks: list[Track]
                              ) -> list[Track]:
    """Without one-sample tracks that are singular at a sample where another track is singular
    too: at a bifurcation that falls on a sample the passive equations lose rank, and the
    homotopy's singular end points there may include closures far out along the lost
    direction (an RCCC's slides at hundreds of link lengths, where the dual part of its
    input-output equation degenerates with the real part's double root). Such a point is
    followed nowhere, so it is no assembly mode; the branches that meet there keep the sample."""
    lone = [tr for tr in tracks if int(tr.mask.sum()) == 1]
    if not lone:
        return tracks

    def singular_at(tr: Track, s: int) -> bool:
        conf = Configuration(tr.scalars[[s]], tr.spherical[[s]])
        return bool(rate_equations(linkage, lay, forward(linkage, conf, lay)).rank_deficient[0])

    drop = set()
    for tr in lone:
        s = int(np.argmax(tr.mask))
        if singular_at(tr, s) and any(o is not tr and o.mask[s] and o.mask.sum() > 1
                                      and singular_at(o, s) for o in tracks):
            drop.add(id(tr))
    return [tr for tr in tracks if id(tr) not in drop]


def attach_lone_ends(linkage: Linkage, lay: Layout, tracks: list[Track]) -> list[Track]:
    """One-sample tracks at a sample s next to where as many branches start (or stop)
    assembling, at s + 1 (or s − 1), are those branches' first (or last) samples: next to a
    fold the continuation may stop a sample short of where the branches still assemble, and
    the root search then finds that sample's roots alone. Each root goes to one branch,
    paired by continuity (the least total distance to the branches' neighbouring
    configurations, as :func:`pair_ends`), and only within ten times the branch's own
    step there. Attached, a branch's run — and an S–S rod's pose carried along it from the run's
    first sample — is the closed forms'."""
    from itertools import permutations

    lone = [tr for tr in tracks if int(tr.mask.sum()) == 1]
    if not lone:
        return tracks
    N = len(tracks[0].mask)
    attached: list[Track] = []
    for s in sorted({int(np.argmax(tr.mask)) for tr in lone}):
        roots = [tr for tr in lone if tr.mask[s] and not any(tr is a for a in attached)]
        for n in (s + 1, s - 1):
            far = n + (n - s)
            if not roots or not 0 <= far < N:
                continue
            ends = [o for o in tracks if int(o.mask.sum()) > 1 and o.mask[n] and o.mask[far]
                    and not o.mask[s]]
            if len(ends) != len(roots) or len(roots) > 4:
                continue
            mine = np.stack([track_signatures(linkage, lay, tr, np.array([s]))[0] for tr in roots])
            near = np.stack([track_signatures(linkage, lay, o, np.array([n, far])) for o in ends])
            gap = np.linalg.norm(mine[:, None, :] - near[None, :, 0, :], axis=-1)
            step = np.linalg.norm(near[:, 0] - near[:, 1], axis=-1)
            best = min(permutations(range(len(ends))),
                       key=lambda perm: sum(gap[i, j] for i, j in enumerate(perm)))
            if not all(gap[i, j] <= 10.0 * step[j] + SAME_ROOT for i, j in enumerate(best)):
                continue
            for i, j in enumerate(best):
                o, tr = ends[j], roots[i]
                o.set_sample(s, tr.scalars[s], tr.spherical[s])
                attached.append(tr)
            roots = []
    return [tr for tr in tracks if not any(tr is a for a in attached)]


def order_key(linkage: Linkage, lay: Layout, tr: Track) -> tuple[float, ...]:
    """A documented, deterministic mode order: by the first sample where the mode assembles,
    then by its configuration there (joint centres and axes), not by the random starts."""
    first = int(np.argmax(tr.mask))
    sig = track_signatures(linkage, lay, tr, np.array([first]))[0]
    return (float(first), *np.round(sig, 9).tolist())

"""Every mode of a mechanism whose decomposition holds a family loop as a sub-chain stage
(graph/subchains.py's :class:`LoopStage`; issue 27, "closed-form sub-chains first").

A loop stage is solved once over the rows (the straight approach from the drawing, then the
inputs) by its family's closed form (graph/loop_subchain.py reads the family off the drawing:
Bagci 1969 eqs. 3.59–3.82 for the RSRC and its 4R case, A cos φ + B sin φ = C for the RSSR and
the RCCC, Rahman 1996 §1.2's quadratic for the CSSP), every loop mode at once. Each loop mode
gives the loop bodies' poses relative to the body the loop hangs on, T_rel = T_link ·
T_link(drawing)⁻¹ (every body frame is the world frame in the drawing), and their world poses
are the parent's pose times T_rel. The dyads and legs after it are placed on each loop mode by
their closed forms (graph/dyads.py, graph/legs.py), so a mode of the mechanism is one loop mode
× one branch of each dyad and leg; the drawn mode is the combination whose loop mode draws the
drawing and whose dyad branches are the drawing's, followed from the drawing until it first
stops assembling (its later runs, where it assembles again, are a mode of their own, as in
graph/closed_modes.py).

A mode is born or dies between two samples where one of its stages folds: the loop (for the
RSRC quartic where its loop mode's own root stops assembling, graph/quartic_folds.py, the loop
mode that meets it named; else where its count of real closed-form solutions changes,
graph/loop_motion.py's ``real_count``) or a dyad or leg (its discriminant crosses zero). Either is located by bisection of the input segment between
the samples; for a dyad's fold the loop is carried along the segment on its branch (at each
bisection point, the loop mode nearest the one at the bisection's last point). Two folds of
a loop of the RSRC quartic inside one step (a gap, an island) are found by the single loop's
search and cut its modes there (graph/stage_steps.py). Rates and accelerations come from the
stacked closure Jacobian (graph/motion.py's ``build_mode``).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.graph.dyads import Placement, driven_pose, dyad_poses
from screwkit.kinematics.graph.loop_motion import (
    FOLD_STEPS,
    approach,
    configuration_from_poses,
    real_count,
)
from screwkit.kinematics.graph.loop_subchain import is_drawing
from screwkit.kinematics.graph.subchains import Decomposition, Driven, Dyad, LoopStage
from screwkit.kinematics.motion import AssemblyError
from screwkit.model.mechanism import GROUND, Mechanism

if TYPE_CHECKING:
    from screwkit.kinematics.graph.motion import MechanismMotion

Array = NDArray[np.float64]
Pose = tuple[Array, Array]
#: one loop stage's bodies relative to its parent at K rows: R (K, n, 3, 3), p (K, n, 3), and
#: where the loop mode assembles (K,)
Relative = tuple[Array, Array, NDArray[np.bool_]]
#: points per round of the fold search (graph/loop_stage.py's ``_bisect``): 2⁵ sections, so
#: a round gains five bits of the fold's place
SECTIONS = 32
#: a mode's end found within this fraction of the segment from a loop's fold bounding it is
#: that fold
BOUND_GAP = 1e-6

LOOP_STAGE_SOLVER = ("closed-form sub-chains (driven joints, family loops with every loop mode, "
                     "planar dyads, spatial legs; every branch), rates and accelerations from "
                     "the stacked loop closure")


@dataclass(frozen=True)
class StageModes:
    """Every mode of one loop stage over K rows: ``R`` (M, K, n, 3, 3) and ``p`` (M, K, n, 3)
    the loop bodies' poses relative to the parent (``stage.loop_bodies`` order; NaN where the
    mode does not assemble), ``ok`` (M, K), the drawn mode's link frames at the drawing
    (``R0``, ``p0``) and its index ``drawn`` (in the closed form's mode order)."""

    R: Array
    p: Array
    ok: NDArray[np.bool_]
    R0: Array
    p0: Array
    drawn: int


def _column(lay: GraphLayout, stage: LoopStage) -> int:
    """The graph input column of the loop's driven joint."""
    return lay.inputs.index(lay.first_freedom[stage.joints[0]])


def _solve(stage: LoopStage, x: Array) -> tuple[object, ...]:
    """The loop's closed-form modes at the driven joint's values ``x`` (K,) and the drawing
    appended (one row more: at least one row assembles)."""
    from screwkit.kinematics.registry import family_of

    lk = stage.chain.linkage
    closed = family_of(lk).closed_form_for(lk)
    assert closed is not None  # loop_chain keeps families with a closed form only
    L = stage.chain.loop_inputs(np.append(x, 0.0)[:, None])
    return tuple(closed(lk, L, np.zeros_like(L), np.zeros_like(L)).modes)


def _relative(modes: tuple[object, ...], R0: Array, p0: Array) -> Relative:
    """Every mode's loop bodies relative to the parent (the appended drawing row dropped):
    (M, K, n, 3, 3), (M, K, n, 3), (M, K)."""
    ok = np.array([md.assembles[:-1] for md in modes])  # type: ignore[attr-defined]
    LR = np.array([md.link_rotation[:-1] for md in modes])  # type: ignore[attr-defined]
    Lp = np.array([md.link_origin[:-1] for md in modes])  # type: ignore[attr-defined]
    R = LR @ np.swapaxes(R0, -1, -2)
    p = Lp - np.einsum("mknij,nj->mkni", R, p0)
    R[~ok], p[~ok] = np.nan, np.nan
    return R, p, ok


def stage_modes(mech: Mechanism, lay: GraphLayout, stage: LoopStage, rows: Array
                ) -> StageModes:
    """Every mode of ``stage`` over the graph input ``rows`` (K, n_in), the first the drawing."""
    modes = _solve(stage, rows[:, _column(lay, stage)])
    drawn = next((m for m, md in enumerate(modes) if is_drawing(stage.sub, stage.chain, md)),
                 None)
    if drawn is None:  # loop_chain checked that the closed form draws the drawing
        raise AssemblyError(f"{mech.name}: no mode of the {stage.describe(mech)} passes "
                            "through the drawing")
    R0 = modes[drawn].link_rotation[0]  # type: ignore[attr-defined]
    p0 = modes[drawn].link_origin[0]  # type: ignore[attr-defined]
    R, p, ok = _relative(modes, R0, p0)
    return StageModes(R, p, ok, R0, p0, drawn)


def carried(mech: Mechanism, lay: GraphLayout, stage: LoopStage, sm: StageModes, X: Array,
            ref: Relative) -> Relative:
    """The loop at input rows ``X`` (T, n_in) on the branch of ``ref`` (its relative poses at
    nearby inputs, T rows): of the loop's modes there, the nearest to ``ref`` (rotation
    entries and positions over the length scale)."""
    R, p, ok = _relative(_solve(stage, X[:, _column(lay, stage)]), sm.R0, sm.p0)
    L = mech.length_scale
    gap = np.maximum(np.abs(R - ref[0]).max(axis=(2, 3, 4)), np.abs(p - ref[1]).max(axis=(2, 3)) / L)
    gap = np.where(ok, gap, np.inf)
    best = np.argmin(gap, axis=0)
    t = np.arange(X.shape[0])
    return R[best, t], p[best, t], ok[best, t]


def place_rows(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array, signs: Array,
               loops: list[Relative]) -> Placement:
    """Every body's pose at input rows ``X`` (K, n_in): the stages' branches ``signs`` (K, S)
    (a dyad's ±1; a loop's column unused here), each loop stage's relative poses ``loops``
    (in placing order); the discriminant of a loop stage is 1 where it assembles (NaN where
    not), a dyad's its own (graph/dyads.py)."""
    K = X.shape[0]
    poses: dict[str, Pose] = {GROUND: (np.broadcast_to(np.eye(3), (K, 3, 3)), np.zeros((K, 3)))}
    disc = np.empty((K, len(dec.stages)))
    d = li = 0
    for step in dec.steps:
        if isinstance(step, Driven):
            poses[step.body] = driven_pose(mech, lay, step, X, poses[step.parent])
            continue
        if isinstance(step, LoopStage):
            Rr, pr, ok = loops[li]
            Rp, pp = poses[step.parent]
            for i, body in enumerate(step.loop_bodies):
                if body in step.bodies:
                    poses[body] = (Rp @ Rr[:, i], np.einsum("kij,kj->ki", Rp, pr[:, i]) + pp)
            disc[:, d] = np.where(ok, 1.0, np.nan)
            li += 1
        else:
            b1, b2, disc[:, d] = dyad_poses(mech, step, signs[:, d], poses[step.placed[0]],
                                            poses[step.placed[1]])
            poses[step.bodies[0]], poses[step.bodies[1]] = b1, b2
        d += 1
    B = len(mech.bodies) + 1
    R = np.empty((K, B, 3, 3))
    p = np.empty((K, B, 3))
    for name, (Rb, pb) in poses.items():
        R[:, lay.body_of[name]], p[:, lay.body_of[name]] = Rb, pb
    return Placement(R, p, disc)


def combinations(dec: Decomposition, loops: list[StageModes]) -> Array:
    """Every combination of stage branches (M, S): a loop's mode index (the drawn one first,
    then those that assemble somewhere), a dyad's ±1 (the drawing's first); row 0 the
    drawing's."""
    choices: list[list[float]] = []
    li = 0
    for st in dec.stages:
        if isinstance(st, LoopStage):
            sm = loops[li]
            li += 1
            choices.append([float(sm.drawn)] + [float(m) for m in range(sm.ok.shape[0])
                                                if m != sm.drawn and sm.ok[m].any()])
        else:
            choices.append([float(st.drawn_branch), -float(st.drawn_branch)][:st.branches])
    return np.array(list(itertools.product(*choices)), dtype=float).reshape(-1, len(choices))


def loop_rows(dec: Decomposition, loops: list[StageModes], combos: Array, k: NDArray[np.intp]
               ) -> list[Relative]:
    """Each loop stage's relative poses for combination rows ``combos`` (T, S) at row
    indices ``k`` (T,) of the solved rows."""
    out = []
    cols = [d for d, st in enumerate(dec.stages) if isinstance(st, LoopStage)]
    for sm, d in zip(loops, cols, strict=True):
        m = combos[:, d].astype(int)
        out.append((sm.R[m, k], sm.p[m, k], sm.ok[m, k]))
    return out


def stage_names(mech: Mechanism, st: Dyad | LoopStage) -> str:
    return "–".join(mech.joints[k].name for k in st.joints)


def combination_label(mech: Mechanism, dec: Decomposition, loops: list[StageModes],
                      signs: Array) -> str:
    """Each stage's branch: a loop's mode (its closed form's index; "drawn" for the drawing's),
    a two-branch dyad's sign (+: the drawing's)."""
    parts, li = [], 0
    for st, s in zip(dec.stages, signs, strict=True):
        if isinstance(st, LoopStage):
            drawn = loops[li].drawn
            li += 1
            parts.append(f"{st.kind} loop {stage_names(mech, st)} mode {int(s)}"
                         + (" (drawn)" if int(s) == drawn else ""))
        elif st.branches == 2:
            parts.append(f"{stage_names(mech, st)} {'+' if s == st.drawn_branch else '−'}")
    return ", ".join(parts)


def _bisect(T: int, assembles: Callable[[Array], NDArray[Any]],
            moved: Callable[[NDArray[np.intp]], None] | None = None) -> tuple[Array, Array]:
    """The parameters t in [0, 1] (T,) where ``assembles`` first leaves its value at t = 0:
    each round evaluates SECTIONS − 1 points of every interval at once (``assembles`` takes
    t (T, n) and gives (T, n)) and keeps the section where the value first changes, until the
    interval is 2⁻FOLD_STEPS long (a closed-form call per round, not per halving): its middle
    and its end (1 where nothing changed);
    ``moved(j)`` is told the column j of the points the interval's start moved to (−1: it
    did not move)."""
    lo, hi = np.zeros(T), np.ones(T)
    at_lo = assembles(lo[:, None])[:, 0]
    r = np.arange(T)
    frac = np.arange(1, SECTIONS) / SECTIONS
    for _ in range(int(np.ceil(FOLD_STEPS / np.log2(SECTIONS)))):
        ts = lo[:, None] + (hi - lo)[:, None] * frac
        changed = assembles(ts) != at_lo[:, None]
        first = np.where(changed.any(axis=1), np.argmax(changed, axis=1), SECTIONS - 1)
        j = first - 1  # the last point before the change (−1: the interval's start)
        if moved is not None:
            moved(j)
        hi = np.where(first < SECTIONS - 1, ts[r, np.minimum(first, SECTIONS - 2)], hi)
        lo = np.where(j >= 0, ts[r, np.maximum(j, 0)], lo)
    return 0.5 * (lo + hi), hi


def fold_events(mech: Mechanism, lay: GraphLayout, dec: Decomposition, loops: list[StageModes],
                X: Array, a: int, combos: Array, held: NDArray[np.bool_], disc: Array
                ) -> tuple[list[list[str]], list[tuple[int, int, int, int]]]:
    """Each mode's births and deaths (modes: rows of ``combos`` (M', S), held at ``held``
    (M', N); ``disc`` (M', a + N, S) their stages' discriminants over the solved rows, the
    approach's ``a`` first), each located between its two samples, and every fold as (mode,
    folding stage, sample k before it, the loop mode meeting it or −1). Where a loop stage does
    not assemble at the far sample, its fold bounds the search: for a loop of the RSRC quartic
    where its own mode's root stops assembling (:func:`_own_folds`: two pairs of its modes may
    fold inside one step), else where its count of real solutions changes; the mode's
    own end is then the first place, from the sample where it assembles, where any of its
    stages stops assembling (a leg on a loop mode just born may assemble only later)."""
    from screwkit.kinematics.graph.motion import input_text

    i, k = np.nonzero(held[:, :-1] != held[:, 1:])
    events: list[list[str]] = [[] for _ in range(held.shape[0])]
    if k.size == 0:
        return events, []
    ka = np.where(held[i, k], k, k + 1)  # the sample of the two where it assembles
    kb = 2 * k + 1 - ka
    folding = np.argmax(~(disc[i, a + kb] >= 0.0), axis=1)  # the first stage that fails
    stages = dec.stages
    xa, xb = X[ka], X[kb].copy()
    partner = np.full(k.size, -1)
    for d, st in enumerate(stages):
        sel = np.flatnonzero(folding == d)
        if sel.size == 0 or not isinstance(st, LoopStage):
            continue
        col = _column(lay, st)
        s0, s1 = xa[sel, col], xb[sel, col]

        def count(ts: Array, st: LoopStage = st, s0: Array = s0, s1: Array = s1
                  ) -> NDArray[np.intp]:
            x = (s0[:, None] + ts * (s1 - s0)[:, None]).reshape(-1, 1)
            return real_count(st.chain, st.chain.loop_inputs(x)).reshape(ts.shape)

        own = _own_folds(lay, st, X, a, combos[i[sel], d], k[sel], ka[sel] == k[sel])
        t = np.full(sel.size, np.nan) if own is None else own[0]
        if np.isnan(t).any():  # where no loop mode's own fold is found: the count's
            t = np.where(np.isnan(t), _bisect(sel.size, count)[0], t)
        if own is not None:
            partner[sel] = own[1]
        xb[sel] = xa[sel] + t[:, None] * (xb[sel] - xa[sel])
    t, failing = _first_failure(mech, lay, dec, loops, xa, xb, combos[i], a + ka)
    named = np.where(failing >= 0, failing, folding)
    partner = np.where(named == folding, partner, -1)
    at = xa + t[:, None] * (xb - xa)
    for m, kk, x, d, p in zip(i, k, at, named, partner, strict=True):
        st = stages[int(d)]
        what = "dies" if held[m, kk] else "is born"
        how = ("its two branches meet" if not isinstance(st, LoopStage) else
               "two of its assembly modes meet" if p < 0 else
               f"its modes {min(p, int(combos[m, d]))} and {max(p, int(combos[m, d]))} meet")
        events[int(m)].append(f"{what} at {input_text(mech, lay, x)}: the {st.kind} {st.word} "
                              f"{stage_names(mech, st)} folds ({how})")
    return events, [(int(m), int(d), int(kk), int(p))
                    for m, d, kk, p in zip(i, named, k, partner, strict=True)]


def _own_folds(lay: GraphLayout, st: LoopStage, X: Array, a: int, modes: Array,
               ks: NDArray[np.intp], dies: NDArray[np.bool_]
               ) -> tuple[Array, NDArray[np.intp]] | None:
    """For a loop of the RSRC quartic (None for any other), where each of its ``modes`` (T,)
    stops assembling between samples ``ks`` and ``ks`` + 1, from the sample where it assembles
    (that at ``ks`` where it ``dies``), as the fraction of the step from there, and the loop
    mode that meets it (−1: none on a sample; NaN and −1 where the loop mode's root does not
    change there, none expected): its own root followed (graph/quartic_folds.py),
    over the rows the stage was solved on (:func:`stage_modes`: the approach, ``X``, the
    drawing)."""
    from screwkit.kinematics.graph.quartic_folds import quartic_folds
    from screwkit.kinematics.registry import has_rsrc_quartic

    if not has_rsrc_quartic(st.chain.linkage):
        return None
    x = np.append(np.vstack([approach(lay, X), X])[:, _column(lay, st)], 0.0)
    found = {(f.mode, f.k, f.dies): f for f in
             quartic_folds(st.chain, st.chain.loop_inputs(x[:, None]))}
    folds = [found.get((int(m), a + int(kk), bool(dd))) for m, kk, dd in
             zip(modes, ks, dies, strict=True)]
    t = np.array([np.nan if f is None else f.t if f.dies else 1.0 - f.t for f in folds])
    return t, np.array([-1 if f is None or f.partner is None else f.partner for f in folds])


def _first_failure(mech: Mechanism, lay: GraphLayout, dec: Decomposition,
                   loops: list[StageModes], xa: Array, xb: Array, combos: Array,
                   k: NDArray[np.intp]) -> tuple[Array, NDArray[np.intp]]:
    """Where each mode (``combos`` (T, S)), assembling at ``xa`` (T, n_in; the solved row
    ``k``), first stops assembling on the segment xa → xb, as the fraction t along it (T,),
    and the stage that fails just past it (−1: none fails before xb). The loops are carried
    on their branches from row k: at each round's points, the loop mode nearest the one at the
    interval's start."""
    ref = loop_rows(dec, loops, combos, k)
    T = k.size
    last: list[list[Relative]] = [ref]

    def placed(ts: Array) -> Placement:
        n = ts.shape[1]
        xm = (xa[:, None] + ts[:, :, None] * (xb - xa)[:, None]).reshape(T * n, -1)
        rel = [carried(mech, lay, st, sm, xm, (np.repeat(r[0], n, axis=0),
                                               np.repeat(r[1], n, axis=0),
                                               np.repeat(r[2], n, axis=0)))
               for st, sm, r in zip(dec.loops, loops, ref, strict=True)]
        last[0] = rel
        return place_rows(mech, lay, dec, xm, np.repeat(combos, n, axis=0), rel)

    def assembles(ts: Array) -> NDArray[np.bool_]:
        return placed(ts).assembles.reshape(ts.shape)

    def moved(j: NDArray[np.intp]) -> None:
        go = np.flatnonzero(j >= 0)
        n = len(last[0][0][2]) // T
        for li, new in enumerate(last[0]):
            R, p, ok = ref[li][0].copy(), ref[li][1].copy(), ref[li][2].copy()
            at = go * n + j[go]
            R[go], p[go], ok[go] = new[0][at], new[1][at], new[2][at]
            ref[li] = (R, p, ok)

    t, hi = _bisect(T, assembles, moved)
    past = placed(hi[:, None])
    fails = ~(past.discriminant >= 0.0)
    # a failure within BOUND_GAP of xb is xb's own (a loop's fold there: next to it the loop's
    # two meeting modes are too close to tell apart by pose)
    failing = np.where(fails.any(axis=1) & (hi < 1.0 - BOUND_GAP), np.argmax(fails, axis=1), -1)
    return t, failing


def _circuits(combos: Array, held: NDArray[np.bool_],
              joins: list[tuple[int, int, int, int]]) -> list[tuple[int, int]]:
    """Pairs of modes that meet at a fold: at a fold of stage d between samples k and k+1, a
    mode meets a mode whose branches differ in d alone and that is born or dies there (at a
    loop's fold whose partner mode is known, ≥ 0, the one on that loop mode)."""
    turns = held[:, :-1] != held[:, 1:]
    pairs = []
    for m, d, k, partner in joins:
        others = np.delete(np.arange(combos.shape[1]), d)
        match = np.flatnonzero(np.all(combos[:, others] == combos[m, others], axis=1)
                               & (combos[:, d] != combos[m, d]) & turns[:, k]
                               & ((combos[:, d] == partner) | (partner < 0)))
        if match.size:
            pairs.append((int(match[0]), m))
    return pairs


def loop_stage_motion(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array,
                      Xd: Array, Xdd: Array, every: bool) -> MechanismMotion:
    """The :class:`~screwkit.kinematics.graph.motion.MechanismMotion` of a mechanism whose
    decomposition holds family loops (module docstring): mode 0 the drawn mode, then with
    ``every`` every other combination of loop modes and dyad branches that assembles
    somewhere, and the drawn combination's later runs (a mode of their own)."""
    from screwkit.budget import ResourceLimitError
    from screwkit.kinematics.graph.closed_modes import drawn_with_events, mode_frames
    from screwkit.kinematics.graph.motion import (
        MechanismMotion,
        build_mode,
        check_cost,
        groups,
        input_text,
        with_events,
    )
    from screwkit.kinematics.graph.stage_steps import stage_pieces, stage_steps

    N = X.shape[0]
    A = approach(lay, X)
    a = A.shape[0]
    rows = np.vstack([A, X])
    K = a + N
    loops = [stage_modes(mech, lay, st, rows) for st in dec.loops]
    combos = combinations(dec, loops)
    skipped = ""
    if every:  # each combination costs a drawn mode's time: only the drawn one when too many
        try:
            check_cost(mech, N * combos.shape[0])
        except ResourceLimitError as err:
            every, skipped = False, (f"every mode: only the drawn mode is solved; the "
                                     f"{combos.shape[0]} branch combinations would be over a "
                                     f"limit ({err})")
    if not every:
        combos = combos[:1]
    M = combos.shape[0]
    signs = np.repeat(combos, K, axis=0)
    pl = place_rows(mech, lay, dec, np.tile(rows, (M, 1)), signs,
                    loop_rows(dec, loops, signs, np.tile(np.arange(K), M)))
    ok = pl.assembles.reshape(M, K)
    R = pl.R.reshape(M, K, *pl.R.shape[1:])
    p = pl.p.reshape(M, K, *pl.p.shape[1:])
    disc = pl.discriminant.reshape(M, K, -1)
    if not ok[0, :a + 1].all():
        raise AssemblyError(f"{mech.name}: the drawn configuration cannot be followed to the "
                            f"first input row {input_text(mech, lay, X[0])}: the mechanism stops "
                            "assembling before it")
    stop = int(np.argmin(ok[0, a:])) if not ok[0, a:].all() else N
    picked = [0] + [m for m in range(1, M) if ok[m, a:].any()]
    masks = [np.arange(N) < stop, *(ok[m, a:] for m in picked[1:])]
    again = ok[0, a:] & (np.arange(N) >= stop)  # the drawn combination after its first fold
    if every and again.any():
        picked.append(0)
        masks.append(again)
    held = np.array(masks)
    folds, joins = fold_events(mech, lay, dec, loops, X, a, combos[picked], held, disc[picked])
    # two folds of a loop mode inside one step cut its modes; islands on no sample
    # (graph/stage_steps.py), the drawn mode ending at its first
    steps = stage_steps(lay, dec, rows, a, N - 1 if every else stop - 1)
    cut = stage_pieces(mech, lay, dec, X, steps, combos[picked], held, folds, joins, every)
    drawn = cut.masks[0]
    stop = int(np.argmin(drawn)) if not drawn.all() else N
    conf = configuration_from_poses(mech, lay, R[0], p[0], rows,
                                    np.concatenate([np.ones(a, dtype=bool), drawn]), True)
    mode = build_mode(mech, lay, conf.take(slice(a, None)), drawn, X, Xd, Xdd,
                      mode_frames(mech, lay, R[0, a:], p[0, a:], drawn))
    modes = [drawn_with_events(mech, lay, mode, X, stop, cut.events[0])]
    for n, (r, ev) in enumerate(zip(cut.rows[1:], cut.events[1:], strict=True), start=1):
        m = picked[max(r, 0)]
        ok_n = cut.masks[n]
        conf = configuration_from_poses(mech, lay, R[m, a:], p[m, a:], X, ok_n, False)
        md = build_mode(mech, lay, conf, ok_n, X, Xd, Xdd,
                        mode_frames(mech, lay, R[m, a:], p[m, a:], ok_n))
        if r < 0:  # an island of a loop stage, on no sample
            label = cut.labels[n]
        else:
            label = f"branches {combination_label(mech, dec, loops, combos[m])}"
            if m == 0:
                label += (" (the drawn branches again, after the drawn mode's fold)" if r
                          else "")
            label += cut.labels[n]
        modes.append(replace(with_events(md, [*ev, *md.events]), label=label, index=len(modes)))
    notes: tuple[str, ...] = (skipped,) if skipped else ()
    if every:
        rows_p = np.array([max(r, 0) for r in cut.rows])
        joined = [(cut.piece(r, k if held[r, k] else k + 1), d, k, q) for r, d, k, q in joins]
        circuits = groups(len(modes), _circuits(combos[picked][rows_p], cut.masks, joined)
                          + cut.meets)
        notes = (f"{M} branch combination(s) of {len(dec.stages)} sub-chain(s) (loop modes × "
                 f"dyad and leg branches); {len(modes)} mode(s) assemble over these inputs",
                 "circuits (modes that meet at a fold, where the input must turn back to go "
                 "on): " + ", ".join("{" + ", ".join(map(str, c)) + "}" for c in circuits))
    return MechanismMotion(mech, X, Xd, Xdd, tuple(modes), method="graph (closed forms)",
                           solver=LOOP_STAGE_SOLVER, notes=notes)

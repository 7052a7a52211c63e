"""The motion of a single-loop mechanism from the loop engine (issue 26: one solving path; the
loop is recognised and its family read off the drawing in graph/loop_subchain.py).

:func:`loop_modes` solves the loop with :func:`~screwkit.kinematics.solve_motion.solve_motion`
on the inputs from the drawing (every input 0) along a straight approach to the first row and
then along the rows, and returns each loop mode as the graph's body poses (the link frames
times the drawn link frames' inverse: every body frame is the world frame in the drawing) and
joint variables, angles counted continuously from the drawing for the drawn mode (the mode whose
joint lines are the drawing's at the first sample); for the drawn mode alone, where the family
offers its closed form's branches, only the drawn branch's positions are built
(:func:`drawn_branch`: the same numbers). :func:`loop_motion` builds the rest of each
mode as for every graph (graph/motion.py's ``build_mode``: rates and accelerations from the
stacked screw Jacobian, points, outputs, singularities) and locates where modes are born and
die: at a fold of the loop, found between the samples around it where that mode's own root
stops assembling for a loop of the RSRC quartic (graph/quartic_folds.py: two pairs of its four
modes may fold inside one step; the mode that meets it is named), else by bisection where the
count of its real closed-form solutions changes by two (as graph/closed_modes.py's
``fold_inputs``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphFrames, GraphLayout, joint_screws
from screwkit.kinematics.graph.loop_subchain import APPROACH_STEP, LoopChain, is_drawing
from screwkit.kinematics.graph.step_folds import HiddenPair as HiddenPairT
from screwkit.kinematics.graph.step_folds import hidden_fold_text
from screwkit.kinematics.motion import AssemblyError, ModeMotion, Motion
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.kinematics.tracker.mode_frames import ModePoses
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

#: bisection steps locating a fold between two samples (2⁻⁵⁰ of their input step)
FOLD_STEPS = 50


@dataclass(frozen=True)
class LoopModes:
    """The loop's solution as graph modes: per loop mode (in ``solve_motion``'s order) the
    samples where it assembles (M, N), the graph configurations and body frames (None for a
    mode not asked for) and which mode is the drawn one (None: none passes through the
    drawing). With every mode asked for, the drawn loop mode's samples after the drawn mode's
    first fold, where it assembles again (an island entered twice), are one more entry, last:
    ``again`` its index (None when the drawn loop mode does not come back). ``motion`` is the
    loop's every-mode Motion (None when only the drawn mode was built, from the closed form's
    branches), ``method`` and ``solver`` its solver's."""

    motion: Motion | None
    assembles: NDArray[np.bool_]
    confs: tuple[Configuration | None, ...]
    frames: tuple[GraphFrames | None, ...]
    drawn: int | None
    method: str
    solver: str
    again: int | None = None


def approach(lay: GraphLayout, X: Array) -> Array:
    """Input rows from the drawing (every input 0) along the straight way to ``X[0]``, in
    steps of at most APPROACH_STEP (rad, or of the length scale), the drawing first and
    ``X[0]`` left out."""
    scale = np.array([lay.length if lay.is_translation[f] else 1.0 for f in lay.inputs])
    steps = max(1, int(np.ceil(float(np.max(np.abs(X[0]) / scale)) / APPROACH_STEP)))
    return np.linspace(0.0, 1.0, steps + 1)[:-1, None] * X[0][None, :]


def loop_modes(mech: Mechanism, lay: GraphLayout, chain: LoopChain, X: Array,
               every: bool = True) -> LoopModes:
    """Every loop mode over the approach (:func:`approach`) and ``X``, as graph configurations
    and body frames over the rows of ``X`` (module docstring): of the drawn mode alone unless
    ``every``, and then, where the family's closed form offers its branches, only the drawn
    one's positions are built (:func:`drawn_branch`); the loop's modes otherwise."""
    from screwkit.kinematics.solve_motion import solve_motion

    A = approach(lay, X)
    rows = np.vstack([A, X])
    a = A.shape[0]
    L = chain.loop_inputs(rows)
    found = None if every else drawn_branch(mech, chain, L)
    motion: Motion | None = None
    drawn: int | None
    if found is not None:
        drawn, assembles, poses, solver = found
        mds: list[ModeMotion | ModePoses | None] = [None] * len(assembles)
        mds[drawn] = poses
        method = "closed"
    else:
        motion = solve_motion(chain.linkage, L, progress=False)
        assembles = tuple(md.assembles for md in motion.modes)
        mds = list(motion.modes)
        method, solver = motion.method, motion.solver or motion.method
        drawn = next((m for m, md in enumerate(motion.modes) if is_drawing(mech, chain, md)),
                     None)
    if drawn is None:
        return LoopModes(motion, np.zeros((0, X.shape[0]), dtype=bool), (), (), None, method,
                         solver)
    drawn_md = mds[drawn]
    assert drawn_md is not None
    R0, p0 = drawn_md.link_rotation[0], drawn_md.link_origin[0]
    confs: list[Configuration | None] = []
    frames: list[GraphFrames | None] = []
    masks = []

    def add(md: object, ok: NDArray[np.bool_], from_drawing: bool) -> None:
        R, p = _body_poses(mech, chain, md, R0, p0, ok)
        conf = configuration_from_poses(mech, lay, R, p, rows, ok, from_drawing)
        confs.append(conf.take(slice(a, None)))
        R, p = R[a:], p[a:]
        screws, centres, axes = joint_screws(mech, lay, R, p)
        frames.append(GraphFrames(R, p, screws, np.zeros((R.shape[0], 1, 6)), centres, axes))

    later: NDArray[np.bool_] | None = None
    for m, md in enumerate(mds):
        ok = np.array(assembles[m])
        if m == drawn:  # followed from the drawing: it ends where it first stops assembling
            stop = int(np.argmin(ok)) if not ok.all() else ok.size
            later = ok & (np.arange(ok.size) >= stop)
            ok[stop:] = False
        masks.append(ok[a:])
        if m != drawn and not every:
            confs.append(None)
            frames.append(None)
            continue
        add(md, ok, m == drawn)
    again = None
    if every and later is not None and later[a:].any():
        again = len(masks)
        masks.append(later[a:])
        add(drawn_md, later, False)
    return LoopModes(motion, np.array(masks), tuple(confs), tuple(frames), drawn, method,
                     solver, again)


def drawn_branch(mech: Mechanism, chain: LoopChain, L: Array
                 ) -> tuple[int, tuple[NDArray[np.bool_], ...], ModePoses, str] | None:
    """The drawn mode from the closed form's branches alone (registry ``closed_branches``) at
    the loop inputs ``L``: its index in ``solve_motion``'s mode order, where each mode
    assembles, the drawn mode's positions (tracker/mode_frames.py's ``mode_poses``, the
    numbers ``solve_motion`` gives) and the solver's name. The first mode whose joint lines
    at the first sample are the drawing's (:func:`is_drawing`, as on the whole Motion), found
    from one sample per branch; None when the family has no branches, when no branch draws
    the drawing, or when the chosen branch over the whole sweep is not the drawing (then the
    caller solves every mode as before)."""
    from screwkit.kinematics.registry import family_of
    from screwkit.kinematics.tracker.loop import layout
    from screwkit.kinematics.tracker.mode_frames import mode_poses

    lk = chain.linkage
    branches_of = family_of(lk).closed_branches_for(lk)
    if branches_of is None:
        return None
    ones, zeros = np.ones_like(L), np.zeros_like(L)  # solve_motion's default rates
    br = branches_of(lk, L, ones, zeros)
    loop_lay = layout(lk)
    first = slice(0, 1)
    drawn = next((m for m, ok in enumerate(br.assembles) if ok[0] and is_drawing(
        mech, chain, mode_poses(lk, loop_lay, br.configuration(m, first), ok[first], L[first]))),
        None)
    if drawn is None:
        return None
    ok = br.assembles[drawn]
    poses = mode_poses(lk, loop_lay, br.configuration(drawn, slice(None)), ok, L)
    if not is_drawing(mech, chain, poses):
        return None
    return drawn, br.assembles, poses, br.solver


def _body_poses(mech: Mechanism, chain: LoopChain, md: object, R0: Array, p0: Array,
                ok: NDArray[np.bool_]) -> tuple[Array, Array]:
    """The graph's body poses (N, B+1, …; the ground last, the identity) from a loop mode's
    link frames: T_body = T_link · T_link(drawing)⁻¹."""
    N = ok.shape[0]
    B = len(mech.bodies) + 1
    R = np.broadcast_to(np.eye(3), (N, B, 3, 3)).copy()
    p = np.zeros((N, B, 3))
    LR = np.where(ok[:, None, None, None], md.link_rotation, np.eye(3))  # type: ignore[attr-defined]
    Lp = np.where(ok[:, None, None], md.link_origin, 0.0)  # type: ignore[attr-defined]
    for k, name in enumerate(chain.bodies[1:-1]):
        b = mech.body_index(name)
        R[:, b] = LR[:, k] @ R0[k].T
        p[:, b] = Lp[:, k] - np.einsum("nij,j->ni", R[:, b], p0[k])
    return R, p


def configuration_from_poses(mech: Mechanism, lay: GraphLayout, R: Array, p: Array, X: Array,
                             ok: NDArray[np.bool_], from_drawing: bool) -> Configuration:
    """Every joint variable from the body poses (the inverse of graph/closure.py's joint
    motions M_j(q) on T_a⁻¹T_b): a rotation angle about the axis (atan2 of its sine and
    cosine), a slide along it, an H joint's turns from its slide, a U joint's two angles, an S
    joint's rotation; angles counted continuously along each run where the mode assembles
    (from the drawing, every variable 0, for the drawn mode), the inputs as given."""
    from screwkit.kinematics.graph.closed_modes import assembling_runs

    N = R.shape[0]
    q = np.zeros((N, lay.n_scalar))
    balls = np.empty((N, lay.n_spherical, 3, 3))
    for i, j in enumerate(mech.joints):
        a, b = (lay.body_of[x] for x in j.bodies)
        Ra = R[:, a]
        Rr = np.swapaxes(Ra, -1, -2) @ R[:, b]
        pr = np.einsum("nji,nj->ni", Ra, p[:, b] - p[:, a])
        if j.kind == "S":
            balls[:, lay.spherical_of_joint[i]] = Rr
            continue
        col = lay.scalar_col[lay.first_freedom[i]]
        u = j.axis
        if j.kind == "P":
            q[:, col] = pr @ u
            continue
        if j.kind == "U":
            assert j.axis2 is not None
            v = j.axis2
            Rv = Rr @ v
            Ru = np.swapaxes(Rr, -1, -2) @ u
            q[:, col] = np.arctan2(np.cross(v, Rv) @ u, Rv @ v)
            q[:, col + 1] = -np.arctan2(np.cross(u, Ru) @ v, Ru @ u)
            continue
        vee = np.stack([Rr[:, 2, 1] - Rr[:, 1, 2], Rr[:, 0, 2] - Rr[:, 2, 0],
                        Rr[:, 1, 0] - Rr[:, 0, 1]], axis=1)
        th = np.arctan2(0.5 * (vee @ u), 0.5 * (np.trace(Rr, axis1=1, axis2=2) - 1.0))
        if j.kind == "H":  # the slide pitch·θ counts the turns
            th = th + 2 * np.pi * np.round((pr @ u / j.pitch - th) / (2 * np.pi))
        q[:, col] = th
        if j.kind == "C":
            q[:, col + 1] = pr @ u
    turning = [lay.scalar_col[f] for f in range(lay.m)
               if not lay.is_translation[f] and lay.scalar_col[f] >= 0]
    for s, e in assembling_runs(ok):
        run = q[s:e, turning]
        if s == 0 and from_drawing:
            q[s:e, turning] = np.unwrap(np.vstack([np.zeros(len(turning)), run]), axis=0)[1:]
        else:
            q[s:e, turning] = np.unwrap(run, axis=0)
    q[~ok] = 0.0
    balls[~ok] = np.eye(3)
    for k, f in enumerate(lay.inputs):
        q[:, lay.scalar_col[f]] = X[:, k]
    return Configuration(q, balls)


LOOP_SOLVER = "the loop engine on the mechanism's one loop (graph/loop_subchain.py): {solver}; " \
              "rates and accelerations from the stacked loop closure"


def loop_motion(mech: Mechanism, lay: GraphLayout, chain: LoopChain, X: Array, Xd: Array,
                Xdd: Array, every: bool) -> object | None:
    """The :class:`~screwkit.kinematics.graph.motion.MechanismMotion` of a single-loop
    mechanism from the loop engine (module docstring): mode 0 the drawn mode, followed from the
    drawing until it first stops assembling; with ``every`` then every other loop mode that
    assembles somewhere, in ``solve_motion``'s order, and the circuits they form (modes that
    meet at a fold). None where no loop mode passes through the drawing (then the caller
    follows the drawing itself)."""
    from screwkit.kinematics.graph.motion import (
        MechanismMode,
        MechanismMotion,
        build_mode,
        groups,
        input_text,
        with_events,
    )

    lm = loop_modes(mech, lay, chain, X, every)
    if lm.drawn is None:
        return None
    d = lm.drawn
    if not lm.assembles[d, 0]:
        raise AssemblyError(f"{mech.name}: the drawn configuration cannot be followed to the "
                            f"first input row {input_text(mech, lay, X[0])}: the mechanism stops "
                            "assembling before it")
    order = [d] + ([m for m in range(len(lm.confs)) if m != d and lm.assembles[m].any()]
                   if every else [])
    of_row = [d if m == lm.again else m for m in order]
    cut = step_pieces(mech, lay, X, lm.assembles[order], every, chain, of_row)
    masks = cut.masks
    order = [order[r] for r in cut.rows]
    # a fold of a piece dropped (the drawn mode's after its first fold, with the drawn mode
    # alone) is not reported
    folds = [(i, k, x, text) for r, k, x, text in _folds(mech, lay, chain, X, cut.source, of_row)
             if (i := cut.piece(r, k, bool(cut.source[r, k]))) is not None]
    # in input order: a fold between samples k and k+1 at k + ½, one inside a step at k + t
    at = [k + 0.5 for _, k, _, _ in folds] + [p for p, _ in cut.events]
    folds += [f for _, f in cut.events]
    modes: list[MechanismMode] = []
    for row, m in enumerate(order):
        ok = masks[row]
        conf = lm.confs[m]
        assert conf is not None
        md = build_mode(mech, lay, conf, ok, X, Xd, Xdd, lm.frames[m] if ok.any() else None)
        events = [folds[i][3] for i in np.argsort(at, kind="stable") if folds[i][0] == row]
        if row == 0:  # the drawn mode ends at its first fold
            events = events[:1]
            stop = int(np.argmin(ok)) if not ok.all() else ok.size
            if stop < ok.size:
                events.insert(0, f"stops assembling after input "
                                 f"{input_text(mech, lay, X[stop - 1])} (a limit position or "
                                 f"dead centre before {input_text(mech, lay, X[stop])})")
        label = ("drawn" if row == 0 else cut.island_name if row in cut.islands
                 else f"loop mode {d} (the drawn branches again, after the drawn mode's fold)"
                 if m == lm.again else f"loop mode {m}") + cut.labels[row]
        modes.append(replace(with_events(md, [*events, *md.events]), label=label,
                             index=len(modes)))
    motion = lm.motion
    notes: tuple[str, ...] = ()
    if every:
        assert motion is not None
        meet = [(r1, r2) for i, (r1, k1, x1, _) in enumerate(folds)
                for (r2, k2, x2, _) in folds[i + 1:]
                if r1 != r2 and k1 == k2 and np.allclose(x1, x2, rtol=0.0, atol=1e-9)]
        notes = (f"{len(motion.modes)} assembly mode(s) of the loop ({motion.method} solver); "
                 f"{len(modes)} assemble over these inputs; mode 0 is the drawn one (the loop's "
                 f"mode {d})",
                 "circuits (modes that meet at a fold, where the input must turn back to go "
                 "on): " + ", ".join("{" + ", ".join(map(str, c)) + "}"
                                     for c in groups(len(modes), meet)),
                 *motion.notes)
    return MechanismMotion(mech, X, Xd, Xdd, tuple(modes), method=f"graph (loop, {lm.method})",
                           solver=LOOP_SOLVER.format(solver=lm.solver), notes=notes)


def _folds(mech: Mechanism, lay: GraphLayout, chain: LoopChain, X: Array,
           masks: NDArray[np.bool_], modes: list[int]) -> list[tuple[int, int, Array, str]]:
    """Every birth and death of the modes ``masks`` (M, N; row r the loop's mode
    ``modes[r]``) between two samples, as (row, sample before it, input rows at the fold,
    event text): for a loop of the RSRC quartic, where that mode's own root stops assembling
    (graph/quartic_folds.py: two pairs of modes may fold inside one step), the mode that meets
    it there named; else located by bisection on the segment X[k] → X[k+1] (all at once)
    where the loop's count of real solutions (its closed form's assembling modes at one input)
    leaves its value at X[k]."""
    from screwkit.kinematics.graph.motion import input_text
    from screwkit.kinematics.registry import family_of, has_rsrc_quartic

    rows, ks = np.nonzero(masks[:, :-1] != masks[:, 1:])
    closed = family_of(chain.linkage).closed_form_for(chain.linkage)
    if rows.size == 0 or closed is None:
        return [(int(r), int(k), X[k + 1], f"{'dies' if masks[r, k] else 'is born'} between "
                 f"{input_text(mech, lay, X[k])} and {input_text(mech, lay, X[k + 1])}")
                for r, k in zip(rows, ks, strict=True)]
    out: list[tuple[int, int, Array, str]] = []
    if has_rsrc_quartic(chain.linkage):
        out = _quartic_folds(mech, lay, chain, X, masks, modes, rows, ks)
        done = {(r, k) for r, k, _, _ in out}  # the rest (none expected) by the count
        rest = np.array([(r, k) not in done for r, k in zip(rows, ks, strict=True)])
        rows, ks = rows[rest], ks[rest]
        if rows.size == 0:
            return out
    x0, x1 = X[ks], X[ks + 1]

    def count(t: Array) -> NDArray[np.intp]:
        """Real solutions at the inputs x0 + t (x1 − x0) (:func:`real_count`)."""
        return real_count(chain, chain.loop_inputs(x0 + t[:, None] * (x1 - x0)))

    lo, hi = np.zeros(ks.size), np.ones(ks.size)
    c_lo = count(lo)
    for _ in range(FOLD_STEPS):
        mid = 0.5 * (lo + hi)
        same = count(mid) == c_lo
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    at = x0 + (0.5 * (lo + hi))[:, None] * (x1 - x0)
    for r, k, x in zip(rows, ks, at, strict=True):
        what = "dies" if masks[r, k] else "is born"
        out.append((int(r), int(k), x, f"{what} at {input_text(mech, lay, x)}: the loop folds "
                                       "(two of its assembly modes meet)"))
    return out


def _quartic_folds(mech: Mechanism, lay: GraphLayout, chain: LoopChain, X: Array,
                   masks: NDArray[np.bool_], modes: list[int], rows: NDArray[np.intp],
                   ks: NDArray[np.intp]) -> list[tuple[int, int, Array, str]]:
    """:func:`_folds` for a loop of the RSRC quartic: each mode's fold where its own root
    stops assembling, over the rows the loop was solved on (the approach, then ``X``); a
    change of a mode's samples where its root does not change (none expected: the modes are
    these roots) is left out, for the caller's count."""
    from screwkit.kinematics.graph.motion import input_text
    from screwkit.kinematics.graph.quartic_folds import quartic_folds

    A = approach(lay, X)
    a = A.shape[0]
    found = {(f.mode, f.k - a, f.dies): f for f in
             quartic_folds(chain, chain.loop_inputs(np.vstack([A, X])))}
    out = []
    for r, k in zip(rows, ks, strict=True):
        dies = bool(masks[r, k])
        f = found.get((modes[r], int(k), dies))
        if f is None:
            continue
        x = X[k] + f.t * (X[k + 1] - X[k])
        meet = (f"loop modes {min(f.mode, f.partner)} and {max(f.mode, f.partner)} meet"
                if f.partner is not None else
                f"loop mode {f.mode} meets a root that assembles at neither sample")
        out.append((int(r), int(k), x, f"{'dies' if dies else 'is born'} at "
                                       f"{input_text(mech, lay, x)}: the loop folds ({meet})"))
    return out


def real_count(chain: LoopChain, L: Array) -> NDArray[np.intp]:
    """The loop's real closed-form solutions at each row of loop inputs ``L`` (K, 1): the
    RSRC's quartic roots (Bagci 1969 eq. 3.63, as its own limit search counts them), else the
    closed form's modes there (its branches, the same count, where the family offers them),
    the drawing appended (so that at least one input assembles)."""
    from screwkit.kinematics.registry import family_of, has_rsrc_quartic

    if has_rsrc_quartic(chain.linkage):  # its quartic's real roots, without the modes
        from screwkit.kinematics.closed_forms.closed_form_motion import rsrc_dimensions
        from screwkit.kinematics.closed_forms.rsrc.positions import rsrc_positions

        return np.asarray(rsrc_positions(rsrc_dimensions(chain.linkage)[0],
                                         L[:, 0]).n_assemblies)
    family = family_of(chain.linkage)
    L = np.vstack([L, chain.offset[None, :]])
    zero = np.zeros_like(L)
    branches_of = family.closed_branches_for(chain.linkage)
    if branches_of is not None:
        return np.asarray(np.sum(branches_of(chain.linkage, L, zero, zero).assembles,
                                 axis=0)[:-1])
    closed = family.closed_form_for(chain.linkage)
    assert closed is not None
    mo = closed(chain.linkage, L, zero, zero)
    return np.asarray(np.sum([md.assembles for md in mo.modes], axis=0)[:-1])


@dataclass(frozen=True)
class StepPieces:
    """The loop's modes (``source`` (M, N)) cut where two folds lie inside one step: each
    piece's mode row (``rows``), samples (``masks``) and label tail; the pieces' fold events
    inside steps as (place k + t, (piece, k, input row, text)), islands on no sample included."""

    source: NDArray[np.bool_]
    rows: list[int]
    masks: NDArray[np.bool_]
    labels: list[str]
    events: list[tuple[float, tuple[int, int, Array, str]]]
    islands: frozenset[int] = frozenset()
    island_name: str = "one of the loop's two modes"

    def piece(self, row: int, k: int, dies: bool) -> int | None:
        """The piece of mode ``row`` that dies after sample k (``dies``) or is born before k+1
        (None: that piece is not kept)."""
        n = k if dies else k + 1
        return next((i for i, (r, m) in enumerate(zip(self.rows, self.masks, strict=True))
                     if r == row and m[n]), None)


def step_pieces(mech: Mechanism, lay: GraphLayout, X: Array, masks: NDArray[np.bool_],
                every: bool, chain: LoopChain, modes: list[int]) -> StepPieces:
    """The modes ``masks`` (M, N; row r the loop's mode ``modes[r]``) of a loop that is one
    two-branch dyad or leg on its driven joint (graph/subchains.py: its two loop modes are that
    sub-chain's two branches, and they fold together), cut where the sub-chain's discriminant
    dips below zero inside one step, and with ``every`` its islands inside one step as modes on
    no sample (graph/step_folds.py; the drawn mode, row 0, ends at its first fold); a loop of
    the RSRC quartic from its quartic's discriminant (graph/quartic_steps.py); any other loop's
    modes as they are."""
    from screwkit.kinematics.graph.closed_modes import ISLAND, SAME_AGAIN, drawn_combination
    from screwkit.kinematics.graph.dyads import place
    from screwkit.kinematics.graph.motion import input_text
    from screwkit.kinematics.graph.step_folds import hidden_pairs
    from screwkit.kinematics.graph.subchains import decompose
    from screwkit.kinematics.registry import has_rsrc_quartic

    M, N = masks.shape
    rows, pieces, labels = list(range(M)), list(masks), [""] * M
    dec = decompose(mech)
    if N < 2 or not dec.complete or dec.loops or len(dec.dyads) != 1 or \
            dec.dyads[0].branches != 2:
        if N > 1 and has_rsrc_quartic(chain.linkage):
            from screwkit.kinematics.graph.quartic_steps import quartic_pieces

            return quartic_pieces(mech, lay, chain, X, masks, modes, every)
        return StepPieces(masks, rows, masks, labels, [])
    # the two branches share the discriminant (they fold together): the drawing's alone, over
    # the drawn mode's samples unless every mode is asked for
    n = N if every else int(np.flatnonzero(masks[0])[-1]) + 1
    signs = drawn_combination(dec)
    pl = place(mech, lay, dec, X[:n], np.repeat(signs, n, axis=0))

    def evaluate(r: NDArray[np.intp], ks: NDArray[np.intp], t: Array
                 ) -> tuple[Array, NDArray[np.bool_]]:
        pl = place(mech, lay, dec, X[ks] + t[:, None] * (X[ks + 1] - X[ks]), signs[r])
        return pl.discriminant, pl.assembles

    pairs = hidden_pairs(evaluate, pl.assembles[None, :], pl.discriminant[None]) if n > 1 else []
    idx = np.arange(N)
    rows, pieces, labels = [], [], []
    for r in range(M):
        cuts = sorted(p.k + 1 for p in pairs if p.gap and masks[r, p.k] and masks[r, p.k + 1])
        for j, (a, b) in enumerate(zip([0, *cuts], [*cuts, N], strict=True)):
            part = masks[r] & (idx >= a) & (idx < b)
            # the drawn mode ends at its first fold: its later pieces only with every mode
            if part.any() and (r or j == 0 or every):
                rows.append(r)
                pieces.append(part)
                labels.append("" if j == 0 else SAME_AGAIN)
    events: list[tuple[float, tuple[int, int, Array, str]]] = []

    def event(i: int, p: HiddenPairT, end: int) -> None:
        x = X[p.k] + p.t[end] * (X[p.k + 1] - X[p.k])
        events.append((p.k + p.t[end], (i, p.k, x, hidden_fold_text(
            (end == 0) == p.gap, input_text(mech, lay, x), end == 0,
            input_text(mech, lay, X[p.k]), input_text(mech, lay, X[p.k + 1]), p.gap))))

    for i, (r, part) in enumerate(zip(rows, pieces, strict=True)):
        for p in pairs:
            if p.gap and part[p.k] and not part[p.k + 1] and masks[r][p.k + 1]:
                event(i, p, 0)
            elif p.gap and part[p.k + 1] and not part[p.k] and masks[r][p.k]:
                event(i, p, 1)
    for p in pairs if every else ():
        if not p.gap:
            for _ in range(2):  # the loop's two modes, born and dying together
                rows.append(0)
                pieces.append(np.zeros(N, dtype=bool))
                labels.append(ISLAND)
                event(len(rows) - 1, p, 0)
                event(len(rows) - 1, p, 1)
    return StepPieces(masks, rows, np.array(pieces), labels, events,
                      frozenset(i for i, t in enumerate(labels) if t == ISLAND))

"""Parameter homotopy: track known solutions at p_start to the solutions at p_target.

:func:`track_parameter_homotopy` moves the parameters along the straight segment
p(s) = (1 − s)·p_start + s·p_target, s ∈ [0, 1], and carries every start solution along
(Sommese & Wampler, *The Numerical Solution of Systems of Polynomials*, 2005, ch. 7: with
p_start generic and complex, the open segment misses the discriminant with probability one, so
the paths are smooth until s = 1 and every isolated solution at p_target is the end of some
path). All paths (and a batch of targets, one per path) run in one vectorised tracker
(:mod:`.path`) on a random affine patch of the homogenised system, so a path going to infinity
stays finite and is reported as at infinity.

Each path first runs to s = 1 − r (r = ``endgame_radius``) and then to s = 1; an end point where
the tracker arrives with a well-conditioned Jacobian is polished by Newton and is regular, or at
infinity when the polished h ≈ 0 (a nonsingular solution at infinity of the homogenised system
on the patch, Sommese & Wampler 2005, §3.2: Newton's convergence there is as good a certificate
as at a finite regular end, so it skips the endgame). The
others (the step collapsed, or the Jacobian is ill-conditioned) go through the Cauchy
endgame (:mod:`.endgame`) from s = 1 − r, which gives their end point and winding number; they
are then classified singular (with the number of paths that reach the same point as its
multiplicity estimate), at infinity, or failed.

A path whose tracking fails (its step collapses where the segment passes close to the
discriminant and Newton stops contracting) is not given up at once: it is first tracked again
alone on the same segment with 10× smaller steps (the same path, so its end is its own); if it
still fails, or ends where another path of its instance ends, every path of its instance is
tracked again through a random complex parameter point (p_start → p_mid → p_target, both legs
generic), and that instance's new ends are kept when fewer of its paths fail.

Path jumping: two paths of one instance ending at the same regular solution cannot both be
right (a regular solution is the end of exactly one path). Both are tracked again with 10×
smaller steps; a pair that still coincides is marked failed.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic import compiled
from screwkit.algebraic.endgame import cauchy_endgame
from screwkit.algebraic.path import Homotopy, TrackOptions, line, newton, track
from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.quadrics import DenseQuadrics, dense_quadrics_apply
from screwkit.errors import InputError

__all__ = ["PathStatus", "TrackOptions", "TrackResult", "track_parameter_homotopy",
           "same_points"]


class PathStatus(IntEnum):
    """How a path ended."""

    REGULAR = 0  # a nonsingular isolated solution, Newton-polished
    SINGULAR = 1  # a singular end point (winding number > 1 or ill-conditioned Jacobian)
    AT_INFINITY = 2  # the path diverged: h → 0 on the patch
    FAILED = 3  # the tracker or the endgame did not finish, or a jump that did not resolve


@dataclass(frozen=True)
class TrackResult:
    """The end of every path at s = 1.

    ``x`` (P, n) are the affine end points (NaN for paths at infinity or failed), ``y`` (P, n+1)
    the end points on the patch (h, h·x); ``status`` (P,) a :class:`PathStatus` code;
    ``condition`` (P,) the 2-norm condition number of the patch Jacobian at the end point;
    ``residual`` (P,) ‖F(x; p_target)‖∞ at finite end points; ``winding`` (P,) the cycle
    number from the endgame (1 for paths that did not need it); ``multiplicity`` (P,) the number
    of paths of the same instance ending at the same point (1 for a regular end); ``steps`` (P,)
    predictor–corrector steps taken; ``retracked`` (P,) paths tracked again (alone after
    their main leg failed, after a suspected jump, or through the detour of an instance with a
    failed path); ``instance`` (P,) the index of each path's homotopy (its pair p_start, p_target)
    among the distinct pairs: paths of one instance are one homotopy, whose regular ends must
    differ."""

    x: Complex
    y: Complex
    status: NDArray[np.int8]
    condition: NDArray[np.float64]
    residual: NDArray[np.float64]
    winding: NDArray[np.int64]
    multiplicity: NDArray[np.int64]
    steps: NDArray[np.int64]
    retracked: NDArray[np.bool_]
    instance: NDArray[np.intp]

    @property
    def regular(self) -> NDArray[np.bool_]:
        return self.status == PathStatus.REGULAR

    def counts(self) -> dict[str, int]:
        """The number of paths per status, by name."""
        return {s.name.lower(): int((self.status == s).sum()) for s in PathStatus}


def _check(system: PolynomialSystem, p_start: ArrayLike, p_target: ArrayLike,
           x_start: ArrayLike) -> tuple[Complex, Complex, Complex]:
    x = np.asarray(x_start, dtype=complex)
    if x.ndim != 2 or x.shape[1] != system.n:
        raise InputError(f"x_start must have shape (paths, {system.n}) for the unknowns "
                         f"{', '.join(system.variables)}; got shape {x.shape}")
    P = x.shape[0]
    ps, pt = (np.asarray(v, dtype=complex) for v in (p_start, p_target))
    for name, v in (("p_start", ps), ("p_target", pt)):
        if v.shape not in ((system.k,), (P, system.k)):
            raise InputError(f"{name} must have shape ({system.k},) or ({P}, {system.k}) for "
                             f"the parameters {', '.join(system.parameters) or '(none)'}; got "
                             f"shape {v.shape}")
        if not np.isfinite(v).all():
            raise InputError(f"{name} must be finite")
    if not np.isfinite(x).all():
        raise InputError("x_start must be finite")
    return (np.broadcast_to(ps, (P, system.k)).copy(), np.broadcast_to(pt, (P, system.k)).copy(),
            x)


def same_points(points: Complex, groups: NDArray[np.intp], tolerance: float, seed: int = 0,
                absolute: NDArray[np.float64] | None = None) -> NDArray[np.intp]:
    """A cluster label per point: points i, j of one group with ‖x_i − x_j‖₂ ≤
    tolerance·(1 + max ‖x‖∞) + absolute_i + absolute_j (transitively) share a label, the
    smallest index among them.

    Candidates are found by sorting each group along a random projection and comparing
    neighbours a few places apart, so it costs O(P log P), not O(P²)."""
    P = len(points)
    label = np.arange(P)
    if P < 2:
        return label
    rng = np.random.default_rng(seed)
    direction = rng.standard_normal(points.shape[1]) + 1j * rng.standard_normal(points.shape[1])
    finite = np.asarray(np.isfinite(points).all(axis=1), dtype=bool)
    safe = np.where(finite[:, None], points, 0.0)
    key = np.where(finite, (safe @ direction).real, np.inf)
    extra = np.zeros(P) if absolute is None else np.nan_to_num(absolute, nan=0.0, posinf=0.0)
    order = np.lexsort((key, groups))
    pairs: list[tuple[int, int]] = []
    width = np.linalg.norm(direction)
    for shift in range(1, min(P, 8)):
        i, j = order[:-shift], order[shift:]
        scale = 1.0 + np.maximum(np.abs(safe[i]).max(axis=1), np.abs(safe[j]).max(axis=1))
        reach = tolerance * scale + extra[i] + extra[j]
        close = (groups[i] == groups[j]) & finite[i] & finite[j]
        close &= np.abs(key[i] - key[j]) <= reach * width
        close &= np.linalg.norm(safe[i] - safe[j], axis=1) <= reach
        pairs.extend(zip(i[close].tolist(), j[close].tolist(), strict=True))
    for first, second in pairs:  # union–find over the (few) close pairs
        a, b = first, second
        while label[a] != a:
            a = int(label[a])
        while label[b] != b:
            b = int(label[b])
        label[max(a, b)] = min(a, b)
    for point in range(P):
        label[point] = label[label[point]]
    return label


def _polish(hom: Homotopy, y: Complex, rows: NDArray[np.intp],
            options: TrackOptions) -> tuple[Complex, NDArray[np.bool_], NDArray[np.float64]]:
    """Three Newton steps at s = 1; converged (last correction ≤ 1e-11 relative, contracting)
    and the condition number there."""
    one = np.ones(len(rows), dtype=complex)
    with np.errstate(all="ignore"):
        polished, sizes = newton(hom, y, rows, one, 3)
        scale = 1.0 + np.abs(y).max(axis=1)
        ok = (sizes[-1] <= 1e-11 * scale) & np.isfinite(polished).all(axis=1)
        _, J, _ = hom.parts(polished, rows, one)
        cond = np.where(np.isfinite(J).all(axis=(1, 2)),
                        np.linalg.cond(np.where(np.isfinite(J), J, 0.0)), np.inf)
    return polished, ok & (cond <= options.max_condition), cond


def _run(system: PolynomialSystem, hom: Homotopy, x_start: Complex, rows: NDArray[np.intp],
         options: TrackOptions) -> dict[str, np.ndarray]:
    """Track the paths ``rows`` from s = 0 to 1 and classify their ends."""
    m = len(rows)
    y0 = hom.to_patch(x_start)
    near = 1.0 - options.endgame_radius
    y_near, ok1, steps = track(hom, line, y0, rows, np.zeros(m), np.full(m, near), options)
    end = options.near_end()
    y_end, ok2, used = track(hom, line, y_near, rows, np.full(m, near), np.ones(m), end)
    steps = steps + used
    status = np.full(m, PathStatus.FAILED, dtype=np.int8)
    winding = np.ones(m, dtype=np.int64)
    y_final = np.full_like(y0, np.nan)
    cond = np.full(m, np.inf)
    arrived = np.flatnonzero(ok1 & ok2)
    polished, good, cond_a = _polish(hom, y_end[arrived], rows[arrived], options)
    h = np.abs(polished[:, 0]) <= options.infinity_threshold * np.abs(polished).max(axis=1)
    # a regular end point with h ≈ 0 is a nonsingular solution at infinity of the homogenised
    # system on the patch: Newton has converged to it, so it needs no endgame
    infinite = good & h
    status[arrived[infinite]] = PathStatus.AT_INFINITY
    y_final[arrived[infinite]] = polished[infinite]
    good &= ~h
    status[arrived[good]] = PathStatus.REGULAR
    y_final[arrived[good]] = polished[good]
    cond[arrived] = cond_a
    late = np.flatnonzero(ok1 & (status == PathStatus.FAILED))
    if late.size:
        eg = cauchy_endgame(hom, y_near[late], rows[late], end)
        steps[late] += eg.steps
        winding[late] = eg.winding
        estimate = eg.y
        fin = np.isfinite(estimate).all(axis=1) & (eg.winding > 0)
        y_final[late[fin]] = estimate[fin]
        infinite = fin & (np.abs(estimate[:, 0])
                          <= options.infinity_threshold * np.abs(estimate).max(axis=1))
        status[late[infinite]] = PathStatus.AT_INFINITY
        finite = np.flatnonzero(fin & ~infinite)
        pol, good, cond_e = _polish(hom, estimate[finite], rows[late[finite]], options)
        cond[late[finite]] = cond_e
        regular = good & (eg.winding[finite] == 1)
        status[late[finite[regular]]] = PathStatus.REGULAR
        y_final[late[finite[regular]]] = pol[regular]
        status[late[finite[~regular]]] = PathStatus.SINGULAR
    return {"y": y_final, "status": status, "condition": cond, "winding": winding,
            "steps": steps, "main_leg": ok1.copy()}


def _run_in_chunks(system: PolynomialSystem, hom: Homotopy, x: Complex,
                   rows: NDArray[np.intp], options: TrackOptions) -> dict[str, np.ndarray]:
    """:func:`_run` over chunks of ``options.chunk`` paths: every array of a chunk stays
    small enough for the cache (a batch of thousands of paths at once runs slower per path
    than a few hundred, measured on the 6-quadric benchmark)."""
    if len(rows) <= options.chunk:
        return _run(system, hom, x, rows, options)
    parts = [_run(system, hom, x[i: i + options.chunk], rows[i: i + options.chunk], options)
             for i in range(0, len(rows), options.chunk)]
    return {key: np.concatenate([part[key] for part in parts]) for key in parts[0]}


def track_parameter_homotopy(system: PolynomialSystem, p_start: ArrayLike,
                             p_target: ArrayLike, x_start: ArrayLike,
                             options: TrackOptions | None = None,
                             instance: ArrayLike | None = None) -> TrackResult:
    """Track the start solutions ``x_start`` (P, n) of F(x; p_start) = 0 to F(x; p_target) = 0
    along p(s) = (1 − s)·p_start + s·p_target (Sommese & Wampler 2005, ch. 7).

    ``p_start`` and ``p_target`` are (k,) or (P, k), one row per path, so a batch of many
    instances times their start solutions is one call. ``p_start`` should be generic complex
    (random complex parameters) for the paths to be smooth; the caller's start solutions must
    solve F(x; p_start) = 0 to tracking accuracy. Returns a :class:`TrackResult`.

    ``instance`` (P,) names each path's problem: the paths of one instance are one homotopy,
    whose regular ends must differ (path-jump check) and which a detour retracks together.
    Default: paths on the same segment (p_start, p_target) are one instance. A caller that
    solves the same target twice in one batch (a closed motion's first and last rows) gives
    its own rows, or the two copies' equal ends would read as jumps."""
    options = options or TrackOptions()
    ps, pt, x = _check(system, p_start, p_target, x_start)
    P = x.shape[0]
    hsys = system.homogenized()
    rng = np.random.default_rng(options.seed)
    patch = ((rng.standard_normal(system.n + 1) + 1j * rng.standard_normal(system.n + 1))
             / 2).astype(complex)
    hom, segment = _homotopy(hsys, patch, ps, pt, options)
    given = segment if instance is None else np.asarray(instance, dtype=np.intp).reshape(-1)
    if given.shape != (P,):
        raise InputError(f"instance must give one index per path ({P}); got shape "
                         f"{given.shape}")
    group: NDArray[np.intp] = np.unique(given, return_inverse=True)[1].reshape(-1).astype(
        np.intp)
    # BLAS held at one thread while the compiled tracks run on the cores in threads of their
    # own (OpenBLAS's threads, woken by a small product, spin on the same cores)
    with compiled.threads_held():
        rows = np.arange(P)
        out = _run_in_chunks(system, hom, x, rows, options)
        retracked = np.zeros(P, dtype=bool)
        if options.retrack:
            _retrack_lost(system, hom, x, rows, group, out, retracked, options)
        failed = out["status"] == PathStatus.FAILED
        if failed.any() and options.detour:
            # every path of an instance with a failed path, through the detour (all of them: a
            # detour for some paths only could permute the solutions they reach, by monodromy);
            # kept for the instances where fewer paths fail than on the straight segment
            touched = np.flatnonzero(np.isin(group, group[failed]))
            other = _detour(system, hsys, patch, ps[touched], pt[touched], x[touched], rng,
                            options)
            before = np.bincount(group[touched], weights=failed[touched], minlength=P)
            after = np.bincount(group[touched],
                                weights=other["status"] == PathStatus.FAILED, minlength=P)
            better = (after < before)[group[touched]]
            for key, value in other.items():
                out[key][touched[better]] = value[better]
            retracked[touched[better]] = True
        jumped = _jumps(out["y"], out["status"], group, options)
        if jumped.size and options.retrack:
            again = _run_in_chunks(system, hom, x[jumped], rows[jumped], options.tighter())
            for key, value in again.items():
                out[key][jumped] = value
            retracked[jumped] = True
            still = _jumps(out["y"], out["status"], group, options)
            out["status"][still] = PathStatus.FAILED
        elif jumped.size:
            out["status"][jumped] = PathStatus.FAILED
        return _result(system, out, pt, group, retracked, options)


def _homotopy(hsys: PolynomialSystem, patch: Complex, ps: Complex, pt: Complex,
              options: TrackOptions) -> tuple[Homotopy, NDArray[np.intp]]:
    """The homotopy of the segments ps → pt (one row per path), evaluated densely when the
    system is made of quadrics, and each path's instance (index of its distinct segment)."""
    first, instance = _segments(ps, pt)
    dense = (DenseQuadrics.build(hsys, ps[first], pt[first] - ps[first])
             if options.dense and dense_quadrics_apply(hsys) else None)
    return (Homotopy(hsys, patch, ps, pt - ps, dense, instance if dense is not None else None),
            instance)


def _retrack_lost(system: PolynomialSystem, hom: Homotopy, x: Complex, rows: NDArray[np.intp],
                  group: NDArray[np.intp], out: dict[str, np.ndarray],
                  retracked: NDArray[np.bool_], options: TrackOptions) -> None:
    """The paths whose main leg failed (the step collapsed), tracked again alone on the same
    segment with :meth:`TrackOptions.tighter` steps. Each is the same path of the same
    homotopy, so its end is its own (no permutation of the ends, unlike a detour of some paths
    only); an end that is still failed, or that another path of its instance also reaches,
    is left failed, and the detour then takes its whole instance. Updates ``out`` and
    ``retracked`` in place."""
    lost = np.flatnonzero((out["status"] == PathStatus.FAILED) & ~out["main_leg"])
    if not lost.size:
        return
    again = _run_in_chunks(system, hom, x[lost], rows[lost], options.tighter())
    mine = {key: value[lost].copy() for key, value in out.items()}
    for key, value in again.items():
        out[key][lost] = value
    shared = np.isin(lost, _jumps(out["y"], out["status"], group, options))
    undo = shared | (again["status"] == PathStatus.FAILED)
    for key, value in mine.items():
        out[key][lost[undo]] = value[undo]
    retracked[lost[~undo]] = True


def _segments(ps: Complex, pt: Complex) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """``np.unique(rows, axis=0, return_index=True, return_inverse=True)[1:]`` of the rows
    (ps, pt), the same arrays, with the sort run over the first row of each run of equal
    rows only (a batch repeats each target once per path, so there are few)."""
    rows = np.concatenate([ps, pt], axis=1)
    head = np.ones(len(rows), dtype=bool)
    head[1:] = (rows[1:] != rows[:-1]).any(axis=1)
    heads = np.flatnonzero(head)
    if len(heads) == 1:  # one segment (one instance alone)
        return np.zeros(1, dtype=np.intp), np.zeros(len(rows), dtype=np.intp)
    first, inverse = np.unique(rows[heads], axis=0, return_index=True, return_inverse=True)[1:]
    return (heads[first].astype(np.intp),
            inverse.reshape(-1)[np.cumsum(head) - 1].astype(np.intp))


def _detour(system: PolynomialSystem, hsys: PolynomialSystem, patch: Complex, ps: Complex,
            pt: Complex, x: Complex, rng: np.random.Generator,
            options: TrackOptions) -> dict[str, np.ndarray]:
    """The paths of instances where tracking failed on the straight segment (the step
    collapsed where the segment passes close to the discriminant, Newton no longer
    contracting), tracked again through a random complex point: p_start → p_mid → p_target. With p_mid generic both legs
    miss the discriminant with probability one (Sommese & Wampler 2005, §7.1: any generic
    path of parameters carries every isolated solution); the first leg ends at regular
    solutions of the generic p_mid, the second is classified as usual (endgame included)."""
    scale = np.abs(pt - ps).max(axis=1, keepdims=True) + 1.0
    groups, which = np.unique(np.concatenate([ps, pt], axis=1), axis=0, return_inverse=True)
    kick = (rng.standard_normal(groups.shape[:1] + ps.shape[1:])
            + 1j * rng.standard_normal(groups.shape[:1] + ps.shape[1:]))
    mid = 0.5 * (ps + pt) + 0.5 * scale * kick[which.reshape(-1)]
    rows = np.arange(len(x))
    hom, _ = _homotopy(hsys, patch, ps, mid, options)
    leg = _run_in_chunks(system, hom, x, rows, options)
    out = {"y": np.full_like(leg["y"], np.nan),
           "status": np.full(len(x), PathStatus.FAILED, dtype=np.int8),
           "condition": np.full(len(x), np.inf), "winding": np.ones(len(x), dtype=np.int64),
           "steps": leg["steps"].copy(), "main_leg": np.zeros(len(x), dtype=bool)}
    through = np.flatnonzero(leg["status"] == PathStatus.REGULAR)
    if through.size:
        y = leg["y"][through]
        hom, _ = _homotopy(hsys, patch, mid[through], pt[through], options)
        second = _run_in_chunks(system, hom, y[:, 1:] / y[:, :1], np.arange(len(through)),
                                options)
        for key, value in second.items():
            out[key][through] = value
        out["steps"][through] += leg["steps"][through]
    return out


def _jumps(y: Complex, status: NDArray[np.int8], instance: NDArray[np.intp],
           options: TrackOptions) -> NDArray[np.intp]:
    """Regular end points shared by two or more paths of one instance."""
    regular = np.flatnonzero(status == PathStatus.REGULAR)
    label = same_points(y[regular], instance[regular], options.same_point_tolerance)
    shared = np.bincount(label, minlength=len(regular))[label] > 1
    return regular[shared]


def _result(system: PolynomialSystem, out: dict[str, np.ndarray], p_target: Complex,
            instance: NDArray[np.intp], retracked: NDArray[np.bool_],
            options: TrackOptions) -> TrackResult:
    y, status = out["y"], out["status"]
    finite = (status == PathStatus.REGULAR) | (status == PathStatus.SINGULAR)
    x = np.full((len(y), system.n), np.nan + 0j)
    with np.errstate(all="ignore"):
        x[finite] = y[finite, 1:] / y[finite, :1]
    residual = np.full(len(y), np.nan)
    if finite.any():
        F, _, _ = system.evaluate(x[finite], p_target[finite], want_jp=False)
        residual[finite] = np.abs(F).max(axis=1)
    multiplicity = np.ones(len(y), dtype=np.int64)
    singular = np.flatnonzero(status == PathStatus.SINGULAR)
    if singular.size:
        label = same_points(x[singular], instance[singular], 1e3 * options.same_point_tolerance)
        multiplicity[singular] = np.bincount(label, minlength=len(singular))[label]
    return TrackResult(x, y, status, out["condition"], residual, out["winding"], multiplicity,
                       out["steps"], retracked, instance)

"""Transmission quality of a loop over its cycle: the transmission index of each output freedom
(any loop), the transmission angle (planar loops) and the cone angle of every ball joint.

**Transmission index** (Sutherland & Roth, "A transmission index for spatial mechanisms", ASME J.
Eng. Ind. 95(2):589–597, 1973): with the input held, the links between the input link and the
output link (the coupler chain) can pass to the output link only wrenches reciprocal to every
freedom of the chain; of those, the transmission wrench $_T of an output freedom is the one that
is also reciprocal to the output joint's other freedoms (a one-dimensional set in a loop of one
freedom; computed within the loop's own twist space, so a planar loop gets its planar wrench).
The index is its virtual coefficient with the output twist $_O, over the largest virtual
coefficient a wrench of the same pitch through the same point could have:

    TI = |$_T ∘ $_O| / max |$_T ∘ $_O| = |f̂·(v_P + h ω)| / |v_P + h ω|

with f̂ the wrench's direction, h its pitch, P the point of its axis nearest the joint through
which the chain drives the output link, and (ω, v_P) the output twist's angular velocity and the
velocity of P. 1 is ideal, 0 a dead centre of the output (no transmission). For a pure force
(h = 0) TI is the cosine of the angle between the transmitted force and the velocity of its point
of application: for a planar four-bar TI = |sin μ|, for a slider-crank |cos| of the rod's angle to
the slide.

**Transmission angle** μ (planar loops whose output joint and the joint before it are revolute):
the angle at the coupler–output joint B between the coupler (from the joint before, A) and the
output link (to the output pivot O): cos μ = (A − B)·(O − B) / (|A − B| |O − B|), 0 … π; the worst
of the cycle is the smallest min(μ, π − μ).

**Ball-joint cone angles**: a ball joint's socket is on one of its two links and its stem is the
line of the other from the ball centre to that link's other joint centre: the socket is on the
proximal link and the stem on the distal one, except that a link between two balls (whose spin
about its own axis is idle, so its frame is a convention) never holds a socket, and a link with no
length at the ball cannot be a stem. Seen from the socket's link, the stem sweeps a set of
directions over the cycle. The socket axis is the centre of the smallest cone containing them all (the best
mounting: the direction a·v_i is largest for, the normalised minimum-norm point of their convex
hull), and the cone angle at each sample is the angle between the stem and that axis; its maximum
is the cone limit a ball joint needs. The spin about the stem does not load a ball's cone limit
(and for a rod between two balls is an idle freedom), so it is left out.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from screwkit.errors import expect_instance
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.kinematics.registry import default_outputs, output_freedom, output_joint
from screwkit.kinematics.tracker.loop import Array, forward, layout
from screwkit.model.linkage import Linkage

__all__ = ["ModeTransmission", "Transmission", "smallest_cone", "transmission"]


@dataclass(frozen=True)
class ModeTransmission:
    """One mode's transmission over the sweep (NaN where it does not assemble, or where the
    transmission wrench is not unique: a singular sample)."""

    mode: int
    index: dict[str, Array]  # output name -> (N,) transmission index, 0 … 1
    angle: Array | None  # (N,) transmission angle μ, rad, 0 … π (planar loops)
    cone_angle: dict[str, Array] = field(default_factory=dict)  # ball joint -> (N,) rad
    socket_axis: dict[str, Array] = field(default_factory=dict)  # ball joint -> (3,) unit
    cone_limit: dict[str, float] = field(default_factory=dict)  # ball joint -> rad


@dataclass(frozen=True)
class Transmission:
    """Transmission quality of every mode of a motion (module docstring)."""

    outputs: tuple[str, ...]
    output_joint: str
    driving_joint: str
    planar: bool
    modes: list[ModeTransmission]

    def summary(self, x: Array) -> list[dict[str, Any]]:
        """Per mode: the minimum index of each output and the input where it occurs, the worst
        transmission angle (smallest min(μ, π − μ)) and where, every ball's cone limit."""
        out = []
        for m in self.modes:
            entry: dict[str, Any] = {"mode": m.mode, "index": {}}
            for name, ti in m.index.items():
                entry["index"][name] = _extreme(ti, x, np.nanargmin)
            if m.angle is not None:
                worst = np.minimum(m.angle, np.pi - m.angle)
                entry["angle"] = _extreme(worst, x, np.nanargmin)
            entry["cone_limit"] = {
                j: {"value": m.cone_limit[j], "at": _extreme(a, x, np.nanargmax)["at"],
                    "socket_axis": m.socket_axis[j]} for j, a in m.cone_angle.items()}
            out.append(entry)
        return out


def _extreme(values: Array, x: Array, pick: Any) -> dict[str, Any]:
    if not np.isfinite(values).any():
        return {"value": None, "at": None}
    k = int(pick(values))
    return {"value": float(values[k]), "at": float(x[k])}


def _planar(linkage: Linkage, mode: ModeMotion) -> bool:
    """Whether every joint is R or P with every R axis along one normal and every P axis
    perpendicular to it (the loop moves in parallel planes)."""
    if any(j.kind not in ("R", "P") for j in linkage.joints):
        return False
    ok = np.nonzero(mode.assembles)[0]
    if ok.size == 0:
        return False
    axes = mode.joint_axes[ok[0]]
    kinds = [j.kind for j in linkage.joints]
    rev = [axes[i] for i, k in enumerate(kinds) if k == "R"]
    if not rev:
        return False
    n = rev[0]
    par = all(np.linalg.norm(np.cross(a, n)) < 1e-9 for a in rev)
    perp = all(abs(axes[i] @ n) < 1e-9 for i, k in enumerate(kinds) if k == "P")
    return bool(par and perp)


def _twist_space(S: Array, L: float) -> Array | None:
    """(N, 6, r) an orthonormal basis of the loop's (scaled) twist space at each sample, r its
    largest rank over the sweep; None when r = 6 (the whole space: any basis will do, and the
    wrench is sought in R⁶ directly, without a decomposition per sample)."""
    Ss = S * _scale(L)[None, :, None]
    # rank 6 on a few samples is rank 6 of the sweep (r is the largest rank, at most 6)
    few = Ss[np.linspace(0, Ss.shape[0] - 1, min(Ss.shape[0], 64)).astype(int)]
    if _rank(np.linalg.svd(np.nan_to_num(few), compute_uv=False)).max() == 6:
        return None
    U, sv, _ = np.linalg.svd(Ss)
    return np.asarray(U[:, :, :int(np.max(_rank(sv)))])


def _scale(L: float) -> Array:
    return np.array([1, 1, 1, 1 / L, 1 / L, 1 / L])


def _rank(sv: Array) -> Array:
    """Numerical rank of each matrix from its singular values (descending): those over
    10⁻⁹ of the largest."""
    return np.asarray(np.sum(sv > 1e-9 * np.maximum(sv[..., :1], 1e-300), axis=-1))


def _maximal_minors(Mt: Array) -> dict[tuple[int, ...], Array]:
    """Every k×k minor (N,) of the r×k matrices ``Mt`` (r, k, N: sample last, so that each
    entry is a contiguous (N,) row and the products stream through memory, 5x faster than
    strided slices of (N, r, k) on 10⁵ samples), by its rows (sorted), built column by column
    with the Laplace expansion along the last column: det M[T, :j+1] =
    Σ_p (−1)^(p+j) M[T_p, j] det M[T∖T_p, :j] (a handful of array operations per minor, where
    a determinant per minor and sample costs a LAPACK call each)."""
    from itertools import combinations

    r, k, N = Mt.shape
    minors: dict[tuple[int, ...], Array] = {(i,): Mt[i, 0] for i in range(r)}
    for j in range(1, k):
        nxt: dict[tuple[int, ...], Array] = {}
        for rows in combinations(range(r), j + 1):
            total = np.zeros(N)
            for pos, row in enumerate(rows):
                rest = rows[:pos] + rows[pos + 1:]
                term = Mt[row, j] * minors[rest]
                total = total + term if (pos + j) % 2 == 0 else total - term
            nxt[rows] = total
        minors = nxt
    return minors


def _null_vector(Mt: Array) -> tuple[Array, np.ndarray[Any, np.dtype[np.bool_]]]:
    """(N, r) a unit vector orthogonal to the k < r columns of each matrix of ``Mt`` (r, k, N;
    sample last), and whether it is unique (rank k, by the SVD's test: every singular value
    over 10⁻⁹ of the largest).

    For k = r − 1 the vector is the generalised cross product of the columns, g_i =
    (−1)^i det M₍ᵢ₎ (M without row i): it is orthogonal to every column (expanding a
    determinant with a repeated column) and, by Cauchy–Binet, |g| = √det(MᵀM) = ∏σ. As σ_max ≤
    ‖M‖_F, σ_min/σ_max ≥ |g| / ‖M‖_F^k, so a sample with |g| > 10⁻⁶ ‖M‖_F^k has rank k and a
    well-defined g; the SVD decides the others and gives their vector."""
    r, k, N = Mt.shape
    gt = np.zeros((r, N))  # g by rows, sample last
    doubt = np.ones(N, dtype=bool)
    if k == r - 1:
        minors = _maximal_minors(Mt)
        for i in range(r):  # the minor without row i is the one on rows {0..r-1} \ {i}
            gt[i] = (-1) ** i * minors[(*range(i), *range(i + 1, r))]
        volume = np.linalg.norm(gt, axis=0)
        doubt = ~(volume > 1e-6 * np.linalg.norm(Mt, axis=(0, 1)) ** k)
        gt /= np.where(doubt, 1.0, volume)[None, :]
    g = gt.T  # (N, r)
    unique = ~doubt
    if doubt.any():
        _, sm, Vt = np.linalg.svd(np.moveaxis(Mt[:, :, doubt], -1, 0).swapaxes(1, 2))
        g[doubt] = Vt[:, -1, :]
        unique[doubt] = _rank(sm) == r - 1
    return g, unique


def _wrench_nullspace(S: Array, cons: list[int], L: float, U: Array | None,
                      St: Array | None = None) -> Array:
    """(N, 6) the transmission wrench (f; m about the ground origin) reciprocal to the
    constraint freedoms ``cons`` within the loop's twist space (basis ``U`` from
    :func:`_twist_space`, None for the whole space); NaN where not unique. ``St``: the screws
    ``S`` (N, 6, F) as (6, F, N), sample last (computed once per mode when U is None)."""
    scale = _scale(L)
    if U is None:  # the constraint screws themselves, sample last
        St = St if St is not None else np.ascontiguousarray(np.moveaxis(S, 0, -1))
        Mt = St[:, cons] * scale[:, None, None]  # (6, k, N)
    else:
        M = np.einsum("nir,nik->nrk", U, S[:, :, cons] * scale[None, :, None])  # (N, r, k)
        Mt = np.ascontiguousarray(np.moveaxis(M, 0, -1))
    g, unique = _null_vector(Mt)  # g ⟂ columns of M
    swap = np.concatenate([np.arange(3, 6), np.arange(3)])
    w_scaled = (g if U is None else np.einsum("nir,nr->ni", U, g))[:, swap]  # Δ U g
    w = w_scaled * np.array([1, 1, 1, L, L, L])[None, :]
    w[~unique] = np.nan
    return np.asarray(w)


def rod_wrench(linkage: Linkage, cons_joints: set[int], centres: Array) -> Array | None:
    """The transmission wrench (N, 6; f, m about the ground origin) in closed form where the
    coupler chain is one S–S rod (the constraint freedoms are the six of two neighbouring ball
    joints): a rod between two balls passes only a force along the line of their centres
    (reciprocal to every rotation about either centre), w = (u, c × u) with u the unit vector
    from one centre to the other — the one-dimensional null space :func:`_wrench_nullspace`
    finds by an SVD per sample. None for any other chain, or where the centres meet (no
    line)."""
    if len(cons_joints) != 2:
        return None
    i, j = sorted(cons_joints)
    if j != i + 1 or linkage.joints[i].kind != "S" or linkage.joints[j].kind != "S":
        return None
    d = centres[:, j] - centres[:, i]
    length = np.linalg.norm(d, axis=-1)
    if not np.all(length[np.isfinite(length)] > 1e-9 * linkage.length_scale):
        return None
    u = d / length[:, None]
    return np.asarray(np.concatenate([u, np.cross(centres[:, i], u)], axis=-1))


def _index(w: Array, twist: Array, joint_point: Array, joint_axis: Array | None,
           L: float) -> Array:
    """Sutherland–Roth transmission index of wrenches ``w`` (N, 6) on output twists (N, 6)."""
    f, m = w[:, :3], w[:, 3:]
    om, v0 = twist[:, :3], twist[:, 3:]
    fn = np.linalg.norm(f, axis=-1)
    couple = fn <= 1e-9 * np.linalg.norm(m, axis=-1) / L
    fs = np.where(couple, 1.0, fn)
    fhat = f / fs[:, None]
    pitch = np.einsum("ni,ni->n", f, m) / fs**2
    p0 = np.cross(f, m) / fs[:, None] ** 2  # the wrench axis' point nearest the origin
    if joint_axis is None:
        t = np.einsum("ni,ni->n", joint_point - p0, fhat)
    else:  # nearest point of the wrench axis to the joint axis (common normal's foot)
        b = np.einsum("ni,ni->n", fhat, joint_axis)
        d = p0 - joint_point
        denom = np.where(np.abs(1 - b * b) < 1e-12, 1.0, 1 - b * b)
        t = np.where(np.abs(1 - b * b) < 1e-12, -np.einsum("ni,ni->n", d, fhat),
                     (b * np.einsum("ni,ni->n", d, joint_axis) - np.einsum("ni,ni->n", d, fhat))
                     / denom)
    P = p0 + t[:, None] * fhat
    vel = v0 + np.cross(om, P) + pitch[:, None] * om
    with np.errstate(divide="ignore", invalid="ignore"):  # P on the output axis: no index (NaN)
        ti = np.abs(np.einsum("ni,ni->n", fhat, vel)) / np.linalg.norm(vel, axis=-1)
    mhat = m / np.maximum(np.linalg.norm(m, axis=-1, keepdims=True), 1e-300)
    on = np.linalg.norm(om, axis=-1)
    by_couple = np.where(on > 0, np.abs(np.einsum("ni,ni->n", mhat, om)) / np.where(on > 0, on, 1),
                         0.0)
    return np.asarray(np.where(couple, by_couple, ti))


def smallest_cone(directions: Array) -> tuple[Array, float]:
    """The axis (3,) and half-angle (rad) of the smallest cone containing unit ``directions``
    (K, 3): the axis is the normalised minimum-norm point of their convex hull (that point
    maximises the smallest a·v_i over unit a), found as a non-negative least-squares problem.

    The problem is solved on a working set (a few hundred evenly spread directions, then every
    direction the cone leaves out, until it leaves none out): an axis a that maximises the
    smallest a·v over a subset and gives no smaller a·v over the whole set maximises it over the
    whole set (a subset's optimum is at least the set's), so the answer is the whole set's
    while the least-squares problem stays small on a sweep of 10⁵ samples."""
    V = directions[np.isfinite(directions).all(axis=1)]
    if V.shape[0] == 0:
        return np.full(3, np.nan), float("nan")
    work = _distinct(np.linspace(0, V.shape[0] - 1, min(V.shape[0], 256)).astype(int))
    while True:
        p = _hull_min_norm_point(V[work])
        if np.linalg.norm(p) < 1e-9:  # the directions surround the centre: wider than 90°
            p = _hull_min_norm_point(V) if work.size < V.shape[0] else p
            if np.linalg.norm(p) < 1e-9:
                p = V.mean(axis=0) if np.linalg.norm(V.mean(axis=0)) > 1e-9 else V[0]
            break
        a = p / np.linalg.norm(p)
        dots = V @ a
        outside = np.flatnonzero(dots < np.min(dots[work]) - 1e-12)
        if outside.size == 0:
            break
        worst = outside[np.argsort(dots[outside])[:256]]
        work = _distinct(np.concatenate([work, worst]))
    axis = p / np.linalg.norm(p)
    return axis, float(np.arccos(np.clip(np.min(V @ axis), -1.0, 1.0)))


def _distinct(indices: Array) -> Array:
    """The distinct values of an integer array, sorted (``np.unique``'s result, without the
    import of numpy.ma that ``np.unique`` makes: 35 ms of ``analyze``'s start-up)."""
    s = np.sort(indices)
    return np.asarray(s[np.concatenate([[True], s[1:] != s[:-1]])]) if s.size else s


def _hull_min_norm_point(V: Array) -> Array:
    """The minimum-norm point of the convex hull of the rows of V: non-negative least squares
    with the weights' sum held to 1 by a heavy row (:func:`nonnegative_least_squares`)."""
    big = 1e4
    A = np.vstack([V.T, big * np.ones((1, V.shape[0]))])
    lam = nonnegative_least_squares(A, np.array([0.0, 0.0, 0.0, big]), 50 * V.shape[0])
    return np.asarray(V.T @ (lam / lam.sum()))


def nonnegative_least_squares(A: Array, b: Array, max_iterations: int) -> Array:
    """min ‖Ax − b‖ over x ≥ 0: the active-set method of Lawson & Hanson ("Solving Least
    Squares Problems", 1974, ch. 23; scipy.optimize.nnls implements the same method). Written
    here for the few rows of the smallest-cone problem, whose passive set stays small, so that
    analyze does not import scipy.optimize (0.3 s of start-up). A passive set met a second time
    ends it: the method then cycles on round-off at the optimum (seen on the RSSR example with
    d2 = 103 mm: 12 800 iterations, 1 s, for the answer of the first)."""
    m, n = A.shape
    x = np.zeros(n)
    passive = np.zeros(n, dtype=bool)
    tol = 10 * np.finfo(float).eps * np.linalg.norm(A, 1) * max(m, n)
    w = A.T @ (b - A @ x)
    seen: set[bytes] = set()
    for _ in range(max_iterations):
        if passive.all() or not (w[~passive] > tol).any():
            break
        # a passive set met again: the method cycles on round-off at the optimum (a multiplier
        # of a tied constraint a hair over tol), where x already is the solution
        key = np.packbits(passive).tobytes()
        if key in seen:
            break
        seen.add(key)
        passive[int(np.argmax(np.where(passive, -np.inf, w)))] = True
        while True:
            z = np.zeros(n)
            z[passive] = np.linalg.lstsq(A[:, passive], b, rcond=None)[0]
            if (z[passive] > 0).all():
                x = z
                break
            shrink = passive & (z <= 0)
            alpha = np.min(x[shrink] / (x[shrink] - z[shrink]))
            x = x + alpha * (z - x)
            passive &= x > tol
            x[~passive] = 0.0
        w = A.T @ (b - A @ x)
    return x


def _idle(linkage: Linkage, link: int) -> bool:
    """Whether moving link ``link`` lies between two ball joints (it spins idly)."""
    n = len(linkage.joints)
    return 0 <= link < n - 1 and linkage.joints[link].kind == "S" == linkage.joints[link + 1].kind


def _cones(linkage: Linkage, md: ModeMotion) -> tuple[dict[str, Array], dict[str, Array],
                                                       dict[str, float]]:
    n = len(linkage.joints)
    N = md.assembles.shape[0]
    L = linkage.length_scale
    c = md.joint_centres
    ground = np.broadcast_to(linkage.base.real, (N, 3, 3))
    angle, axis, limit = {}, {}, {}
    for i, joint in enumerate(linkage.joints):
        if joint.kind != "S":
            continue
        # (frame of the link that holds the socket, stem = the other link's line at the ball)
        prox = (md.link_rotation[:, i - 1] if i > 0 else ground, c[:, i - 1] - c[:, i])
        dist = (md.link_rotation[:, i] if i < n - 1 else ground, c[:, (i + 1) % n] - c[:, i])
        choices = [(prox[0], dist[1]), (dist[0], prox[1])]  # socket on proximal, else distal
        if _idle(linkage, i - 1):  # never hold the socket on an idly spinning rod
            choices = choices[1:]
        elif _idle(linkage, i):
            choices = choices[:1]
        usable = [(R, stem) for R, stem in choices
                  if np.nanmin(np.linalg.norm(stem[md.assembles], axis=-1), initial=np.inf)
                  > 1e-9 * L]
        if not usable or not md.assembles.any():
            continue
        R, stem = usable[0]
        stem = stem / np.linalg.norm(stem, axis=-1, keepdims=True)
        local = np.einsum("nji,nj->ni", R, stem)
        a, lim = smallest_cone(local[md.assembles])
        angle[joint.name] = np.arccos(np.clip(local @ a, -1.0, 1.0))
        axis[joint.name], limit[joint.name] = a, lim
    return angle, axis, limit


def transmission(motion: Motion, *, cones: bool = True) -> Transmission:
    """Transmission index of every output, transmission angle (planar loops) and ball-joint
    cone angles over every mode of ``motion`` (module docstring). A ValueError says why a loop
    has none (its input is not on the ground, so it has no output joint). ``cones=False``
    leaves out the cone angles (their smallest cones are a third of the time; the studio's
    curves do not show them): the index and angle are the same numbers."""
    expect_instance(motion, Motion, "transmission: motion", "a solved Motion (sk.solve_motion(...))")
    linkage = motion.linkage
    lay = layout(linkage)
    n = len(linkage.joints)
    out_j = output_joint(linkage)
    drive = n - 2 if out_j == n - 1 else 1
    outputs = default_outputs(linkage)
    in_joints = {name.split(".")[0] for name in linkage.inputs}
    L = linkage.length_scale
    modes = []
    planar = False
    for md in motion.modes:
        planar = _planar(linkage, md)
        # screws, centres and axes in the ground frame (the link frames are not needed)
        fr = forward(linkage, md.conf, lay, frames=False, points=True)
        S = fr.screws
        U = _twist_space(S, L)
        St = np.ascontiguousarray(np.moveaxis(S, 0, -1)) if U is None else None
        index: dict[str, Array] = {}
        for name in outputs:
            freedom, _ = output_freedom(linkage, name)
            f_out = lay.names.index(freedom)
            cons = [k for k, fname in enumerate(lay.names)
                    if fname.split(".")[0] not in in_joints and k != f_out]
            w = rod_wrench(linkage, {lay.joint_of[k] for k in cons}, fr.centres)
            if w is None:
                w = _wrench_nullspace(S, cons, L, U, St)
            kind = linkage.joints[drive].kind
            axis = None if kind in ("S", "U") else fr.axes[:, drive]
            ti = _index(w, S[:, :, f_out], fr.centres[:, drive], axis, L)
            ti[~md.assembles] = np.nan
            index[name] = ti
        angle = None
        if planar and linkage.joints[out_j].kind == "R" and linkage.joints[drive].kind == "R":
            before = drive - 1 if out_j == n - 1 else drive + 1
            c = md.joint_centres
            ba, bo = c[:, before] - c[:, drive], c[:, out_j] - c[:, drive]
            cos_mu = np.einsum("ni,ni->n", ba, bo) / (np.linalg.norm(ba, axis=-1)
                                                      * np.linalg.norm(bo, axis=-1))
            angle = np.arccos(np.clip(cos_mu, -1.0, 1.0))
        cone_angle, socket, limit = _cones(linkage, md) if cones else ({}, {}, {})
        modes.append(ModeTransmission(md.index, index, angle, cone_angle, socket, limit))
    return Transmission(outputs, linkage.joints[out_j].name, linkage.joints[drive].name, planar,
                        modes)

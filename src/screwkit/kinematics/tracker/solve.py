"""Generic position solver for any single loop: damped Newton on the loop-closure equation
(Bagci 1969 §3.3, eqs. 3.19–3.48, the reduced form Σ ĥ_i Q̂_i = Ĝᵀ − I, here with the exact
SE(3) logarithm as residual and minimum-norm steps), started from many points to find every
assembly mode. Batched over samples × starts; no Python loop over samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    Layout,
    apply_increment,
    closure_error,
    closure_twist,
    constants,
    forward,
    layout,
)
from screwkit.model.linkage import Linkage

CLOSURE_TOL = 1e-11  # residual (radians, and lengths / length scale) accepted as closed
POLISHED = 1e-15  # the corrector stops early below this (round-off)


@dataclass(frozen=True)
class NewtonResult:
    conf: Configuration
    residual: Array  # (N,) closure error: max(|rotation|, |translation| / length scale)
    converged: NDArray[np.bool_]
    iterations: int


def _scales(lay: Layout, L: float) -> tuple[Array, Array]:
    rows = np.array([1.0, 1.0, 1.0, 1.0 / L, 1.0 / L, 1.0 / L])
    cols = np.array([L if t else 1.0 for t in lay.is_translation])
    return rows, cols


def set_inputs(conf: Configuration, lay: Layout, input_names: tuple[str, ...], values: Array) -> Configuration:
    q = conf.scalars.copy()
    for k, name in enumerate(input_names):
        q[:, lay.scalar_col[lay.names.index(name)]] = values[:, k]
    return Configuration(q, conf.spherical)


def newton(
    linkage: Linkage,
    conf: Configuration,
    max_iter: int = 60,
    tol: float = CLOSURE_TOL,
    max_step: float = 0.5,
    lay: Layout | None = None,
) -> NewtonResult:
    """Close the loop from ``conf`` by damped Gauss–Newton with minimum-norm steps over the
    passive freedoms (inputs are held). Works on every sample at once; each iteration touches
    only the samples that have not converged or stalled.

    The step is δ = −Jᵀ(JJᵀ + μI)⁻¹ξ with a tiny μ (10⁻¹² of the largest eigenvalue): the
    minimum-norm Gauss–Newton step, also where J has fewer independent rows than 6 (a planar
    loop seen in space)."""
    lay = lay or layout(linkage)
    L = constants(linkage, lay)[2]
    rows, cols = _scales(lay, L)
    passive = np.array([n not in linkage.inputs for n in lay.names])
    pidx = np.nonzero(passive)[0]
    N = conf.size
    q = conf.scalars.copy()
    sph = conf.spherical.copy()
    res = np.full(N, np.inf)
    best = np.full(N, np.inf)
    stall = np.zeros(N, dtype=int)
    todo = np.arange(N)
    it = 0
    for it in range(1, max_iter + 1):  # noqa: B007 - loop over iterations, vectorised over samples
        sub = Configuration(q[todo], sph[todo])
        fr = forward(linkage, sub, lay, frames=False)
        xi = closure_twist(fr.closure_R, fr.closure_p) * rows
        r = np.max(np.abs(xi), axis=-1)
        res[todo] = r
        improved = r < 0.5 * best[todo]
        stall[todo] = np.where(improved, 0, stall[todo] + 1)
        best[todo] = np.minimum(best[todo], r)
        keep = (r > tol) & (stall[todo] < 8)
        if not np.any(keep):
            break
        todo, xi, fr_screws = todo[keep], xi[keep], fr.screws[keep]
        J = fr_screws[:, :, pidx] * rows[:, None] * cols[pidx][None, :]
        JJt = J @ np.swapaxes(J, -1, -2)
        mu = 1e-12 * np.maximum(np.trace(JJt, axis1=-2, axis2=-1), 1e-300)
        A = JJt + mu[:, None, None] * np.eye(6)
        y = np.linalg.solve(A, xi[..., None])[..., 0]
        step = -np.einsum("nji,nj->ni", J, y)
        big = np.max(np.abs(step), axis=-1, keepdims=True)
        step *= np.minimum(1.0, max_step / np.maximum(big, 1e-300))
        delta = np.zeros((len(todo), len(lay.names)))
        delta[:, pidx] = step * cols[pidx]
        moved = apply_increment(Configuration(q[todo], sph[todo]), delta, lay)
        q[todo] = moved.scalars
        sph[todo] = moved.spherical
    else:
        sub = Configuration(q[todo], sph[todo])
        fr = forward(linkage, sub, lay, frames=False)
        res[todo] = np.max(np.abs(closure_twist(fr.closure_R, fr.closure_p) * rows), axis=-1)
    ok = np.isfinite(res) & (res <= max(tol * 10, 1e-10))
    return NewtonResult(Configuration(q, sph), res, ok, it)


@dataclass(frozen=True)
class Correction:
    """The corrector's verdict on a batch of predicted configurations (:func:`correct`)."""

    conf: Configuration
    accepted: NDArray[np.bool_]  # converged and passed the contraction test


def polish_verdict(r: Array, todo: NDArray[np.intp], last: Array, done: NDArray[np.bool_],
                   tol: float) -> NDArray[np.bool_]:
    """One corrector iteration's residuals ``r`` of the predictions ``todo``: marks those within
    ``tol`` in ``done``, keeps ``r`` in ``last``, and says which take another Newton step (within
    tolerance, one more quadratically converging step polishes to round-off; stop when that no
    longer gains a digit)."""
    fine = (r <= POLISHED) | ((r <= tol) & (r > 0.1 * last[todo]))
    last[todo] = r
    done[todo[r <= tol]] = True
    return np.asarray(~fine & np.isfinite(r))


def step_verdict(it: int, step: Array, todo: NDArray[np.intp], total: Array, first: Array,
                 reach: Array, limit: Array) -> NDArray[np.bool_]:
    """Which Newton steps ``step`` of iteration ``it`` keep their predictions hopeful (adding
    them to ``total``, the first one's size to ``first``): the first within ``reach``, all
    together within 1.5 ``reach``, the second at most ``limit`` times the first (Deuflhard's
    contraction test)."""
    size = np.linalg.norm(step, axis=-1)
    total[todo] += step
    if it == 0:
        first[todo] = size
        return np.asarray(size <= reach[todo])
    hopeful = np.linalg.norm(total[todo], axis=-1) <= 1.5 * reach[todo]
    if it == 1:
        hopeful &= size <= limit[todo] * np.maximum(first[todo], 1e-12)
    return np.asarray(hopeful)


def correct(linkage: Linkage, conf: Configuration, lay: Layout, reach: Array,
            contraction: float | Array = 0.5, max_iter: int = 7, tol: float = CLOSURE_TOL,
            ) -> Correction:
    """Newton corrector of a continuation step (inputs held): minimum-norm Gauss–Newton steps
    over the passive freedoms, vectorised over the batch, without damping.

    A prediction is accepted when Newton converges to ``tol`` within ``max_iter`` steps, its
    first step stays within ``reach`` (N,) (scaled freedoms), all its steps together within
    1.5 ``reach``, and the
    second step is at most ``contraction`` (a number or one per prediction) times the first
    — Deuflhard's contraction test: a
    prediction inside the branch's basin of quadratic convergence contracts fast, a jump
    towards another branch does not. Predictions that fail a test are dropped at once."""
    L = constants(linkage, lay)[2]
    rows, cols = _scales(lay, L)
    pidx = np.array([k for k, n in enumerate(lay.names) if n not in linkage.inputs])
    N = conf.size
    q = conf.scalars.copy()
    sph = conf.spherical.copy()
    limit = np.broadcast_to(np.asarray(contraction, dtype=float), (N,))
    first = np.zeros(N)
    total = np.zeros((N, len(pidx)))
    done = np.zeros(N, dtype=bool)
    last = np.full(N, np.inf)
    todo = np.arange(N)
    for it in range(max_iter + 1):
        fr = forward(linkage, Configuration(q[todo], sph[todo]), lay, frames=False)
        xi = closure_error(fr.closure_R, fr.closure_p) * rows
        r = np.max(np.abs(xi), axis=-1)
        keep = polish_verdict(r, todo, last, done, tol)
        if it == max_iter or not keep.any():
            break
        done[todo[keep]] = False  # a polishing step must succeed too
        todo, xi = todo[keep], xi[keep]
        J = fr.screws[keep][:, :, pidx] * rows[:, None] * cols[pidx][None, :]
        JJt = J @ np.swapaxes(J, -1, -2)
        mu = 1e-13 * np.maximum(np.trace(JJt, axis1=-2, axis2=-1), 1e-300)
        y = np.linalg.solve(JJt + mu[:, None, None] * np.eye(6), xi[..., None])[..., 0]
        step = -np.einsum("nji,nj->ni", J, y)
        hopeful = step_verdict(it, step, todo, total, first, reach, limit)
        if not hopeful.all():
            todo, step = todo[hopeful], step[hopeful]
            if todo.size == 0:
                break
        delta = np.zeros((len(todo), len(lay.names)))
        delta[:, pidx] = step * cols[pidx]
        moved = apply_increment(Configuration(q[todo], sph[todo]), delta, lay)
        q[todo] = moved.scalars
        sph[todo] = moved.spherical
    return Correction(Configuration(q, sph), done)


def random_configurations(linkage: Linkage, count: int, rng: np.random.Generator, lay: Layout | None = None) -> Configuration:
    """``count`` random starting configurations: angles uniform in (−π, π], translations
    uniform within ± the length scale, spherical joints uniformly random rotations."""
    lay = lay or layout(linkage)
    L = constants(linkage, lay)[2]
    q = np.empty((count, lay.n_scalar))
    for f in range(len(lay.names)):
        c = lay.scalar_col[f]
        if c < 0:
            continue
        if lay.is_translation[f]:
            q[:, c] = rng.uniform(-L, L, count)
        else:
            q[:, c] = rng.uniform(-np.pi, np.pi, count)
    sph = np.empty((count, lay.n_spherical, 3, 3))
    from scipy.spatial.transform import Rotation  # on first use (start-up time)

    for k in range(lay.n_spherical):
        sph[:, k] = Rotation.random(count, random_state=rng).as_matrix()
    return Configuration(q, sph)


def signature(linkage: Linkage, conf: Configuration, lay: Layout | None = None) -> Array:
    """A vector per sample that identifies an assembly up to passive freedoms: every joint
    centre (divided by the length scale) and every non-spherical joint axis, in the ground
    frame. Two configurations with the same signature are the same assembly."""
    lay = lay or layout(linkage)
    fr = forward(linkage, conf, lay)
    L = constants(linkage, lay)[2]
    parts = [fr.centres.reshape(conf.size, -1) / L]
    ax = [fr.axes[:, i] for i, j in enumerate(linkage.joints) if j.kind != "S"]
    if ax:
        parts.append(np.concatenate(ax, -1))
    return np.concatenate(parts, -1)


@dataclass(frozen=True)
class Assemblies:
    """Every assembly found at each sample: ``conf`` (N, K) flattened as N*K samples with
    ``found`` (N, K) saying which slots hold a distinct closed configuration."""

    conf: Configuration
    found: NDArray[np.bool_]
    signature: Array  # (N, K, d)
    radius: Array  # (N, K) signature distance within which another root is the same one


def find_assemblies(
    linkage: Linkage,
    input_values: Array,
    starts: int = 48,
    seed: int = 0,
    max_modes: int = 16,
    tol_same: float = 1e-6,
) -> Assemblies:
    """All assembly modes at each row of ``input_values`` (N, n_inputs), by Newton from
    ``starts`` random points per sample, vectorised over samples × starts. Returns at most
    ``max_modes`` distinct assemblies per sample (by :func:`signature`)."""
    values = np.atleast_2d(np.asarray(input_values, dtype=float))
    chunk = max(1, 65536 // max(starts, 1))  # bounded memory: ~65k Newton problems at a time
    if values.shape[0] > chunk:
        parts = [find_assemblies(linkage, values[i:i + chunk], starts, seed + i, max_modes, tol_same)
                 for i in range(0, values.shape[0], chunk)]
        return Assemblies(
            Configuration(np.concatenate([p.conf.scalars for p in parts]),
                          np.concatenate([p.conf.spherical for p in parts])),
            np.concatenate([p.found for p in parts]),
            np.concatenate([p.signature for p in parts]),
            np.concatenate([p.radius for p in parts]),
        )
    lay = layout(linkage)
    N = values.shape[0]
    rng = np.random.default_rng(seed)
    conf0 = random_configurations(linkage, N * starts, rng, lay)
    conf0 = set_inputs(conf0, lay, linkage.inputs, np.repeat(values, starts, axis=0))
    return assemblies_from(linkage, conf0, starts, max_modes, tol_same)


def assemblies_from(linkage: Linkage, conf0: Configuration, starts: int, max_modes: int = 16,
                    tol_same: float = 1e-6) -> Assemblies:
    """The distinct assemblies Newton reaches from given starting configurations, ``starts``
    consecutive rows per sample (inputs already set): :func:`find_assemblies` from chosen
    starts."""
    lay = layout(linkage)
    N = conf0.size // starts
    res = newton(linkage, conf0, max_iter=50, lay=lay)
    fr = forward(linkage, res.conf, lay)
    sig = signature(linkage, res.conf, lay).reshape(N, starts, -1)
    ok = res.converged.reshape(N, starts)
    # Near a double root (a limit position) the closure error grows only quadratically with
    # the distance from the root, so Newton's roots scatter by ~√tolerance: merge within that
    # wider radius where the passive Jacobian is near-singular.
    rows, cols = _scales(lay, constants(linkage, lay)[2])
    pidx = [k for k, n in enumerate(lay.names) if n not in linkage.inputs]
    Jp = fr.screws[:, :, pidx] * rows[None, :, None] * cols[pidx][None, None, :]
    sv = np.linalg.svd(Jp, compute_uv=False)
    generic_rank = int(np.max(np.sum(sv > 1e-6 * sv[:, :1], axis=-1)))
    weakest = sv[:, generic_rank - 1] / sv[:, 0] if generic_rank > 0 else np.ones(len(sv))
    radius = np.where(weakest < 1e-3, np.sqrt(tol_same) * 3e-2, tol_same).reshape(N, starts)
    # de-duplicate within each sample: keep the first of every cluster (vectorised pairwise)
    d = np.max(np.abs(sig[:, :, None, :] - sig[:, None, :, :]), axis=-1)  # (N, K, K)
    near = np.maximum(radius[:, :, None], radius[:, None, :])
    same = (d < near) & ok[:, None, :] & ok[:, :, None]
    earlier = np.tril(np.ones((starts, starts), dtype=bool), k=-1)
    dup = np.any(same & earlier[None], axis=-1)
    keep = ok & ~dup
    # compact to max_modes slots
    order = np.argsort(~keep, axis=1, kind="stable")[:, :max_modes]
    found = np.take_along_axis(keep, order, axis=1)
    flat = (np.arange(N)[:, None] * starts + order).ravel()
    conf = res.conf.take(flat)
    sig_k = np.take_along_axis(sig, order[..., None], axis=1)
    return Assemblies(conf, found, sig_k, np.take_along_axis(radius, order, axis=1))

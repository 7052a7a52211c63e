"""Singularities of a mechanism graph along its motion: condition numbers and classes.

Three matrices are read at every sample, each scaled as the tracker scales them
(graph/newton.py: rotations in rad, lengths over the length scale), each against the rank it
has at the drawing (idle freedoms such as a rod's spin and redundant constraints excluded):

- the passive block J_p of the stacked screw Jacobian J = [J_in J_p] (inputs held);
- the whole closure Jacobian J (the loop constraints themselves);
- for a mechanism with a platform (the body other than the ground with the most joints, at
  least three), the Jacobian with the platform held, M = [J; K], K the platform's twist
  (angular velocity and the velocity of its joints' centroid, over the length scale) as a
  linear map of every freedom's rate along the spanning tree.

``jacobian_condition`` holds σ₁/σ_r of each (r its rank at the drawing; at most 1/ε, ε the
machine epsilon, where σ_r vanishes to round-off):
``passive``, ``closure`` and, with a platform, ``platform_held``. A sample is singular for
one of them where 1/condition falls below :data:`SINGULAR_TOL`. The class
(Gosselin & Angeles 1990, "Singularity analysis of closed-loop kinematic chains", IEEE Trans.
Robot. Autom. 6(3); Zlatanov, Fenton & Benhabib 1995 for constraint singularities):

- **input** (serial, type I; platforms): M loses rank and its null motion moves an input:
  an input turns with the platform held, a leg loses a freedom (a leg stretched straight);
- **output** (parallel, type II; platforms): J_p loses rank, J keeps it, and J_p's null motion
  moves the platform: it gains a freedom with the inputs held;
- **constraint** (platforms): J itself loses rank (the loop constraints become dependent);
- **dead centre** (no platform, or a null motion that leaves the platform still): J_p loses
  rank and J keeps it: the inputs cannot drive the mechanism there (a limit of the input);
- **bifurcation** (change point; no platform): J_p and J both lose rank, branches cross.

Rates are undefined (NaN) where J_p loses rank (graph/motion.py); at an input singularity they
exist and are kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphFrames, GraphLayout
from screwkit.kinematics.graph.newton import (
    RANK_CUTOFF,
    Linearised,
    column_scale,
    drawn_linearisation,
    gram_sigma,
    linearise,
)
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]

#: a matrix is singular at a sample where σ_r/σ₁ falls below this (graph/motion.py's flag)
SINGULAR_TOL = 1e-7
#: a null motion moves a body or an input where its part there exceeds this (unit null vector)
MOVES = 1e-4

CLASS_TEXT = {
    "input": "an input singularity (serial, type I): {moving} turn with the platform held, "
             "a leg loses a freedom",
    "output": "an output singularity (parallel, type II): the platform gains a freedom "
              "(joints {moving} move with the inputs held)",
    "constraint": "a constraint singularity: the loop constraints become dependent (joints "
                  "{moving} move with the inputs held)",
    "dead centre": "a dead centre of loop {loop} (joints {moving} move with the inputs held)",
    "dead centre of the mechanism": "a dead centre of the mechanism: the inputs cannot drive "
                                    "it here (joints {moving} move with the inputs held)",
    "bifurcation": "a bifurcation (change point): the branches cross and the loop constraints "
                   "become dependent (joints {moving} move with the inputs held)",
}


def platform_body(mech: Mechanism) -> str | None:
    """The platform: the body other than the ground with the most joints, if it has ≥ 3."""
    count = {b.name: sum(b.name in j.bodies for j in mech.joints) for b in mech.bodies}
    if not count:
        return None
    best = max(count, key=lambda b: count[b])
    return best if count[best] >= 3 else None


def platform_jacobian(mech: Mechanism, lay: GraphLayout, fr: GraphFrames, body: str) -> Array:
    """K (N, 6, m): the twist of ``body`` (ω; the velocity of its joints' centroid) per unit
    rate of every freedom, Σ ± S_f along the spanning tree from the ground, scaled as J."""
    parent = {child: (k, par) for k, par, child in mech.topology.tree}
    N = fr.screws.shape[0]
    K = np.zeros((N, 6, lay.m))
    b = body
    while b != GROUND:
        k, par = parent[b]
        sign = 1.0 if mech.joints[k].bodies[0] == par else -1.0
        f0 = lay.first_freedom[k]
        n = len(mech.joints[k].freedoms)
        K[:, :, f0:f0 + n] += sign * fr.screws[:, :, f0:f0 + n]
        b = par
    mine = [i for i, j in enumerate(mech.joints) if body in j.bodies]
    c = fr.centres[:, mine].mean(axis=1)[:, :, None]
    w = K[:, :3]
    K[:, 3:] += np.stack([w[:, 1] * c[:, 2] - w[:, 2] * c[:, 1],  # v_c = v₀ + ω × c
                          w[:, 2] * c[:, 0] - w[:, 0] * c[:, 2],
                          w[:, 0] * c[:, 1] - w[:, 1] * c[:, 0]], axis=1)
    K[:, 3:] /= lay.length
    K *= column_scale(lay)[None, None, :]
    return K


@dataclass(frozen=True)
class Singularities:
    """Per sample (N): ``condition`` (name → σ₁/σ_r, NaN where not assembled), ``kind`` the
    class ("" where regular; module docstring) and ``text`` its description."""

    condition: dict[str, Array]
    kind: NDArray[np.str_]
    text: list[str]


def _ranks(mech: Mechanism, lay: GraphLayout, platform: str | None,
           drawn: Linearised | None) -> tuple[int, int, int]:
    """The ranks of J_p, J and M at the drawing (``drawn``: its linearisation, if made)."""
    lin = drawn if drawn is not None else drawn_linearisation(mech, lay)
    out = []
    mats = [lin.Jp, lin.J]
    if platform is not None:
        mats.append(np.concatenate([lin.J, platform_jacobian(mech, lay, lin.frames, platform)],
                                   axis=1))
    for A in mats:
        s = np.linalg.svd(A[0], compute_uv=False) if A.size else np.zeros(0)
        out.append(int(np.sum(s > RANK_CUTOFF * max(float(s[0]) if s.size else 0.0, 1e-300))))
    return out[0], out[1], out[2] if len(out) > 2 else 0


def _condition(s: Array, r: int) -> Array:
    """σ₁/σ_r (N,) from singular values s (N, k), largest first (at most 1/ε)."""
    if r == 0 or s.shape[1] == 0:
        return np.ones(s.shape[0])
    tiny = np.maximum(s[:, 0] * np.finfo(float).eps, 1e-300)
    return np.asarray(s[:, 0] / np.maximum(s[:, r - 1], tiny))


def _null(A: Array, r: int) -> Array:
    """The right singular vectors (n, cols) of σ_r of A (n, …): the motion a rank loss frees."""
    if A.shape[0] == 0:
        return np.zeros((0, A.shape[2]))
    return np.asarray(np.linalg.svd(A, full_matrices=False)[2][:, max(r - 1, 0)])


def singularities(mech: Mechanism, lay: GraphLayout, conf: Configuration,
                  mask: NDArray[np.bool_], lin: Linearised | None = None,
                  drawn: Linearised | None = None) -> Singularities:
    """The condition numbers and singular classes of ``conf`` (N) where ``mask`` holds
    (``lin``: its exact linearisation at every sample, when already made: its passive
    singular values are reused; ``drawn``: newton.drawn_linearisation, when already made).
    Singular values at every sample, singular vectors only at
    the singular ones."""
    N = conf.size
    platform = platform_body(mech)
    rp, rJ, rM = _ranks(mech, lay, platform, drawn)
    kind = np.full(N, "", dtype=object)
    text = [""] * N
    names = ["passive", "closure"] + (["platform_held"] if platform else [])
    condition = {n: np.full(N, np.nan) for n in names}
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return Singularities(condition, kind.astype(str), text)
    idx_in: slice | NDArray[np.intp]
    if lin is None:
        lin = linearise(mech, lay, conf.take(idx))
        idx_in = slice(None)
    else:  # every sample assembled: views, not copies
        idx_in = slice(None) if idx.size == N else idx
    J, Jp = lin.J[idx_in], lin.Jp[idx_in]
    passive, inputs = list(lay.passive), list(lay.inputs)
    sp = lin.sigma[idx_in] if lin.sigma.shape[1] == min(Jp.shape[1:]) else \
        np.linalg.svd(Jp, compute_uv=False)
    cp = _condition(np.asarray(sp, dtype=float), rp)
    cJ = _condition(gram_sigma(J, rJ), rJ)  # the SVD's values near singular
    p_sing = ~(1.0 / cp > SINGULAR_TOL)
    at = np.flatnonzero(p_sing)  # exact singular values where the rank is in question
    if at.size:
        cJ[at] = _condition(np.asarray(np.linalg.svd(J[at], compute_uv=False)), rJ)
    condition["passive"][idx], condition["closure"][idx] = cp, cJ
    K = M = None
    cM = np.zeros(0)
    if platform is not None:
        fr = lin.frames
        K = platform_jacobian(mech, lay, GraphFrames(
            fr.R, fr.p, fr.screws[idx_in], fr.residual, fr.centres[idx_in], fr.axes),
            platform)
        M = np.concatenate([J, K], axis=1)
        cM = _condition(gram_sigma(M, rM), rM)  # the SVD's values near singular
        condition["platform_held"][idx] = cM
    J_sing = ~(1.0 / cJ > SINGULAR_TOL)
    M_sing = ~(1.0 / cM > SINGULAR_TOL) if K is not None else np.zeros(idx.size, bool)
    loops = [{k for k, _ in loop} for loop in mech.topology.loops]

    def moving(v: Array, cols: list[int]) -> set[int]:
        a = np.abs(v)
        return {lay.joint_of[cols[c]] for c in np.flatnonzero(a > 0.05 * a.max())}

    def named(js: set[int]) -> str:
        return ", ".join(mech.joints[j].name for j in sorted(js))

    flagged = np.flatnonzero(p_sing | M_sing)  # the singular samples only
    vp = dict(zip(flagged.tolist(), _null(Jp[flagged], rp), strict=True))
    vM = dict(zip(flagged.tolist(), _null(M[flagged], rM), strict=True)) if M is not None \
        else {}
    for n in flagged.tolist():
        k = int(idx[n])
        if p_sing[n]:
            joints = moving(vp[n], passive)
            if K is not None:
                moves = float(np.linalg.norm(K[n][:, passive] @ vp[n])) > MOVES
                c = "constraint" if J_sing[n] else ("output" if moves else "dead centre")
            else:
                c = "bifurcation" if J_sing[n] else "dead centre"
            inside = [l for l, js in enumerate(loops) if joints <= js]
            if c == "dead centre" and len(inside) != 1:
                c = "dead centre of the mechanism"
            kind[k] = "dead centre" if c.startswith("dead centre") else c
            text[k] = CLASS_TEXT[c].format(moving=named(joints),
                                           loop=inside[0] + 1 if inside else "")
        else:
            part = vM[n][inputs]
            if float(np.linalg.norm(part)) > MOVES:
                kind[k] = "input"
                text[k] = CLASS_TEXT["input"].format(moving=", ".join(
                    mech.inputs[i] for i in np.flatnonzero(np.abs(part) > 0.05 *
                                                           np.abs(part).max())))
    return Singularities(condition, kind.astype(str), text)


def singular_events(X_text: dict[int, str], sing: Singularities) -> list[str]:
    """Events for the samples with a class: consecutive samples of one description together,
    each with the inputs where it holds (``X_text`` formats sample k's inputs)."""
    idx = np.flatnonzero(sing.kind != "")
    events: list[str] = []
    start = 0
    for k in range(1, len(idx) + 1):
        if k == len(idx) or sing.text[idx[k]] != sing.text[idx[start]] or \
                idx[k] != idx[k - 1] + 1:
            a, b = int(idx[start]), int(idx[k - 1])
            where = X_text[a] if a == b else f"{X_text[a]} … {X_text[b]}"
            events.append(f"singular at {where}: {sing.text[a]}")
            start = k
        if len(events) >= 20:
            events.append(f"… and more singular samples ({len(idx)} in all)")
            break
    return events

"""The joint wrenches of a statically determinate mechanism graph through its spanning tree: the
route :mod:`screwkit.dynamics.graph_statics` takes when its system has full column rank (one
solution at most: square, or with more equations where a rod's idle spin adds one).

Cut the graph along a spanning tree rooted at the ground (breadth first); the joints left out
(the chords, one per independent loop) carry unknown wrenches W_c (about the world origin).
Summing the Newton–Euler balances of the moving bodies below tree joint t (its subtree S_t),
every joint inside S_t cancels, so

    W_t = −s_t (Σ_{b ∈ S_t} B_b + Σ_c e_tc W_c)

with s_t = +1 when the subtree's body is t's second body (−1: its first) and e_tc = +1 / −1 /
0 when chord c's second / first / neither or both bodies lie in S_t (wrenches about one point
add). Every passive freedom k of joint j then gives S_k·W_j = 0, linear in the chord wrenches:
6·(number of chords) unknowns, as many equations as passive freedoms — the same count, because
the full system is square (6B + m_p = 6J, J = B + chords); more equations than unknowns when it
is tall (solved by the normal equations). A system of full column rank has at most one
solution, so where the full system is consistent this one is its solution, found by an LU of a
(6C × 6C) matrix instead of (6J × 6J): 30 × 30 against 108 × 108 for the Stewart platform. The
residual of the full system (A·y − rhs, with the same row scaling) is rebuilt from the
wrenches, so a sample where the LU is inaccurate, or where the loads work along an idle
freedom (no exact solution: the full system's least-squares one is wanted), is seen and solved
again by the caller.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]


@dataclass(frozen=True)
class TreeCut:
    """A spanning tree of the joint graph: its joints ``tree`` and the ``chords``; per tree
    joint, ``sign`` s_t, ``below`` (T, B) the bodies of its subtree and ``cross`` (T, C)
    e_tc; ``incidence`` (B, J): +1 where the body is the joint's second body, −1 its first."""

    tree: tuple[int, ...]
    chords: tuple[int, ...]
    sign: Array
    below: Array
    cross: Array
    incidence: Array


def tree_cut(mech: Mechanism) -> TreeCut:
    """The breadth-first spanning tree from the ground (module docstring)."""
    index = {b: k for k, b in enumerate(mech.body_names)}
    parent: dict[str, tuple[int, str]] = {}  # body -> (tree joint, parent body)
    seen, queue, tree = {GROUND}, deque([GROUND]), []
    while queue:
        body = queue.popleft()
        for j, joint in enumerate(mech.joints):
            if body in joint.bodies:
                other = joint.bodies[1] if joint.bodies[0] == body else joint.bodies[0]
                if other not in seen:
                    seen.add(other)
                    parent[other] = (j, body)
                    tree.append(j)
                    queue.append(other)
    chords = tuple(j for j in range(len(mech.joints)) if j not in tree)
    B, T, C = len(mech.bodies), len(tree), len(chords)
    child = {j: b for b, (j, _) in parent.items()}
    below = np.zeros((T, B))
    for b in mech.body_names:  # each body lies below every tree joint on its way to the ground
        node = b
        while node != GROUND:
            j, up = parent[node]
            below[tree.index(j), index[b]] = 1.0
            node = up
    sign = np.array([1.0 if mech.joints[j].bodies[1] == child[j] else -1.0 for j in tree])
    cross = np.zeros((T, C))
    for ci, c in enumerate(chords):
        first, second = mech.joints[c].bodies
        for t in range(T):
            cross[t, ci] = (float(second != GROUND and below[t, index[second]] == 1.0)
                            - float(first != GROUND and below[t, index[first]] == 1.0))
    incidence = np.zeros((B, len(mech.joints)))
    for j, joint in enumerate(mech.joints):
        a, b = joint.bodies
        if b != GROUND:
            incidence[index[b], j] += 1.0
        if a != GROUND:
            incidence[index[a], j] -= 1.0
    return TreeCut(tuple(tree), chords, sign, below, cross, incidence)


def tree_statics(mech: Mechanism, cut: TreeCut, screws: Array, loads: Array,
                 passive: list[int], joint_of: tuple[int, ...], length: float
                 ) -> tuple[Array, Array, Array]:
    """Joint wrenches (N, J, 6, K) about the origin for body loads ``loads`` (N, B, 6, K),
    the full system's residual A·y − rhs (N, 6B + m_p, K) and the norm of its right-hand side
    (N, K) (graph_statics' row scaling)."""
    N, B, _, K = loads.shape
    J, C = len(mech.joints), len(cut.chords)
    chord_of = {c: i for i, c in enumerate(cut.chords)}
    tree_of = {t: i for i, t in enumerate(cut.tree)}
    below_loads = np.einsum("tb,nbik->ntik", cut.below, loads)  # Σ_{b ∈ S_t} B_b
    P = len(passive)
    M = np.zeros((N, P, 6 * C))
    r = np.zeros((N, P, K))
    Sr = np.concatenate([screws[:, 3:, :], screws[:, :3, :]], axis=1)  # S·W = v·f + ω·m
    for row, f in enumerate(passive):
        j = joint_of[f]
        if j in chord_of:
            M[:, row, 6 * chord_of[j]:6 * chord_of[j] + 6] = Sr[:, :, f]
            continue
        t = tree_of[j]
        s = cut.sign[t]
        for ci in np.nonzero(cut.cross[t])[0]:
            M[:, row, 6 * ci:6 * ci + 6] = -s * cut.cross[t, ci] * Sr[:, :, f]
        r[:, row] = s * np.einsum("ni,nik->nk", Sr[:, :, f], below_loads[:, t])
    with np.errstate(all="ignore"):
        try:
            if P == 6 * C:
                x = np.linalg.solve(M, r)
            else:  # more equations (an idle spin's): the normal equations, exact if consistent
                Mt = np.swapaxes(M, 1, 2)
                x = np.linalg.solve(Mt @ M, Mt @ r)
        except np.linalg.LinAlgError:  # a singular sample: the caller solves it again
            x = np.full((N, 6 * C, K), np.nan)
    chord_w = x.reshape(N, C, 6, K)
    wrench = np.empty((N, J, 6, K))
    wrench[:, list(cut.chords)] = chord_w
    wrench[:, list(cut.tree)] = -cut.sign[None, :, None, None] * (
        below_loads + np.einsum("tc,ncik->ntik", cut.cross, chord_w))
    rows = np.ones(6)
    rows[3:] = 1.0 / length
    body = (np.einsum("bj,njik->nbik", cut.incidence, wrench) + loads) * rows[:, None]
    res = np.empty((N, 6 * B + P, K))
    res[:, :6 * B] = body.reshape(N, 6 * B, K)
    for row, f in enumerate(passive):
        scale = 1.0 / length if np.any(screws[:, :3, f] != 0.0) else 1.0
        res[:, 6 * B + row] = scale * np.einsum("ni,nik->nk", Sr[:, :, f],
                                                wrench[:, joint_of[f]])
    size = np.linalg.norm((loads * rows[:, None]).reshape(N, 6 * B, K), axis=1) + 1e-300
    return wrench, res, size

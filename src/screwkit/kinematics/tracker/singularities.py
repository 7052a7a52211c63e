"""Why a sample is singular: the kind of rank loss of the rate equations, in words.

At a singular sample (:mod:`screwkit.kinematics.tracker.rates`) the scaled passive Jacobian J_p (with the
S–S rods' zero-spin rows) and the whole Jacobian J = [J_p J_in] are compared:

* **locked**: J_p has full column rank but an input screw is not in its range: the loop closes
  here but the input cannot move it (a rigid structure closing at an isolated input, e.g. a
  Bennett linkage with one length off);
* **dead centre**: J_p loses rank, the input is not in its range and the closed
  configurations at this input are isolated: the loop can move to first
  order with the input held, but not with the input; the branch turns back in the input (a
  limit position of the input, where two assembly modes meet);
* **bifurcation**: J_p loses rank, the input is in its range, and the closed configurations at
  this input are isolated: two branches cross here (e.g. the change point of a Grashof-neutral
  4R);
* **free motion**: J_p loses rank and the closed configurations at this input form a continuum
  (of the dimension of J_p's null space): a motion is left free with the input fixed, whether or
  not the input can move the loop.

Free motion is told apart from a dead centre or a bifurcation by stepping along J_p's null vectors with the input
held and closing the loop again (:func:`continuum_dimension`): on a continuum the corrected
point stays a step away; at an isolated point Newton does not land a step away.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.motion import format_inputs
from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    Layout,
    apply_increment,
    configuration_difference,
    constants,
)
from screwkit.kinematics.tracker.rates import SINGULAR_RTOL, RateEquations
from screwkit.kinematics.tracker.solve import newton
from screwkit.model.linkage import Linkage

KIND_TEXT = {
    "locked": "locked: the loop closes but the input cannot move it (a rigid, isolated closure)",
    "dead centre": "dead centre: the input cannot drive the loop here, which can move with the "
                   "input held (the branch turns back; two assembly modes meet)",
    "bifurcation": "bifurcation: two branches cross here and the rates are not unique",
    "free motion": "a motion left free with the input fixed",
    "ill-conditioned": "ill-conditioned: the rate equations leave a residual above tolerance",
}

_STEP = 1e-3  # the step along a null vector (scaled freedoms: rad, length / length scale)


def continuum_dimension(linkage: Linkage, lay: Layout, conf: Configuration, null: Array,
                        ) -> NDArray[np.int_]:
    """How many of the null directions ``null`` (N, m_p, d) (scaled passive freedoms) of each
    configuration lead along a continuum of closed configurations with the inputs held: a
    step of 1e-3 along each, closed again by Newton, must land 0.5–2 steps away."""
    N, _, d = null.shape
    if d == 0 or N == 0:
        return np.zeros(N, dtype=int)
    names = list(lay.names)
    p_idx = [k for k, n in enumerate(names) if n not in linkage.inputs]
    L = constants(linkage, lay)[2]
    cols = np.array([L if t else 1.0 for t in lay.is_translation])[p_idx]
    rep = conf.take(np.repeat(np.arange(N), d))
    delta = np.zeros((N * d, len(names)))
    direction = np.swapaxes(null, 1, 2).reshape(N * d, -1)
    delta[:, p_idx] = _STEP * direction * cols
    moved = newton(linkage, apply_increment(rep, delta, lay), max_iter=12, lay=lay)
    gap = _scaled_distance(linkage, lay, moved.conf, rep)
    ok = moved.converged & (gap > 0.5 * _STEP) & (gap < 2.0 * _STEP)
    return np.asarray(ok.reshape(N, d).sum(axis=1))


def _scaled_distance(linkage: Linkage, lay: Layout, a: Configuration, b: Configuration) -> Array:
    """|a ⊖ b| over the passive freedoms, scaled (rad; length / length scale)."""
    L = constants(linkage, lay)[2]
    cols = np.array([1.0 / L if t else 1.0 for t in lay.is_translation])
    diff = configuration_difference(a, b, lay) * cols
    return np.asarray(np.linalg.norm(diff, axis=1))


def classify(linkage: Linkage, lay: Layout, conf: Configuration, eq: RateEquations,
             ) -> tuple[list[str], list[int]]:
    """The kind of every sample of ``conf`` (all singular) and the dimension of its free motion
    (0 unless the kind is "free motion")."""
    N = conf.size
    if N == 0:
        return [], []
    Jp = eq.passive
    Jin = np.concatenate([eq.screws[:, :, eq.in_idx] * eq.rows[None, :, None],
                          eq.spin[:, :, eq.in_idx]], axis=1) * eq.cols[eq.in_idx]
    J = np.concatenate([Jp, Jin], axis=2)
    _, sp, vt = np.linalg.svd(Jp)
    sj = np.linalg.svd(J, compute_uv=False)
    mp = Jp.shape[2]
    top = np.maximum(sj[:, :1], 1e-300)
    rank_p = np.sum(sp > SINGULAR_RTOL * top, axis=1)
    rank = np.sum(sj > SINGULAR_RTOL * top, axis=1)
    nullity = mp - rank_p
    kinds = np.where(rank > rank_p, np.where(nullity == 0, "locked", "dead centre"),
                     np.where(nullity == 0, "ill-conditioned", "bifurcation")).astype(object)
    dims = np.zeros(N, dtype=int)
    test = np.nonzero(nullity > 0)[0]
    if test.size:
        d = int(nullity[test].max())
        null = np.swapaxes(vt[test][:, mp - d:, :], 1, 2)  # (n, m_p, d)
        free = continuum_dimension(linkage, lay, conf.take(test), null)
        dims[test] = free
        kinds[test[free > 0]] = "free motion"
    return [str(k) for k in kinds], [int(v) for v in dims]


def singular_events(linkage: Linkage, X: Array, samples: NDArray[np.intp], kinds: list[str],
                    dims: list[int], limit: int = 4) -> list[str]:
    """One sentence per kind: where (the first few inputs) and why; no rates there."""
    events = []
    for kind in dict.fromkeys(kinds):
        idx = [int(s) for s, k in zip(samples, kinds, strict=True) if k == kind]
        where = "; ".join(format_inputs(linkage, X[i]) for i in idx[:limit])
        more = f" and {len(idx) - limit} more" if len(idx) > limit else ""
        text = KIND_TEXT[kind]
        if kind == "free motion":
            d = max(dims[i] for i, k in enumerate(kinds) if k == kind)
            text += f" (a set of closed configurations of dimension {d} at each such input; " \
                    "one of them is reported)"
        events.append(f"singular at {len(idx)} sample(s), no rates there: {text}; at {where}{more}")
    return events

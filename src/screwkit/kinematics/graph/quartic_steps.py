"""Two folds of a loop of the RSRC quartic inside one sample step (issue 27: every birth and
death reported, "a motion never switches mode silently"), found by the search the single-loop
engine uses too (kinematics/closed_forms/rsrc/hidden_folds.py's ``hidden_steps``: the
quartic's discriminant Δ(θ0) bracketed by its values and slopes at the samples, its two zeros
located, every root followed across the step by ``rsrc_motion``'s own matching): a mode whose
root dies inside the step, or whose root at k+1 is born inside it, is cut there (its runs
before and after are two modes), and the roots at t* that neither reaches are an island.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.closed_forms.rsrc import rsrc_motion
from screwkit.kinematics.closed_forms.rsrc.hidden_folds import QuarticStep, hidden_steps
from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.graph.loop_motion import StepPieces
from screwkit.kinematics.graph.loop_subchain import LoopChain
from screwkit.kinematics.graph.step_folds import hidden_fold_text
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]


def quartic_steps(chain: LoopChain, L: Array, first: int, last: int) -> list[QuarticStep]:
    """Every step k → k+1 of the loop inputs ``L`` (K, 1; the rows its modes were solved on)
    with ``first`` ≤ k < ``last`` that hides two folds (module docstring)."""
    from screwkit.kinematics.closed_forms.closed_form_motion import rsrc_dimensions

    dims = rsrc_dimensions(chain.linkage)[0]
    if dims.special_case != "general" or last <= first:
        return []
    return hidden_steps(dims, rsrc_motion(dims, L[:, 0], events=False), first, last)


def quartic_pieces(mech: Mechanism, lay: GraphLayout, chain: LoopChain, X: Array,
                   masks: NDArray[np.bool_], modes: list[int], every: bool) -> StepPieces:
    """graph/loop_motion.py's ``step_pieces`` for a loop of the RSRC quartic: the modes
    ``masks`` (M, N; row r the loop's mode ``modes[r]``) cut where their root dies or is born
    inside a step between samples where they assemble (:func:`quartic_steps`; the drawn mode,
    row 0, ends at its first fold), with ``every`` the roots on no sample as modes of their
    own, each with its fold events."""
    from screwkit.kinematics.graph.closed_modes import ISLAND, SAME_AGAIN
    from screwkit.kinematics.graph.loop_motion import approach
    from screwkit.kinematics.graph.motion import input_text

    M, N = masks.shape
    A = approach(lay, X)
    a = A.shape[0]
    n = N if every else int(np.flatnonzero(masks[0])[-1]) + 1
    steps = quartic_steps(chain, chain.loop_inputs(np.vstack([A, X])), a, a + n - 1)
    idx = np.arange(N)
    rows: list[int] = []
    pieces: list[NDArray[np.bool_]] = []
    labels: list[str] = []
    for r in range(M):
        m = modes[r]
        cuts = sorted(s.k - a + 1 for s in steps if (m in s.dies or m in s.born)
                      and masks[r, s.k - a] and masks[r, s.k - a + 1])
        for j, (lo, hi) in enumerate(zip([0, *cuts], [*cuts, N], strict=True)):
            part = masks[r] & (idx >= lo) & (idx < hi)
            if part.any() and (r or j == 0 or every):  # the drawn mode: its first piece
                rows.append(r)
                pieces.append(part)
                labels.append("" if j == 0 else SAME_AGAIN)
    events: list[tuple[float, tuple[int, int, Array, str]]] = []

    def event(i: int, s: QuarticStep, t: float, dies: bool, gap: bool) -> None:
        k = s.k - a
        x = X[k] + t * (X[k + 1] - X[k])
        first = abs(t - s.t[0]) <= abs(t - s.t[1])
        events.append((k + t, (i, k, x, hidden_fold_text(
            dies, input_text(mech, lay, x), first, input_text(mech, lay, X[k]),
            input_text(mech, lay, X[k + 1]), gap))))

    for i, (r, part) in enumerate(zip(rows, pieces, strict=True)):
        for s in steps:
            k, m = s.k - a, modes[r]
            if part[k] and not part[k + 1] and masks[r, k + 1] and m in s.dies:
                event(i, s, s.dies[m], True, True)
            elif part[k + 1] and not part[k] and masks[r, k] and m in s.born:
                event(i, s, s.born[m], False, True)
    for s in steps if every else ():
        for _ in range(s.island):
            rows.append(0)
            pieces.append(np.zeros(N, dtype=bool))
            labels.append(ISLAND)
            event(len(rows) - 1, s, s.t[0], False, False)
            event(len(rows) - 1, s, s.t[1], True, False)
    return StepPieces(masks, rows, np.array(pieces).reshape(-1, N), labels, events,
                      frozenset(i for i, t in enumerate(labels) if t == ISLAND),
                      "a mode of the loop")

"""Two folds of one loop mode inside one sample step, for a family loop stage inside a larger
graph (graph/loop_stage.py; issue 27: every birth and death reported, "a motion never switches
mode silently").

A loop stage of the RSRC quartic is searched by the single loop's own search
(graph/quartic_steps.py's ``quartic_steps``, i.e. kinematics/closed_forms/rsrc/
hidden_folds.py's ``hidden_steps``: the quartic's discriminant Δ(θ0) bracketed by its values and
slopes at the samples, its two zeros located to 2⁻⁵⁰ of the step, every root followed across
the step by ``rsrc_motion``'s own matching), over the rows the stage was solved on (the
approach, the inputs, the drawing), so its loop modes are numbered as the stage's. A mode of
the mechanism (one loop mode × one branch of each dyad and leg hung on it) whose loop mode's
root dies inside a step where it assembles at both samples, or whose root at the second sample
is born inside it, is cut there: its runs before and after are two modes (the input must turn
back at the first fold), each with its death or birth at the loop's own fold. A root on no
sample (an island between the two folds) is listed as a mode of the loop on no sample, born and
dying at the two folds; the dyads and legs hung on the loop are not placed on it (no sample
lies on it), which its label says.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.closed_forms.rsrc.hidden_folds import QuarticStep
from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.graph.subchains import Decomposition, LoopStage
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]
#: a hidden fold: (stage index, the step's sample k in the inputs, fraction of the step)
Place = tuple[int, int, float]


def stage_steps(lay: GraphLayout, dec: Decomposition, rows: Array, a: int, last: int
                ) -> list[tuple[int, QuarticStep]]:
    """Every step k → k+1 with k < ``last`` between two input samples (``rows`` (K, n_in): the
    approach's ``a`` rows, then the inputs) where a loop stage of the RSRC quartic hides two folds, as (its index
    in ``dec.stages``, the step with its k counted in the inputs)."""
    from dataclasses import replace

    from screwkit.kinematics.graph.quartic_steps import quartic_steps
    from screwkit.kinematics.registry import has_rsrc_quartic

    out = []
    for d, st in enumerate(dec.stages):
        if not isinstance(st, LoopStage) or not has_rsrc_quartic(st.chain.linkage):
            continue
        col = lay.inputs.index(lay.first_freedom[st.joints[0]])
        x = np.append(rows[:, col], 0.0)  # the drawing appended, as the stage was solved
        for s in quartic_steps(st.chain, st.chain.loop_inputs(x[:, None]), a,
                               a + last):
            out.append((d, replace(s, k=s.k - a)))
    return out


@dataclass(frozen=True)
class StagePieces:
    """The modes of a loop-stage motion cut at two folds inside one step: each piece's mode
    row (``rows``, into the held modes; −1 an island on no sample), samples (``masks``), label
    tail, events in input order, and the pairs of pieces that meet at a hidden fold."""

    rows: list[int]
    masks: NDArray[np.bool_]
    labels: list[str]
    events: list[list[str]]
    meets: list[tuple[int, int]]

    def piece(self, row: int, n: int) -> int:
        """The piece of held mode ``row`` holding sample n."""
        return next(i for i, (r, m) in enumerate(zip(self.rows, self.masks, strict=True))
                    if r == row and m[n])


def stage_pieces(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array,
                 steps: list[tuple[int, QuarticStep]], combos: Array, held: NDArray[np.bool_],
                 folds: list[list[str]], joins: list[tuple[int, int, int, int]], every: bool
                 ) -> StagePieces:
    """The held modes (``combos`` (M, S) their branch combinations, ``held`` (M, N) their
    samples, row 0 the drawn mode's first run; ``folds``, ``joins`` their births and deaths
    between samples from loop_stage.py's ``fold_events``) cut at the hidden folds ``steps``
    (:func:`stage_steps`), the drawn mode ending at its first; with ``every`` the drawn
    mode's later pieces kept and each island a mode on no sample (module docstring)."""
    from screwkit.kinematics.graph.closed_modes import ISLAND, SAME_AGAIN
    from screwkit.kinematics.graph.loop_stage import stage_names
    from screwkit.kinematics.graph.motion import input_text

    M, N = held.shape
    idx = np.arange(N)
    rows: list[int] = []
    masks: list[NDArray[np.bool_]] = []
    labels: list[str] = []
    #: per piece: (place k + t, text); and the hidden folds it meets, for the circuits
    events: list[list[tuple[float, str]]] = []
    places: list[list[Place]] = []

    def text(d: int, s: QuarticStep, t: float, dies: bool, gap: bool) -> tuple[float, str]:
        st = dec.stages[d]
        x = X[s.k] + t * (X[s.k + 1] - X[s.k])
        first = abs(t - s.t[0]) <= abs(t - s.t[1])
        return s.k + t, (
            f"{'dies' if dies else 'is born'} at {input_text(mech, lay, x)}: the {st.kind} "
            f"{st.word} {stage_names(mech, st)} folds (two of its assembly modes meet; "
            f"{'the first' if first else 'the second'} of two folds between the samples at "
            f"{input_text(mech, lay, X[s.k])} and {input_text(mech, lay, X[s.k + 1])}, where "
            f"it {'assembles' if gap else 'does not assemble'})")

    for r in range(M):
        hits = [(d, s) for d, s in steps if held[r, s.k] and held[r, s.k + 1]
                and (int(combos[r, d]) in s.dies or int(combos[r, d]) in s.born)]
        cuts = sorted({s.k + 1 for _, s in hits})
        for j, (lo, hi) in enumerate(zip([0, *cuts], [*cuts, N], strict=True)):
            part = held[r] & (idx >= lo) & (idx < hi)
            if not part.any() or not (r or j == 0 or every):  # the drawn mode: its first
                continue
            rows.append(r)
            masks.append(part)
            labels.append("" if j == 0 else SAME_AGAIN)
            ev: list[tuple[float, str]] = []
            pl: list[Place] = []
            for d, s in hits:
                m = int(combos[r, d])
                if s.k + 1 == hi and hi < N and m in s.dies:
                    ev.append(text(d, s, s.dies[m], True, True))
                    pl.append((d, s.k, s.dies[m]))
                if s.k + 1 == lo and m in s.born:
                    ev.append(text(d, s, s.born[m], False, True))
                    pl.append((d, s.k, s.born[m]))
            events.append(ev)
            places.append(pl)
    # the births and deaths between samples, each to the piece holding its sample
    seen = [0] * M
    for r, _, k, _ in joins:
        n = k if held[r, k] else k + 1
        e = folds[r][seen[r]]
        seen[r] += 1
        i = next((i for i, (q, m) in enumerate(zip(rows, masks, strict=True))
                  if q == r and m[n]), None)
        if i is not None:  # a piece dropped (the drawn mode's after its first hidden fold)
            events[i].append((k + 0.5, e))
    for d, s in steps if every else ():
        for _ in range(s.island):
            st = dec.stages[d]
            rows.append(-1)
            masks.append(np.zeros(N, dtype=bool))
            labels.append(f"a mode of the {st.kind} {st.word} {stage_names(mech, st)}{ISLAND}; "
                          "the bodies hung on the loop are not placed on it")
            events.append([text(d, s, s.t[0], False, False), text(d, s, s.t[1], True, False)])
            places.append([(d, s.k, s.t[0]), (d, s.k, s.t[1])])
    meets = [(i, j) for i in range(len(rows)) for j in range(i + 1, len(rows))
             if any(p[0] == q[0] and p[1] == q[1] and abs(p[2] - q[2]) <= 1e-9
                    for p in places[i] for q in places[j])
             and (rows[i] < 0 or rows[j] < 0 or _others_agree(combos, rows[i], rows[j],
                                                             places[i]))]
    return StagePieces(rows, np.array(masks).reshape(-1, N), labels,
                       [[t for _, t in sorted(ev, key=lambda q: q[0])] for ev in events], meets)


def _others_agree(combos: Array, r1: int, r2: int, places: list[Place]) -> bool:
    """Whether modes r1 and r2 take the same branch in every stage but the folding loop."""
    d = places[0][0]
    others = np.delete(np.arange(combos.shape[1]), d)
    return bool(np.all(combos[r1, others] == combos[r2, others]))

"""The drawn mode of a mechanism followed along the inputs by the loop engine's continuation on
its stacked loop closure (issue 26: one continuation engine for loops and mechanisms).

From the drawn configuration (every freedom 0 at inputs 0; or a given closed start, a mode at
an anchor of modes/along.py) the mode is followed along the straight approach to the first
input row, in steps of at most APPROACH_STEP, and then along the rows, by
:class:`~screwkit.kinematics.tracker.continuation.Tracker` on
:class:`~screwkit.kinematics.graph.system.GraphSystem`: second-order predictor from directional
jets of the stacked rate equations (one rate and one acceleration solve per front and wave,
whatever the number of inputs), Newton corrector with Deuflhard's contraction test, the
step-halving test near singular configurations, fold detection from σ_min of the passive
Jacobian. The mode holds from the start up to where it first stops assembling (a fold: a dead
centre or limit position between two samples). :func:`reach` takes one configuration to other
inputs the same way, stepping as near a fold as asked (graph/limits.py, modes/along.py).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphFrames, GraphLayout, graph_forward
from screwkit.kinematics.graph.loop_subchain import APPROACH_STEP
from screwkit.kinematics.graph.system import GraphSystem
from screwkit.kinematics.tracker.continuation import Tracker
from screwkit.kinematics.tracker.loop import Array, Configuration
from screwkit.model.mechanism import Mechanism

#: a failed step of :func:`reach` is cut until its sub-steps are this small (rad, or this
#: fraction of the length scale for a slide): a step that ends next to a fold needs them there
SMALLEST_STEP = 1e-7

SOLVER = ("the loop engine's continuation from the drawn configuration on the stacked loop "
          "closure (graph/follow.py)")


@dataclass(frozen=True)
class Followed:
    """The drawn mode over the samples: configurations (N), where they hold, and the input
    where the mode stops assembling (None if it assembles throughout)."""

    conf: Configuration
    mask: NDArray[np.bool_]
    stopped_after: int | None
    #: the body poses, screws, joint centres and axes at every sample reached, for the motion
    #: build to reuse
    frames: GraphFrames | None = None
    #: where the first sample is not reached: the last input on the straight way there from
    #: the drawing that assembles (the drawing, 0, if no step does)
    reached: Array | None = None
    #: the continuation that followed it, for the motion's solver string
    solver: str = SOLVER


def approach_rows(lay: GraphLayout, x0: Array, x1: Array) -> Array:
    """Input rows from ``x0`` along the straight way to ``x1``, in steps of at most
    APPROACH_STEP (rad, or of the length scale), ``x0`` first and ``x1`` left out."""
    scale = np.array([lay.length if lay.is_translation[f] else 1.0 for f in lay.inputs])
    steps = max(1, int(np.ceil(float(np.max(np.abs(x1 - x0) / scale)) / APPROACH_STEP)))
    return np.asarray(x0[None, :] + np.linspace(0.0, 1.0, steps + 1)[:-1, None]
                      * (x1 - x0)[None, :])


def follow_drawn_mode(mech: Mechanism, lay: GraphLayout, X: Array,
                      progress: Callable[[int, int], None] | None = None,
                      start: Configuration | None = None,
                      start_inputs: Array | None = None) -> Followed:
    """Follow the drawn configuration (inputs 0) to ``X[0]`` and along every row of ``X``;
    ``start`` replaces the drawing (one closed sample at inputs ``start_inputs``, 0 if not
    given: a mechanism re-assembled near its drawing, motion.reassemble_drawing; a mode found
    at an anchor, kinematics/modes/along.py)."""
    N, n_in = X.shape
    conf0 = start if start is not None else Configuration(
        np.zeros((1, lay.n_scalar)), np.broadcast_to(np.eye(3), (1, lay.n_spherical, 3, 3)).copy())
    x0 = np.zeros(n_in) if start_inputs is None else np.asarray(start_inputs, dtype=float)
    A = approach_rows(lay, x0, X[0]) if np.any(X[0] != x0) else np.zeros((0, n_in))
    a = A.shape[0]
    rows = np.vstack([A, X]) if a else X
    done = [0]

    def count(n: int) -> None:  # the tracker counts the samples it holds
        done[0] += n
        if progress is not None:
            progress(int(np.clip(done[0] - a, 0, N)), N)

    system = graph_system(mech, lay)
    system.forget()  # the poses kept from another sweep: not this one's
    tracker = Tracker(None, None, rows, count, system=system)
    tracker.follow(tracker.add_seeds(0, conf0))
    if progress is not None:
        progress(N, N)
    tr = tracker.tracks[0]
    stop = int(np.argmin(tr.mask)) if not tr.mask.all() else tr.mask.size
    held = (np.arange(rows.shape[0]) < stop)[a:]
    conf = Configuration(np.where(held[:, None], tr.scalars[a:], 0.0),
                         np.where(held[:, None, None, None], tr.spherical[a:], np.eye(3)))
    if stop <= a:  # the first row is not reached: where the approach ends
        last = stop - 1  # the seed is always held
        at = Configuration(tr.scalars[last:stop], tr.spherical[last:stop])
        return Followed(conf, held, -1, reached=_furthest(mech, lay, at, rows[last],
                                                          rows[stop]))
    frames = held_frames(mech, lay, conf, held, system.frames)
    system.forget()
    return Followed(conf, held, stop - a - 1 if stop < rows.shape[0] else None, frames)


def _furthest(mech: Mechanism, lay: GraphLayout, at: Configuration, good: Array, bad: Array,
              ) -> Array:
    """The furthest input towards ``bad`` reached from ``at`` (closed at ``good``): bisection,
    5 halvings (to a 32nd of an approach step)."""
    for _ in range(5):
        mid = 0.5 * (good + bad)
        end = reach(mech, lay, at, good, mid)
        if end is None:
            bad = mid
        else:
            at, good = end, mid
    return np.asarray(good, dtype=float).copy()


_SYSTEMS: dict[tuple[int, int], tuple[Mechanism, GraphLayout, GraphSystem]] = {}


def graph_system(mech: Mechanism, lay: GraphLayout) -> GraphSystem:
    """The stacked closure of ``mech`` (the last few kept: :func:`reach` is called often on
    one mechanism, and the system's rank and σ reference come from an SVD at the drawing)."""
    key = (id(mech), id(lay))
    if key not in _SYSTEMS:
        if len(_SYSTEMS) >= 8:
            _SYSTEMS.pop(next(iter(_SYSTEMS)))
        _SYSTEMS[key] = (mech, lay, GraphSystem(mech, lay))
    return _SYSTEMS[key][2]


def reach(mech: Mechanism, lay: GraphLayout, conf: Configuration, x_from: Array, x_to: Array,
          smallest: float = SMALLEST_STEP) -> Configuration | None:
    """The configuration at inputs ``x_to`` on the branch through ``conf`` (one sample, closed
    at ``x_from``), followed by the same continuation in sub-steps no shorter than
    ``smallest``; None where the branch does not get there (a fold in between)."""
    rows = np.stack([np.asarray(x_from, dtype=float), np.asarray(x_to, dtype=float)])
    tracker = Tracker(None, None, rows, system=graph_system(mech, lay), smallest=smallest)
    tracker.follow(tracker.add_seeds(0, conf))
    tr = tracker.tracks[0]
    if not tr.mask[1]:
        return None
    return Configuration(tr.scalars[1:2].copy(), tr.spherical[1:2].copy())


def held_frames(mech: Mechanism, lay: GraphLayout, conf: Configuration,
                mask: NDArray[np.bool_],
                forward: Callable[[Configuration], GraphFrames] | None = None) -> GraphFrames:
    """The body poses, screws, joint centres and axes at the samples ``mask`` holds (the
    identity and zeros elsewhere, which the build marks as not assembling), for the build to
    reuse: the graph's forward map evaluated where the mode holds only (by ``forward`` when
    given: the tracker's system, which kept those of the samples it closed)."""
    idx = np.flatnonzero(mask)
    part = forward(conf.take(idx)) if forward is not None else \
        graph_forward(mech, lay, conf.take(idx), exact=False)
    out = []
    for arr in (part.R, part.p, part.screws, part.residual, part.centres, part.axes):
        full = np.zeros((mask.size, *arr.shape[1:]))
        if arr is part.R:
            full[:] = np.eye(3)
        full[idx] = arr
        out.append(full)
    return GraphFrames(*out)


__all__ = ["SMALLEST_STEP", "Followed", "approach_rows", "follow_drawn_mode", "graph_system",
           "held_frames", "reach"]

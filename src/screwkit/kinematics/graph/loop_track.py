"""The drawn mode of a single loop without a closed form, followed by the loop engine (issue 26:
one solving path for a loop, however it is given).

A mechanism that is one loop and no family with a closed form (graph/loop_subchain.py reads the
families) is the joint list in frame form that ``loop_chain(mech, generic=True)`` builds: every
joint variable 0 at the drawing and equal to the graph's (R, P, C, H the same variable; a U
joint's two angles swap where the loop runs through it backwards, as an S joint's rotation
turns into its transpose: the graph's M_j(q) is F_i J_i(q) F_i⁻¹ or its inverse, Rahman eq. 2.2
with a general screw matrix). Its drawn mode is followed by the continuation every branch of the
generic loop solver is followed with (:class:`~screwkit.kinematics.tracker.continuation.Tracker`:
second-order predictor from the loop's rate equations, Newton corrector with Deuflhard's
contraction test and the step-halving test near singular configurations, fold detection from
σ_min of the passive Jacobian, steps over bifurcations), seeded at the drawing (every freedom 0,
inputs 0) and run forwards along the straight approach to the first input row and then the rows
— a drawn-mode request: no root searches. An S–S rod's idle spin is held at zero from the
drawing on (tracker/idle_spin.py's zero-spin frame, as the loop's own mode build holds it). The
graph's build (graph/motion.py ``build_mode``) then gives the rates, accelerations, points,
outputs and singular classes from the stacked screw Jacobian, as for every graph.

Mechanisms that are not one loop in frame form (several loops, driven body freedoms, parts made
off their drawing, a U joint whose axes are not perpendicular) are followed by the same engine on the stacked closure (graph/follow.py).
Measured (benchmarks/bench_graph.py, the same loop side by side, each with the graph's build):
an RCCC driven at a cylinder in ~0.7× the CPU time of the graph tracker this replaced, an RSSR in frame form in
~1.25× (the following alone ~1.1×; the rest is its rod's zero-spin pose, which the graph
tracker's minimum-norm steps leave drifting).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.graph.follow import Followed, follow_drawn_mode, held_frames
from screwkit.kinematics.graph.loop_subchain import LoopChain, loop_chain
from screwkit.kinematics.tracker.continuation import Tracker
from screwkit.kinematics.tracker.idle_spin import hold_idle_spin
from screwkit.kinematics.tracker.loop import Configuration, Layout, forward, layout
from screwkit.kinematics.tracker.rates import rate_equations, spin_links
from screwkit.kinematics.tracker.solve import newton
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

SOLVER = ("the loop engine's continuation (second-order predictor, Newton corrector) from the "
          "drawing along the mechanism's one loop (graph/loop_track.py); rates and accelerations "
          "from the stacked loop closure")


def follow_drawn(mech: Mechanism, lay: GraphLayout, X: Array,
                 progress: Callable[[int, int], None] | None = None,
                 start: Configuration | None = None) -> Followed:
    """The drawn mode over the rows ``X``: by the loop engine for a single loop in frame form
    (:func:`follow_drawn_loop`), else on the stacked closure, graph/follow.py (also from a ``start`` other than the
    drawing: a mechanism re-assembled near its drawing)."""
    chain = loop_chain(mech, generic=True) if start is None else None
    if chain is not None:
        return follow_drawn_loop(mech, lay, chain, X, progress)
    return follow_drawn_mode(mech, lay, X, progress, start)


def follow_drawn_loop(mech: Mechanism, lay: GraphLayout, chain: LoopChain, X: Array,
                      progress: Callable[[int, int], None] | None = None) -> Followed:
    """The drawn mode of the single loop ``chain`` (frame form) over the rows ``X``, followed by
    the loop engine's continuation from the drawing (module docstring), as graph/follow.py's
    :class:`Followed`: configurations in the graph's layout, where they hold (the first run
    from the drawing: the mode ends where it first stops assembling), the sample after which it
    stops, and where the first row is not reached the last approach row that is."""
    from screwkit.kinematics.graph.loop_motion import approach

    N = X.shape[0]
    A = approach(lay, X) if np.any(X[0] != 0.0) else np.zeros((0, X.shape[1]))
    a = A.shape[0]
    rows = np.vstack([A, X])
    L = chain.linkage
    llay = layout(L)
    done = [0]

    def count(n: int) -> None:  # the tracker counts the samples it holds
        done[0] += n
        if progress is not None:
            progress(int(np.clip(done[0] - a, 0, N)), N)

    tracker = Tracker(L, llay, chain.loop_inputs(rows), count)
    drawing = Configuration(np.zeros((1, llay.n_scalar)),
                            np.broadcast_to(np.eye(3), (1, llay.n_spherical, 3, 3)).copy())
    tracker.follow(tracker.add_seeds(0, drawing))
    if progress is not None:  # done: also where the mode ends before the last row
        progress(N, N)
    tr = tracker.tracks[0]
    stop = int(np.argmin(tr.mask)) if not tr.mask.all() else tr.mask.size
    held = np.arange(rows.shape[0]) < stop
    loop_conf = Configuration(np.where(held[:, None], tr.scalars, 0.0),
                              np.where(held[:, None, None, None], tr.spherical, np.eye(3)))
    if spin_links(L) and stop:  # S–S rods: their idle spin held at zero from the drawing on
        fr = forward(L, loop_conf, llay)
        turned = hold_idle_spin(L, llay, loop_conf, held, tracker.X, fr,
                                rate_equations(L, llay, fr, held, exact_sigma=False))
        # the turns leave round-off in the closure: Newton (minimum-norm) restores it
        polished = newton(L, turned, max_iter=2, tol=1e-15, lay=llay).conf
        loop_conf = Configuration(np.where(held[:, None], polished.scalars, turned.scalars),
                                  np.where(held[:, None, None, None], polished.spherical,
                                           turned.spherical))
    mask = held[a:]
    conf = _graph_configuration(mech, lay, chain, llay, loop_conf.take(slice(a, None)), mask)
    if stop <= a:  # the first row is not reached: where the approach ends
        return Followed(conf, mask, -1, reached=rows[max(stop - 1, 0)].copy(), solver=SOLVER)
    return Followed(conf, mask, stop - a - 1 if stop < rows.shape[0] else None,
                    held_frames(mech, lay, conf, mask), solver=SOLVER)


def _graph_configuration(mech: Mechanism, lay: GraphLayout, chain: LoopChain, llay: Layout,
                         conf: Configuration, mask: NDArray[np.bool_]) -> Configuration:
    """The loop's configurations (frame form) as the graph's: the same joint variables (a U
    joint's two angles swapped, an S joint's rotation transposed, where the loop runs through
    the joint from its second body to its first); the drawing where ``mask`` does not hold."""
    N = conf.size
    q = np.zeros((N, lay.n_scalar))
    balls = np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)).copy()
    loop_first = [llay.joint_of.index(i) for i in range(len(chain.joints))]
    for i, k in enumerate(chain.joints):
        j = mech.joints[k]
        backwards = j.bodies != (chain.bodies[i], chain.bodies[i + 1])
        if j.kind == "S":
            R = conf.spherical[:, llay.spherical_of_joint[i]]
            balls[:, lay.spherical_of_joint[k]] = np.swapaxes(R, -1, -2) if backwards else R
            continue
        n = len(j.freedoms)
        order = [1, 0] if j.kind == "U" and backwards else list(range(n))
        for g, loop_f in enumerate(order):
            q[:, lay.scalar_col[lay.first_freedom[k] + g]] = \
                conf.scalars[:, llay.scalar_col[loop_first[i] + loop_f]]
    q[~mask] = 0.0
    balls[~mask] = np.eye(3)
    return Configuration(q, balls)

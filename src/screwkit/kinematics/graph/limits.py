"""Limit positions of any output of a one-input mechanism graph: where d output / d input = 0.

Sign changes of the exact rate (graph/newton.py) between solved samples bracket each limit;
Newton's method on the rate, with the exact second derivative (the acceleration at unit input
rate and zero input acceleration), finds it to round-off, following the mode by continuation
(graph/follow.py:reach). The dwell order counts the vanishing derivatives: the first two are exact;
the third and fourth come from central differences of the exact second derivative (step 1e-3 rad
or 1e-3 of the length scale), good to about 1e-6 relative.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import CapabilityError, UnknownNameError
from screwkit.kinematics.analysis.limit_results import LimitPosition, LimitPositions
from screwkit.kinematics.graph.closure import GraphLayout, graph_layout
from screwkit.kinematics.graph.follow import reach
from screwkit.kinematics.graph.motion import MechanismMotion
from screwkit.kinematics.graph.newton import accelerations, linearise, rates
from screwkit.kinematics.tracker.loop import Configuration

Array = NDArray[np.float64]

DERIVATIVES = ("first and second exact (stacked screw Jacobian); third and fourth by central "
               "differences of the exact second")


def _jet(motion: MechanismMotion, lay: GraphLayout, conf: Configuration, f: int
         ) -> tuple[float, float, float]:
    """Value, first and second derivative of freedom ``f`` with respect to the input."""
    mech = motion.mechanism
    lin = linearise(mech, lay, conf, exact=False)
    qd = rates(mech, lay, lin, np.ones((1, 1)))
    qdd, _ = accelerations(mech, lay, lin, qd, np.zeros((1, 1)))
    value = float(conf.scalars[0, lay.scalar_col[f]])
    return value, float(qd[0, f]), float(qdd[0, f])


def graph_limit_positions(motion: MechanismMotion, output: str | None = None,
                          dwell_tolerance: float = 1e-6, mode: int = 0) -> LimitPositions:
    """Every limit of ``output`` (a scalar joint freedom; default: every passive R, P, C, H
    freedom) over the motion's input sweep, on ``mode``. A mechanism driven by body freedoms
    (``[[drives]]``), or a named ``[[outputs]]`` entry asked for (camber, toe), is handed to
    :func:`screwkit.kinematics.graph.limits_driven.driven_limit_positions` (any output, along
    the input rows)."""
    mech = motion.mechanism
    if mech.drives or output in {o.name for o in mech.outputs}:  # along the input rows
        from screwkit.kinematics.graph.limits_driven import driven_limit_positions

        return driven_limit_positions(motion, output, dwell_tolerance, mode)
    if len(mech.inputs) != 1:
        raise CapabilityError(f"{mech.name}: limit positions need one input; this mechanism "
                              f"has {len(mech.inputs)} ({', '.join(mech.inputs)})")
    lay = graph_layout(mech)
    scalar = [lay.names[f] for f in lay.passive if lay.scalar_col[f] >= 0]
    if output is not None and output not in scalar:
        raise UnknownNameError(f"{mech.name}: no output {output!r}; the outputs are the joint "
                               f"freedoms {scalar}")
    outputs = [output] if output is not None else scalar
    md = motion.mode(mode)
    x = motion.inputs[:, 0]
    found = []
    h = 1e-3 * (lay.length if lay.is_translation[lay.inputs[0]] else 1.0)
    ok_samples = md.assembles & ~md.singular
    # d output / d input at every sample (unit input rate: independent of the motion's speed)
    lin = linearise(mech, lay, md.conf.take(np.nonzero(ok_samples)[0]), exact=False)
    unit = np.full((int(ok_samples.sum()), lay.m), np.nan)
    unit[:] = rates(mech, lay, lin, np.ones((unit.shape[0], 1)))
    for name in outputs:
        f = lay.names.index(name)
        d1 = np.full(md.samples, np.nan)
        d1[ok_samples] = unit[:, f]
        ok = ok_samples & np.isfinite(d1)
        for k in np.nonzero(ok[:-1] & ok[1:] & (np.sign(d1[:-1]) * np.sign(d1[1:]) < 0))[0]:
            lim = _refine(motion, lay, md.conf.take(slice(k, k + 1)), x[k], x[k + 1], f, h,
                          dwell_tolerance)
            if lim is not None:
                found.append(lim)
    found.sort(key=lambda p: (p.output, p.input))
    notes = tuple(ev for ev in md.events if ev.startswith("stops assembling"))
    return LimitPositions(mech.name, "graph", "generic", mech.inputs[0], tuple(outputs),
                          dwell_tolerance, 4, found, derivatives=DERIVATIVES, notes=notes)


def _refine(motion: MechanismMotion, lay: GraphLayout, conf: Configuration, xa: float,
            xb: float, f: int, h: float, tol: float) -> LimitPosition | None:
    mech = motion.mechanism
    x = 0.5 * (xa + xb)
    at, x_at = conf, xa
    for _ in range(30):
        here = reach(mech, lay, at, np.array([x_at]), np.array([x]))
        if here is None:
            return None
        value, d1, d2 = _jet(motion, lay, here, f)
        at, x_at = here, x
        step = -d1 / d2 if d2 != 0 else 0.0
        x_new = min(max(x + step, min(xa, xb)), max(xa, xb))  # inside the bracket, either way
        if abs(x_new - x) < 1e-14 * max(1.0, abs(x)):
            break
        x = x_new
    derivs = [d1, d2]
    for dx in (-h, h):
        near = reach(mech, lay, at, np.array([x]), np.array([x + dx]))
        if near is None:
            break
        derivs.append(_jet(motion, lay, near, f)[2])
    if len(derivs) == 4:
        d2m, d2p = derivs[2], derivs[3]
        derivs[2:] = [(d2p - d2m) / (2 * h), (d2p - 2 * d2 + d2m) / h**2]
    else:
        derivs = derivs[:2]
    order = next((k for k, v in enumerate(derivs[1:], start=1) if abs(v) > tol), None)
    kind = "translation" if lay.is_translation[f] else "rotation"
    return LimitPosition(lay.names[f], kind, float(x), value, d2, order, derivs, mode=0,
                         variables={})

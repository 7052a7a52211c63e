"""Limit positions (extremes) of any output of a mechanism graph driven by body freedoms
(``[[drives]]``: a wheel's travel, a platform's pose; graph/drives.py), along its input rows;
also the limits of a named ``[[outputs]]`` entry of a graph driven by joints.

The rows x_0, x_1, … are joined by straight segments x(t) = x_k + t Δ_k, Δ_k = x_{k+1} − x_k,
t ∈ [0, 1] (for one driven freedom that is the sweep itself). The output y is a scalar joint
freedom (an R, P, C or H joint's variable, the actuated leg slides included) or a named
``[[outputs]]`` entry (camber, toe, a point's travel: graph/outputs.py). Along a segment its
first and second derivatives are exact: the motion solved with input rate Δ_k and zero input
acceleration gives dy/dt and d²y/dt² (graph/newton.py through the mechanism's virtual chains).
A sign change of dy/dt between a segment's two ends brackets a stationary point; Newton's method
on dy/dt in t (kept inside the bracket, each step solved by continuation of the drawn mode from
the drawing through x_k — straight to x_k when that reaches the motion's configuration there,
else through every row before it) finds it to round-off. The dwell order counts the vanishing
derivatives as for joint inputs (graph/limits.py): the first two exact, the third and fourth by
central differences of the exact second (step 1e-3 rad or 1e-3 of the length scale in the
driven freedom, 1e-3 of a segment along a path of several).

With one driven freedom a limit's ``input`` is that freedom's value (m or rad) and its
derivatives are per its unit; with several (a pose given row by row) ``input`` is the position
along the path counted in rows, s = k + t (0 at the first row), the derivatives are per row, and
``variables`` holds every driven freedom's value there. Where the path turns at a row the
output may peak there without a vanishing derivative: such a corner is not a limit position.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import CapabilityError, UnknownNameError
from screwkit.kinematics.analysis.limit_results import LimitPosition, LimitPositions
from screwkit.kinematics.graph.motion import MechanismMode, MechanismMotion, solve_mechanism
from screwkit.messages import listing
from screwkit.model.mechanism import Mechanism
from screwkit.model.mechanism_outputs import BodyAngle

Array = NDArray[np.float64]

DERIVATIVES = ("first and second exact along the path (stacked screw Jacobian, through the "
               "virtual chains of any [[drives]]); third and fourth by central differences of "
               "the exact second")


def driven_outputs(mech: Mechanism) -> dict[str, str]:
    """The outputs a limit can be asked of, with their kind: every named ``[[outputs]]`` entry,
    then every scalar joint freedom (not a ball joint's rotation vector)."""
    out = {o.name: "rotation" if isinstance(o, BodyAngle) else "translation"
           for o in mech.outputs}
    slides = {j.name for j in mech.joints if j.kind in "PCH"}
    for j in mech.joints:
        if j.kind == "S":
            continue
        for f in j.freedom_names():
            out[f] = "translation" if f.endswith(".s") and j.name in slides else "rotation"
    return out


def _track(md: MechanismMode, name: str) -> tuple[Array, Array, Array]:
    """Value, rate and acceleration (N,) of output ``name`` in a solved mode."""
    if name in md.outputs:
        return md.outputs[name], md.output_rates[name], md.output_accelerations[name]
    return md.variables[name], md.velocities[name], md.accelerations[name]


def _solve(mech: Mechanism, rows: Array, rate: Array) -> MechanismMode:
    """The drawn mode through ``rows`` with input rate ``rate`` (one per row and freedom)."""
    return solve_mechanism(mech, rows, rates=rate, accelerations=0.0).modes[0]


def _jets(mech: Mechanism, path: Array, xs: Array, delta: Array, name: str
          ) -> tuple[Array, Array, Array] | None:
    """Value, d/dt and d²/dt² of ``name`` at the rows ``xs``, followed through the rows
    ``path`` (ending at the segment's first row) along the direction ``delta``; None where one
    does not assemble."""
    rows = np.vstack([path, xs])
    md = _solve(mech, rows, np.broadcast_to(delta, rows.shape))
    if not md.assembles.all():
        return None
    v, d1, d2 = _track(md, name)
    m = len(path)
    return v[m:], d1[m:], d2[m:]


def _way_to(mech: Mechanism, X: Array, k: int, motion: MechanismMode) -> Array:
    """The rows to follow to reach row k as the motion did: row k alone (straight from the
    drawing) when that lands on the motion's configuration there (every body's pose to 1e-9),
    else every row up to k."""
    alone = solve_mechanism(mech, X[k:k + 1]).modes[0]
    scale = mech.length_scale
    same = bool(alone.assembles[0]) and \
        np.abs(alone.link_rotation[0] - motion.link_rotation[k]).max() <= 1e-9 and \
        np.abs(alone.link_origin[0] - motion.link_origin[k]).max() <= 1e-9 * scale
    return X[k:k + 1] if same else X[:k + 1]


def driven_limit_positions(motion: MechanismMotion, output: str | None = None,
                           dwell_tolerance: float = 1e-6, mode: int = 0) -> LimitPositions:
    """Every limit of ``output`` (default every output of :func:`driven_outputs`) along the
    input rows of a body-driven ``motion`` (module docstring), on the drawn mode."""
    mech = motion.mechanism
    if mode != 0:
        raise CapabilityError(f"{mech.name}: limit positions of a mechanism driven by body "
                              "freedoms are found on its drawn mode (mode 0) only")
    kinds = driven_outputs(mech)
    if output is not None and output not in kinds:
        raise UnknownNameError(f"{mech.name}: no output {output!r}; the outputs are "
                               f"{listing(kinds)}")
    outputs = [output] if output is not None else list(kinds)
    X = np.asarray(motion.inputs, dtype=float)
    N, n = X.shape
    if N < 2:
        raise CapabilityError(f"{mech.name}: limit positions need at least two input rows")
    D = np.diff(X, axis=0)  # (N - 1, n): each segment's direction
    moving = np.linalg.norm(D, axis=1) > 0
    # every output's derivative along each segment at its two ends: two solves of all rows
    at_start = _solve(mech, X, np.vstack([D, D[-1:]]))
    at_end = _solve(mech, X, np.vstack([D[:1], D]))
    one = n == 1
    slide = bool(mech.driven_is_translation()[0])
    h = 1e-3 * (mech.length_scale if slide else 1.0)
    found = []
    ways: dict[int, Array] = {}  # per segment, the rows that reach its start (_way_to)
    for name in outputs:
        _, s0, _ = _track(at_start, name)
        _, s1, _ = _track(at_end, name)
        a, b = s0[:-1], s1[1:]
        ok = at_start.assembles[:-1] & at_start.assembles[1:] & moving & np.isfinite(a) \
            & np.isfinite(b)
        for k in np.nonzero(ok & (np.sign(a) * np.sign(b) < 0))[0]:
            ht = h / abs(float(D[k, 0])) if one else 1e-3
            if int(k) not in ways:
                ways[int(k)] = _way_to(mech, X, int(k), at_start)
            lim = _refine(mech, ways[int(k)], D[k], name, float(np.sign(a[k])), ht)
            if lim is None:
                continue
            t, value, derivs = lim
            x = X[k] + t * D[k]
            if one:  # per unit of the driven freedom
                derivs = [d / float(D[k, 0]) ** (i + 1) for i, d in enumerate(derivs)]
                where = float(x[0])
                variables: dict[str, float | None] = {}
            else:
                where = float(k + t)
                variables = {d: float(v) for d, v in zip(mech.driven_names, x, strict=True)}
            order = next((i for i, v in enumerate(derivs[1:], start=1)
                          if abs(v) > dwell_tolerance), None)
            found.append(LimitPosition(name, kinds[name], where, value, derivs[1], order,
                                       derivs, mode=0, variables=variables))
    found.sort(key=lambda p: (p.output, p.input))
    md = motion.mode(0)
    notes = tuple(ev for ev in md.events if ev.startswith("stops assembling"))
    if not one:
        notes = (f"{n} driven freedoms ({', '.join(mech.driven_names)}) given as rows: the "
                 "limits are along the straight path through the rows; 'input' is the position "
                 "along it in rows (0 at the first), the derivatives are per row",) + notes
    input_name = mech.driven_names[0] if one else "row"
    input_kind = ("length" if slide else "angle") if one else "ratio"
    return LimitPositions(mech.name, "graph", "generic", input_name, tuple(outputs),
                          dwell_tolerance, 4, found, derivatives=DERIVATIVES, notes=notes,
                          input_kind=input_kind)


def _refine(mech: Mechanism, path: Array, delta: Array, name: str, sign0: float, ht: float
            ) -> tuple[float, float, list[float]] | None:
    """Newton's method on dy/dt inside t ∈ [0, 1] (bisecting when a step leaves the bracket;
    ``sign0`` the sign of dy/dt at t = 0), then the derivatives there (module docstring):
    (t, y, [dy/dt … d⁴y/dt⁴]); None if it stops assembling."""
    start = path[-1]
    lo, hi, t = 0.0, 1.0, 0.5
    jets = None
    for _ in range(60):
        jets = _jets(mech, path, start + t * delta[None, :], delta, name)
        if jets is None:
            return None
        d1, d2 = float(jets[1][0]), float(jets[2][0])
        if d1 == 0.0:
            break
        if np.sign(d1) == sign0:
            lo = t
        else:
            hi = t
        t_new = t - d1 / d2 if d2 != 0 else 0.5 * (lo + hi)
        if not lo <= t_new <= hi:  # outside what is known to hold the root: bisect
            t_new = 0.5 * (lo + hi)
        if abs(t_new - t) < 1e-15:
            break
        t = t_new
    assert jets is not None
    value, d1, d2 = float(jets[0][0]), float(jets[1][0]), float(jets[2][0])
    derivs = [d1, d2]
    near = _jets(mech, path, start + np.array([t - ht, t + ht])[:, None] * delta, delta, name)
    if near is not None:
        d2m, d2p = float(near[2][0]), float(near[2][1])
        derivs += [(d2p - d2m) / (2 * ht), (d2p - 2 * d2 + d2m) / ht**2]
    return t, value, derivs

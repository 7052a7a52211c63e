"""Tolerance analysis of a graph spec (docs/sweeps.md, "Tolerances on a graph"): hardpoints
made off the drawing, the mechanism re-assembled, and the spread of its named outputs (camber,
toe, track change …) over the motion.

**What a hardpoint tolerance is.** ``joints.<J>.at[k] = ±t`` moves joint J's seat in its
*first* body (``between[0]``: the chassis pick-up of a chassis joint, the arm's ball of an arm–
upright joint) while its second body keeps the drawn seat: the part is made off its drawing
(model/mechanism.py, ``seat_offset`` δ: T_second = T_first · M_J(q) · Trans(δ)). The drawing
then no longer closes; the inputs are held at the drawing and the closure is solved by Newton's
method from the drawn configuration (the assembly nearest the drawing), then the mode is
followed (kinematics/graph/motion.py). ``points.<P>.at[k] = ±t`` moves a point on its body.
Outputs are measured against the *nominal* drawing, so a static misalignment counts.

**First order, by the implicit function theorem.** With the inputs held, the closure r(q, δ) =
0 gives J_p ∂q_p/∂δ = −∂r/∂δ: the passive block of the stacked screw Jacobian (exact, the
solver's) against the residual's derivative at fixed q, and dy/dδ = ∂y/∂δ + ∂y/∂q · ∂q/∂δ for an
output y. The two explicit derivatives are taken by central differences of the forward maps
only (no re-solve): ∂r/∂δ from the loop residuals at δ = ±h, dy/dδ from y(±h, q ± h ∂q/∂δ), both
O(h²) with h = 1e-5 of the length scale (≈1e-10 relative). Stack-ups as for a loop
(:mod:`screwkit.sweep.tolerance`): worst case Σ|∂y/∂x_k| t_k, RSS √Σ(∂y/∂x_k t_k)², ±t = ±3σ.

**Monte Carlo** (:func:`graph_monte_carlo_batch`): each drawn design is closed by Newton's
method at every sample from the nominal mode's configuration (the same assembly mode).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from screwkit.kinematics.graph.closure import GraphLayout, graph_forward, graph_layout
from screwkit.kinematics.graph.newton import (
    CLOSURE_TOL,
    column_scale,
    increment,
    linearise,
    newton,
    scaled_residual,
)
from screwkit.kinematics.graph.outputs import body_angle
from screwkit.kinematics.tracker.loop import Array, Configuration
from screwkit.model.mechanism import Mechanism
from screwkit.model.mechanism_outputs import BodyAngle
from screwkit.sweep.engine import Engine, batch_size, batches
from screwkit.sweep.tolerance import FirstOrder, Tolerance, ToleranceError

#: Monte Carlo designs per engine task
MC_BATCH = 50


def expand_keys(data: dict[str, Any], name: str) -> list[str]:
    """A ``--tol`` key of a graph spec as the keys it stands for: ``joints.LB.at`` → its three
    coordinates, ``joints.*.at`` and ``points.*.at`` → every joint's (point's) coordinates;
    any other key unchanged."""
    parts = name.split(".")
    if len(parts) != 3 or parts[0] not in ("joints", "points") or parts[2] != "at":
        return [name]
    items = [it.get("name") for it in data.get(parts[0]) or [] if isinstance(it, dict)]
    names = [n for n in items if isinstance(n, str)] if parts[1] == "*" else [parts[1]]
    return [f"{parts[0]}.{n}.at[{k}]" for n in names for k in range(3)]


@dataclass(frozen=True)
class Hardpoint:
    """One toleranced coordinate: ``table`` "joints" or "points", the item's index there, the
    coordinate k, and the SI metres per unit of the key."""

    table: str
    index: int
    coordinate: int
    metres: float


def hardpoints(tolerances: list[Tolerance]) -> list[Hardpoint]:
    """The hardpoint of every tolerance; a ToleranceError for a key that is not one."""
    from screwkit.io.units import to_si

    out = []
    for t in tolerances:
        p = t.key.path
        if len(p) != 4 or p[0] not in ("joints", "points") or p[2] != "at":
            raise ToleranceError(f"--tol {t.key.text}: tolerance analysis of a graph spec takes "
                                 "hardpoint coordinates: joints.<joint>.at[k] (the joint's seat "
                                 "in its first body), points.<point>.at[k], or joints.<joint>.at "
                                 "and joints.*.at / points.*.at for all three coordinates")
        assert isinstance(p[1], int) and isinstance(p[3], int)
        out.append(Hardpoint(str(p[0]), p[1], p[3], to_si(1.0, "length", t.key.unit)))
    return out


def made_off(mech: Mechanism, points: list[Hardpoint], delta: Array) -> Mechanism:
    """``mech`` with each hardpoint moved by ``delta`` (k,) in its key's unit: joints made off
    their drawing (seat_offset), points moved on their bodies."""
    jd = np.zeros((len(mech.joints), 3))
    pd = np.zeros((len(mech.points), 3))
    for h, d in zip(points, delta, strict=True):
        (jd if h.table == "joints" else pd)[h.index, h.coordinate] += d * h.metres
    joints = tuple(replace(j, at=j.at + jd[i], seat_offset=jd[i]) if jd[i].any() else j
                   for i, j in enumerate(mech.joints))
    pts = tuple(replace(p, at=p.at + pd[i]) if pd[i].any() else p
                for i, p in enumerate(mech.points))
    return replace(mech, joints=joints, points=pts)


def output_names(mech: Mechanism, lay: GraphLayout) -> dict[str, str]:
    """Output → kind ("angle"/"length"): the named outputs, else every scalar passive freedom."""
    if mech.outputs:
        return {o.name: o.kind for o in mech.outputs}
    return {lay.names[f]: ("length" if lay.is_translation[f] else "angle") for f in lay.passive
            if lay.scalar_col[f] >= 0}


def output_values(mech: Mechanism, lay: GraphLayout, conf: Configuration, nominal: Mechanism
                  ) -> dict[str, Array]:
    """The outputs (N,) at closed configurations of ``mech`` (a design), measured against the
    ``nominal`` drawing (a point's travel from its nominal drawn place)."""
    if not mech.outputs:
        return {n: conf.scalars[:, lay.scalar_col[lay.names.index(n)]].copy()
                for n in output_names(mech, lay)}
    fr = graph_forward(mech, lay, conf)
    zero = np.zeros((conf.size, 3))
    drawn = {p.name: p for p in mech.points}
    drawn0 = {p.name: p.at for p in nominal.points}
    out = {}
    for o in mech.outputs:
        if isinstance(o, BodyAngle):
            out[o.name] = body_angle(o, fr.R[:, lay.body_of[o.body]], zero, zero)[0]
        else:
            pt = drawn[o.point]
            b = lay.body_of[pt.body]
            x = np.einsum("nij,j->ni", fr.R[:, b], pt.at) + fr.p[:, b]
            out[o.name] = (x - drawn0[o.point]) @ o.along
    return out


#: a misfit the passive freedoms take up leaves J_p ∂q_p/∂δ + ∂r/∂δ below this fraction of ∂r/∂δ
ABSORBED = 1e-6


def _passive_derivative(mech: Mechanism, lay: GraphLayout, conf: Configuration, lin: Any,
                        plus: Mechanism, minus: Mechanism, h: float) -> tuple[Array, float]:
    """∂q/∂δ (N, m) per unit δ: J_p ∂q_p/∂δ = −∂r/∂δ (module docstring), and the largest
    relative part of ∂r/∂δ that no motion of the passive freedoms takes up (0 where the
    mechanism assembles with the misfit; not 0 where it is overconstrained against it)."""
    rp = scaled_residual(plus, lay, graph_forward(plus, lay, conf))
    rm = scaled_residual(minus, lay, graph_forward(minus, lay, conf))
    dr = (rp - rm) / (2 * h)
    x = lin.solve(dr)
    miss = np.linalg.norm(np.einsum("nij,nj->ni", lin.Jp, x) - dr, axis=1)
    size = np.linalg.norm(dr, axis=1)
    passive = list(lay.passive)
    dq = np.zeros((conf.size, lay.m))
    dq[:, passive] = -x * column_scale(lay)[passive]
    return dq, float(np.max(miss / np.maximum(size, 1e-300), initial=0.0))


def graph_first_order(spec: Any, tolerances: list[Tolerance], mode: Any) -> FirstOrder:
    """Sensitivities and stack-ups of the named outputs of the drawn ``mode`` (a solved
    :class:`~screwkit.kinematics.graph.motion.MechanismMode`) to the hardpoint tolerances."""
    mech = spec.mechanism
    lay = graph_layout(mech)
    pts = hardpoints(tolerances)
    ok = np.asarray(mode.assembles) & ~np.asarray(mode.singular)
    idx = np.nonzero(ok)[0]
    conf = mode.conf.take(idx)
    lin = linearise(mech, lay, conf)
    kinds = output_names(mech, lay)
    if not kinds:
        raise ToleranceError(f"{spec.path}: {mech.name} has no named outputs and no scalar "
                             "joint freedom besides its inputs to analyse: name them in "
                             "[[outputs]] (a body's angle, a point's travel; docs/mechanisms.md)")
    N = ok.size
    nominal = {o: np.full(N, np.nan) for o in kinds}
    for o, v in output_values(mech, lay, conf, mech).items():
        nominal[o][idx] = v
    sens: dict[str, dict[str, Array]] = {o: {} for o in kinds}
    k = len(pts)
    for i, (t, hp) in enumerate(zip(tolerances, pts, strict=True)):
        h = 1e-5 * lay.length / hp.metres  # in the key's unit
        e = np.zeros(k)
        e[i] = h
        plus, minus = made_off(mech, pts, e), made_off(mech, pts, -e)
        dq, stuck = _passive_derivative(mech, lay, conf, lin, plus, minus, h)
        if stuck > ABSORBED:
            raise ToleranceError(
                f"--tol {t.key.text}: {mech.name} cannot take this misfit up by moving (it is "
                "overconstrained in that direction: its loops have redundant constraints, "
                "docs/mechanisms.md), so a part made off so only assembles by straining; leave "
                "this coordinate out (e.g. a planar mechanism's out-of-plane coordinate)")
        yp = output_values(plus, lay, increment(conf, h * dq, lay), mech)
        ym = output_values(minus, lay, increment(conf, -h * dq, lay), mech)
        for o in kinds:
            s = np.full(N, np.nan)
            s[idx] = (yp[o] - ym[o]) / (2 * h)
            sens[o][t.key.text] = s
    tol_of = {t.key.text: t.tolerance for t in tolerances}
    worst = {o: np.sum([np.abs(s[x]) * tol_of[x] for x in s], axis=0) for o, s in sens.items()}
    rss = {o: np.sqrt(np.sum([(s[x] * tol_of[x]) ** 2 for x in s], axis=0))
           for o, s in sens.items()}
    x = spec.inputs[:, 0]  # the first input's value labels a sample (several inputs: rows)
    return FirstOrder(np.asarray(x, dtype=float), list(kinds), nominal, sens, worst, rss,
                      {o: (o, 1.0) for o in kinds}, kinds)


@dataclass(frozen=True)
class GraphMonteCarloTask:
    """What every Monte Carlo batch of a graph shares: the nominal mechanism, the toleranced
    hardpoints and their nominal values, the nominal mode's configuration at the samples where
    it assembles (and those inputs and indices), the outputs and their nominal values."""

    mechanism: Mechanism
    points: tuple[Hardpoint, ...]
    nominal: Array
    scalars: Array
    spherical: Array
    inputs: Array
    index: np.ndarray
    samples: int
    outputs: tuple[str, ...]
    nominal_outputs: Array  # (outputs, n_ok)


def graph_monte_carlo_batch(task: GraphMonteCarloTask, indices: np.ndarray, values: np.ndarray
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Solved output deviations (n, outputs, N) of a batch of drawn designs from the nominal
    (NaN where a design does not close at a sample)."""
    mech = task.mechanism
    lay = graph_layout(mech)
    out = np.full((len(indices), len(task.outputs), task.samples), np.nan)
    start = Configuration(task.scalars, task.spherical)
    for r, v in enumerate(values):
        design = made_off(mech, list(task.points), v - task.nominal)
        conf, err, _ = newton(design, lay, start, task.inputs, max_iter=60)
        y = output_values(design, lay, conf, mech)
        closed = err <= 10 * CLOSURE_TOL
        for c, o in enumerate(task.outputs):
            dev = y[o] - task.nominal_outputs[c]
            dev[~closed] = np.nan
            out[r, c, task.index] = dev
    return indices, out


def run_graph_monte_carlo(engine: Engine, spec: Any, tolerances: list[Tolerance], mode: Any,
                          fo: FirstOrder, n: int, seed: int,
                          progress: Callable[[int, int, int], None] | None = None) -> np.ndarray:
    """Solved deviations (n, outputs, N) of ``n`` drawn designs (σ = t/3), in draw order."""
    from screwkit.sweep.monte_carlo import draw_designs

    mech = spec.mechanism
    ok = np.asarray(mode.assembles) & ~np.asarray(mode.singular)
    idx = np.nonzero(ok)[0]
    task = GraphMonteCarloTask(
        mech, tuple(hardpoints(tolerances)), np.array([t.nominal for t in tolerances]),
        mode.conf.scalars[idx], mode.conf.spherical[idx], spec.inputs[idx], idx, ok.size,
        tuple(fo.outputs), np.stack([fo.nominal[o][idx] for o in fo.outputs]))
    values = draw_designs(tolerances, n, seed)
    result = np.full((n, len(fo.outputs), ok.size), np.nan)
    size = batch_size(n, engine.workers, None, largest=MC_BATCH)
    payloads = [(np.array(b, dtype=np.int64), values[b]) for b in batches(list(range(n)), size)]
    done = [0]

    def finished(_: int, batch: tuple[np.ndarray, np.ndarray]) -> None:
        i, dev = batch
        result[i] = dev
        done[0] += len(i)
        if progress is not None:
            progress(done[0], n, done[0])

    engine.map(graph_monte_carlo_batch, task, payloads, finished)
    return result

"""Every root of a single loop at given inputs by the polynomial homotopy (issue 27, "one engine
for single loops"), for the generic loop solver's root searches.

Where a formulation of :mod:`screwkit.kinematics.modes` fits the loop (a planar R loop; an R
loop with six free joints; a loop of R, P and C joints with six free freedoms; an RSSR, RSRC or
RCCC driven at a ground R joint), the generic
solver seeds its branches from every real solution of one batched parameter homotopy over the
rows searched, instead of Newton from random starts, which cannot promise every root.

1. **The drawing.** A formulation reads the loop as a mechanism graph drawn in one closed
   configuration (:func:`~screwkit.kinematics.graph.from_loop.mechanism_drawn`). That
   configuration is found with the inputs left free: damped minimum-norm Gauss–Newton over every
   freedom (:func:`closed_somewhere`) closes the loop at whatever input value is nearest a
   random start, so a loop that assembles anywhere is drawn, also where random starts at the
   sweep's inputs find nothing (an RCCC with a small twist whose roots lie at slides of many
   link lengths). The formulations' parameters are invariants of the links, so any closed
   configuration will do; of those found, the best-conditioned is kept.
2. **The solve.** One batched solve over every row (inputs measured from the drawing):
   :func:`~screwkit.kinematics.modes.every_mode.solve_formulation`, the parameter homotopy, or
   for a single R loop the elimination solver that falls back to it; each real regular solution turned into the graph tracker's
   configuration by the formulation (with the nearly real singular end points off a continuum:
   double roots, where two modes meet at a fold) and kept only if the graph closure (exact SE(3) logarithm)
   is within :data:`~screwkit.kinematics.modes.every_mode.CLOSURE_TOLERANCE`. A row whose
   singular end points lie on a curve of solutions is a continuum
   (:func:`~screwkit.kinematics.modes.continuum.on_a_continuum`): no root is reported there.
   A row whose paths do not end at the generic count of distinct finite solutions (a double
   root at a fold; a non-generic mechanism whose paths run off to infinity) is not
   ``complete``: the generic solver searches it by random starts as well.
3. **Back to the loop.** Each graph configuration becomes the loop's: scalar freedoms are the
   drawing's plus the graph's (both measure the same joint about the same drawn line); a ball
   joint's rotation is S = Bᵀ G B S₀, with G the graph's relative rotation of its two bodies
   (world, drawn frame), B the joint frame before its motion in the drawing and S₀ the drawing's
   ball rotation (the child frame B S₀ moves with its body: P_b B S₀ = P_a B S). Every root is
   then checked once more against the loop's own closure (:func:`~screwkit.kinematics.tracker.loop.forward`)
   and dropped if it does not close to :data:`LOOP_CLOSURE`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic.track import PathStatus
from screwkit.errors import ScrewkitError
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.from_loop import mechanism_drawn
from screwkit.kinematics.modes.continuum import on_a_continuum
from screwkit.kinematics.modes.every_mode import (
    CLOSURE_TOLERANCE,
    Formulation,
    closure_formulation,
    solve_formulation,
)
from screwkit.kinematics.modes.planar import PlanarFormulation
from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    Layout,
    apply_increment,
    closure_twist,
    constants,
    forward,
)
from screwkit.kinematics.tracker.solve import Assemblies, random_configurations, signature
from screwkit.model.linkage import Linkage
from screwkit.model.mechanism import Mechanism

#: a root converted back to the loop must close the loop's own chain to this (scaled residual)
LOOP_CLOSURE = 1e-9
#: a singular end point (a double root at a fold) is taken as real when its imaginary part is
#: at most this, relative (the endgame resolves a double root to about √ε)
DOUBLE_ROOT_IMAG = 1e-6
#: a solution this large (in any unknown) is a path on its way to infinity: its row is not
#: complete
FAR_OUT = 1e8
#: random starts of the search for a drawing (inputs free), and how many closed ones are enough
#: to choose from
DRAWING_STARTS = 24
DRAWINGS = 4


@dataclass(frozen=True)
class LoopFormulation:
    """A loop's polynomial formulation: the ``mechanism`` drawn at ``drawn`` (one loop
    configuration, inputs ``drawn_inputs``), the formulation ``form`` of that mechanism, the
    joint frames before their motion in the drawing ``before_R`` (n, 3, 3), and ``name`` (the
    formulation's kind, for the Motion's solver string)."""

    mechanism: Mechanism
    form: Formulation
    drawn: Configuration
    drawn_inputs: Array
    before_R: Array
    name: str


def _form_inputs(form: Formulation, rel: Array) -> Array:
    """Rows of inputs (B, n_inputs) as ``form`` reads them: (B,) for the one-input rod loops
    and the RCCC, (B, n_inputs) for the planar and 6R formulations."""
    return rel[:, 0] if formulation_name(form) in ("RSSR", "RSRC", "RCCC") else rel


def formulation_name(form: Formulation) -> str:
    """A short name of the formulation: "planar R loop", "6R", "R/P/C loop", "RSSR", "RSRC" or
    "RCCC"."""
    if isinstance(form, PlanarFormulation):
        return "planar R loop"
    kind = getattr(form, "kind", None)
    if isinstance(kind, str):
        return kind
    return "RCCC" if type(form).__name__ == "RCCCLoop" else "6R"


def closed_somewhere(linkage: Linkage, lay: Layout, starts: int = DRAWING_STARTS, seed: int = 0,
                     iterations: int = 60) -> Configuration:
    """Closed configurations of the loop at any input value (inputs free): damped minimum-norm
    Gauss–Newton over every freedom from ``starts`` random configurations
    (:func:`~screwkit.kinematics.tracker.solve.random_configurations`), vectorised; the
    converged ones (scaled residual ≤ 1e-12; it stops once :data:`DRAWINGS` are closed to
    1e-13), possibly none."""
    L = constants(linkage, lay)[2]
    rows = np.array([1.0, 1.0, 1.0, 1.0 / L, 1.0 / L, 1.0 / L])
    cols = np.array([L if t else 1.0 for t in lay.is_translation])
    conf = random_configurations(linkage, starts, np.random.default_rng(seed), lay)
    for _ in range(iterations):
        fr = forward(linkage, conf, lay, frames=False)
        xi = closure_twist(fr.closure_R, fr.closure_p) * rows
        if np.sum(np.max(np.abs(xi), axis=-1) <= 1e-13) >= DRAWINGS:
            break
        J = fr.screws * rows[:, None] * cols[None, :]
        JJt = J @ np.swapaxes(J, -1, -2)
        mu = 1e-12 * np.maximum(np.trace(JJt, axis1=-2, axis2=-1), 1e-300)
        y = np.linalg.solve(JJt + mu[:, None, None] * np.eye(6), xi[..., None])[..., 0]
        step = -np.einsum("nji,nj->ni", J, y)
        step *= np.minimum(1.0, 0.5 / np.maximum(np.max(np.abs(step), -1, keepdims=True),
                                                 1e-300))
        conf = apply_increment(conf, step * cols, lay)
    fr = forward(linkage, conf, lay, frames=False)
    res = np.max(np.abs(closure_twist(fr.closure_R, fr.closure_p) * rows), axis=-1)
    return conf.take(np.flatnonzero(np.isfinite(res) & (res <= 1e-12)))


def _may_fit(linkage: Linkage, lay: Layout) -> bool:
    """Whether a formulation may take the loop, from its joints alone (before the drawing is
    searched): R joints only, planar (every link keeps the z axis, up to its sign) or with six
    free joints; R, P and C joints (some P or C) with six free freedoms; or four joints making
    an RSSR, RSRC or RCCC."""
    kinds = sorted(j.kind for j in linkage.joints)
    if set(kinds) == {"R"}:
        planar = bool(np.all(np.abs(np.abs(constants(linkage, lay)[0][:, 2, 2]) - 1.0)
                             < 1e-12))
        return planar or len(kinds) - len(linkage.inputs) == 6
    if set(kinds) <= {"R", "P", "C"} and set(kinds) & {"P", "C"}:
        freedoms = sum(2 if k == "C" else 1 for k in kinds)
        if freedoms - len(linkage.inputs) == 6:
            return True
    return len(linkage.inputs) == 1 and kinds in (["R", "R", "S", "S"], ["C", "R", "R", "S"],
                                                  ["C", "C", "C", "R"])


def loop_formulation(linkage: Linkage, lay: Layout, seed: int = 0) -> LoopFormulation | None:
    """The formulation that fits ``linkage``, drawn at a closed configuration (module
    docstring, step 1), or None: no formulation takes this loop (its joints; a U joint, whose
    second axis a drawing does not keep; an input not at a ground R joint ...), or the loop
    closes nowhere."""
    if not _may_fit(linkage, lay):
        return None
    closed = closed_somewhere(linkage, lay, seed=seed)
    if closed.size == 0:
        return None
    # the best-conditioned drawing: the largest smallest singular value of the scaled Jacobian
    L = constants(linkage, lay)[2]
    rows = np.array([1.0, 1.0, 1.0, 1.0 / L, 1.0 / L, 1.0 / L])
    cols = np.array([L if t else 1.0 for t in lay.is_translation])
    fr = forward(linkage, closed, lay)
    sv = np.linalg.svd(fr.screws * rows[:, None] * cols[None, :], compute_uv=False)
    best = int(np.argmax(sv[:, -1] / sv[:, 0]))
    drawn = closed.take(np.array([best]))
    try:
        mech = mechanism_drawn(linkage, fr.centres[best], fr.axes[best])
        form = closure_formulation(mech)
        form.parameters(_form_inputs(form, np.zeros((1, len(linkage.inputs)))))
    except ScrewkitError:  # e.g. an R loop without six free joints
        return None
    inputs = np.array([drawn.scalars[0, lay.scalar_col[lay.names.index(n)]]
                       for n in linkage.inputs])
    return LoopFormulation(mech, form, drawn, inputs, fr.before_R[best],
                           formulation_name(form))


@dataclass(frozen=True)
class AlgebraicRoots:
    """Every real root at each row searched, as the root search's
    :class:`~screwkit.kinematics.tracker.solve.Assemblies`, with ``continuum`` (rows on a curve
    of solutions, no root reported), ``certified`` (B, K) the roots that passed Smale's α-test,
    ``found`` (B,) distinct complex solutions, the topology's ``generic_count``, and
    ``complete`` (B,): the row's paths ended at ``generic_count`` distinct finite solutions
    (none failed, none at or near infinity; or the row is a continuum)."""

    assemblies: Assemblies
    continuum: NDArray[np.bool_]
    certified: NDArray[np.bool_]
    found: NDArray[np.int64]
    generic_count: int
    complete: NDArray[np.bool_]


def _loop_configuration(lf: LoopFormulation, linkage: Linkage, lay: Layout,
                        graph: Configuration) -> Configuration:
    """The loop's configurations of the graph's (module docstring, step 3)."""
    glay = graph_layout(lf.mechanism)
    N = graph.size
    q = np.repeat(lf.drawn.scalars, N, axis=0)
    for f, name in enumerate(lay.names):
        c = lay.scalar_col[f]
        if c >= 0:
            q[:, c] += graph.scalars[:, glay.scalar_col[glay.names.index(name)]]
    sph = np.repeat(lf.drawn.spherical, N, axis=0)
    for k, s in lay.spherical_of_joint.items():
        B = lf.before_R[k]
        G = graph.spherical[:, glay.spherical_of_joint[k]]
        sph[:, s] = B.T @ G @ B @ lf.drawn.spherical[0, s]
    return Configuration(q, sph)


def algebraic_roots(lf: LoopFormulation, linkage: Linkage, lay: Layout, X: Array
                    ) -> AlgebraicRoots:
    """Every real root of the loop at each row of inputs ``X`` (B, n_inputs), by one batched
    parameter homotopy (module docstring, step 2); vectorised over rows and roots."""
    form = lf.form
    B = X.shape[0]
    rel = X - lf.drawn_inputs
    p = form.parameters(_form_inputs(form, rel))
    sol = solve_formulation(form, p)
    continuum = np.zeros(B, dtype=bool)
    singular = np.flatnonzero(sol.status == PathStatus.SINGULAR)
    if singular.size:
        on = on_a_continuum(form.system, sol.x[singular],
                            np.asarray(p[sol.instance[singular]], dtype=complex))
        continuum[np.unique(sol.instance[singular][on])] = True
    # a singular end point off a continuum is a double root: a real dead centre (a fold) when
    # nearly real (the endgame's accuracy there is ~√ε, and its closure is checked below)
    nearly_real = np.abs(sol.x.imag).max(axis=1, initial=0.0) <= DOUBLE_ROOT_IMAG * (
        1.0 + np.abs(sol.x).max(axis=1, initial=0.0))
    take = np.flatnonzero(((sol.real & (sol.status == PathStatus.REGULAR))
                           | ((sol.status == PathStatus.SINGULAR) & nearly_real))
                          & ~continuum[sol.instance])
    inst = sol.instance[take]
    if take.size and lf.name != "6R":
        graph, glay = form.configuration(sol.x[take], _form_inputs(form, rel[inst]))
    elif take.size:  # the 6R instances differ per row: their way back is per row
        take = take[np.argsort(inst, kind="stable")]
        inst = sol.instance[take]
        parts = [form.configuration(sol.x[take[inst == b]], rel[b]) for b in np.unique(inst)]
        glay = parts[0][1]
        graph = Configuration(np.concatenate([c.scalars for c, _ in parts]),
                              np.concatenate([c.spherical for c, _ in parts]))
    if take.size:
        closes = np.abs(graph_forward(lf.mechanism, glay, graph).residual).max(axis=(1, 2)) \
            <= CLOSURE_TOLERANCE * max(lf.mechanism.length_scale, 1.0)
        conf = _loop_configuration(lf, linkage, lay, graph)
        L = constants(linkage, lay)[2]
        fr = forward(linkage, conf, lay, frames=False)
        xi = closure_twist(fr.closure_R, fr.closure_p)
        res = np.maximum(np.abs(xi[:, :3]).max(-1), np.abs(xi[:, 3:]).max(-1) / L)
        ok = closes & (res <= LOOP_CLOSURE)
        take, inst, conf = take[ok], inst[ok], conf.take(np.flatnonzero(ok))
    else:
        conf = lf.drawn.take(np.zeros(0, dtype=np.intp))
    # slots: the k-th root of each row
    counts = np.bincount(inst, minlength=B)
    K = max(int(counts.max(initial=0)), 1)
    order = np.argsort(inst, kind="stable")
    slot = np.arange(take.size) - np.repeat(np.cumsum(counts) - counts, counts)
    found = np.zeros((B, K), dtype=bool)
    found[inst[order], slot] = True
    scal = np.repeat(lf.drawn.scalars, B * K, axis=0)
    sph = np.repeat(lf.drawn.spherical, B * K, axis=0)
    flat = inst[order] * K + slot
    scal[flat] = conf.scalars[order]
    sph[flat] = conf.spherical[order]
    full = Configuration(set_input_values(scal, lay, linkage, np.repeat(X, K, axis=0)), sph)
    sig = signature(linkage, full, lay).reshape(B, K, -1)
    certified = np.zeros((B, K), dtype=bool)
    certified[inst[order], slot] = sol.certified_real[take[order]]
    asm = Assemblies(full, found, sig, np.full((B, K), 1e-6))
    # a row is complete when its paths account for the generic count with finite, distinct
    # solutions of moderate size (a non-generic mechanism, e.g. an RSRC with its coupler's R
    # parallel to the C joint, sends paths to infinity, and its paths near a fold may miss)
    huge = np.abs(sol.x).max(axis=1, initial=0.0) > FAR_OUT
    complete = (sol.found == sol.generic_count) & (sol.failed == 0) & (sol.at_infinity == 0) \
        & (np.bincount(sol.instance[huge], minlength=B) == 0)
    return AlgebraicRoots(asm, continuum, certified, sol.found, sol.generic_count,
                          complete | continuum)


def set_input_values(scalars: Array, lay: Layout, linkage: Linkage, X: Array) -> Array:
    """``scalars`` with the inputs' columns set to ``X`` exactly (the drawing's value plus the
    graph's difference agrees with them to round-off)."""
    out = scalars.copy()
    for k, name in enumerate(linkage.inputs):
        out[:, lay.scalar_col[lay.names.index(name)]] = X[:, k]
    return out


__all__ = ["AlgebraicRoots", "LoopFormulation", "algebraic_roots", "closed_somewhere",
           "loop_formulation"]

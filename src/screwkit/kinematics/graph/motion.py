"""The motion of any mechanism over its inputs: :func:`solve_mechanism` → :class:`MechanismMotion`.

A mechanism built of closed-form sub-chains (driven joints, planar dyads and RSS legs,
graph/subchains.py) gets its drawn mode, and on request every mode, from their closed forms
(graph/dyads.py, graph/legs.py, graph/closed_modes.py); any other has its drawn assembly mode
followed along the inputs: a single loop by the loop engine's continuation (graph/loop_track.py),
a mechanism of several loops by the same engine on the stacked closure (graph/follow.py).
Then, for each mode, at every sample and all at once, the body poses, the freedoms' rates and
accelerations from the stacked screw Jacobian (graph/newton.py: J_p q̇_p = −J_in ẋ,
J_p q̈_p = −J_in ẍ − bias), every body's twist and acceleration (graph/closure.py), joint centres
and axes, and the paths of the points carried by bodies. Per mode the fields are those of a single loop's :class:`ModeMotion` with "link" read as
"body" (``link_rotation[:, k]`` is body k's pose, in ``mechanism.bodies`` order), plus the points.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import cross
from screwkit.errors import InputError, UnknownNameError
from screwkit.kinematics.graph.closure import (
    GraphFrames,
    GraphLayout,
    body_accelerations,
    graph_layout,
    loop_residuals,
)
from screwkit.kinematics.graph.loop_track import follow_drawn
from screwkit.kinematics.graph.newton import (
    RANK_CUTOFF,
    Linearised,
    accelerations_twists,
    drawn_linearisation,
    linearise,
    rates,
    scaled_residual,
)
from screwkit.kinematics.graph.singular import SINGULAR_TOL
from screwkit.kinematics.graph.subchains import Decomposition, decompose
from screwkit.kinematics.motion import AssemblyError, ModeMotion
from screwkit.kinematics.tracker.loop import Configuration, rotation_vector
from screwkit.messages import given, listing
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

#: a sample is singular where the passive block's smallest kept singular value falls below
#: SINGULAR_TOL of its largest (the inputs no longer fix the mechanism there; graph/singular.py)


@dataclass(frozen=True, eq=False)
class MechanismMode(ModeMotion):
    """One assembly mode of a mechanism (ModeMotion's fields, "link" read as "body") with the
    paths of its points: ``points[name]`` (N, 3) world positions, and their velocities and
    accelerations."""

    points: dict[str, Array] = field(default_factory=dict)
    point_velocities: dict[str, Array] = field(default_factory=dict)
    point_accelerations: dict[str, Array] = field(default_factory=dict)
    #: the mechanism's named outputs (kinematics/graph/outputs.py): value, rate, acceleration
    outputs: dict[str, Array] = field(default_factory=dict)
    output_rates: dict[str, Array] = field(default_factory=dict)
    output_accelerations: dict[str, Array] = field(default_factory=dict)
    #: per sample: σ₁/σ_r of the passive block, the closure Jacobian and (with a platform) the
    #: Jacobian with the platform held (graph/singular.py), NaN where the mode does not assemble
    jacobian_condition: dict[str, Array] = field(default_factory=dict)
    #: per sample: "" or the singularity's class (input, output, constraint, dead centre,
    #: bifurcation; graph/singular.py)
    singular_class: NDArray[np.str_] = field(default_factory=lambda: np.zeros(0, dtype=str))


@dataclass(frozen=True, eq=False)
class MechanismMotion:
    """Positions, rates and accelerations of a mechanism over its inputs, per assembly mode
    (mode 0 is the drawn mode)."""

    mechanism: Mechanism
    inputs: Array
    input_rates: Array
    input_accelerations: Array
    modes: tuple[MechanismMode, ...]
    method: str = "graph"
    solver: str = "continuation from the drawn configuration on the stacked loop closure"
    notes: tuple[str, ...] = ()

    @property
    def input_names(self) -> tuple[str, ...]:
        """The joint inputs, then the driven body freedoms (the columns of ``inputs``)."""
        return self.mechanism.driven_names

    @property
    def samples(self) -> int:
        return int(self.inputs.shape[0])

    def mode(self, index: int) -> MechanismMode:
        n = len(self.modes)
        if isinstance(index, bool) or not isinstance(index, int | np.integer):
            raise InputError(f"mode must be an integer index 0…{n - 1}; got {index!r}")
        if not 0 <= index < n:
            raise AssemblyError(f"{self.mechanism.name}: assembly mode {index} asked for; the "
                                f"mechanism has {n} mode(s) here (0…{n - 1})")
        return self.modes[index]

    def variable(self, name: str, mode: int = 0, *, derivative: int = 0) -> Array:
        md = self.mode(mode)
        if derivative not in (0, 1, 2):
            raise InputError(f"derivative must be 0, 1 or 2; got {derivative!r}")
        table = (md.variables, md.velocities, md.accelerations)[derivative]
        if name not in table:
            raise UnknownNameError(f"{self.mechanism.name}: no variable {name!r}; the "
                                   f"variables are {listing(sorted(table))}")
        return table[name]

    def point(self, name: str, mode: int = 0, *, derivative: int = 0) -> Array:
        md = self.mode(mode)
        table = (md.points, md.point_velocities, md.point_accelerations)[derivative]
        if name not in table:
            raise UnknownNameError(f"{self.mechanism.name}: no point {name!r}; the points "
                                   f"are {listing(sorted(md.points))}")
        return table[name]


def _per_sample(values: ArrayLike | None, N: int, n_in: int, name: str) -> Array:
    if values is None:
        return np.zeros((N, n_in))
    try:
        a = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers; got {given(values)}") from None
    if a.ndim == 0:
        a = np.full((N, n_in), float(a))
    elif a.ndim == 1 and a.shape[0] == N and n_in == 1:
        a = a[:, None]
    elif a.ndim == 1 and a.shape[0] == n_in:
        a = np.broadcast_to(a, (N, n_in))
    if a.shape != (N, n_in) or not np.all(np.isfinite(a)):
        raise InputError(f"{name}: give one finite value per input ({n_in}) or one per sample "
                         f"and input ({N}×{n_in}); got shape {'×'.join(map(str, np.shape(values))) or 'scalar'}")
    return np.array(a, dtype=float)


def input_rows(mech: Mechanism, inputs: ArrayLike) -> Array:
    """Input values as (N, n_in) rows, checked (one column per joint input and driven body
    freedom of ``mech``)."""
    try:
        X = np.asarray(inputs, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"inputs must be numbers; got {given(inputs)}") from None
    names = mech.driven_names
    n_in = len(names)
    if X.ndim == 1 and n_in == 1:
        X = X[:, None]
    if X.ndim != 2 or X.shape[1] != n_in or X.shape[0] == 0:
        raise InputError(f"{mech.name}: inputs must be rows of {n_in} value(s) "
                         f"({', '.join(names)}); got shape {'×'.join(map(str, X.shape)) or 'scalar'}")
    if not np.all(np.isfinite(X)):
        raise InputError(f"{mech.name}: inputs must be finite numbers (a NaN or inf was given)")
    return X


#: computing time per sample, per joint, inflated by the loops (measured on the bundled
#: examples, rounded up: the Watt six-bar's 7 joints and 2 loops take ~25 µs per sample)
SECONDS_PER_JOINT_SAMPLE = 5e-6


def check_cost(mech: Mechanism, samples: int) -> None:
    """Refuse up front a motion whose computing time or memory is over the limits
    (screwkit.budget), with the estimate and what to change."""
    from screwkit.budget import check_memory, check_time

    J, L, B = len(mech.joints), len(mech.topology.loops), len(mech.bodies) + 1
    m = sum(len(j.freedoms) for j in mech.joints)
    seconds = samples * SECONDS_PER_JOINT_SAMPLE * J * (1.0 + 0.3 * L)
    advice = "use fewer input samples (a larger [motion] step, a shorter range, fewer rows)"
    check_time(seconds, f"the motion of {mech.name} over {samples} samples", advice)
    # per sample: poses, twists, accelerations of every body, the screws, the Jacobian, rates
    floats = 12 * B + 6 * 3 * B + 6 * m + 2 * 36 * L * m + 3 * m + 6 * J
    check_memory(8.0 * samples * floats * 3, f"the motion of {mech.name} over {samples} "
                 "samples", advice)


def solve_mechanism(mech: Mechanism, inputs: ArrayLike, *, rates: ArrayLike | None = 1.0,
                    accelerations: ArrayLike | None = 0.0,
                    progress: Callable[[int, int], None] | None = None,
                    every_mode: bool = False) -> MechanismMotion:
    """The drawn mode of ``mech`` over ``inputs`` (N rows, one value per input, measured from
    the drawing; SI), with input ``rates`` and ``accelerations`` (a scalar, one per input or
    one per sample and input). The inputs are the joint inputs, then the driven body freedoms
    (``mech.driven_names``; graph/drives.py).

    A mechanism that decomposes into closed-form sub-chains (graph/subchains.py: driven joints,
    planar dyads, RSS legs) is solved by their closed forms (graph/dyads.py, legs.py), and with
    ``every_mode`` every other assembly mode follows the drawn one (graph/closed_modes.py);
    any other mechanism by continuation of the drawn mode (graph/loop_track.py for a single
    loop, graph/follow.py otherwise; ``every_mode`` then adds the homotopy's modes where a
    formulation takes the mechanism, modes/along.py, and the motion's notes say so where none
    does)."""
    if mech.drives:
        return _solve_driven(mech, inputs, rates, accelerations, progress, every_mode)
    X = input_rows(mech, inputs)
    N, n_in = X.shape
    check_cost(mech, N)
    Xd = _per_sample(rates, N, n_in, "rates")
    Xdd = _per_sample(accelerations, N, n_in, "accelerations")
    lay = graph_layout(mech)
    from screwkit.kinematics.graph.loop_motion import loop_motion
    from screwkit.kinematics.graph.loop_stage import loop_stage_motion
    from screwkit.kinematics.graph.loop_subchain import loop_chain

    chain = loop_chain(mech)
    if chain is not None:  # one loop: the loop engine is its sub-chain solver
        looped = loop_motion(mech, lay, chain, X, Xd, Xdd, every_mode)
        if looped is not None:
            if callable(progress):
                progress(N, N)
            return looped  # type: ignore[return-value]
    dec = decompose(mech)
    if dec.complete and not misfits(mech):  # seat offsets (tolerances): re-assembled below
        solve = loop_stage_motion if dec.loops else _closed_form_motion  # a family loop in it?
        motion = solve(mech, lay, dec, X, Xd, Xdd, every_mode)
        if callable(progress):
            progress(N, N)
        return motion
    start = reassemble_drawing(mech, lay) if misfits(mech) else None
    followed = follow_drawn(mech, lay, X, progress, start)
    if not followed.mask.any():
        where = ""
        if followed.reached is not None:
            where = (f", on the straight way from the drawing (every input 0) after "
                     f"{input_text(mech, lay, followed.reached)}: the inputs that assemble end there "
                     "(a limit of the workspace, or a dead centre)")
        raise AssemblyError(f"{mech.name}: the drawn configuration cannot be followed to the "
                            f"first input row {input_text(mech, lay, X[0])}: the mechanism stops "
                            f"assembling before it{where}")
    mode = build_mode(mech, lay, followed.conf, followed.mask, X, Xd, Xdd, followed.frames)
    events = list(mode.events)
    if followed.stopped_after is not None and followed.stopped_after >= 0:
        k = followed.stopped_after
        nxt = f" (a limit position or dead centre before {input_text(mech, lay, X[k + 1])})" \
            if k + 1 < N else ""
        events.insert(0, f"stops assembling after input {input_text(mech, lay, X[k])}{nxt}")
    mode = with_events(mode, events)
    if every_mode:
        from screwkit.kinematics.modes.along import every_mode_motion

        modes, notes = every_mode_motion(mech, lay, dec, X, Xd, Xdd, mode, followed.conf)
        method = "graph (homotopy at anchors, tracking between)" if len(notes) and \
            notes[0].startswith("every mode along") else "graph"
        return MechanismMotion(mech, X, Xd, Xdd, modes, method=method, solver=followed.solver,
                               notes=notes)
    return MechanismMotion(mech, X, Xd, Xdd, (mode,), solver=followed.solver)


CLOSED_FORM_SOLVER = ("closed-form sub-chains (driven joints, planar dyads, spatial legs; every "
                      "branch), rates and accelerations from the stacked loop closure")


def _closed_form_motion(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array,
                        Xd: Array, Xdd: Array, every: bool) -> MechanismMotion:
    """The drawn mode (and with ``every`` every other mode that assembles somewhere) from the
    closed forms (graph/closed_modes.py). The drawn mode stops at its first fold; with
    ``every``, where the drawn branches assemble again after it, their later runs are one more
    mode, last, born at a fold (issue 27: a run that re-enters is reported)."""
    from screwkit.budget import ResourceLimitError
    from screwkit.kinematics.graph.closed_modes import (
        branch_combinations,
        drawn_combination,
        drawn_start,
        drawn_with_events,
        every_mode,
        fold_events,
        held_modes,
        mode_configuration,
        mode_frames,
        mode_label,
    )
    from screwkit.kinematics.graph.dyads import place

    N = X.shape[0]
    skipped = ""
    if every:  # 2^D modes, each costing a drawn mode's time: only the drawn one when too many
        try:
            check_cost(mech, N * dec.mode_count)
        except ResourceLimitError as err:
            every, skipped = False, (f"every mode: only the drawn mode is solved; the "
                                     f"{dec.mode_count} branch combinations would be over a "
                                     f"limit ({err})")
    if every:
        signs = branch_combinations(dec)
        pl = every_mode(mech, lay, dec, X).placement
    else:
        signs = drawn_combination(dec)
        pl = place(mech, lay, dec, X, np.repeat(signs, N, axis=0))
    M = signs.shape[0]
    ok = pl.assembles.reshape(M, N)
    R = pl.R.reshape(M, N, *pl.R.shape[1:])
    p = pl.p.reshape(M, N, *pl.p.shape[1:])
    start = drawn_start(mech, lay, dec, X[0])
    if start is None or not ok[0, 0]:
        raise AssemblyError(f"{mech.name}: the drawn configuration cannot be followed to the "
                            f"first input row {input_text(mech, lay, X[0])}: the mechanism stops "
                            "assembling before it")
    held = held_modes(mech, lay, dec, X, signs, ok, pl.discriminant.reshape(M, N, -1), every)
    drawn = held.masks[0]
    conf = mode_configuration(mech, lay, R[0], p[0], X, drawn, start)
    mode = build_mode(mech, lay, conf, drawn, X, Xd, Xdd,
                      mode_frames(mech, lay, R[0], p[0], drawn))  # the poses reused
    folds, joins = fold_events(mech, lay, dec, X, signs, held)
    modes = [drawn_with_events(mech, lay, mode, X, held.stop, folds[0])]
    for i, (m, events) in enumerate(zip(held.rows[1:], folds[1:], strict=True), start=1):
        conf = mode_configuration(mech, lay, R[m], p[m], X, held.masks[i])
        md = build_mode(mech, lay, conf, held.masks[i], X, Xd, Xdd,
                        mode_frames(mech, lay, R[m], p[m], held.masks[i]))
        label = f"branches {mode_label(mech, dec, signs[m])}{held.labels[i]}"
        modes.append(replace(with_events(md, [*events, *md.events]), label=label,
                             index=len(modes)))
    notes: tuple[str, ...] = (skipped,) if skipped else ()
    if every:
        notes = (f"{M} branch combination(s) of {len(dec.dyads)} sub-chain(s); {len(modes)} "
                 "mode(s) assemble over these inputs (the same branches again where they "
                 "assemble again after a fold, and islands inside one sample step as modes of "
                 "their own)" if len(modes) > len(set(held.rows))
                 else f"{M} branch combination(s) of {len(dec.dyads)} sub-chain(s); "
                 f"{len(modes)} assemble over these inputs",
                 "circuits (modes that meet at a fold, where the input must turn back to go "
                 "on): " + ", ".join("{" + ", ".join(map(str, c)) + "}"
                                     for c in groups(len(modes), joins)))

    return MechanismMotion(mech, X, Xd, Xdd, tuple(modes), method="graph (closed forms)",
                           solver=CLOSED_FORM_SOLVER, notes=notes)


def groups(n: int, joins: list[tuple[int, int]]) -> list[list[int]]:
    """0 … n−1 grouped by the pairs ``joins`` (union–find)."""
    group = list(range(n))

    def root(i: int) -> int:
        while group[i] != i:
            i = group[i]
        return i

    for a, b in joins:
        group[root(a)] = root(b)
    out: dict[int, list[int]] = {}
    for i in range(n):
        out.setdefault(root(i), []).append(i)
    return sorted(out.values())


def _solve_driven(mech: Mechanism, inputs: ArrayLike, rates_: ArrayLike | None,
                  accelerations_: ArrayLike | None,
                  progress: Callable[[int, int], None] | None,
                  every_mode: bool = False) -> MechanismMotion:
    """A mechanism with driven body freedoms: solved with its virtual chains (graph/drives.py),
    which are then removed from the result."""
    from screwkit.kinematics.graph.drives import augmented, rename_virtual, restricted_mode
    from screwkit.kinematics.graph.topology import mechanism_topology

    X = input_rows(mech, inputs)
    topology = mechanism_topology(mech)
    if not topology.as_dict()["drives"]:
        raise InputError(f"{mech.name}: {topology.verdict}")
    try:
        whole = solve_mechanism(augmented(mech), X, rates=rates_,
                                accelerations=accelerations_, progress=progress,
                                every_mode=every_mode)
    except AssemblyError as exc:
        raise AssemblyError(rename_virtual(mech, str(exc))) from None
    modes = tuple(restricted_mode(mech, md) for md in whole.modes)
    return MechanismMotion(mech, whole.inputs, whole.input_rates, whole.input_accelerations,
                           modes,  # type: ignore[arg-type]
                           method=whole.method, solver=whole.solver, notes=whole.notes)


def misfits(mech: Mechanism) -> bool:
    """Whether any joint of ``mech`` is made off its drawing (a ``seat_offset``): no closure."""
    return any(j.seat_offset is not None for j in mech.joints)


#: Newton iterations allowed to re-assemble a drawing whose parts are made off it
REASSEMBLE_ITERATIONS = 30


def reassemble_drawing(mech: Mechanism, lay: GraphLayout) -> Configuration:
    """The assembly nearest the drawing of a mechanism whose parts are made off it
    (``seat_offset``): the inputs held at the drawing (0), the passive freedoms closed by
    Newton's method on the stacked closure (graph/newton.py) from the drawn configuration.
    An AssemblyError where it does not converge (the misfits are too large to assemble)."""
    from screwkit.kinematics.graph.closure import zero_configuration
    from screwkit.kinematics.graph.newton import CLOSURE_TOL, newton

    X0 = np.zeros((1, len(mech.inputs)))
    conf, err, _ = newton(mech, lay, zero_configuration(lay), X0,
                          max_iter=REASSEMBLE_ITERATIONS)
    if not err[0] <= 10 * CLOSURE_TOL:
        raise AssemblyError(f"{mech.name}: with its parts made off the drawing (seat offsets of "
                            f"{', '.join(j.name for j in mech.joints if j.seat_offset is not None)}"
                            f") the mechanism does not re-assemble near the drawing (closure "
                            f"residual {err[0]:.3g} after {REASSEMBLE_ITERATIONS} Newton steps); "
                            "use smaller offsets")
    return conf


def with_events(mode: MechanismMode, events: list[str]) -> MechanismMode:
    fields = {k: getattr(mode, k) for k in mode.__dataclass_fields__}
    fields["events"] = events
    return MechanismMode(**fields)


def input_text(mech: Mechanism, lay: GraphLayout, x: Array) -> str:
    """One row of inputs for a message, in the spec's units (kinematics/motion.py
    ``format_inputs``)."""
    from screwkit.kinematics.motion import format_inputs

    return format_inputs(mech, x)


def build_mode(mech: Mechanism, lay: GraphLayout, conf: Configuration, mask: NDArray[np.bool_],
               X: Array, Xd: Array, Xdd: Array, tracked: GraphFrames | None = None
               ) -> MechanismMode:
    """Everything about one mode from its configurations (module docstring); ``tracked``, the
    tracker's body poses and screws at those configurations, are reused when given (only the
    loops' exact closure twists are evaluated anew)."""
    drawn = drawn_linearisation(mech, lay)  # one for the ranks here and in singularities
    rank = expected_rank(mech, lay, drawn)
    if tracked is not None:
        tracked = GraphFrames(tracked.R, tracked.p, tracked.screws,
                              loop_residuals(mech, lay, conf, tracked.R, tracked.p),
                              tracked.centres, tracked.axes)
    lin = linearise(mech, lay, conf, tracked, full_rank=rank == len(lay.passive))
    fr = lin.frames
    qd = rates(mech, lay, lin, Xd)
    from screwkit.kinematics.graph.idle import IdleBasis, hold_rod_spin, idle_basis

    basis: IdleBasis | None = None
    if rank < len(lay.passive):  # rods between two balls: their spin held still (graph/idle.py)
        basis = idle_basis(mech, lay, lin)  # one SVD for the rates and the accelerations
    if basis is not None:
        qd = hold_rod_spin(mech, lay, lin, qd, basis=basis)
    qdd, bias, V = accelerations_twists(mech, lay, lin, qd, Xdd)  # V: the body twists
    if basis is not None:
        qdd = hold_rod_spin(mech, lay, lin, qdd, bias, basis=basis)
    A = body_accelerations(mech, lay, fr.screws, qdd, bias)
    nb = len(mech.bodies)
    singular = mask & _singular(rank, lin.sigma)
    w, v0, al, a0 = V[:, :nb, :3], V[:, :nb, 3:], A[:, :nb, :3], A[:, :nb, 3:]
    p = fr.p[:, :nb]
    v_o = v0 + cross(w, p)
    a_o = a0 + cross(al, p) + cross(w, v_o)
    variables, velocities, accels = _variables(mech, lay, conf, qd, qdd)
    residual = np.linalg.norm(scaled_residual(mech, lay, fr), axis=1)
    points, pv, pa = {}, {}, {}
    for pt in mech.points:
        b = lay.body_of[pt.body]
        x = np.einsum("nij,j->ni", fr.R[:, b], pt.at) + fr.p[:, b]
        v = V[:, b, 3:] + cross(V[:, b, :3], x)
        a = A[:, b, 3:] + cross(A[:, b, :3], x) + cross(V[:, b, :3], v)
        points[pt.name], pv[pt.name], pa[pt.name] = x, v, a
    outs = _outputs(mech, lay, fr.R, V, A, points, pv, pa)
    frames = [fr.R[:, :nb].copy(), p.copy()]
    twists = [w.copy(), v_o, al.copy(), a_o]
    bad = ~mask
    for table in (variables, velocities, accels, points, pv, pa, *outs):
        for values in table.values():
            values[bad] = np.nan
    for table in (velocities, accels, pv, pa, outs[1], outs[2]):
        for values in table.values():
            values[singular] = np.nan
    centres, axes = fr.centres.copy(), fr.axes.copy()
    for arr in [*frames, *twists, centres, axes]:
        arr[bad] = np.nan
    for arr in twists:
        arr[singular] = np.nan
    residual[bad] = np.nan
    from screwkit.kinematics.graph.singular import singular_events, singularities

    sing = singularities(mech, lay, conf, mask, lin, drawn)
    idx = np.flatnonzero(sing.kind != "")
    events = singular_events({int(k): input_text(mech, lay, X[k]) for k in idx}, sing) \
        if idx.size else []
    return MechanismMode(mask, singular, conf, variables, velocities, accels,
                         link_rotation=frames[0], link_origin=frames[1],
                         link_angular_velocity=twists[0], link_origin_velocity=twists[1],
                         link_angular_acceleration=twists[2], link_origin_acceleration=twists[3],
                         joint_centres=centres, joint_axes=axes, closure_residual=residual,
                         events=events, points=points, point_velocities=pv,
                         point_accelerations=pa, outputs=outs[0], output_rates=outs[1],
                         output_accelerations=outs[2], jacobian_condition=sing.condition,
                         singular_class=sing.kind)


def _outputs(mech: Mechanism, lay: GraphLayout, R: Array, V: Array, A: Array,
             points: dict[str, Array], pv: dict[str, Array], pa: dict[str, Array]
             ) -> tuple[dict[str, Array], dict[str, Array], dict[str, Array]]:
    """The mechanism's named outputs over the samples (kinematics/graph/outputs.py)."""
    from screwkit.kinematics.graph.outputs import body_angle, point_travel
    from screwkit.model.mechanism_outputs import BodyAngle

    values: dict[str, Array] = {}
    rates_: dict[str, Array] = {}
    accs: dict[str, Array] = {}
    drawn = {pt.name: pt.at for pt in mech.points}
    for o in mech.outputs:
        if isinstance(o, BodyAngle):
            b = lay.body_of[o.body]
            got = body_angle(o, R[:, b], V[:, b, :3], A[:, b, :3])
        else:
            got = point_travel(o, drawn[o.point], points[o.point], pv[o.point], pa[o.point])
        values[o.name], rates_[o.name], accs[o.name] = (np.array(g) for g in got)
    return values, rates_, accs


def expected_rank(mech: Mechanism, lay: GraphLayout, drawn: Linearised | None = None) -> int:
    """Rank of the passive block at the drawing (idle freedoms and redundant constraints
    excluded): what a regular sample keeps (``drawn``: the drawing's linearisation if made)."""
    lin = drawn if drawn is not None else drawn_linearisation(mech, lay)
    s = lin.sigma[0]
    return int(np.sum(s > RANK_CUTOFF * max(float(s[0]) if s.size else 0.0, 1e-300)))


def _singular(r: int, sigma: Array) -> NDArray[np.bool_]:
    if r == 0 or sigma.shape[1] == 0:
        return np.zeros(sigma.shape[0], dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = sigma[:, r - 1] / sigma[:, 0]
    return np.asarray(~(ratio > SINGULAR_TOL))


def _variables(mech: Mechanism, lay: GraphLayout, conf: Configuration, qd: Array, qdd: Array
               ) -> tuple[dict[str, Array], dict[str, Array], dict[str, Array]]:
    values: dict[str, Array] = {}
    vel: dict[str, Array] = {}
    acc: dict[str, Array] = {}
    for i, j in enumerate(mech.joints):
        f0 = lay.first_freedom[i]
        if j.kind == "S":
            rv = rotation_vector(conf.spherical[:, lay.spherical_of_joint[i]])
            for k, c in enumerate("xyz"):
                values[f"{j.name}.r{c}"] = rv[:, k].copy()
        for k in range(len(j.freedoms)):
            f = f0 + k
            full = lay.names[f]
            if j.kind != "S":
                values[full] = conf.scalars[:, lay.scalar_col[f]].copy()
            vel[full] = qd[:, f].copy()
            acc[full] = qdd[:, f].copy()
    return values, vel, acc

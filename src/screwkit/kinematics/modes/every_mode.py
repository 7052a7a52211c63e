"""Every assembly mode of a mechanism at given input values, by the homotopy (issue 27).

:func:`closure_formulation` picks the formulation of this package that fits the mechanism (a
planar R-joint graph; a single loop of R joints with six free; a single loop of R, P, C and U
joints with six free freedoms (modes/rpc_loop.py); an RSSR, RSRC or RCCC driven at a ground R
joint) and :func:`every_mode` solves it for every row of inputs in one batched
parameter homotopy from the topology's start solutions; a 6-6 Stewart–Gough platform (U–P–S or
S–P–S legs) by the Study-coordinate system, its poses decoded into joint variables
(modes/stewart_decode.py); a Delta robot by the same system with the elbow balls as base
points (modes/delta.py). Each real solution is turned into the
graph tracker's :class:`Configuration` and kept only if the tracker's own closure
(``graph_forward``, the exact SE(3) logarithm round every loop) is within
:data:`CLOSURE_TOLERANCE` of the length scale, and its input freedoms read back are the
inputs: the checks are independent of the polynomial system. A row whose paths end singular on a curve of solutions is reported as a continuum.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.algebraic.solve import Solutions, StartSolutions, solve_all
from screwkit.algebraic.track import PathStatus
from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.graph.closure import GraphLayout, graph_forward
from screwkit.kinematics.modes.continuum import on_a_continuum
from screwkit.kinematics.modes.loop6r import loop6r_start, loop6r_system
from screwkit.kinematics.modes.loop6r_solve import solve_loop6r
from screwkit.kinematics.modes.planar import planar_formulation
from screwkit.kinematics.modes.r_loop import r_loop_instance
from screwkit.kinematics.modes.rccc import rccc_loop
from screwkit.kinematics.modes.rod_loops import rod_loop
from screwkit.kinematics.modes.starts import start_solutions
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]
#: a real solution is a mode when every loop closes to this, relative to the length scale
CLOSURE_TOLERANCE = 1e-10
#: and its input freedoms, read back, are the inputs to this (radians, or relative)
INPUT_TOLERANCE = 1e-8


class Formulation(Protocol):
    """What :func:`every_mode` needs of a formulation."""

    @property
    def system(self) -> PolynomialSystem: ...

    def parameters(self, input_values: ArrayLike) -> Array: ...

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]: ...


def _r_loop_formulation(mech: Mechanism) -> Formulation:
    """A single R loop's formulation: the 6R axes system (elimination first) where the links
    of its labelling are :data:`~screwkit.kinematics.modes.rpc_loop.WELL_APART` from parallel
    in the drawing, else the R/P/C axes formulation, which relabels the loop so that a nearly
    parallel pair is the ground link (the 6R reading divides by each link's sin α: a 7R loop
    with two axes 1e-3 rad from parallel missed its tracked mode, at 1e-5 it had no mode, and
    exactly parallel ones raised an InputError)."""
    from screwkit.kinematics.modes.rpc_loop import WELL_APART, rpc_loop

    form = _RLoopFormulation(mech, loop6r_system())
    try:
        p = form.parameters(np.zeros((1, len(mech.inputs))))[0]
    except InputError:  # two consecutive axes exactly parallel
        return rpc_loop(mech)
    z1, z6, cos_alpha = p[0:3], p[3:6], p[6:11]
    cosines = np.append(cos_alpha, float(z1 @ z6) / float(np.linalg.norm(z1) * np.linalg.norm(z6)))
    if np.sqrt(np.maximum(1.0 - cosines**2, 0.0)).min() >= WELL_APART:
        return form
    return rpc_loop(mech)


@dataclass(frozen=True)
class _RLoopFormulation:
    """A single R loop as a formulation over rows of inputs (one 6R instance per row)."""

    mechanism: Mechanism
    system: PolynomialSystem

    def parameters(self, input_values: ArrayLike) -> Array:
        X = np.atleast_2d(np.asarray(input_values, dtype=float))
        return np.array([r_loop_instance(self.mechanism, row).params for row in X])

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        row = np.atleast_1d(np.asarray(input_values, dtype=float)).reshape(-1)
        return r_loop_instance(self.mechanism, row).configuration(solutions)

    def solve(self, p: Array) -> Solutions:
        """Every solution at the rows of parameters p: elimination, the homotopy where it
        falls short (modes/loop6r_solve.py)."""
        return solve_loop6r(p)


def closure_formulation(mech: Mechanism) -> Formulation:
    """The formulation of this package that takes ``mech``, or a ScrewkitError that says why
    none does. A mechanism driven at body freedoms: its augmented mechanism's
    (kinematics/graph/drives.py; its inputs the joint inputs then the drives), which only the
    point formulation takes (modes/spatial_point_drives.py)."""
    if mech.drives:
        from screwkit.kinematics.graph.drives import augmented

        return closure_formulation(augmented(mech))
    helical = [j.name for j in mech.joints if j.kind == "H"]
    if helical:
        raise CapabilityError(
            f"{mech.name}: joints {helical} are helical; an H joint's slide (pitch·θ) is not "
            "polynomial in cos θ and sin θ, so its closure is not algebraic and the homotopy "
            "cannot promise every mode: follow the mechanism with the graph tracker "
            "(solve_mechanism) instead")
    off = [j.name for j in mech.joints if j.seat_offset is not None]
    if off:
        raise CapabilityError(
            f"{mech.name}: joints {off} are made off their drawing (a seat offset, e.g. from a "
            "hardpoint tolerance); the polynomial formulations read the mechanism from its "
            "drawing and do not model that, so they would solve the drawn mechanism instead: "
            "follow it with the graph tracker (solve_mechanism) instead")
    kinds = {j.kind for j in mech.joints}
    parallel = all(np.linalg.norm(np.cross(j.axis, mech.joints[0].axis)) < 1e-9
                   for j in mech.joints)
    if kinds == {"R"} and parallel:
        return planar_formulation(mech)
    if kinds == {"R"} and len(mech.topology.loops) == 1:
        return _r_loop_formulation(mech)
    single = len(mech.topology.loops) == 1 and len(mech.joints) == 4
    if single and sorted(j.kind for j in mech.joints) in (["R", "R", "S", "S"],
                                                          ["C", "R", "R", "S"]):
        try:
            return rod_loop(mech)
        except CapabilityError:  # not an RSSR/RSRC driven at a ground R: the points below
            pass
    if single and sorted(j.kind for j in mech.joints) == ["C", "C", "C", "R"]:
        try:
            return rccc_loop(mech)
        except CapabilityError:  # not driven at its ground R joint: the R/P/C loop below
            pass
    if kinds <= {"R", "P", "C", "U"} and kinds & {"P", "C", "U"} and len(mech.topology.loops) == 1:
        from screwkit.kinematics.modes.rpc_loop import rpc_loop

        return rpc_loop(mech)  # a CapabilityError where the axes formulation does not take it
    if kinds <= {"U", "P", "S"} and len(mech.joints) == 18:
        from screwkit.kinematics.modes.stewart_decode import stewart_formulation

        return stewart_formulation(mech)  # a CapabilityError where the legs are not found
    if kinds == {"R", "S"} and len(mech.joints) == 15:
        from screwkit.kinematics.modes.delta import delta_formulation

        return delta_formulation(mech)  # a CapabilityError where it is not a Delta robot
    if kinds <= {"R", "S", "U", "P", "C"}:
        from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation

        try:
            return spatial_point_formulation(mech)
        except CapabilityError as err:
            why = f" ({err})"
    else:
        why = ""
    raise CapabilityError(
        f"{mech.name}: no polynomial formulation takes this mechanism yet (joints "
        f"{''.join(sorted(j.kind for j in mech.joints))}, {len(mech.topology.loops)} loops); there are "
        "formulations for planar R-joint graphs, single R loops with six free joints, "
        "single loops of R, P, C and U joints with six free freedoms, "
        "RSSR, RSRC and RCCC loops driven at a ground R joint, 6-6 Stewart–Gough "
        "platforms (U–P–S or S–P–S legs driven at the P joints) and Delta robots (three "
        "driven arms, each with an S–S parallelogram to the plate), and graphs of R, P, C, S "
        f"and U joints driven at R or P joints or at body freedoms{why}")


@dataclass(frozen=True)
class MechanismModes:
    """Every mode at each row of inputs (B): ``configurations[b]`` the real modes that close
    (graph-tracker configurations), ``certified[b]`` whether each passed Smale's α-test,
    ``found`` the distinct complex solutions per row, ``continuum`` rows whose singular end
    points lie on a curve of solutions, ``generic_count`` and ``how_found`` from the start
    solutions, ``worst_closure`` the largest loop residual of a kept mode, ``rejected`` the
    real regular solutions per row not kept because the graph closure exceeds
    :data:`CLOSURE_TOLERANCE` (a formulation that read the mechanism inaccurately, e.g. two
    axes nearly parallel, whose common normal's feet are far away)."""

    mechanism: Mechanism
    inputs: Array
    configurations: tuple[Configuration, ...]
    certified: tuple[NDArray[np.bool_], ...]
    found: NDArray[np.int64]
    continuum: NDArray[np.bool_]
    generic_count: int
    how_found: str
    worst_closure: float
    rejected: NDArray[np.int64]


def _at_inputs(mech: Mechanism, lay: GraphLayout, conf: Configuration, x: Array
               ) -> NDArray[np.bool_]:
    """Whether each configuration's input freedoms, read back, are the inputs ``x`` (angles
    modulo a turn; to :data:`INPUT_TOLERANCE`). Not so for the poses a body with two or more
    driven turns also satisfies in the point formulation, each turn taken from the other
    Tait–Bryan triple of the same rotation (modes/spatial_point_drives.py)."""
    ok = np.ones(conf.size, dtype=bool)
    for c, f in enumerate(lay.inputs):
        d = conf.scalars[:, lay.scalar_col[f]] - x[c]
        if lay.is_translation[f]:
            ok &= np.abs(d) <= INPUT_TOLERANCE * max(mech.length_scale, 1.0)
        else:
            ok &= np.abs(np.angle(np.exp(1j * d))) <= INPUT_TOLERANCE
    return ok


def formulation_start(form: Formulation) -> StartSolutions:
    """The start solutions of ``form``'s topology (cached per topology, modes/starts.py)."""
    if isinstance(form, _RLoopFormulation):
        return loop6r_start()
    own = getattr(form, "start", None)  # a formulation with its own (monodromy) start
    if callable(own):
        return own()  # type: ignore[no-any-return]
    return start_solutions(form.system, grouping=getattr(form, "grouping", None))


def solve_formulation(form: Formulation, p: ArrayLike) -> Solutions:
    """Every isolated solution of ``form``'s system at the parameter rows p: its own exact
    solver where it has one (a single R loop: elimination, modes/loop6r_solve.py; a
    Stewart–Gough platform: the elimination template, modes/stewart_solve.py), else the
    parameter homotopy from the topology's start solutions."""
    own_solve = getattr(form, "solve", None)
    if callable(own_solve):
        return own_solve(p)  # type: ignore[no-any-return]
    return solve_all(form.system, p, formulation_start(form))


def every_mode(mech: Mechanism, inputs: ArrayLike) -> MechanismModes:
    """Every real assembly mode of ``mech`` at each row of ``inputs`` (B, n_inputs; a
    mechanism driven at body freedoms: B, joint inputs then drives, ``mech.driven_names``),
    radians and metres from the drawing (module docstring). Equal rows are solved once (a closed
    motion's first and last rows, both anchors of modes/along.py: one homotopy of the
    Stewart example's eight)."""
    if mech.drives:  # solved as its augmented mechanism, the virtual chains then left out
        from screwkit.kinematics.graph.drives import augmented, real_configuration

        whole = every_mode(augmented(mech), inputs)
        return replace(whole, mechanism=mech, configurations=tuple(
            real_configuration(mech, c) for c in whole.configurations))
    X = np.atleast_2d(np.asarray(inputs, dtype=float))
    # a structure (no inputs) has rows of nothing: keep their count
    X = X.reshape(X.shape[0], 0) if not mech.inputs else X.reshape(-1, len(mech.inputs))
    distinct, back = np.unique(X, axis=0, return_inverse=True)
    if len(distinct) == len(X):
        return _every_mode_rows(mech, X)
    once = _every_mode_rows(mech, distinct)
    idx = back.reshape(-1)
    return MechanismModes(mech, X, tuple(once.configurations[i] for i in idx),
                          tuple(once.certified[i] for i in idx), once.found[idx],
                          once.continuum[idx], once.generic_count, once.how_found,
                          once.worst_closure, once.rejected[idx])


def _every_mode_rows(mech: Mechanism, X: Array) -> MechanismModes:
    """:func:`every_mode` at rows ``X`` (B, n_inputs), each solved (one batched solve)."""
    form = closure_formulation(mech)
    p = form.parameters(X)  # (B, n_in); the one-input loops read it as (B,)
    sol = solve_formulation(form, p)
    confs, certs, continuum, worst = [], [], np.zeros(len(X), dtype=bool), 0.0
    rejected = np.zeros(len(X), dtype=np.int64)
    for b in range(len(X)):
        rows = np.flatnonzero((sol.instance == b) & sol.real)
        singular = np.flatnonzero((sol.instance == b) & (sol.status == PathStatus.SINGULAR))
        if len(singular):
            continuum[b] = bool(on_a_continuum(form.system, sol.x[singular], p[b]).any())
        if len(rows) == 0:
            confs.append(Configuration(np.zeros((0, 0)), np.zeros((0, 0, 3, 3))))
            certs.append(np.zeros(0, dtype=bool))
            continue
        conf, lay = form.configuration(sol.x[rows], X[b])
        residual = np.abs(graph_forward(mech, lay, conf).residual).max(axis=(1, 2))
        regular = sol.status[rows] == PathStatus.REGULAR
        at_inputs = _at_inputs(mech, lay, conf, X[b])
        keep = (residual <= CLOSURE_TOLERANCE * max(mech.length_scale, 1.0)) & regular
        rejected[b] = int(np.count_nonzero(regular & ~keep))
        keep &= at_inputs
        worst = max(worst, float(residual[keep].max(initial=0.0)))
        confs.append(conf.take(np.flatnonzero(keep)))
        certs.append(sol.certified_real[rows][keep])
    return MechanismModes(mech, X, tuple(confs), tuple(certs), sol.found, continuum,
                          sol.generic_count, sol.how_found, worst, rejected)

"""Closed forms as solvers of a :class:`~screwkit.kinematics.motion.Motion`: the RSRC quartic, the
planar 4R and the CSSP quadratic, each returning the same type, fields and mode numbering as the
generic loop solver (:func:`~screwkit.kinematics.solve_motion.solve_motion` dispatches here
through the family registry).

Each adapter turns the closed form's branches into joint configurations of the family's
:class:`~screwkit.model.Linkage` and hands them to
:func:`~screwkit.kinematics.tracker.mode_frames.mode_from_configuration`, so link frames, twists and every
joint rate follow from the same rate equations as for any loop; the seed's own variables and their
closed-form rates are added under the seed's names (an independent check of the rate equations:
the tests compare both).

Mode numbering (docs/conventions.md): the closed form's branches that assemble somewhere over the
sweep, in the closed form's order — RSRC/4R: the columns of :func:`rsrc_motion` (branches
labelled by Bagci's root order at the first sample); CSSP: the root s4 = −b + √(b² − c)
(Rahman's branch) first, then the other root; RSSR and RCCC: the root with +acos of their
input-output equation A cos x + B sin x = K first, then the one with −acos.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.kinematics.lazy_fields import derived_table, table_keys
from screwkit.kinematics.motion import AssemblyError, ModeMotion, Motion, format_inputs
from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    close_spherical_joint,
    forward,
    layout,
)
from screwkit.kinematics.tracker.mode_frames import (
    expect_modes,
    mode_from_configuration,
    unwrap_runs,
)
from screwkit.model.linkage import Linkage

if TYPE_CHECKING:
    from screwkit.kinematics.closed_forms.rccc import RCCCDimensions, RCCCMotion
    from screwkit.kinematics.closed_forms.rsrc import BranchEvent, RSRCDimensions, RSRCMotion
    from screwkit.kinematics.closed_forms.rssr import RSSRDimensions, RSSRMotion
    from screwkit.kinematics.tracker.loop import Layout

RSRC_SOLVER = "RSRC closed form: quartic in tan(φ0/2) (Bagci 1969 eqs. 3.59–3.82)"
RSSR_SOLVER = ("RSSR closed form: A cos φ0 + B sin φ0 = K from the crank circles and the coupler "
               "length (kinematics/closed_forms/rssr.py)")
RCCC_SOLVER = ("RCCC closed form: the dual input-output equation Â cos θ̂4 + B̂ sin θ̂4 = Ĉ "
               "(transference of the spherical four-bar; kinematics/closed_forms/rccc.py)")
FOURBAR_SOLVER = "planar 4R closed form: Bagci's RSRC with δ0 = λ0 = b = e = 0 (§3.4)"
CSSP_SOLVER = "CSSP closed form: quadratic in s4 (Rahman 1996 §1.2)"


#: every sample of a sweep
ALL = slice(None)
#: a branch's joint configurations at the samples ``rows`` of the sweep: (branch, rows)
BranchConfiguration = Callable[[int, slice], Configuration]


@dataclass(frozen=True)
class ClosedBranches:
    """A closed form's modes before they are built (issue 26: the graph's drawn mode needs one
    of them): per mode, in the adapter's mode order, the samples where it assembles, and its
    joint configurations, built on demand (``configuration(mode, rows)``, ``rows`` a slice of
    the sweep: ALL gives the ones the adapter hands to :func:`mode_from_configuration`)."""

    assembles: tuple[NDArray[np.bool_], ...]
    configuration: BranchConfiguration
    solver: str


def _branches(assembles: NDArray[np.bool_], configuration: BranchConfiguration,
              solver: str) -> ClosedBranches:
    """The branches (columns of ``assembles``) that assemble somewhere, as modes."""
    cols = [j for j in range(assembles.shape[1]) if assembles[:, j].any()]

    def of_mode(m: int, rows: slice) -> Configuration:
        return configuration(cols[m], rows)

    return ClosedBranches(tuple(assembles[:, j].copy() for j in cols), of_mode, solver)


def _with_seed(mode: ModeMotion, index: int, label: str, seed: tuple[dict[str, Array], ...],
               singular: NDArray[np.bool_] | None = None, masked: bool = False) -> ModeMotion:
    """``mode`` with the seed's variables added (NaN outside the mask; with ``masked`` they
    already are, and are taken as they are) and its index; samples the closed form finds
    singular (e.g. a locked RSRC) lose their rates too."""
    ok = mode.assembles
    tables = []
    for general, named in zip((mode.variables, mode.velocities, mode.accelerations), seed,
                              strict=True):
        merged = (dict(named) if masked else
                  {k: np.where(ok, np.asarray(v, dtype=float), np.nan) for k, v in named.items()})
        merged.update(general)
        tables.append(merged)
    sing = mode.singular if singular is None else (mode.singular | singular)
    if not sing.any():
        return replace(mode, variables=tables[0], velocities=tables[1],
                       accelerations=tables[2], singular=sing, index=index, label=label)
    for v in [*tables[1].values(), *tables[2].values(), mode.link_angular_velocity,
              mode.link_origin_velocity, mode.link_angular_acceleration,
              mode.link_origin_acceleration]:
        v[sing] = np.nan
    return replace(mode, variables=tables[0], velocities=tables[1], accelerations=tables[2],
                   singular=sing, index=index, label=label)


def _no_modes(linkage: Linkage, X: Array, where: str) -> AssemblyError:
    """The loop closes at none of the inputs: say where over a full turn it does, if anywhere."""
    return AssemblyError(
        f"{linkage.name}: the loop does not close at any of the {len(X)} inputs "
        f"(from {format_inputs(linkage, X[0])} to {format_inputs(linkage, X[-1])}); it "
        f"assembles {where}" + ("; check the dimensions" if where.startswith("at no") else
                                "; change [motion] start/stop to a range where it does"))


def rsrc_dimensions(linkage: Linkage) -> tuple[RSRCDimensions, bool]:
    """Bagci's RSRC dimensions of a linkage built by :func:`~screwkit.model.families.rsrc` or
    :func:`~screwkit.model.families.fourbar` (the plane case δ0 = λ0 = b = e = 0), and whether
    it is the planar 4R (four R joints)."""
    from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions

    p = dict(linkage.parameters)
    if all(j.kind == "R" for j in linkage.joints):
        return RSRCDimensions(d1=p["d1"], d2=p["d2"], d3=p["d3"], a=p["a"], b=0.0, e=0.0,
                              delta0=0.0, lambda0=0.0), True
    return RSRCDimensions(**p), False


def rsrc_closed_motion(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    """Every assembly mode of Bagci's RSRC (or its planar 4R case) from the quartic; the
    branches of :func:`~screwkit.kinematics.closed_forms.rsrc.rsrc_motion` become modes."""
    dims, planar, mot, lay, configuration = _rsrc_solution(linkage, X, Xd, Xdd)
    theta = X[:, 0]
    rates = mot.rates
    modes: list[ModeMotion] = []
    expect_modes(int(mot.assembles.any(axis=0).sum()))
    mode_of = np.cumsum(mot.assembles.any(axis=0)) - 1  # column → mode
    for j in range(mot.phi0.shape[1]):
        ok = mot.assembles[:, j]
        if not ok.any():
            continue
        events = [_event_text(linkage, mot, mode_of, e) for e in mot.events if e.branch == j]
        conf = configuration(j, ALL)
        md = mode_from_configuration(linkage, lay, conf, ok.copy(), X, Xd, Xdd, events)
        seed_v = {"theta0": theta, "phi0": mot.phi0[:, j], "chi0": mot.chi0[:, j]}
        seed_d = {"theta0": Xd[:, 0], "phi0": rates.phi0_dot[:, j], "chi0": rates.chi0_dot[:, j]}
        seed_dd = {"theta0": Xdd[:, 0], "phi0": rates.phi0_ddot[:, j],
                   "chi0": rates.chi0_ddot[:, j]}
        if not planar:
            seed_v["S"], seed_d["S"], seed_dd["S"] = mot.S[:, j], rates.S_dot[:, j], rates.S_ddot[:, j]
        modes.append(_with_seed(md, len(modes), f"branch {len(modes)} (root order at the first "
                                f"sample: label {int(np.max(mot.inversion_label[ok, j][:1]))})",
                                (seed_v, seed_d, seed_dd), singular=ok & ~rates.valid[:, j]))
    if not modes:
        from screwkit.kinematics.tracker.assembly_range import (
            assembling_intervals,
            describe_intervals,
        )

        raise _no_modes(linkage, X, describe_intervals(assembling_intervals(dims)))
    return Motion(linkage, X, Xd, Xdd, tuple(modes), method="closed",
                  solver=FOURBAR_SOLVER if planar else RSRC_SOLVER)


def _event_text(linkage: Linkage, mot: RSRCMotion, mode_of: NDArray[np.intp],
                e: BranchEvent) -> str:
    """A branch event of ``rsrc_motion`` as a mode's event: where its root stops or starts
    assembling and the mode that meets it there (closed_forms/rsrc/folds.py); where the mode
    assembles at both samples of the step, its root dies inside it and its samples after are
    another root's, born inside it (closed_forms/rsrc/hidden_folds.py)."""
    across = bool(mot.assembles[e.sample - 1, e.branch] and mot.assembles[e.sample, e.branch])
    m = int(mode_of[e.branch])
    if e.partner is not None:
        a, b = sorted((m, int(mode_of[e.partner])))
        meet = f": modes {a} and {b} meet"
    else:
        meet = f": mode {m} meets a root that assembles at neither sample" if across else ""
    text = (f"{e.kind} assembling at input {format_inputs(linkage, np.array([e.theta0]))} "
            f"(limit position or dead centre{meet})")
    if not across:
        return text
    return text + ("; its samples after this step are on another root, born inside the step"
                   if e.kind == "stops" else
                   "; its samples after this step are on this root, its root before dies "
                   "inside the step")


def _rsrc_solution(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> tuple[
        RSRCDimensions, bool, RSRCMotion, Layout, BranchConfiguration]:
    """Bagci's dimensions, whether the loop is the planar 4R, the quartic's branches over the
    sweep (:func:`~screwkit.kinematics.closed_forms.rsrc.rsrc_motion`), the loop's layout and
    branch j's joint configurations (θ0, χ0, −φ0 and S on the loop's joints, the ball closing
    the loop; the 4R's from θ0 and φ0)."""
    from screwkit.kinematics.closed_forms.rsrc import rsrc_motion

    dims, planar = rsrc_dimensions(linkage)
    p = dict(linkage.parameters)
    theta = X[:, 0]
    mot = rsrc_motion(dims, theta, Xd[:, 0], Xdd[:, 0])
    lay = layout(linkage)

    def configuration(j: int, rows: slice = ALL) -> Configuration:
        ok, th = mot.assembles[rows, j], theta[rows]
        phi = np.where(ok, mot.phi0[rows, j], 0.0)
        if planar:
            return _fourbar_configuration(p, th, phi)
        chi = np.where(ok, mot.chi0[rows, j], 0.0)
        s = np.where(ok, mot.S[rows, j], 0.0)
        scalars = np.zeros((len(th), lay.n_scalar))
        for name, values in (("input.theta", th), ("coupler_R.theta", chi),
                             ("output_C.theta", -phi), ("output_C.s", s)):
            scalars[:, lay.scalar_col[lay.names.index(name)]] = values
        return close_spherical_joint(linkage, scalars, lay)

    return dims, planar, mot, lay, configuration


def rsrc_branches(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> ClosedBranches:
    """:func:`rsrc_closed_motion`'s modes as branches, before they are built."""
    _, planar, mot, _, configuration = _rsrc_solution(linkage, X, Xd, Xdd)
    return _branches(mot.assembles, configuration, FOURBAR_SOLVER if planar else RSRC_SOLVER)


def _fourbar_configuration(p: dict[str, float], theta: Array, phi: Array) -> Configuration:
    """Joint angles of :func:`~screwkit.model.families.fourbar` from θ0 and φ0 (both measured
    from the line of centres): crank pin c1 = d1(cos θ0, sin θ0), rocker pin
    c2 = (a, 0) + d3(cos φ0, sin φ0), coupler direction γ = ∠(c2 − c1); the relative angles are
    θ0, γ − θ0, φ0 + π − γ and −φ0 (they sum to 2π with the frame link's half turn)."""
    c1 = p["d1"] * np.stack([np.cos(theta), np.sin(theta)], -1)
    c2 = np.stack([p["a"] + p["d3"] * np.cos(phi), p["d3"] * np.sin(phi)], -1)
    gamma = np.arctan2(c2[:, 1] - c1[:, 1], c2[:, 0] - c1[:, 0])
    scalars = np.stack([theta, gamma - theta, phi + np.pi - gamma, -phi], -1)
    return Configuration(scalars, np.zeros((len(theta), 0, 3, 3)))


def cssp_closed_motion(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    """Both roots of Rahman's quadratic in s4 (§1.2) as modes, from the fused closed form
    (:func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_mode_motion`), with the seed's angles θ2, η2
    (rod) and θ3, η3 (slider ball) and their exact rates. The two roots stay separate: they meet
    only at a branch point, where the mode stops."""
    from screwkit.kinematics.closed_forms.cssp import CSSPDimensions
    from screwkit.kinematics.closed_forms.cssp_inputs import cssp_sweep, sweep_for_root
    from screwkit.kinematics.closed_forms.cssp_motion import sweep_mode_motion

    p = dict(linkage.parameters)
    dims = CSSPDimensions(p["a1"], p["a2"], p["a4"], p["alpha4"], p.get("s1", 0.0))
    theta = X[:, 0]
    angles = ("theta2", "eta2", "theta3", "eta3")
    modes: list[ModeMotion] = []
    driven = len(linkage.inputs) == 2  # the crank offset s1 is a second input
    # a rate the same at every sample goes in as a number: the closed form then does scalar
    # arithmetic (same values)
    w, wd = (_constant_or(Xd[:, 0]), _constant_or(Xdd[:, 0]))
    crank, slider = linkage.joints[0].name, linkage.joints[3].name
    # the inputs checked, their trigonometry and where the loop assembles: once for both roots
    inputs = cssp_sweep(linkage, theta, w, wd, 1, allow_partial=True,
                        s1=X[:, 1] if driven else None, s1_dot=Xd[:, 1] if driven else 0.0,
                        s1_ddot=Xdd[:, 1] if driven else 0.0)
    for root, label in ((1, "s4 = -b + sqrt(b^2 - c)"), (-1, "s4 = -b - sqrt(b^2 - c)")):
        # the seed's angles with their closed-form rates, block by block, for a fixed crank
        # offset (with a driven one the registry's names from the link frames are used)
        md = sweep_mode_motion(linkage, sweep_for_root(inputs, root), seed_angles=not driven,
                               lazy=True)
        ok = np.asarray(md.assembles)
        if not ok.any():
            continue
        # the seed's θ1 and s4 are the crank's and the slider's joint variables (the same
        # arrays: NaN where the mode does not assemble already), as the generic solver's seed
        # names are (seed_names.py)
        seed: tuple[dict[str, Array], ...] = tuple(
            {"theta1": table[f"{crank}.theta"]}
            for table in (md.variables, md.velocities, md.accelerations))
        if not driven:
            for table, named in zip((md.variables, md.velocities, md.accelerations), seed,
                                    strict=True):
                named["s4"] = table[f"{slider}.s"]
        # the seed's names first, then the joints' (the seed's angles move from the joint
        # tables to the seed's, θ2 … unwrapped along each run); the angles stay lazy
        unwrap = {key: (lambda a, ok=ok: unwrap_runs(a, ok)) for key in angles}
        tables = []
        for k, (table, named) in enumerate(zip(
                (md.variables, md.velocities, md.accelerations), seed, strict=True)):
            moved = [] if driven else list(angles)
            rest = [key for key in table_keys(table) if key not in angles]
            tables.append(derived_table(table, [*named, *moved, *rest], named,
                                        unwrap if k == 0 else None))
        md = replace(md, variables=tables[0], velocities=tables[1], accelerations=tables[2])
        stops = np.nonzero(ok[:-1] & ~ok[1:])[0]
        starts = np.nonzero(~ok[:-1] & ok[1:])[0] + 1
        events = [f"stops assembling after input {format_inputs(linkage, X[i])} (branch point "
                  f"before {format_inputs(linkage, X[i + 1])})" for i in stops]
        events += [f"starts assembling at input {format_inputs(linkage, X[i])}" for i in starts]
        modes.append(replace(md, events=events, index=len(modes), label=label))
    if not modes:
        from screwkit.kinematics.closed_forms.cssp import assembly_intervals
        from screwkit.kinematics.tracker.assembly_range import describe_intervals

        raise _no_modes(linkage, X, describe_intervals(
            [(a % (2 * np.pi), a % (2 * np.pi) + (b - a)) for a, b in assembly_intervals(dims)]))
    return Motion(linkage, X, Xd, Xdd, tuple(modes), method="closed", solver=CSSP_SOLVER)


def _constant_or(values: Array) -> float | Array:
    """``values`` (N,) as one float when every sample holds the same (finite) number."""
    v0 = values[0] if values.size else 0.0
    if values.size and np.isfinite(v0) and not np.any(values != v0):
        return float(v0)
    return values


def _branch_events(linkage: Linkage, X: Array, ok: NDArray[np.bool_]) -> list[str]:
    """Where a mode stops and starts assembling, the inputs in the message units."""
    stops = np.nonzero(ok[:-1] & ~ok[1:])[0]
    starts = np.nonzero(~ok[:-1] & ok[1:])[0] + 1
    return ([f"stops assembling after input {format_inputs(linkage, X[i])} (limit position or "
             f"dead centre before {format_inputs(linkage, X[i + 1])})" for i in stops]
            + [f"starts assembling at input {format_inputs(linkage, X[i])} (limit position or "
               f"dead centre after {format_inputs(linkage, X[i - 1])})" for i in starts])


def rssr_closed_motion(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    """Both roots of the RSSR's input-output equation (:mod:`screwkit.kinematics.closed_forms.rssr`) as
    modes, with θ0, φ0 and the closed form's own rates of φ0 under the seed's names."""
    from screwkit.kinematics.closed_forms.rssr import rssr_motion

    dims, mot, lay, phis, configuration = _rssr_solution(linkage, X)
    theta = X[:, 0]
    modes: list[ModeMotion] = []
    expect_modes(int(mot.assembles.any(axis=0).sum()))
    for j, label in ((0, "+acos root"), (1, "-acos root")):
        ok = mot.assembles[:, j]
        if not ok.any():
            continue
        phi = phis(j)
        conf = configuration(j, ALL)
        md = mode_from_configuration(linkage, lay, conf, ok.copy(), X, Xd, Xdd,
                                     _branch_events(linkage, X, ok))
        rate = mot.dphi[:, j]
        seed = ({"theta0": theta, "phi0": phi}, {"theta0": Xd[:, 0], "phi0": rate * Xd[:, 0]},
                {"theta0": Xdd[:, 0],
                 "phi0": mot.ddphi[:, j] * Xd[:, 0] ** 2 + rate * Xdd[:, 0]})
        modes.append(_with_seed(md, len(modes), label, seed, singular=mot.dead_centre[:, j]))
    if not modes:
        raise _no_modes(linkage, X, _where_over_a_turn(
            lambda th: np.asarray(rssr_motion(dims, th).assembles.any(axis=1))))
    return Motion(linkage, X, Xd, Xdd, tuple(modes), method="closed", solver=RSSR_SOLVER)


def _rssr_solution(linkage: Linkage, X: Array) -> tuple[
        RSSRDimensions, RSSRMotion, Layout, Callable[[int], Array], BranchConfiguration]:
    """The RSSR's dimensions, both roots of its input-output equation over the sweep, the
    loop's layout, root j's output angle φ0 (continuous along each run) and its joint
    configurations (θ0 and −φ0 on the R joints, the rod along the two ball centres)."""
    from screwkit.kinematics.closed_forms.rssr import RSSRDimensions, rssr_motion

    dims = RSSRDimensions(**dict(linkage.parameters))
    theta = X[:, 0]
    mot = rssr_motion(dims, theta)
    lay = layout(linkage)
    base = linkage.base.real
    first, out = (f"{linkage.joints[k].name}.theta" for k in (0, 3))

    def phis(j: int) -> Array:
        ok = mot.assembles[:, j]
        return unwrap_runs(np.where(ok, mot.phi0[:, j], np.nan), ok)

    def configuration(j: int, rows: slice = ALL) -> Configuration:
        ok, th = mot.assembles[rows, j], theta[rows]
        scalars = np.zeros((len(th), lay.n_scalar))
        scalars[:, lay.scalar_col[lay.names.index(first)]] = th
        scalars[:, lay.scalar_col[lay.names.index(out)]] = -np.where(ok, phis(j)[rows], 0.0)
        rod = np.where(ok[:, None], mot.coupler_ball[rows, j] - mot.crank_ball[rows],
                       [1.0, 0.0, 0.0])
        return _two_ball_configuration(linkage, scalars, rod @ base)

    return dims, mot, lay, phis, configuration


def rssr_branches(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> ClosedBranches:
    """:func:`rssr_closed_motion`'s modes as branches, before they are built."""
    _, mot, _, _, configuration = _rssr_solution(linkage, X)
    return _branches(mot.assembles, configuration, RSSR_SOLVER)


def _where_over_a_turn(assembles: Callable[[Array], NDArray[np.bool_]]) -> str:
    """Where over a full input turn a closed form assembles, in words (0.25° scan)."""
    from screwkit.kinematics.tracker.assembly_range import (
        SCAN_SAMPLES,
        describe_intervals,
        runs_over_a_turn,
    )

    theta = np.linspace(0.0, 2 * np.pi, SCAN_SAMPLES, endpoint=False)
    return describe_intervals(runs_over_a_turn(theta, np.asarray(assembles(theta))))


def _two_ball_configuration(linkage: Linkage, scalars: Array, rod: Array) -> Configuration:
    """Joint configuration of a loop with two ball joints (an S–S rod) from its scalar
    freedoms and the rod's direction ``rod`` (N, 3, ground frame): the proximal ball is the
    least rotation turning the rod's rest direction into it (the idle spin is then set by
    :mod:`screwkit.kinematics.tracker.idle_spin`), the distal ball closes the loop."""
    from screwkit.kinematics.tracker.idle_spin import minimal_rotation_apply

    lay = layout(linkage)
    i = next(iter(lay.spherical_of_joint))
    N = scalars.shape[0]
    rest = Configuration(scalars, np.broadcast_to(np.eye(3), (N, 2, 3, 3)).copy())
    B = forward(linkage, rest, lay).before_R[:, i]
    u = np.einsum("nji,nj->ni", B, rod / np.linalg.norm(rod, axis=1, keepdims=True))
    along = linkage.link_transforms[i].translation
    u0 = np.broadcast_to(along / np.linalg.norm(along), (N, 3))
    cols = [minimal_rotation_apply(u0, u, np.broadcast_to(e, (N, 3))) for e in np.eye(3)]
    sph = rest.spherical
    sph[:, 0] = np.stack(cols, axis=-1)
    return close_spherical_joint(linkage, scalars, lay, sph, i + 1)


def rccc_closed_motion(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    """Both roots of the RCCC's dual input-output equation (:mod:`screwkit.kinematics.closed_forms.rccc`)
    as modes; every joint's angle and slide from the closed form, rates from the loop's rate
    equations."""
    from screwkit.kinematics.closed_forms.rccc import rccc_motion

    dims, mot, lay, configuration = _rccc_solution(linkage, X)
    modes: list[ModeMotion] = []
    expect_modes(int(mot.assembles.any(axis=0).sum()))
    for j, label in ((0, "+acos root"), (1, "-acos root")):
        ok = mot.assembles[:, j]
        if not ok.any():
            continue
        conf = configuration(j, ALL)
        md = mode_from_configuration(linkage, lay, conf, ok.copy(), X, Xd, Xdd,
                                     _branch_events(linkage, X, ok))
        modes.append(_with_seed(md, len(modes), label, ({}, {}, {}),
                                singular=mot.dead_centre[:, j]))
    if not modes:
        raise _no_modes(linkage, X, _where_over_a_turn(
            lambda th: np.asarray(rccc_motion(dims, th).assembles.any(axis=1))))
    return Motion(linkage, X, Xd, Xdd, tuple(modes), method="closed", solver=RCCC_SOLVER)


def _rccc_solution(linkage: Linkage, X: Array) -> tuple[
        RCCCDimensions, RCCCMotion, Layout, BranchConfiguration]:
    """The RCCC's dimensions, both roots of its dual input-output equation over the sweep, the
    loop's layout and root j's joint configurations (every joint's angle and slide, the angles
    continuous along each run)."""
    from screwkit.kinematics.closed_forms.rccc import rccc_dimensions, rccc_motion

    dims = rccc_dimensions(linkage)
    if dims is None:
        raise InputError(f"{linkage.name}: not an R-C-C-C loop in Hartenberg-Denavit form with "
                         "the R joint as its input; use method 'generic'")
    theta = X[:, 0]
    mot = rccc_motion(dims, theta)
    lay = layout(linkage)

    def configuration(j: int, rows: slice = ALL) -> Configuration:
        ok = mot.assembles[:, j]
        scalars = np.where(ok[:, None], mot.scalars[:, j], 0.0)
        for c in (1, 3, 5):
            scalars[:, c] = np.where(ok, unwrap_runs(scalars[:, c], ok), 0.0)
        scalars = scalars[rows]
        return Configuration(scalars, np.zeros((len(scalars), 0, 3, 3)))

    return dims, mot, lay, configuration


def rccc_branches(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> ClosedBranches:
    """:func:`rccc_closed_motion`'s modes as branches, before they are built."""
    _, mot, _, configuration = _rccc_solution(linkage, X)
    return _branches(mot.assembles, configuration, RCCC_SOLVER)

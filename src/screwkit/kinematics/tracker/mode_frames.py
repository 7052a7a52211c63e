"""One assembly mode's full motion from its closed configurations: link frames, joint centres and
axes, and the velocities and accelerations of every freedom and link.

Velocities and accelerations come from the loop's rate equations (:mod:`screwkit.kinematics.tracker.rates`:
J_p q̇_p = −J_in q̇_in and J_p q̈_p = −J_in q̈_in − J̇q̇, zero spin for an S–S rod); a sample where
they have no unique solution is flagged ``singular``, gets no rates (NaN) and its mode's events
say why (:mod:`screwkit.kinematics.tracker.singularities`). An S–S rod's pose is its zero-spin frame
along the branch (:mod:`screwkit.kinematics.tracker.idle_spin`), so every link's rotation differentiates
to its reported angular velocity.

Every solver ends here — the generic loop solver and the closed forms alike — so every
:class:`~screwkit.kinematics.motion.ModeMotion` has the same fields and conventions.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import cross
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.tracker.idle_spin import hold_idle_spin
from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    Layout,
    LoopFrames,
    closure_error,
    closure_twist,
    forward,
    rotation_vector,
)
from screwkit.kinematics.tracker.rates import (
    RESIDUAL_TOL,
    RateEquations,
    rate_equations,
    solve_rates,
    spin_links,
)
from screwkit.kinematics.tracker.singularities import classify, singular_events
from screwkit.kinematics.tracker.solve import newton
from screwkit.model.linkage import Linkage


class _BuildReport:
    """How far the modes being built have come, for :func:`build_progress`."""

    def __init__(self, report: Callable[[int, int], None], samples: int) -> None:
        self.report, self.samples = report, samples
        self.modes = 0  # builds started
        self.expected = 0  # builds announced by expect_modes

    def expect(self, count: int) -> None:
        self.expected = self.modes + count

    def stage(self, fraction: float) -> None:
        if fraction == 0.0:
            self.modes += 1
        total = max(self.modes, self.expected) * self.samples
        self.report(int((self.modes - 1 + fraction) * self.samples), total)


#: where :func:`mode_from_configuration` reports how far its build has come; set by
#: :func:`build_progress`
_BUILD_PROGRESS: ContextVar[_BuildReport | None] = ContextVar("screwkit_build_progress",
                                                              default=None)


def _built(fraction: float) -> None:
    active = _BUILD_PROGRESS.get()
    if active is not None:
        active.stage(fraction)


def expect_modes(count: int) -> None:
    """Tell an active :func:`build_progress` how many modes are about to be built (a closed
    form knows after its root finding), so its total is right from the start."""
    active = _BUILD_PROGRESS.get()
    if active is not None:
        active.expect(count)


@contextmanager
def build_progress(report: Callable[[int, int], None] | None, samples: int) -> Iterator[None]:
    """While active, every mode built by :func:`mode_from_configuration` reports ``report(done,
    to do)`` as its build passes its stages (frames, rate equations, idle spin, rates, link
    motion, variables): each mode counts ``samples``, and the total grows by that as each mode
    starts, unless the builder said beforehand how many it builds (:func:`expect_modes`). A
    closed form's Motion is nearly all build, so this is its progress."""
    if report is None:
        yield
        return
    token = _BUILD_PROGRESS.set(_BuildReport(report, samples))
    try:
        yield
    finally:
        _BUILD_PROGRESS.reset(token)


def start_in_half_open(run: Array) -> Array:
    """``run`` (a continuous angle) shifted by whole turns so that it starts in (−π, π]."""
    return np.asarray(run - 2 * np.pi * np.ceil((run[0] - np.pi) / (2 * np.pi)))


#: jumps of 2π in a run above which :func:`unwrap_in_place` leaves the work to ``np.unwrap``
_SPARSE_JUMPS = 256


def unwrap_in_place(run: Array) -> None:
    """``run[:] = np.unwrap(run)`` (period 2π, jumps of π or more) for a 1-D run of finite
    angles, the same values, but by touching only the samples after a jump: np.unwrap adds the
    running sum of its corrections, which is zero until the first jump and constant between
    two, so the corrections are summed at the jumps only (in the same order)."""
    if run.size < 2:
        return
    dd = run[1:] - run[:-1]
    jumps = np.flatnonzero(~(np.abs(dd) < np.pi))
    if jumps.size == 0:
        return
    if jumps.size > _SPARSE_JUMPS:
        run[:] = np.unwrap(run)
        return
    d = dd[jumps]
    ddmod = np.mod(d + np.pi, 2.0 * np.pi) - np.pi  # np.unwrap's, term by term
    ddmod[(ddmod == -np.pi) & (d > 0)] = np.pi
    total = np.cumsum(ddmod - d)
    ends = np.append(jumps[1:] + 1, run.size)
    for start, end, shift in zip((jumps + 1).tolist(), ends.tolist(), total.tolist(),
                                 strict=True):
        run[start:end] += shift


def unwrap_runs(angle: Array, ok: NDArray[np.bool_]) -> Array:
    """Continuous angles along each run of assembling samples, each run starting in (−π, π]."""
    out = np.array(angle, dtype=float)
    good = ok & np.isfinite(out)
    if out.size and good.all():  # one run, the whole sweep
        starts, stops = [0], [out.size - 1]
    else:
        idx = np.flatnonzero(good)
        if idx.size == 0:
            return out
        breaks = np.flatnonzero(np.diff(idx) > 1)
        starts = [int(idx[0])] + (idx[breaks + 1] if breaks.size else idx[:0]).tolist()
        stops = (idx[breaks] if breaks.size else idx[:0]).tolist() + [int(idx[-1])]
    for a, b in zip(starts, stops, strict=True):
        run = out[a:b + 1]
        unwrap_in_place(run)
        turns = np.ceil((run[0] - np.pi) / (2 * np.pi))  # start_in_half_open
        if turns != 0.0:
            run -= 2 * np.pi * turns
    return out


def _variable_tables(linkage: Linkage, lay: Layout, conf: Configuration, mask: NDArray[np.bool_],
                     X: Array, qd: Array, qdd: Array) -> tuple[dict[str, Array], ...]:
    variables: dict[str, Array] = {}
    velocities: dict[str, Array] = {}
    accelerations: dict[str, Array] = {}
    for f, name in enumerate(lay.names):
        c = lay.scalar_col[f]
        if c >= 0:
            values = conf.scalars[:, c].copy()
            if name in linkage.inputs:
                values = X[:, linkage.inputs.index(name)].copy()  # exactly as given
            elif not lay.is_translation[f] and mask.any():
                # continuous along each run of the branch, starting in (−π, π] (as the closed
                # forms do)
                values = unwrap_runs(values, mask)
            variables[name] = values
        velocities[name] = qd[:, f]
        accelerations[name] = qdd[:, f]
    for i, sidx in lay.spherical_of_joint.items():
        rv = rotation_vector(conf.spherical[:, sidx])
        jn = linkage.joints[i].name
        for a, ax in enumerate("xyz"):
            variables[f"{jn}.r{ax}"] = rv[:, a]
    return variables, velocities, accelerations


def closure_residual(R: Array, p: Array, rows: Array) -> Array:
    """The loop-closure error max|ξ| (scaled rows) of G = (R, p): the first-order twist
    (:func:`~screwkit.kinematics.tracker.loop.closure_error`) where that is below 1e-6 (it then equals
    the exact SE(3) logarithm's to a relative 1e-6, and the residual is only ever compared
    with tolerances), the exact logarithm elsewhere (a rotation near a half turn has a small
    first-order error)."""
    res = np.max(np.abs(closure_error(R, p) * rows), axis=-1)
    far = ~(res < 1e-6) | (np.trace(R, axis1=-2, axis2=-1) < 2.0)
    if far.any():
        res[far] = np.max(np.abs(closure_twist(R[far], p[far]) * rows), axis=-1)
    return np.asarray(res)


def idle_spin_held(linkage: Linkage, lay: Layout, conf: Configuration,
                   mask: NDArray[np.bool_], X: Array, fr: LoopFrames, eq: RateEquations,
                   ) -> tuple[Configuration, LoopFrames, RateEquations]:
    """The configurations with every S–S rod's idle spin held at zero along the sweep
    (:func:`~screwkit.kinematics.tracker.idle_spin.hold_idle_spin`), their frames and rate equations."""
    conf, fr = _spin_held(linkage, lay, conf, mask, X, fr, eq)
    return conf, fr, rate_equations(linkage, lay, fr, mask, exact_sigma=False)


def _spin_held(linkage: Linkage, lay: Layout, conf: Configuration, mask: NDArray[np.bool_],
               X: Array, fr: LoopFrames, eq: RateEquations) -> tuple[Configuration, LoopFrames]:
    """:func:`idle_spin_held` without the rate equations of the result."""
    conf = hold_idle_spin(linkage, lay, conf, mask, X, fr, eq)
    # the turns about the rods' axes leave round-off in the closure: one Newton step
    # (minimum-norm, so it does not turn the rods back) restores it
    polished = newton(linkage, conf, max_iter=2, tol=1e-15, lay=lay).conf
    conf = Configuration(np.where(mask[:, None], polished.scalars, conf.scalars),
                         np.where(mask[:, None, None, None], polished.spherical,
                                  conf.spherical))
    return conf, forward(linkage, conf, lay)


@dataclass(frozen=True)
class ModePoses:
    """The positions of one assembly mode without its rates: the fields of
    :class:`~screwkit.kinematics.motion.ModeMotion` of the same names, the same numbers."""

    assembles: NDArray[np.bool_]
    link_rotation: Array
    link_origin: Array
    joint_centres: Array
    joint_axes: Array


def mode_poses(linkage: Linkage, lay: Layout, conf: Configuration, mask: NDArray[np.bool_],
               X: Array) -> ModePoses:
    """The link frames, joint centres and axes that :func:`mode_from_configuration` gives for
    the same arguments (an S–S rod's idle spin held as there), without the rate equations'
    solution: a caller that needs one mode's positions picks it from several branches at the
    cost of their frames only (graph/loop_motion.py)."""
    mask = np.asarray(mask, dtype=bool)
    fr = forward(linkage, conf, lay)
    if spin_links(linkage):
        eq = rate_equations(linkage, lay, fr, mask, exact_sigma=False)
        conf, fr = _spin_held(linkage, lay, conf, mask, X, fr, eq)
    R, p, cen, axs = _world_poses(linkage, fr)
    for arr in (R, p, cen, axs):
        arr[~mask] = np.nan
    return ModePoses(mask, R, p, cen, axs)


def _world_poses(linkage: Linkage, fr: LoopFrames) -> tuple[Array, Array, Array, Array]:
    """Every moving link's frame (rotation, origin), the joint centres and axes in the world
    (the loop's base frame applied to its ground-frame poses)."""
    nl = len(linkage.joints) - 1
    bR, bp = linkage.base.real, linkage.base.translation
    return (np.asarray(bR @ fr.after_R[:, :nl]), np.asarray(fr.after_p[:, :nl] @ bR.T) + bp,
            np.asarray(fr.centres @ bR.T) + bp, np.asarray(fr.axes @ bR.T))


def mode_from_configuration(linkage: Linkage, lay: Layout, conf: Configuration,
                            mask: NDArray[np.bool_], X: Array, Xd: Array, Xdd: Array,
                            events: list[str]) -> ModeMotion:
    """Everything about one assembly mode from its closed configurations ``conf`` (N samples,
    ``mask`` where they hold): link frames, joint centres and axes, and the rates and
    accelerations of every freedom and link from the loop's rate equations (module docstring).
    ``X``, ``Xd``, ``Xdd`` (N, n_in) are the inputs and their first two time derivatives."""
    mask = np.asarray(mask, dtype=bool)
    _built(0.0)
    fr = forward(linkage, conf, lay)
    eq = rate_equations(linkage, lay, fr, mask, exact_sigma=False)
    _built(0.25)
    if eq.spin_links:
        conf, fr, eq = idle_spin_held(linkage, lay, conf, mask, X, fr, eq)
        _built(0.45)
    rates = solve_rates(linkage, lay, eq, Xd, Xdd)
    _built(0.7)
    singular = mask & (eq.singular | ~(rates.residual <= RESIDUAL_TOL))
    qd, qdd, link_V, link_A = rates.qd, rates.qdd, rates.link_V, rates.link_A
    # link frames and their motion in the world, per moving link i < n
    nl = len(linkage.joints) - 1
    bR = linkage.base.real
    w, v0 = link_V[:, :nl, :3], link_V[:, :nl, 3:]
    al, a0 = link_A[:, :nl, :3], link_A[:, :nl, 3:]
    p_g = fr.after_p[:, :nl]
    v_o = v0 + cross(w, p_g)
    a_o = a0 + cross(al, p_g) + cross(w, v_o)

    def world(x: Array) -> Array:
        return np.asarray(x @ bR.T)

    R, p, cen, axs = _world_poses(linkage, fr)
    frames = [R, p]
    twists = [world(w), world(v_o), world(al), world(a_o)]
    _built(0.85)
    variables, velocities, accelerations = _variable_tables(linkage, lay, conf, mask, X, qd, qdd)
    xi_res = closure_residual(fr.closure_R, fr.closure_p, eq.rows)
    bad = ~mask
    for table in (variables, velocities, accelerations):
        for values in table.values():
            values[bad] = np.nan
    for table in (velocities, accelerations):
        for values in table.values():
            values[singular] = np.nan
    for arr in frames + twists + [cen, axs]:
        arr[bad] = np.nan
    for arr in twists:
        arr[singular] = np.nan
    xi_res[bad] = np.nan
    if singular.any():
        idx = np.nonzero(singular)[0]
        sub = conf.take(idx)
        kinds, dims = classify(linkage, lay, sub, rate_equations(
            linkage, lay, forward(linkage, sub, lay)))
        events = [*events, *singular_events(linkage, X, idx, kinds, dims)]
    _built(1.0)
    return ModeMotion(mask, singular, conf, variables, velocities, accelerations,
                      link_rotation=frames[0], link_origin=frames[1],
                      link_angular_velocity=twists[0], link_origin_velocity=twists[1],
                      link_angular_acceleration=twists[2], link_origin_acceleration=twists[3],
                      joint_centres=cen, joint_axes=axs, closure_residual=xi_res, events=events)

"""``solve_motion``: the one entry point of the kinematics — every assembly mode of a loop over
an input sweep, with velocities and accelerations, from a family's closed form or the generic
loop solver, as one :class:`~screwkit.kinematics.motion.Motion`."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike

from screwkit.budget import check_memory, check_time
from screwkit.errors import CapabilityError, InputError, expect_number
from screwkit.kinematics.motion import ModeMotion, Motion, as_input_array, per_sample
from screwkit.kinematics.registry import family_of, seed_variables
from screwkit.kinematics.tracker.generic_motion import Progress, generic_motion, progress_reporter
from screwkit.kinematics.tracker.loop import Array
from screwkit.kinematics.tracker.mode_frames import build_progress
from screwkit.model.linkage import Linkage

METHODS = ("auto", "closed", "generic")


def solve_motion(
    linkage: Linkage,
    inputs: ArrayLike,
    *,
    rates: ArrayLike = 1.0,
    accelerations: ArrayLike = 0.0,
    method: str = "auto",
    starts: int = 48,
    seed: int = 0,
    progress: Progress | bool | None = None,
) -> Motion:
    """Positions, velocities and accelerations of every freedom and link of ``linkage`` over an
    input sweep, in every assembly mode.

    Parameters
    ----------
    linkage:
        the loop (read only).
    inputs:
        (N,) input values for a one-input loop, or (N, n_inputs): radians for a rotation,
        metres for a translation.
    rates, accelerations:
        the inputs' first and second time derivatives (rad/s, rad/s² or m/s, m/s²): a scalar
        for all samples or one value per sample.
    method:
        ``"closed"`` the family's closed form (RSRC quartic, Bagci 1969 eqs. 3.59–3.82; the planar
        4R as its δ0 = λ0 = b = e = 0 case; the CSSP quadratic in s4, Rahman 1996 §1.2);
        ``"generic"`` the generic loop solver (any loop; docs/kinematics.md); ``"auto"`` the
        closed form where the family has one and the sweep has at least 2 samples.
    starts, seed:
        random starts per sample and their seed, for the generic solver's root search.
    progress:
        a callback ``progress(done, total)`` called as the generic solver follows its branches
        and builds its modes, or as a closed form builds its modes (each mode counting every
        sample): ``done`` never decreases and ends equal to ``total``, which is revised as
        modes are found (and, in the generic solver, merged),
        ``False`` for none, or ``None``: a progress bar on stderr for a sweep of 50 000
        samples or more when stderr is a terminal.

    Both methods give the same fields and the same mode numbering (docs/conventions.md,
    "Assembly modes"): generic modes are numbered as the closed form's where a family has one.
    """
    if method not in METHODS:
        raise InputError(f"method must be 'auto', 'closed' or 'generic'; got {method!r}")
    expect_number(starts, "starts", integer=True, positive=True)
    expect_number(seed, "seed", integer=True)
    X = as_input_array(linkage, inputs, "inputs")
    fam = family_of(linkage)
    N = X.shape[0]
    modes_bound = fam.max_modes or MODES_ESTIMATE
    check_memory(motion_bytes(linkage, N, modes_bound), f"a motion of {N} samples",
                 "use fewer input samples (a larger [motion] step or a shorter range)")
    Xd = per_sample(linkage, rates, "rates", X)
    Xdd = per_sample(linkage, accelerations, "accelerations", X)
    closed = fam.closed_form_for(linkage) if N >= 2 else None
    if method == "closed" and closed is None:
        with_closed = ", ".join(f.name for f in _families_with_closed_forms())
        raise CapabilityError(
            f"no closed form for a {fam.name} with {N} input sample(s) (closed forms: "
            f"{with_closed}, with at least 2 input samples); use method 'generic'")
    use_closed = method in ("auto", "closed") and closed is not None
    seconds = check_motion_time(linkage, N, modes_bound, generic=not use_closed,
                                closed=closed is not None)
    if use_closed:
        assert closed is not None
        with progress_reporter(progress, N, "building assembly modes (closed form)",
                               seconds) as report, build_progress(report, N):
            motion = closed(linkage, X, Xd, Xdd)
        if callable(progress):
            progress(len(motion.modes) * N, len(motion.modes) * N)
        return motion
    with progress_reporter(progress, N, seconds=seconds) as report:
        motion = generic_motion(linkage, X, Xd, Xdd, starts=starts, seed=seed,
                                progress=report if report is not None else False)
    modes = tuple(with_seed_names(linkage, md) for md in motion.modes)
    notes = motion.notes
    if closed is not None:
        modes = _numbered_as(modes, closed(linkage, X, Xd, Xdd).modes, linkage.length_scale)
    elif fam.closed_form_for(linkage) is not None and method == "auto":
        notes += ("one input sample: the generic solver was used (the closed form tracks "
                  "branches over at least 2 samples)",)
    return replace(motion, modes=modes, notes=notes)


#: assembly modes assumed when estimating the memory of a loop whose family does not bound them
#: (``Family.max_modes``)
MODES_ESTIMATE = 4


def motion_bytes(linkage: Linkage, samples: int, modes: int = MODES_ESTIMATE) -> float:
    """About how many bytes a Motion of ``samples`` samples takes, with the solver's temporaries:
    per mode and sample, every link frame and its twists and accelerations, joint centres and
    axes, and three tables of every variable, times 2.8 (measured peak: 2.0 times the result for
    10⁶ samples of a planar 4R with the generic solver, 6.3 GB; 1.4 with the closed form)."""
    n, links = len(linkage.joints), len(linkage.links)
    freedoms = sum(j.dof for j in linkage.joints)
    floats = 24 * links + 6 * n + 4 * (freedoms + 8) + 9 * n
    return 2.8 * 8 * floats * modes * samples


#: seconds of computing per sample and mode: a closed form's Motion (measured ~8–9 µs on the
#: RSRC, ~2 on the CSSP), and the generic solver's per joint freedom (~2 µs × 7 freedoms on
#: the RSRC, ~17 µs × 40 on an underdriven 40R); both rounded up (docs/reliability.md)
CLOSED_SECONDS = 12e-6
GENERIC_SECONDS_PER_FREEDOM = 4e-6


def search_seconds(freedoms: int) -> float:
    """The generic solver's root searches (first sample, anchors, branch ends) over a sweep, in
    seconds: Newton on ``freedoms`` unknowns from 48 starts, with the continuum checks, grows as
    the square to the cube of the freedoms (measured 0.35, 0.9, 2.2 and 11.6 s for planar loops
    of 5, 40, 80 and 160 R joints; the fit 0.3 + 2.9e-4 m² + 1e-6 m³ bounds them)."""
    return 0.3 + 2.9e-4 * freedoms**2 + 1e-6 * freedoms**3


def motion_seconds(linkage: Linkage, samples: int, modes: int = MODES_ESTIMATE, *,
                   generic: bool = False, closed: bool = False) -> float:
    """About how many seconds of computing :func:`solve_motion` needs (known before it
    starts): ``samples`` × ``modes`` × the per-sample cost of the route, plus the generic
    solver's root searches; ``closed`` adds the closed form that numbers a generic run's modes
    as its own."""
    freedoms = sum(j.dof for j in linkage.joints)
    seconds = CLOSED_SECONDS * samples * modes if closed else 0.0
    if generic:
        seconds += (search_seconds(freedoms)
                    + GENERIC_SECONDS_PER_FREEDOM * freedoms * samples * modes)
    return seconds


def check_motion_time(linkage: Linkage, samples: int, modes: int, *, generic: bool,
                      closed: bool) -> float:
    """:func:`motion_seconds`, refused over the time limit (:func:`screwkit.budget.check_time`)
    with what to change: fewer samples, or fewer joints where the root searches dominate."""
    seconds = motion_seconds(linkage, samples, modes, generic=generic, closed=closed)
    freedoms = sum(j.dof for j in linkage.joints)
    if generic and search_seconds(freedoms) > seconds / 2:
        advice = (f"its root searches grow as the cube of the loop's {freedoms} joint freedoms: "
                  "describe the mechanism with fewer joints")
    else:
        advice = "use fewer input samples (a larger [motion] step or a shorter range)"
        if generic and closed:
            advice += ", or its closed form (method 'auto')"
    check_time(seconds, f"a motion of {samples} samples"
               + (f" by the generic solver ({freedoms} joint freedoms)" if generic else ""),
               advice)
    return seconds


def _families_with_closed_forms() -> list:  # type: ignore[type-arg]
    from screwkit.kinematics.registry import FAMILIES

    return [f for f in FAMILIES.values() if f.closed_form is not None]


def with_seed_names(linkage: Linkage, mode: ModeMotion) -> ModeMotion:
    """A generic mode with the seed's variable names added (from its joint variables)."""
    named = seed_variables(linkage, mode)
    tables = tuple({**n, **general} for n, general in
                   zip(named, (mode.variables, mode.velocities, mode.accelerations), strict=True))
    return replace(mode, variables=tables[0], velocities=tables[1], accelerations=tables[2])


def _agreement(a: ModeMotion, b: ModeMotion, length: float) -> int:
    """Samples where two modes are the same configuration (joint centres within 1e-6 of the
    length scale)."""
    both = a.assembles & b.assembles
    if not both.any():
        return 0
    d = np.max(np.abs(a.joint_centres[both] - b.joint_centres[both]), axis=(1, 2))
    return int(np.sum(d < 1e-6 * length))


def _numbered_as(modes: tuple[ModeMotion, ...], reference: tuple[ModeMotion, ...],
                 length: float) -> tuple[ModeMotion, ...]:
    """Generic ``modes`` renumbered as the closed form's ``reference`` modes: mode k is the
    generic branch that is the same configuration as closed-form mode k over most samples.
    Where the closed form continues a branch past a limit position the generic solver may start
    a new one; such extra branches, and any without a counterpart, follow in their own order."""
    score: Array = np.array([[_agreement(g, r, length) for r in reference] for g in modes]
                            ).reshape(len(modes), len(reference))
    order: list[int] = []
    for k in range(len(reference)):
        candidates = [g for g in np.argsort(-score[:, k], kind="stable")
                      if score[g, k] > 0 and int(g) not in order
                      and int(np.argmax(score[g])) == k]
        if candidates:
            order.append(int(candidates[0]))
    order += [g for g in range(len(modes)) if g not in order]
    return tuple(replace(modes[g], index=k) for k, g in enumerate(order))

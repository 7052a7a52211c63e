"""Limit positions and dwell orders of any output variable of any loop, from a solved
:class:`~screwkit.kinematics.motion.Motion` (the generic route; docs/kinematics.md).

Along each mode the output's rate r = d output/d input comes from the motion's exact rates
(the loop's rate equation). A limit is a zero of r: every sign change between two consecutive
regular samples (assembling, not singular) is a bracket — across the end of a full input turn
too, when the mode comes back to itself — and is refined by safeguarded Newton on r with the
exact r′ = d² output/d input² (bisection whenever a Newton step leaves the bracket), the
positions being re-solved at every iterate (:func:`~screwkit.kinematics.tracker.loop_jets.follow`). A
sign change through a pole (r → ∞ at a dead centre) is not a limit and is dropped. At the root
the derivatives of every order come from the exact Taylor coefficients of the loop closure
(:mod:`screwkit.kinematics.tracker.loop_jets`), so the dwell order — the number of vanishing consecutive
derivatives dᵏ output/d inputᵏ within the dwell tolerance — is exact to rounding, as Bagci's App. D
is for the RSRC (the tests compare both routes).
"""

from __future__ import annotations

import math

import numpy as np

from screwkit.kinematics.analysis.limit_results import DwellAt, LimitPosition, LimitPositions
from screwkit.kinematics.motion import AssemblyError, ModeMotion, Motion, format_inputs
from screwkit.kinematics.registry import family_of, output_freedom, seed_variables
from screwkit.kinematics.tracker.loop import Array, Configuration, Layout, forward, layout
from screwkit.kinematics.tracker.loop_jets import follow, taylor_jets
from screwkit.kinematics.tracker.mode_frames import mode_from_configuration
from screwkit.model.linkage import Linkage

GENERIC_DERIVATIVES = ("orders 1 and 2: the motion's rate equations; every order at a limit: "
                       "exact Taylor coefficients of the loop closure (kinematics/tracker/loop_jets.py)")


def _full_turn(motion: Motion, lay: Layout) -> float | None:
    """The sweep's step when it is one uniform full turn of an angle input (the next sample
    after the last is the first plus 2π), else None."""
    x = motion.input_values
    f_in = lay.names.index(motion.linkage.inputs[0])
    if lay.is_translation[f_in] or x.size < 3:
        return None
    step = np.diff(x)
    if np.ptp(step) > 1e-9 * abs(step[0]) or step[0] <= 0:
        return None
    return float(step[0]) if abs(x[-1] + step[0] - x[0] - 2 * math.pi) < 1e-9 else None


def _wraps(linkage: Linkage, lay: Layout, md: ModeMotion, x: Array, step: float) -> bool:
    """Whether the mode at the last sample, continued one step, is the mode at the first."""
    if not (md.assembles[0] and md.assembles[-1]):
        return False
    end, ok = follow(linkage, md.conf.take(np.array([x.size - 1])), x[-1:], x[-1:] + step, lay=lay)
    if not ok[0]:
        return False
    a = forward(linkage, end, lay).centres[0]
    b = forward(linkage, md.conf.take(np.array([0])), lay).centres[0]
    return bool(np.max(np.abs(a - b)) < 1e-6 * linkage.length_scale)


def _rate(motion: Motion, md: ModeMotion, freedom: str, sign: float) -> Array:
    """d output/d input at every sample: the motion's rate over the input rate (the exact
    Taylor coefficient where the input does not move)."""
    xd = motion.input_rates[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = sign * md.velocities[freedom] / xd
    still = (xd == 0) & md.assembles & ~md.singular
    if still.any() or len(motion.linkage.inputs) > 1:
        idx = np.nonzero(md.assembles & ~md.singular)[0]
        jets = taylor_jets(motion.linkage, md.conf.take(idx), 1)
        rate[idx] = sign * jets.derivatives(freedom)[:, 0]
    return np.asarray(rate)


def _refine(linkage: Linkage, lay: Layout, conf: Configuration, x: Array, a: Array, b: Array,
            fa: Array, fb: Array, freedom: str, sign: float
            ) -> tuple[Array, Configuration, Array]:
    """Safeguarded Newton on r(x) = d output/d input inside brackets [a, b] (fa·fb < 0), from
    closed configurations ``conf`` at ``x`` (one of the ends); returns the roots, their
    configurations and r there."""
    r = np.zeros_like(x)
    failed = np.zeros(x.shape, dtype=bool)
    for _ in range(80):
        jets = taylor_jets(linkage, conf, 2, lay)
        d = sign * jets.derivatives(freedom)
        r, rp = d[:, 0], d[:, 1]
        left = np.sign(r) == np.sign(fa)
        a, fa = np.where(left, x, a), np.where(left, r, fa)
        b, fb = np.where(left, b, x), np.where(left, fb, r)
        with np.errstate(invalid="ignore", divide="ignore"):
            newton = x - r / rp
        inside = np.isfinite(newton) & (newton > a) & (newton < b)
        new = np.where(inside, newton, 0.5 * (a + b))
        new = np.where((r == 0) | failed, x, new)
        done = np.abs(new - x) <= 1e-14 * (1 + np.abs(x))
        if done.all():
            break
        new = np.where(done, x, new)
        conf, ok = follow(linkage, conf, x, new, lay=lay)
        failed |= ~ok
        x = np.where(ok, new, x)
    x = np.where(failed, np.nan, x)
    return x, conf, r


def variables_at(linkage: Linkage, lay: Layout, conf: Configuration, x: float
                 ) -> dict[str, float | None]:
    """Every scalar variable (the seed's names and the scalar joint freedoms) of one closed
    configuration, angles in (−π, π] (the convention of a mode's first sample)."""
    X = np.array([[conf.scalars[0, lay.scalar_col[lay.names.index(n)]] for n in linkage.inputs]])
    X[0, 0] = x
    md = mode_from_configuration(linkage, lay, conf, np.array([True]), X, np.ones_like(X),
                                 np.zeros_like(X), [])
    named = seed_variables(linkage, md)[0]
    scalar = {n for n, c in zip(lay.names, lay.scalar_col, strict=True) if c >= 0}
    out: dict[str, float | None] = {k: float(v[0]) for k, v in named.items()}
    out.update({k: float(v[0]) for k, v in md.variables.items() if k in scalar})
    return out


def _order(derivatives: Array, tol: float, max_order: int) -> int:
    small = np.abs(derivatives[:max_order]) <= tol
    return int(np.cumprod(small).sum())


def _mode_limits(motion: Motion, lay: Layout, md: ModeMotion, output: str, tol: float,
                 max_order: int, step: float | None) -> tuple[list[LimitPosition], list[str]]:
    linkage = motion.linkage
    freedom, sign = output_freedom(linkage, output)
    x = motion.input_values
    rate = _rate(motion, md, freedom, sign)
    valid = md.assembles & ~md.singular & np.isfinite(rate)
    i = np.nonzero(valid[:-1] & valid[1:] & (rate[:-1] * rate[1:] < 0))[0]
    j, xb = i + 1, x[np.minimum(i + 1, x.size - 1)]
    if step is not None and valid[-1] and valid[0] and rate[-1] * rate[0] < 0 \
            and _wraps(linkage, lay, md, x, step):
        i, j = np.append(i, x.size - 1), np.append(j, 0)
        xb = np.append(xb, x[0] + 2 * math.pi)
    notes: list[str] = []
    roots: list[tuple[float, Configuration]] = [(float(x[k]), md.conf.take(np.array([k])))
                                                for k in np.nonzero(valid & (rate == 0))[0]]
    if i.size:
        start_left = np.abs(rate[i]) <= np.abs(rate[j])
        conf = md.conf.take(np.where(start_left, i, j))
        x0 = np.where(start_left, x[i], xb)
        root, conf, r = _refine(linkage, lay, conf, x0, x[i], xb, rate[i], rate[j], freedom, sign)
        scale = max(1.0, float(np.nanmedian(np.abs(rate[valid]))))
        for k in range(i.size):
            if np.isfinite(root[k]) and abs(r[k]) <= 1e-9 * scale:
                roots.append((float(root[k]), conf.take(np.array([k]))))
            elif not np.isfinite(root[k]):
                notes.append(f"mode {md.index}: a sign change of d{output}/d input between "
                             f"{format_inputs(linkage, x[i[k]:i[k] + 1])} and the next sample "
                             "could not be followed (the branch ends there)")
    out: list[LimitPosition] = []
    kind = "translation" if lay.is_translation[lay.names.index(freedom)] else "rotation"
    for xr, c in sorted(roots, key=lambda t: t[0]):
        if step is not None and xr >= x[0] + 2 * math.pi:
            xr -= 2 * math.pi
        if out and abs(out[-1].input - xr) < 1e-9:
            continue
        deriv = sign * taylor_jets(linkage, c, max_order + 1, lay).derivatives(freedom)[0]
        variables = variables_at(linkage, lay, c, xr)
        value = variables.get(output)
        out.append(LimitPosition(output, kind, xr, float(value if value is not None else np.nan),
                                 float(deriv[1]), _order(deriv, tol, max_order), deriv.tolist(),
                                 mode=md.index, variables=variables))
    return out, notes


def _dwells_at(motion: Motion, lay: Layout, outputs: tuple[str, ...], at: list[float],
               tol: float, max_order: int, step: float | None) -> list[DwellAt]:
    linkage = motion.linkage
    x = motion.input_values
    found: list[DwellAt] = []
    for xa in at:
        hit = False
        for md in motion.modes:
            valid = np.nonzero(md.assembles & ~md.singular)[0]
            if valid.size == 0:
                continue
            gap = xa - x[valid]
            if step is not None:
                gap = np.remainder(gap + math.pi, 2 * math.pi) - math.pi
            k = int(valid[np.argmin(np.abs(gap))])
            g = float(gap[np.argmin(np.abs(gap))])
            c, ok = follow(linkage, md.conf.take(np.array([k])), x[k:k + 1], x[k:k + 1] + g,
                           lay=lay)
            if not ok[0]:
                continue
            hit = True
            for output in outputs:
                freedom, sign = output_freedom(linkage, output)
                deriv = sign * taylor_jets(linkage, c, max_order + 1, lay).derivatives(freedom)[0]
                value = variables_at(linkage, lay, c, xa).get(output)
                found.append(DwellAt(output, float(xa), float(np.nan if value is None else value),
                                     _order(deriv, tol, max_order), deriv.tolist(),
                                     mode=md.index))
        if not hit:
            raise AssemblyError(f"{linkage.name}: no assembly mode reaches the input "
                                f"{format_inputs(linkage, np.array([xa]))} asked for from the "
                                "motion's samples; widen the [motion] sweep")
    return found


def generic_limit_positions(motion: Motion, outputs: tuple[str, ...], dwell_tolerance: float,
                            max_order: int, at: list[float] | None = None) -> LimitPositions:
    """Limit positions of ``outputs`` on every mode of ``motion`` and the dwell order of each
    (module docstring); ``at``: inputs (rad or m) where every mode's dwell order is wanted."""
    linkage = motion.linkage
    lay = layout(linkage)
    step = _full_turn(motion, lay)
    limits: list[LimitPosition] = []
    notes: list[str] = []
    for output in outputs:
        for md in motion.modes:
            found, why = _mode_limits(motion, lay, md, output, dwell_tolerance, max_order, step)
            limits += found
            notes += why
    if step is None:
        notes.append("limits are searched over the [motion] sweep "
                     f"({format_inputs(linkage, motion.inputs[0])} to "
                     f"{format_inputs(linkage, motion.inputs[-1])}), not a full turn")
    dwells = _dwells_at(motion, lay, outputs, list(at or []), dwell_tolerance, max_order, step)
    return LimitPositions(linkage.name, family_of(linkage).name, "generic", linkage.inputs[0],
                          outputs, dwell_tolerance, max_order, limits, dwells,
                          GENERIC_DERIVATIVES, tuple(notes))

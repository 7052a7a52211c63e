"""Limit positions of a loop's output variables and the order of the instantaneous dwell at
each: Bagci 1969 App. D's closed form for the RSRC and the planar 4R (their φ0 and S over a full
input turn), and the generic route for any output of any loop
(:mod:`screwkit.kinematics.analysis.generic_limits`; docs/kinematics.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from screwkit.errors import InputError, expect_instance, expect_number
from screwkit.kinematics.analysis.generic_limits import generic_limit_positions
from screwkit.kinematics.analysis.limit_results import DwellAt, LimitPosition, LimitPositions
from screwkit.kinematics.motion import Motion
from screwkit.kinematics.registry import default_outputs, family_of, output_freedom, require
from screwkit.model.linkage import Linkage

__all__ = ["DwellAt", "LimitPosition", "LimitPositions", "LimitsConfig", "check_limits_config",
           "limit_positions", "uses_closed_form"]

METHODS = ("auto", "closed", "generic")


@dataclass(frozen=True)
class LimitsConfig:
    """What a spec's ``[limits]`` table asks for (SI units; docs/spec-format.md): the output
    (None: the loop's outputs), the dwell tolerance, the highest derivative counted, inputs where
    the dwell order is wanted, and the route."""

    output: str | None = None
    dwell_tolerance: float = 1e-6
    max_order: int = 5
    at: tuple[float, ...] = ()
    method: str = "auto"


def check_limits_config(linkage: Linkage, config: LimitsConfig) -> None:
    """A ValueError naming what ``config`` asks that the loop cannot give."""
    require(linkage, "limits")
    expect_number(config.max_order, "max_order", integer=True)
    expect_number(config.dwell_tolerance, "dwell_tolerance", positive=True)
    if config.at:
        for x in config.at:
            expect_number(x, "at")
    if not 1 <= int(config.max_order) <= 10:
        raise InputError(f"max_order must be 1 … 10; got {config.max_order}")
    if not config.dwell_tolerance > 0:
        raise InputError(f"dwell_tolerance must be positive; got {config.dwell_tolerance}")
    if config.method not in METHODS:
        raise InputError(f"method must be 'auto', 'closed' or 'generic'; got {config.method!r}")
    outputs = (config.output,) if config.output is not None else default_outputs(linkage)
    for name in outputs:
        output_freedom(linkage, name)
    if config.method == "closed" and not uses_closed_form(linkage, config.output, "closed"):
        fam = family_of(linkage)
        raise InputError(f"no closed-form limits of {', '.join(outputs)} for a {fam.name} "
                         "(Bagci's App. D covers the RSRC's φ0 and S and the 4R's φ0); use "
                         "method = \"generic\" or \"auto\"")


def uses_closed_form(linkage: Linkage, output: str | None, method: str) -> bool:
    """Whether :func:`limit_positions` takes Bagci's closed-form route for these arguments."""
    fam = family_of(linkage)
    outputs = (output,) if output is not None else fam.outputs
    return (method != "generic" and fam.closed_limits is not None and bool(outputs)
            and set(outputs) <= set(fam.outputs))


def limit_positions(source: Linkage | Motion, dwell_tolerance: float = 1e-6, max_order: int = 5,
                    at: list[float] | None = None, *, output: str | None = None,
                    method: str = "auto") -> LimitPositions:
    """Limit positions of a loop's outputs (d output/d input = 0) with the order of the
    instantaneous dwell at each: the number of vanishing consecutive derivatives
    dᵏ output/d inputᵏ, k = 1 … ``max_order``, within ``dwell_tolerance`` (output unit per
    input unitᵏ).

    ``source``: a solved :class:`Motion` (the generic route searches its sweep and modes) or a
    :class:`Linkage` (a full input turn in 1° steps is solved for the generic route).
    ``output``: one variable (a scalar joint freedom or a seed name such as ``phi0``); default
    the loop's outputs (:func:`~screwkit.kinematics.registry.default_outputs`). ``method``:
    ``"closed"`` Bagci 1969 App. D (RSRC and 4R, their φ0 and S, rotation limits Q4 = 0 eq. D.1,
    translation limits by the corrected eq. D.3, over a full input turn), ``"generic"`` the
    generic route (any loop), ``"auto"`` the closed form where it answers the outputs asked for.
    ``at``: inputs (rad or m) where the dwell order of every mode is wanted too."""
    expect_instance(source, Linkage | Motion, "limit_positions: source",
                    "a Linkage or a solved Motion (sk.solve_motion(...))")
    linkage = source.linkage if isinstance(source, Motion) else source
    if at is not None and (isinstance(at, str) or not np.iterable(at)):
        at = [at]  # type: ignore[list-item]  # one input value; expect_number names a wrong one
    check_limits_config(linkage, LimitsConfig(output, dwell_tolerance, max_order,
                                              tuple(at or ()), method))
    fam = family_of(linkage)
    outputs = (output,) if output is not None else default_outputs(linkage)
    if uses_closed_form(linkage, output, method):
        assert fam.closed_limits is not None
        result: LimitPositions = fam.closed_limits(linkage, dwell_tolerance, max_order, at)
        if output is None:
            return result
        keep = [lim for lim in result.limits if lim.output == output]
        dwells = [d for d in result.dwells_at if d.output == output]
        return LimitPositions(result.mechanism, result.family, result.method, result.input_name,
                              (output,), dwell_tolerance, max_order, keep, dwells,
                              result.derivatives, result.notes)
    if isinstance(source, Motion):
        motion = source
    else:
        from screwkit.kinematics.solve_motion import solve_motion

        motion = solve_motion(linkage, np.radians(np.arange(0.0, 360.0, 1.0)) if not
                              linkage.inputs[0].endswith(".s") else _translation_sweep(linkage))
    return generic_limit_positions(motion, outputs, dwell_tolerance, int(max_order), at)


def _translation_sweep(linkage: Linkage) -> np.ndarray:
    L = linkage.length_scale
    return np.linspace(-L, L, 401)

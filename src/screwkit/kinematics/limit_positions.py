"""Limit positions of the output and the order of the instantaneous dwell at each (Bagci 1969,
App. D), for the families that offer them (the registry's ``limits`` capability: the RSRC and
the planar 4R)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.kinematics.motion import AssemblyError
from screwkit.kinematics.registry import require
from screwkit.model.linkage import Linkage


@dataclass(frozen=True)
class LimitPosition:
    """A rotation (``kind="rotation"``: dφ0/dθ0 = 0, eq. D.1) or translation (``"translation"``:
    dS/dθ0 = 0, corrected eq. D.3) limit of the output on one closed-form branch, with the dwell
    order (rotation limits only): the number of vanishing consecutive derivatives dᵏφ0/dθ0ᵏ."""

    kind: str
    theta0: float
    phi0: float
    chi0: float
    S: float | None
    second_derivative: float
    branch: int
    dwell_order: int | None = None
    derivatives: list[float] | None = None


@dataclass(frozen=True)
class DwellAt:
    """The dwell order of the output rotation at a given input angle and inversion label."""

    theta0: float
    inversion_label: int
    phi0: float
    dwell_order: int
    derivatives: list[float]


@dataclass(frozen=True)
class LimitPositions:
    """Result of :func:`limit_positions` (SI units, radians)."""

    mechanism: str
    family: str
    dwell_tolerance: float
    limits: list[LimitPosition]
    dwells_at: list[DwellAt] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        """The JSON document of ``screwkit limits`` (docs/cli.md)."""
        def limit(lim: LimitPosition) -> dict[str, Any]:
            d = {k: getattr(lim, k) for k in ("kind", "theta0", "phi0", "chi0", "S",
                                              "second_derivative", "branch")}
            if lim.kind == "rotation":
                d["dwell_order"] = lim.dwell_order
                d["derivatives"] = lim.derivatives
            return d

        return {"mechanism": self.mechanism, "family": self.family,
                "dwell_tolerance": self.dwell_tolerance, "units": {"angle": "rad", "length": "m"},
                "limits": [limit(x) for x in self.limits],
                "dwells_at": [vars(d) for d in self.dwells_at]}


def limit_positions(linkage: Linkage, dwell_tolerance: float = 1e-6, max_order: int = 5,
                    at: list[float] | None = None) -> LimitPositions:
    """Limit positions of the output rotation and translation over a full input turn, each with
    the order of its instantaneous dwell (Bagci 1969, App. D: rotation limits Q4 = 0, eq. D.1;
    translation limits by the corrected eq. D.3; dwell order = number of vanishing consecutive
    derivatives dᵏφ0/dθ0ᵏ, k = 1…max_order, within ``dwell_tolerance`` rad/radᵏ). ``at``: input
    angles (rad) where the dwell order of every inversion is wanted too."""
    from screwkit.kinematics.assembly_range import assembling_intervals, describe_intervals
    from screwkit.kinematics.closed_form_motion import rsrc_dimensions
    from screwkit.kinematics.rsrc import (
        rsrc_dwell_order,
        rsrc_positions,
        rsrc_rotation_limits,
        rsrc_translation_limits,
    )

    fam = require(linkage, "limits")
    if not dwell_tolerance > 0:
        raise InputError(f"the dwell tolerance must be positive; got {dwell_tolerance}")
    dims, planar = rsrc_dimensions(linkage)
    out: list[LimitPosition] = []
    rot = rsrc_rotation_limits(dims)
    runs = assembling_intervals(dims)
    if not runs and not rot:
        raise AssemblyError(f"{linkage.name}: the mechanism does not assemble at any input angle "
                            "(scanned every 0.25° over a full turn), so it has no limit positions; "
                            "check the dimensions (docs/kinematics.md)")
    if rot:
        order, deriv = rsrc_dwell_order(dims, np.array([r.theta0 for r in rot]),
                                        np.array([r.phi0 for r in rot]), tol=dwell_tolerance,
                                        max_order=max_order)
    for k, r in enumerate(rot):
        out.append(LimitPosition("rotation", r.theta0, r.phi0, r.chi0, None if planar else r.S,
                                 r.second_derivative, r.branch, int(order[k]),
                                 np.asarray(deriv[k]).tolist()))
    if not planar:
        for r in rsrc_translation_limits(dims):
            out.append(LimitPosition("translation", r.theta0, r.phi0, r.chi0, r.S,
                                     r.second_derivative, r.branch))
    dwells: list[DwellAt] = []
    if at:
        th = np.asarray(at, dtype=float)
        pos = rsrc_positions(dims, th)
        nowhere = ~np.asarray(pos.assembles).any(axis=1)
        if nowhere.any():
            shown = ", ".join(f"{np.degrees(t):.6g}°" for t in th[nowhere][:8])
            raise AssemblyError(f"{linkage.name}: the mechanism does not assemble at the input "
                                f"angle(s) {shown} asked for; it assembles "
                                f"{describe_intervals(runs)} (sampled every 0.25°)")
        for j in range(pos.phi0.shape[1]):
            ok = pos.assembles[:, j]
            if not ok.any():
                continue
            order_at, deriv_at = rsrc_dwell_order(dims, th[ok], pos.phi0[ok, j],
                                                  tol=dwell_tolerance, max_order=max_order)
            for t, ph, o, dv in zip(th[ok], pos.phi0[ok, j], order_at, deriv_at, strict=True):
                dwells.append(DwellAt(float(t), j + 1, float(ph), int(o),
                                      np.asarray(dv).tolist()))
    return LimitPositions(linkage.name, fam.name, dwell_tolerance, out, dwells)

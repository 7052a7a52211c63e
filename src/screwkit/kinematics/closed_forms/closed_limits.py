"""Bagci 1969 App. D's closed-form route to the limit positions of the RSRC and of its plane case,
the 4R: rotation limits Q4 = 0 (eq. D.1), translation limits by the corrected eq. D.3, and the
dwell order from the exact Taylor coefficients of φ0(θ0) (``rsrc_output_derivatives``), over a
full input turn. The family registry points the RSRC and the 4R here (``closed_limits``)."""

from __future__ import annotations

import numpy as np

from screwkit.kinematics.analysis.limit_results import DwellAt, LimitPosition, LimitPositions
from screwkit.kinematics.motion import AssemblyError
from screwkit.messages import shown
from screwkit.model.linkage import Linkage

CLOSED_DERIVATIVES = ("exact Taylor coefficients of the RSRC loop equation 3.61 (Bagci 1969 "
                      "App. D), every order")


def rsrc_limit_positions(linkage: Linkage, dwell_tolerance: float, max_order: int,
                         at: list[float] | None) -> LimitPositions:
    """Limit positions of φ0 and S over a full input turn, each rotation limit with its dwell
    order (Bagci 1969 App. D); ``at``: input angles (rad) where every inversion's dwell order is
    wanted too."""
    from screwkit.kinematics.closed_forms.closed_form_motion import rsrc_dimensions
    from screwkit.kinematics.closed_forms.rsrc import (
        rsrc_dwell_order,
        rsrc_positions,
        rsrc_rotation_limits,
        rsrc_translation_limits,
    )
    from screwkit.kinematics.tracker.assembly_range import assembling_intervals, describe_intervals

    dims, planar = rsrc_dimensions(linkage)
    rot = rsrc_rotation_limits(dims)
    runs = assembling_intervals(dims)
    if not runs and not rot:
        raise AssemblyError(f"{linkage.name}: the mechanism does not assemble at any input angle "
                            "(scanned every 0.25° over a full turn), so it has no limit positions; "
                            "check the dimensions (docs/kinematics.md)")
    out: list[LimitPosition] = []
    if rot:
        order, deriv = rsrc_dwell_order(dims, np.array([r.theta0 for r in rot]),
                                        np.array([r.phi0 for r in rot]), tol=dwell_tolerance,
                                        max_order=max_order)
    for k, r in enumerate(rot):
        seed = {"theta0": r.theta0, "phi0": r.phi0, "chi0": r.chi0,
                "S": None if planar else r.S}
        out.append(LimitPosition("phi0", "rotation", r.theta0, r.phi0, r.second_derivative,
                                 int(order[k]), np.asarray(deriv[k]).tolist(), branch=r.branch,
                                 variables=seed))
    if not planar:
        for r in rsrc_translation_limits(dims):
            seed = {"theta0": r.theta0, "phi0": r.phi0, "chi0": r.chi0, "S": r.S}
            out.append(LimitPosition("S", "translation", r.theta0, r.S, r.second_derivative,
                                     None, None, branch=r.branch, variables=seed))
    dwells: list[DwellAt] = []
    if at:
        th = np.asarray(at, dtype=float)
        pos = rsrc_positions(dims, th)
        nowhere = ~np.asarray(pos.assembles).any(axis=1)
        if nowhere.any():
            listed = ", ".join(shown(t, "angle") for t in th[nowhere][:8])
            raise AssemblyError(f"{linkage.name}: the mechanism does not assemble at the input "
                                f"angle(s) {listed} asked for; it assembles "
                                f"{describe_intervals(runs)} (sampled every 0.25°)")
        for j in range(pos.phi0.shape[1]):
            ok = pos.assembles[:, j]
            if not ok.any():
                continue
            order_at, deriv_at = rsrc_dwell_order(dims, th[ok], pos.phi0[ok, j],
                                                  tol=dwell_tolerance, max_order=max_order)
            for t, ph, o, dv in zip(th[ok], pos.phi0[ok, j], order_at, deriv_at, strict=True):
                dwells.append(DwellAt("phi0", float(t), float(ph), int(o),
                                      np.asarray(dv).tolist(), inversion_label=j + 1))
    from screwkit.kinematics.registry import family_of

    outputs = ("phi0",) if planar else ("phi0", "S")
    return LimitPositions(linkage.name, family_of(linkage).name, "closed", "theta0", outputs,
                          dwell_tolerance, max_order, out, dwells, CLOSED_DERIVATIVES)

"""The seeds' variable names read off any :class:`~screwkit.kinematics.motion.ModeMotion` (the
generic solver's included); the family registry maps each family to its function.

RSRC (Bagci 1969 §3.1): θ0, φ0, S, χ0. CSSP (Rahman 1996 §1.2): θ1, s4, θ2, η2 with the rod
direction u = (cη2 c(θ1+θ2), cη2 s(θ1+θ2), −sη2). Planar 4R (Bagci's special case): θ0 and φ0
measured from the line of centres. RSSR: θ0 and φ0 as for the RSRC.
"""

from __future__ import annotations

import numpy as np

from screwkit.dual.spatial import elevation_azimuth, rot_x, wrap_angle
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.tracker.loop import Array
from screwkit.kinematics.tracker.mode_frames import unwrap_runs
from screwkit.model.families import rsrc_seed_variables
from screwkit.model.linkage import Linkage

Named = dict[str, Array]


def rsrc_names(linkage: Linkage, mode: ModeMotion) -> tuple[Named, Named, Named]:
    """θ0, φ0, S, χ0 of an RSRC mode (Bagci 1969 §3.1) from its joint variables."""
    return (rsrc_seed_variables(mode.variables), rsrc_seed_variables(mode.velocities),
            rsrc_seed_variables(mode.accelerations))


def rssr_names(linkage: Linkage, mode: ModeMotion) -> tuple[Named, Named, Named]:
    """θ0 and φ0 of an RSSR mode, measured as for the RSRC."""
    def pick(d: dict[str, Array]) -> Named:
        return {"theta0": d["input.theta"], "phi0": -d["output.theta"]}
    return pick(mode.variables), pick(mode.velocities), pick(mode.accelerations)


def fourbar_names(linkage: Linkage, mode: ModeMotion) -> tuple[Named, Named, Named]:
    """θ0, φ0 (from the line of centres) and χ0 of a planar 4R mode (Bagci's plane case)."""
    c = mode.joint_centres
    crank = c[:, 1] - c[:, 0]
    rocker = c[:, 2] - c[:, 3]
    th = np.arctan2(crank[:, 1], crank[:, 0])
    ph = np.arctan2(rocker[:, 1], rocker[:, 0])
    ok = mode.assembles
    th, ph = unwrap_runs(th, ok), unwrap_runs(ph, ok)
    w = mode.link_angular_velocity
    a = mode.link_angular_acceleration
    # Bagci's χ0 of the plane case is the coupler–rocker joint angle turned by π, in (−π, π]
    rocker_pin = next(j.name for j in linkage.joints[2:3])
    chi = wrap_angle(mode.variables[f"{rocker_pin}.theta"] + np.pi)
    return ({"theta0": th, "phi0": ph, "chi0": chi},
            {"theta0": w[:, 0, 2], "phi0": w[:, 2, 2],
             "chi0": mode.velocities[f"{rocker_pin}.theta"]},
            {"theta0": a[:, 0, 2], "phi0": a[:, 2, 2],
             "chi0": mode.accelerations[f"{rocker_pin}.theta"]})


def cssp_names(linkage: Linkage, mode: ModeMotion) -> tuple[Named, Named, Named]:
    """θ1, s4, θ2, η2, θ3, η3 of a CSSP mode (Rahman 1996 §1.2) from its rod direction u and
    its rates: the rod's azimuth θ1 + θ2 and elevation −η2 in the crank frame, and u's elevation
    θ3 and azimuth η3 in the slider frame X(α4)·u (reference SPEC §1.1)."""
    a2 = linkage.parameters["a2"]
    c = mode.joint_centres
    # in the loop frame {1} (world → loop: x ↦ baseᵀ x, by rows x @ base), where Rahman's
    # angles are defined (the closed form's, cssp.rod_and_slider_angles)
    base = np.asarray(linkage.base.real, dtype=float)
    u = (c[:, 2] - c[:, 1]) @ base / a2
    w = mode.link_angular_velocity[:, 1] @ base
    al = mode.link_angular_acceleration[:, 1] @ base
    ud = np.cross(w, u)
    udd = np.cross(al, u) + np.cross(w, ud)
    crank = linkage.joints[0].name
    slider = linkage.joints[-1].name
    th1 = mode.variables[f"{crank}.theta"]
    th1d = mode.velocities[f"{crank}.theta"]
    th1dd = mode.accelerations[f"{crank}.theta"]
    _, elev, e_d, e_dd, psi, psi_d, psi_dd = elevation_azimuth(u, ud, udd)
    psi = unwrap_runs(psi, mode.assembles & np.isfinite(psi))
    to_slider = rot_x(linkage.parameters["alpha4"])  # X(α4)
    _, th3, th3_d, th3_dd, eta3, eta3_d, eta3_dd = elevation_azimuth(
        u @ to_slider.T, ud @ to_slider.T, udd @ to_slider.T)
    eta3 = unwrap_runs(eta3, mode.assembles & np.isfinite(eta3))
    return ({"theta1": th1, "s4": mode.variables[f"{slider}.s"], "theta2": psi - th1,
             "eta2": -elev, "theta3": th3, "eta3": eta3},
            {"theta1": th1d, "s4": mode.velocities[f"{slider}.s"], "theta2": psi_d - th1d,
             "eta2": -e_d, "theta3": th3_d, "eta3": eta3_d},
            {"theta1": th1dd, "s4": mode.accelerations[f"{slider}.s"], "theta2": psi_dd - th1dd,
             "eta2": -e_dd, "theta3": th3_dd, "eta3": eta3_dd})

"""The seeds' variable names read off any :class:`~screwkit.kinematics.motion.ModeMotion` (the
generic solver's included); the family registry maps each family to its function.

RSRC (Bagci 1969 §3.1): θ0, φ0, S, χ0. CSSP (Rahman 1996 §1.2): θ1, s4, θ2, η2 with the rod
direction u = (cη2 c(θ1+θ2), cη2 s(θ1+θ2), −sη2). Planar 4R (Bagci's special case): θ0 and φ0
measured from the line of centres. RSSR: θ0 and φ0 as for the RSRC.
"""

from __future__ import annotations

import numpy as np

from screwkit.kinematics.loop import Array
from screwkit.kinematics.motion import ModeMotion
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
    th[ok] = np.unwrap(th[ok])
    ph[ok] = np.unwrap(ph[ok])
    w = mode.link_angular_velocity
    a = mode.link_angular_acceleration
    # Bagci's χ0 of the plane case is the coupler–rocker joint angle turned by π, in (−π, π]
    rocker_pin = next(j.name for j in linkage.joints[2:3])
    chi = np.pi - np.mod(np.pi - (mode.variables[f"{rocker_pin}.theta"] + np.pi), 2 * np.pi)
    return ({"theta0": th, "phi0": ph, "chi0": chi},
            {"theta0": w[:, 0, 2], "phi0": w[:, 2, 2],
             "chi0": mode.velocities[f"{rocker_pin}.theta"]},
            {"theta0": a[:, 0, 2], "phi0": a[:, 2, 2],
             "chi0": mode.accelerations[f"{rocker_pin}.theta"]})


def cssp_names(linkage: Linkage, mode: ModeMotion) -> tuple[Named, Named, Named]:
    """θ1, s4, θ2, η2 of a CSSP mode (Rahman 1996 §1.2) from its rod direction and rates."""
    a2 = linkage.parameters["a2"]
    c = mode.joint_centres
    u = (c[:, 2] - c[:, 1]) / a2
    w = mode.link_angular_velocity[:, 1]
    al = mode.link_angular_acceleration[:, 1]
    ud = np.cross(w, u)
    udd = np.cross(al, u) + np.cross(w, ud)
    th1 = mode.variables["crank.theta"]
    th1d = mode.velocities["crank.theta"]
    th1dd = mode.accelerations["crank.theta"]
    r2 = u[:, 0] ** 2 + u[:, 1] ** 2
    cross_xy = u[:, 0] * ud[:, 1] - u[:, 1] * ud[:, 0]
    psi = np.arctan2(u[:, 1], u[:, 0])
    ok = mode.assembles
    psi[ok] = np.unwrap(psi[ok])
    psid = cross_xy / r2
    psidd = (u[:, 0] * udd[:, 1] - u[:, 1] * udd[:, 0]) / r2 - 2 * cross_xy * (
        u[:, 0] * ud[:, 0] + u[:, 1] * ud[:, 1]) / r2**2
    wz = -u[:, 2]
    root = np.sqrt(1 - wz**2)
    eta = np.arcsin(wz)
    etad = -ud[:, 2] / root
    etadd = -udd[:, 2] / root + wz * (ud[:, 2] ** 2) / root**3
    s4 = mode.variables["slider.s"]
    return ({"theta1": th1, "s4": s4, "theta2": psi - th1, "eta2": eta},
            {"theta1": th1d, "s4": mode.velocities["slider.s"], "theta2": psid - th1d, "eta2": etad},
            {"theta1": th1dd, "s4": mode.accelerations["slider.s"], "theta2": psidd - th1dd,
             "eta2": etadd})

"""The seeds' variable names read off a general :class:`~screwkit.kinematics.motion.ModeMotion`.

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


def seed_variables(linkage: Linkage, mode: ModeMotion) -> tuple[Named, Named, Named]:
    """(variables, velocities, accelerations) under the seed's names for the linkage's family;
    empty dicts for a general loop."""
    fam = linkage.family
    if fam == "RSRC":
        return (rsrc_seed_variables(mode.variables), rsrc_seed_variables(mode.velocities),
                rsrc_seed_variables(mode.accelerations))
    if fam == "RSSR":
        def pick(d: dict[str, Array]) -> Named:
            return {"theta0": d["input.theta"], "phi0": -d["output.theta"]}
        return pick(mode.variables), pick(mode.velocities), pick(mode.accelerations)
    if fam == "4R":
        return _fourbar(mode)
    if fam == "CSSP":
        return _cssp(linkage, mode)
    return {}, {}, {}


def _fourbar(mode: ModeMotion) -> tuple[Named, Named, Named]:
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
    return ({"theta0": th, "phi0": ph},
            {"theta0": w[:, 0, 2], "phi0": w[:, 2, 2]},
            {"theta0": a[:, 0, 2], "phi0": a[:, 2, 2]})


def _cssp(linkage: Linkage, mode: ModeMotion) -> tuple[Named, Named, Named]:
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

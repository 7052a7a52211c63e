"""Cross-check of screwkit's graph inverse dynamics against Pinocchio (BSD-2, someone else's rigid
body library) on the Stewart–Gough platform driven by its pose
(examples/mechanisms/stewart_platform_pose.toml): the six leg forces over the platform's
trajectory, with gravity.

The Pinocchio model is built here from the spec's joints and mass properties alone: six legs as
kinematic chains from the ground — a revolute about the U joint's first axis, a revolute about
its second axis (both at the U centre), a prismatic along the leg's slide — and the platform as
a free-flyer; the six ball joints are the cut, closed by 3-D point constraints (the ball centre
carried by the piston = the ball centre carried by the platform). Every body frame of the model
is world-aligned at the drawing, so a body's inertia in world axes and its centre of mass minus
its joint's placement are its Pinocchio inertia.

At every sample, the legs' joint angles, slide, rates and accelerations are screwkit's
(``md.variables``/``velocities``/``accelerations``) and the platform's configuration, twist and
acceleration are screwkit's body frame expressed as Pinocchio's free-flyer (local) quantities.
Pinocchio's forward kinematics must carry every body where screwkit does and close every ball
(a check of the mapping). The loads: τ = RNEA(q, v, a) − Jcᵀλ, with λ (18) the ball forces
found from the 18 unactuated rows (12 U angles, the platform's 6 freedoms) being zero; the
prismatic rows of τ are the leg forces, which must equal screwkit's ``efforts``
(``graph_inverse_dynamics``) to 1e-9 relative.

Run: ``python validation/pinocchio/stewart.py`` (needs ``pip install pin``, the ``[validate]``
extra); prints the report and exits non-zero if a check fails.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "examples" / "mechanisms" / "stewart_platform_pose.toml"
TOLERANCE = 1e-9  # leg forces, relative to the largest
POSE_TOLERANCE = 1e-12  # body poses and ball gaps, relative to the length scale
#: the spec's trajectory (constant drive rates), and the same poses and rates with drive
#: accelerations (m/s², rad/s²; x, y, z, roll, pitch, yaw) so every inertial term is loaded
RUNS = (("the spec's motion", None),
        ("with drive accelerations", np.array([0.3, -0.2, 0.5, 1.5, -1.0, 0.8])))


@dataclass
class PinStewart:
    """The Pinocchio model, its data and per leg: (U first, U second, P) joint ids and velocity
    indices, the piston frame id and the platform's ball frame id."""

    model: Any
    data: Any
    legs: list[dict[str, Any]]
    platform: int


def build(mech: Any, gravity: np.ndarray) -> PinStewart:
    """The Pinocchio model of a six-leg U–P–S platform graph (module docstring)."""
    import pinocchio as pin

    model = pin.Model()
    model.gravity = pin.Motion(np.asarray(gravity, float), np.zeros(3))
    bodies = {b.name: b for b in mech.bodies}

    def inertia(body: str, origin: np.ndarray) -> Any:
        mp = bodies[body].mass
        return pin.Inertia(mp.mass, np.asarray(mp.com) - origin, np.asarray(mp.inertia))

    ff = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "platform")
    model.appendBodyToJoint(ff, inertia("platform", np.zeros(3)), pin.SE3.Identity())
    joints = {j.name: j for j in mech.joints}
    legs = []
    for k in range(1, 7):
        U, P, S = joints[f"U{k}"], joints[f"P{k}"], joints[f"S{k}"]
        cyl, piston = P.bodies
        assert U.bodies == ("ground", cyl) and S.bodies == (piston, "platform")
        assert U.kind == "U" and P.kind == "P" and S.kind == "S" and P.seat_offset is None
        c = np.asarray(U.at, float)
        j1 = model.addJoint(0, pin.JointModelRevoluteUnaligned(np.asarray(U.axis, float)),
                            pin.SE3(np.eye(3), c), f"U{k}a")
        j2 = model.addJoint(j1, pin.JointModelRevoluteUnaligned(np.asarray(U.axis2, float)),
                            pin.SE3.Identity(), f"U{k}b")
        model.appendBodyToJoint(j2, inertia(cyl, c), pin.SE3.Identity())
        j3 = model.addJoint(j2, pin.JointModelPrismaticUnaligned(np.asarray(P.axis, float)),
                            pin.SE3.Identity(), f"P{k}")
        model.appendBodyToJoint(j3, inertia(piston, c), pin.SE3.Identity())
        ball = np.asarray(S.at, float)
        fp = model.addFrame(pin.Frame(f"S{k} piston", j3, pin.SE3(np.eye(3), ball - c),
                                      pin.FrameType.OP_FRAME))
        fq = model.addFrame(pin.Frame(f"S{k} platform", ff, pin.SE3(np.eye(3), ball),
                                      pin.FrameType.OP_FRAME))
        legs.append({"names": (f"U{k}.theta1", f"U{k}.theta2", f"P{k}.s"),
                     "joints": (j1, j2, j3), "bodies": (cyl, piston),
                     "frames": (fp, fq)})
    return PinStewart(model, model.createData(), legs, ff)


def state(pm: PinStewart, mech: Any, md: Any, n: int) -> tuple[np.ndarray, ...]:
    """Pinocchio's q, v, a at sample ``n`` of screwkit's mode ``md``."""
    from scipy.spatial.transform import Rotation

    model = pm.model
    q, v, a = np.zeros(model.nq), np.zeros(model.nv), np.zeros(model.nv)
    b = mech.body_names.index("platform")
    R, p = md.link_rotation[n, b], md.link_origin[n, b]
    w, vo = md.link_angular_velocity[n, b], md.link_origin_velocity[n, b]
    al, ao = md.link_angular_acceleration[n, b], md.link_origin_acceleration[n, b]
    iq, iv = model.idx_qs[pm.platform], model.idx_vs[pm.platform]
    q[iq:iq + 3], q[iq + 3:iq + 7] = p, Rotation.from_matrix(R).as_quat()  # x y z w
    wl, vl = R.T @ w, R.T @ vo
    v[iv:iv + 3], v[iv + 3:iv + 6] = vl, wl
    a[iv:iv + 3], a[iv + 3:iv + 6] = R.T @ ao - np.cross(wl, vl), R.T @ al
    for leg in pm.legs:
        for name, j in zip(leg["names"], leg["joints"], strict=True):
            q[model.idx_qs[j]] = md.variables[name][n]
            v[model.idx_vs[j]] = md.velocities[name][n]
            a[model.idx_vs[j]] = md.accelerations[name][n]
    return q, v, a


def leg_forces(pm: PinStewart, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """The six prismatic forces (module docstring: RNEA and the ball constraints' forces)."""
    import pinocchio as pin

    model, data = pm.model, pm.data
    tau = pin.rnea(model, data, q, v, a)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J = np.vstack([pin.getFrameJacobian(model, data, fp, pin.LOCAL_WORLD_ALIGNED)[:3]
                   - pin.getFrameJacobian(model, data, fq, pin.LOCAL_WORLD_ALIGNED)[:3]
                   for fp, fq in (leg["frames"] for leg in pm.legs)])
    slides = [model.idx_vs[leg["joints"][2]] for leg in pm.legs]
    free = [i for i in range(model.nv) if i not in slides]
    lam = np.linalg.solve(J[:, free].T, tau[free])
    return np.asarray(tau[slides] - J[:, slides].T @ lam)


def pose_gap(pm: PinStewart, mech: Any, md: Any, n: int, q: np.ndarray) -> float:
    """Largest difference (m) between Pinocchio's and screwkit's body frames at sample ``n``
    (rotations scaled by the length scale), and the largest ball gap."""
    import pinocchio as pin

    model, data = pm.model, pm.data
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    L = mech.length_scale
    gap = 0.0
    names = mech.body_names
    for leg in pm.legs:
        for body, j in zip(leg["bodies"], leg["joints"][1:], strict=True):
            k = names.index(body)
            M = data.oMi[j]
            R, p = md.link_rotation[n, k], md.link_origin[n, k]
            origin = M.translation - M.rotation @ model.jointPlacements[leg["joints"][0]].translation
            gap = max(gap, np.abs(M.rotation - R).max() * L, np.abs(origin - p).max())
        fp, fq = leg["frames"]
        gap = max(gap, np.abs(data.oMf[fp].translation - data.oMf[fq].translation).max())
    k = names.index("platform")
    M = data.oMi[pm.platform]
    gap = max(gap, np.abs(M.rotation - md.link_rotation[n, k]).max() * L,
              np.abs(M.translation - md.link_origin[n, k]).max())
    return float(gap)


def compare(spec: Any, accelerations: Any = None) -> dict[str, float]:
    """screwkit's and Pinocchio's leg forces over the spec's trajectory (with the drives'
    ``accelerations``, default the spec's): the largest relative difference of the forces,
    the largest pose/ball gap relative to the length scale."""
    from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
    from screwkit.kinematics.graph import solve_mechanism

    mech = spec.mechanism
    motion = solve_mechanism(mech, spec.inputs, rates=spec.speed,
                             accelerations=spec.acceleration if accelerations is None
                             else accelerations)
    md = motion.modes[0]
    dyn = graph_inverse_dynamics(motion, gravity=spec.gravity_vector)
    assert dyn.input_names == tuple(f"P{k}.s" for k in range(1, 7))
    pm = build(mech, spec.gravity_vector)
    forces, gap = np.full_like(dyn.efforts, np.nan), 0.0
    for n in np.nonzero(dyn.ok)[0]:
        q, v, a = state(pm, mech, md, int(n))
        gap = max(gap, pose_gap(pm, mech, md, int(n), q))
        forces[n] = leg_forces(pm, q, v, a)
    ok = dyn.ok
    scale = np.abs(dyn.efforts[ok]).max()
    return {"samples": float(ok.sum()),
            "leg force": float(np.abs(forces[ok] - dyn.efforts[ok]).max() / scale),
            "largest leg force (N)": float(scale),
            "pose": gap / mech.length_scale}


def main() -> int:
    import pinocchio as pin

    import screwkit as sk

    spec = sk.load_spec(SPEC)
    print("# screwkit against Pinocchio: Stewart platform leg forces\n")
    print(f"Pinocchio {pin.__version__}; {SPEC.relative_to(ROOT)}, gravity on.\n")
    print("The Pinocchio model is built from the spec alone: per leg a revolute about each U "
          "axis and a prismatic along the slide, the platform a free-flyer, the six balls "
          "closed by 3-D point constraints. At every sample it takes screwkit's leg angles, "
          "slides and their rates and accelerations and the platform's frame, twist and "
          "acceleration; its forward kinematics must put every body where screwkit does and "
          "close every ball. Leg forces: tau = RNEA(q, v, a) - Jc^T lambda with lambda from "
          "the 18 unactuated rows (U angles, platform freedoms) being zero; against "
          "screwkit's graph_inverse_dynamics efforts.\n")
    print("| motion | samples | body frames and balls: largest gap / length scale | leg "
          "forces: largest difference / largest force |\n|---|---|---|---|")
    good = True
    for label, acc in RUNS:
        r = compare(spec, acc)
        good = good and r["leg force"] <= TOLERANCE and r["pose"] <= POSE_TOLERANCE
        print(f"| {label} | {int(r['samples'])} | {r['pose']:.2e} | {r['leg force']:.2e} "
              f"(of {r['largest leg force (N)']:.4g} N) |")
    print(f"\nTolerances: {POSE_TOLERANCE:g} (poses), {TOLERANCE:g} (forces). "
          f"{'PASS' if good else 'FAIL'}")
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main())

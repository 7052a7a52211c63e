"""Cross-check of screwkit's forward dynamics of mechanism graphs against MuJoCo.

For the Watt six-bar (under gravity; with a constant motor torque on the crank; with viscous
friction in its tree joints) and the double-wishbone suspension (under gravity, released from rest in the drawing):

1. ``screwkit export-mjcf`` writes the graph as a MuJoCo model: the spanning tree as the body
   tree, the loops closed by ``connect`` constraints at the chord joints
   (:mod:`screwkit.simulation.graph_mjcf`).
2. MuJoCo integrates it (RK4) from the drawing at rest, with the motor's torque as the input
   actuator's control; screwkit integrates its reduced equations of motion
   (:mod:`screwkit.simulation.graph_eom`, closed by the graph Newton at every evaluation).
3. The input angle is compared at equal times. MuJoCo's own accuracy is measured and stated:
   its constraint accuracy (the largest equality-constraint violation ``efc_pos`` over the run,
   in metres and divided by the mechanism's length scale) and its time-step error (the change
   of its answer when the step is halved). The check: screwkit's angle and MuJoCo's at half
   the step differ by at most twice that step error plus :data:`FLOOR`, and the difference
   shrinks with MuJoCo's step (MuJoCo converges onto screwkit's answer).

Run: ``python validation/mujoco/graph_crosscheck.py`` (needs ``pip install
'screwkit[validate]'``); prints the report (validation/mujoco/graph_crosscheck.md) and exits
non-zero if a check fails.
"""

from __future__ import annotations

import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "src"))

import mujoco  # noqa: E402

from screwkit.io.drive_table import JointFriction, MotorConfig  # noqa: E402
from screwkit.io.mechanism_spec import GraphSpec, graph_spec_from_data  # noqa: E402
from screwkit.simulation.graph_eom import GraphEquationOfMotion  # noqa: E402
from screwkit.simulation.graph_mjcf import graph_mjcf_layout, graph_mjcf_model  # noqa: E402
from screwkit.simulation.graph_run import simulate_graph  # noqa: E402

#: MuJoCo's time step (s) and the equality constraints' time constant in steps
TIMESTEP = 1e-5
SOLREF_STEPS = 20.0
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
#: the check: screwkit's input angle and MuJoCo's at half the step differ by at most twice
#: MuJoCo's own step error (its angle at the step minus at half the step, measured) plus
#: FLOOR (rad), round-off and the screwkit integrator's tolerance
FLOOR = 1e-8
#: (example, motor torque on the first input in N·m, duration in s, viscous friction in every
#: tree R joint in N·m·s/rad — MuJoCo's joint damping; a cut joint cannot be damped there)
CASES = (("watt_sixbar", 0.0, 0.3, 0.0), ("watt_sixbar", 0.05, 0.2, 0.0),
         ("watt_sixbar", 0.0, 0.3, 1e-3), ("double_wishbone", 0.0, 0.2, 0.0))
SAMPLES = 21  # sample spacing a whole number of MuJoCo (half) steps


def load(name: str) -> GraphSpec:
    path = ROOT / "examples" / "mechanisms" / f"{name}.toml"
    with path.open("rb") as f:
        return graph_spec_from_data(tomllib.load(f), path)


@dataclass
class MujocoRun:
    angle: np.ndarray
    violation: float  # largest |efc_pos| of the equality rows (m)


def friction_for(spec: GraphSpec, c: float) -> tuple[JointFriction, ...]:
    """Viscous friction ``c`` in every R joint of the spanning tree (not at a cut)."""
    mech = spec.mechanism
    cut = {mech.joints[k].name for k in mech.topology.chords}
    return tuple(JointFriction(j.name, c) for j in mech.joints
                 if c and j.kind == "R" and j.name not in cut)


def mujoco_run(spec: GraphSpec, torque: float, duration: float, dt: float,
               friction: tuple[JointFriction, ...] = ()) -> MujocoRun:
    mech = spec.mechanism
    xml = graph_mjcf_model(mech, gravity=spec.gravity_vector, timestep=dt,
                           solref=(SOLREF_STEPS * dt, 1.0), solimp=SOLIMP, friction=friction)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT,
                            graph_mjcf_layout(mech).dofs[mech.inputs[0]])
    adr = int(m.jnt_qposadr[jid])
    d.ctrl[0] = torque
    times = np.linspace(0.0, duration, SAMPLES)
    steps = np.rint(times / dt).astype(int)
    assert np.allclose(steps * dt, times, rtol=0, atol=1e-12), "sample times off the steps"
    angle, violation, k = [], 0.0, 0
    for target in steps:
        while k < target:
            mujoco.mj_step(m, d)
            k += 1
            eq = d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
            violation = max(violation, float(np.max(np.abs(d.efc_pos[: d.nefc][eq]),
                                                    initial=0.0)))
        angle.append(float(d.qpos[adr]))
    return MujocoRun(np.array(angle), violation)


def screwkit_run(spec: GraphSpec, torque: float, duration: float,
                 friction: tuple[JointFriction, ...] = ()) -> tuple[np.ndarray, float, float]:
    mech = spec.mechanism
    motors = [MotorConfig("constant", torque=torque) if torque else MotorConfig()]
    motors += [MotorConfig()] * (len(mech.inputs) - 1)
    eom = GraphEquationOfMotion(mech, motors=motors, gravity=spec.gravity_vector,
                                friction=friction)
    run = simulate_graph(eom, duration=duration, samples=SAMPLES, rtol=1e-10)
    assert run.status == "completed", run.message
    return run.inputs[:, 0], run.energy_error, float(np.max(run.closure_residual))


def check(name: str, torque: float, duration: float, c: float = 0.0) -> dict[str, float]:
    spec = load(name)
    friction = friction_for(spec, c)
    sk_angle, energy, closure = screwkit_run(spec, torque, duration, friction)
    coarse = mujoco_run(spec, torque, duration, TIMESTEP, friction)
    fine = mujoco_run(spec, torque, duration, TIMESTEP / 2, friction)
    return {"difference": float(np.max(np.abs(coarse.angle - sk_angle))),
            "MuJoCo step error": float(np.max(np.abs(coarse.angle - fine.angle))),
            "difference (half step)": float(np.max(np.abs(fine.angle - sk_angle))),
            "violation": coarse.violation,
            "violation / L": coarse.violation / spec.mechanism.length_scale,
            "travel": float(np.ptp(sk_angle)), "energy error": energy, "closure": closure}


EXPLANATION = [
    "How to read this: both engines start from the drawing at rest. MuJoCo closes the loops "
    "with soft equality constraints (time constant 20 steps), so its configuration is off the "
    "constraint manifold by the violation shown, and its RK4 step adds its own error; screwkit "
    "closes every loop by Newton's method to 1e-13 at every evaluation and integrates with "
    "DOP853 at rtol 1e-10 (its energy balance error and closure residual are shown). The "
    "difference falls with MuJoCo's step (the half-step column): MuJoCo converges onto "
    "screwkit's answer, and what remains is MuJoCo's discretisation, not a modelling "
    "difference.", ""]


def main() -> int:
    failed: list[str] = []
    lines = ["# MuJoCo cross-check of mechanism graphs (regenerate: "
             "`python validation/mujoco/graph_crosscheck.py`)", "",
             f"MuJoCo {mujoco.__version__}; RK4, timestep {TIMESTEP:g} s (and half); equality "
             f"constraints solref = ({SOLREF_STEPS:g}·timestep, 1), solimp = {SOLIMP}; gravity "
             "as the spec (9.80665 m/s²); input angle compared at "
             f"{SAMPLES} equal times.", "",
             "| example | motor torque (N·m) | friction (N·m·s/rad) | duration (s) | input travel (rad) | max |Δθ| "
             "(rad) | max |Δθ|, half step | MuJoCo constraint violation (m) | violation / L | "
             "screwkit energy error | screwkit closure | bound: 2 × MuJoCo step error + "
             f"{FLOOR:g} |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, torque, duration, c in CASES:
        r = check(name, torque, duration, c)
        bound = 2.0 * r["MuJoCo step error"] + FLOOR
        ok = (r["difference (half step)"] <= bound
              and r["difference (half step)"] <= r["difference"] + FLOOR)
        if not ok:
            failed.append(f"{name} (torque {torque}): |Δθ| {r['difference']:.3g}, half step "
                          f"{r['difference (half step)']:.3g}")
        lines.append(f"| {name} | {torque:g} | {c:g} | {duration:g} | {r['travel']:.4g} | "
                     f"{r['difference']:.2e} | {r['difference (half step)']:.2e} | "
                     f"{r['violation']:.2e} | {r['violation / L']:.2e} | "
                     f"{r['energy error']:.1e} | {r['closure']:.1e} | {bound:.2e}"
                     f"{'' if ok else ' FAILED'} |")
    lines += ["", *EXPLANATION]
    lines += ["All checks passed." if not failed else "FAILED:\n" + "\n".join(failed)]
    print("\n".join(lines))
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())

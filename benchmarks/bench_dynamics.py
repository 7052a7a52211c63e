"""Speed and memory of CSSP inverse dynamics over 10⁶ samples, side by side with Pinocchio's
RNEA (per call) where it is installed.

``run()`` returns a list of measurements ``{name, value, unit, target, note}``;
``python benchmarks/bench_dynamics.py --profile`` also prints where the dynamics spends its time.

Times are CPU time (``time.process_time``), best of ``REPEATS`` — the machines are shared and
their wall time varies with the load (as in bench_fourbar.py). Memory is the tracemalloc peak.

* generic kinematics: ``motion`` (Newton + continuation) on a 72-sample sweep, per sample;
* closed-form kinematics: ``cssp_mode_motion`` on ``SAMPLES`` crank angles — as it is by
  default, without the ball joints' rotation vectors (``joint_rotations=False``) and lean
  (``ball_joints=False``: only what the dynamics reads; its lean pass and the rod's zero-spin
  turn compiled by numba where it is installed, kinematics/closed_forms/cssp_compiled.py);
* dynamics: ``inverse_dynamics`` on that ModeMotion (the CSSP closed-form statics, blocked;
  compiled by numba where it is installed, dynamics/cssp_compiled.py), and
  the chain kinematics + dynamics, the issue's target (≤ 1 µs per sample, ≤ 2 GiB);
* fused: ``cssp_inverse_dynamics`` — the same loads, kinematics and dynamics block by block
  without building the ModeMotion;
* generic statics (``closed_form=False``) on the same motion, and the peak memory of the
  blocked generic path for every family on 10⁶ samples (a 72-sample mode tiled);
* prototype: ``fused_cssp_dynamics`` below, the hand-specialised kernel the library path was
  built from (axisymmetric rod only; not library code), checked against the library first;
* Pinocchio ``rnea`` on a 3-link open chain (R, S, P), per call, if ``pinocchio`` imports: on
  bounded random configurations (its ``randomConfiguration`` gives inf for unbounded revolute
  and prismatic joints), every output checked finite before timing, in a process of its own.
"""

from __future__ import annotations

import cProfile
import io
import math
import pstats
import sys
import time
import tracemalloc
from collections.abc import Callable
from typing import Any

import numpy as np

from screwkit.constants import STANDARD_GRAVITY

SAMPLES = 1_000_000
REPEATS = 3
BLOCK = 16_384  # samples per block of the prototype kernel
INCH = 0.0254
GRAVITY = [0.0, 0.0, -STANDARD_GRAVITY]


def _best_time(fn: Callable[[], Any], repeats: int = REPEATS) -> float:
    """Best CPU time (process_time) of ``repeats`` calls, in seconds."""
    best = math.inf
    for _ in range(repeats):
        start = time.process_time()
        fn()
        best = min(best, time.process_time() - start)
    return best


def _peak_mib(fn: Callable[[], Any]) -> float:
    """tracemalloc peak of one call, MiB (numpy reports its allocations to tracemalloc)."""
    tracemalloc.start()
    fn()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2**20


def _cssp() -> tuple[Any, float]:
    """Rahman's example (SPEC §5) in SI, with gravity along −z1 in the timed runs."""
    from screwkit.model.families import cssp
    from screwkit.model.linkage import Link
    from screwkit.model.mass import MassProperties

    lk = cssp(2 * INCH, 8 * INCH, 1 * INCH, np.radians(250.0), 0.4 * INCH)
    lk = lk.with_links([
        Link("crank", MassProperties(0.861, [0.0254, 0.002, -0.001],
                                     np.diag([2.3e-5, 1.97e-4, 1.97e-4]))),
        Link("rod", MassProperties(3.44, [0.1016, 0.0, 0.0], np.diag([9.3e-5, 1.19e-2, 1.19e-2]))),
        Link("slider", MassProperties(2.72, [0.001, 0.0, 0.002], np.diag([4.8e-4, 4.8e-4, 8.8e-4]))),
    ])
    return lk, 314.159


# ---------------------------------------------------------------------------------------------
# prototype: fused structure-of-arrays CSSP inverse dynamics
# ---------------------------------------------------------------------------------------------
def _cross(a: tuple, b: tuple) -> tuple:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _fused_block(p: dict[str, Any], th: np.ndarray, w: float, wd: float,
                 out: dict[str, np.ndarray], sl: slice) -> None:
    a1, a2, a4, s1 = p["a1"], p["a2"], p["a4"], p["s1"]
    sa, ca = p["sa"], p["ca"]
    g = p["gravity"]
    c, s = np.cos(th), np.sin(th)
    # closed-form kinematics (SPEC §1.2), mode +1
    b = a1 * sa * s + s1 * ca
    cq = 2 * a1 * a4 * c + p["c0"]
    root = np.sqrt(b * b - cq)
    s4 = np.where(b > 0, cq / (-b - root), root - b)
    bd = a1 * sa * c * w
    bdd = a1 * sa * (c * wd - s * w * w)
    cd = -2 * a1 * a4 * s * w
    cdd = -2 * a1 * a4 * (c * w * w + s * wd)
    s4d = -(bd * s4 + 0.5 * cd) / root
    s4dd = -(s4d * s4d + 2 * bd * s4d + bdd * s4 + 0.5 * cdd) / root
    pin = (a1 * c, a1 * s, s1)
    pin_a = (-a1 * (c * w * w + s * wd), a1 * (c * wd - s * w * w), 0.0)
    ball = (-a4, -s4 * sa, -s4 * ca)
    u = tuple((ball[k] - pin[k]) / a2 for k in range(3))
    udd = ((-pin_a[0]) / a2, (-s4dd * sa - pin_a[1]) / a2, -s4dd * ca / a2)
    ball_a = (0.0, -s4dd * sa, -s4dd * ca)
    al_rod = _cross(u, udd)
    # crank: CoM ρ = Rz(θ) c1 about the axis point (0, 0, s1)
    m1, (c1x, c1y, c1z) = p["m1"], p["c1"]
    rho = (c * c1x - s * c1y, s * c1x + c * c1y)
    r1 = (rho[0], rho[1], s1 + c1z)
    a1c = (-wd * rho[1] - w * w * rho[0], wd * rho[0] - w * w * rho[1], 0.0)
    F1 = tuple(m1 * (g[k] - a1c[k]) for k in range(3))
    ixz, iyz, izz = p["I1_col3"]
    iw = (c * ixz - s * iyz, s * ixz + c * iyz, izz)  # R I R^T e_z
    M1 = (-(wd * iw[0]) + w * w * iw[1], -(wd * iw[1]) - w * w * iw[0], -wd * izz)
    M1 = tuple(M1[k] + _cross(r1, F1)[k] for k in range(3))  # about O
    # rod: CoM on the axis at cx from the pin, axisymmetric (I_t transverse), zero spin:
    # its moment about the CoM is −I_t α (ω × I ω = 0 and α ⟂ u), so ω_rod is not needed
    m2, cx, it = p["m2"], p["rod_cx"], p["rod_it"]
    r2 = tuple(pin[k] + cx * u[k] for k in range(3))
    F2 = tuple(m2 * (g[k] - pin_a[k] - cx * udd[k]) for k in range(3))
    cr2 = _cross(r2, F2)
    M2 = tuple(-it * al_rod[k] + cr2[k] for k in range(3))
    # slider: translates with the ball; CoM offset d3 = R_slider c3 (constant)
    m3, d3 = p["m3"], p["slider_offset"]
    F3 = tuple(m3 * (g[k] - ball_a[k]) for k in range(3))
    r3 = tuple(ball[k] + d3[k] for k in range(3))
    M3 = _cross(r3, F3)
    for k in range(3):
        out["shaking_force"][sl, k] = F1[k] + F2[k] + F3[k]
        out["shaking_moment"][sl, k] = M1[k] + M2[k] + M3[k]
    # statics: rod moment about the pin gives u × f_b = m, the P joint takes no force along k4
    cp = _cross(pin, F2)
    m = tuple((M2[k] - cp[k]) / a2 for k in range(3))
    mxu = _cross(m, u)
    k4u = sa * u[1] + ca * u[2]
    lam = -(sa * (mxu[1] + F3[1]) + ca * (mxu[2] + F3[2])) / k4u
    fb = tuple(lam * u[k] + mxu[k] for k in range(3))  # rod on slider, at the ball
    fp = tuple(fb[k] - F2[k] for k in range(3))  # crank on rod, at the pin
    fc = tuple(fp[k] - F1[k] for k in range(3))  # ground on crank
    pfp = _cross(pin, fp)
    mc_o = tuple(pfp[k] - M1[k] for k in range(3))
    m3c = _cross(d3, F3)  # slider on ground, about the ball, negated below
    for k in range(3):
        out["crank.force"][sl, k] = fc[k]
        out["pin.force"][sl, k] = fp[k]
        out["ball.force"][sl, k] = fb[k]
        out["slider.force"][sl, k] = -(fb[k] + F3[k])
        out["slider.moment"][sl, k] = -m3c[k]
    # about the crank joint centre (0, 0, s1): m_c = m_O − (0, 0, s1) × f
    out["crank.moment"][sl, 0] = mc_o[0] + s1 * fc[1]
    out["crank.moment"][sl, 1] = mc_o[1] - s1 * fc[0]
    out["crank.moment"][sl, 2] = mc_o[2]
    out["input_torque"][sl] = mc_o[2]


def fused_cssp_dynamics(linkage: Any, theta: np.ndarray, omega: float, omega_dot: float = 0.0,
                        gravity: Any = (0.0, 0.0, 0.0)) -> dict[str, np.ndarray]:
    """Prototype: shaking force and moment (about O), the four joint reactions (on the distal
    link, moment about the joint centre; ball joints carry no moment) and the input torque of
    a CSSP from its closed form, in structure-of-arrays blocks. Needs an axisymmetric rod
    (CoM on its axis, Iyy = Izz) — the case where the zero-spin rule leaves no idle load."""
    lp = linkage.parameters
    crank, rod, slider = (link.mass for link in linkage.links)
    if not (np.allclose(rod.com[1:], 0.0) and np.isclose(rod.inertia[1, 1], rod.inertia[2, 2])
            and np.allclose(rod.inertia - np.diag(np.diag(rod.inertia)), 0.0)):
        raise ValueError("fused_cssp_dynamics needs an axisymmetric rod (CoM on x, Iyy = Izz)")
    alpha4 = lp["alpha4"]
    ca, sa = np.cos(alpha4), np.sin(alpha4)
    slider_R = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(-(alpha4 + np.pi / 2)),
                                           -np.sin(-(alpha4 + np.pi / 2))],
                         [0.0, np.sin(-(alpha4 + np.pi / 2)), np.cos(-(alpha4 + np.pi / 2))]])
    p = {
        "a1": lp["a1"], "a2": lp["a2"], "a4": lp["a4"], "s1": lp["s1"], "sa": sa, "ca": ca,
        "c0": lp["a4"] ** 2 + lp["a1"] ** 2 + lp["s1"] ** 2 - lp["a2"] ** 2,
        "gravity": tuple(float(x) for x in gravity),
        "m1": crank.mass, "c1": tuple(crank.com), "I1_col3": tuple(crank.inertia[:, 2]),
        "m2": rod.mass, "rod_cx": rod.com[0], "rod_it": rod.inertia[1, 1],
        "m3": slider.mass, "slider_offset": tuple(slider_R @ slider.com),
    }
    n = theta.shape[0]
    out: dict[str, np.ndarray] = {k: np.empty((n, 3)) for k in ("shaking_force", "shaking_moment", "crank.force",
                                         "crank.moment", "pin.force", "ball.force",
                                         "slider.force", "slider.moment")}
    out["input_torque"] = np.empty(n)
    for start in range(0, n, BLOCK):
        sl = slice(start, min(start + BLOCK, n))
        _fused_block(p, theta[sl], omega, omega_dot, out, sl)
    return out


def _check_fused(lk: Any, omega: float, gravity: list[float]) -> float:
    """Largest difference of the prototype from the library, relative to the peak load."""
    from screwkit.dynamics import inverse_dynamics
    from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion

    theta = np.linspace(0.0, 2 * np.pi, 20_000, endpoint=False)
    ref = inverse_dynamics(lk, cssp_mode_motion(lk, theta, omega, 0.0), gravity=gravity)
    got = fused_cssp_dynamics(lk, theta, omega, 0.0, gravity)
    forces = [(got["shaking_force"], ref.shaking_force)]
    moments = [(got["shaking_moment"], ref.shaking_moment),
               (got["input_torque"], ref.efforts["crank.theta"])]
    for joint in ("crank", "pin", "ball", "slider"):
        forces.append((got[f"{joint}.force"], ref.reactions[joint]["force"]))
        # ball joints carry no moment: the prototype does not store one
        mine: np.ndarray = got.get(f"{joint}.moment",
                                   np.zeros_like(ref.reactions[joint]["moment"]))
        moments.append((mine, ref.reactions[joint]["moment"]))
    worst = 0.0
    for group in (forces, moments):
        scale = max(float(np.abs(b).max()) for _, b in group)
        worst = max(worst, max(float(np.abs(a - b).max()) for a, b in group) / scale)
    return worst


# ---------------------------------------------------------------------------------------------
def _generic_kinematics(lk: Any, omega: float) -> float:
    from screwkit.kinematics.tracker.generic_motion import generic_motion as motion

    base = 72
    theta = np.linspace(0.0, 2 * np.pi, base, endpoint=False)
    return _best_time(lambda: motion(lk, theta, omega, 0.0), 1) / base * 1e6


#: bounds of the random configurations the Pinocchio peer is timed on: its
#: ``randomConfiguration`` draws from the model's position limits, which are ±1.8e308 for the
#: revolute and prismatic joints, so it returned inf for them and rnea was timed on inf
PINOCCHIO_BOUNDS = {"j0 (RZ)": (-np.pi, np.pi), "j2 (PX)": (-0.1, 0.1)}


def pinocchio_peer(n: int = 200_000) -> dict[str, Any]:
    """Pinocchio ``rnea`` on a 3-link open chain (R, S, P), per call, on bounded random
    configurations whose every input and output is checked finite before timing. Run in its
    own process by :func:`_pinocchio` (no other peer's libraries loaded)."""
    name = "pinocchio rnea, 3-link open chain (R, S, P), per call"
    try:
        import pinocchio as pin  # type: ignore[import-not-found]
    except ImportError:
        return {"name": name, "value": None, "unit": "us/sample", "target": None,
                "note": "pin not installed (pip install pin to compare)"}
    model = pin.Model()
    parent = 0
    for k, joint in enumerate([pin.JointModelRZ(), pin.JointModelSpherical(),
                               pin.JointModelPX()]):
        place = pin.SE3(np.eye(3), np.array([0.05 * (k > 0), 0.0, 0.0]))
        parent = model.addJoint(parent, joint, place, f"j{k}")
        model.appendBodyToJoint(parent, pin.Inertia.Random(), pin.SE3.Identity())
    data = model.createData()
    lower = np.array([-np.pi, -1.0, -1.0, -1.0, -1.0, -0.1])  # RZ, quaternion (x y z w), PX
    upper = np.array([np.pi, 1.0, 1.0, 1.0, 1.0, 0.1])
    rng = np.random.default_rng(0)
    qs = [pin.randomConfiguration(model, lower, upper) for _ in range(64)]
    vs = rng.normal(size=(64, model.nv))
    as_ = rng.normal(size=(64, model.nv))
    for q, v, a in zip(qs, vs, as_, strict=True):
        tau = pin.rnea(model, data, q, v, a)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(tau))):
            raise RuntimeError(f"pinocchio peer: non-finite configuration or torque {q}, {tau}")
    q, v, a = qs[0], vs[0], as_[0]

    def calls() -> None:
        for _ in range(n):
            pin.rnea(model, data, q, v, a)

    per = _best_time(calls) / n * 1e6
    return {"name": name, "value": per, "unit": "us/sample", "target": None,
            "note": f"pinocchio {pin.__version__}, one Python call per sample (C++ inside), "
                    f"best of {REPEATS} x {n} calls, bounded random configurations checked "
                    "finite, own process"}


def pinocchio_constraint_peer(n: int = 100_000) -> dict[str, Any]:
    """Pinocchio ``constraintDynamics`` on a CSSP-like closed loop, per call: the crank (RZ)
    and the rod (spherical at the pin) as one chain, the slider (PX) as another, closed by a
    3-D point constraint at the ball; one call per sample from Python (issue 30's yardstick)."""
    name = "pinocchio constraintDynamics, CSSP-like closed loop, per call"
    try:
        import pinocchio as pin
    except ImportError:
        return {"name": name, "value": None, "unit": "us/sample", "target": None,
                "note": "pin not installed (pip install pin to compare)"}
    model = pin.Model()
    crank = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "crank")
    model.appendBodyToJoint(crank, pin.Inertia.Random(), pin.SE3.Identity())
    rod = model.addJoint(crank, pin.JointModelSpherical(),
                         pin.SE3(np.eye(3), np.array([2 * INCH, 0.0, 0.0])), "pin")
    model.appendBodyToJoint(rod, pin.Inertia.Random(), pin.SE3.Identity())
    slider = model.addJoint(0, pin.JointModelPX(),
                            pin.SE3(np.eye(3), np.array([0.0, INCH, 0.0])), "slider")
    model.appendBodyToJoint(slider, pin.Inertia.Random(), pin.SE3.Identity())
    data = model.createData()
    ball = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, rod,
                                    pin.SE3(np.eye(3), np.array([8 * INCH, 0.0, 0.0])), slider,
                                    pin.SE3.Identity(), pin.ReferenceFrame.LOCAL)
    models = pin.StdVec_RigidConstraintModel()
    models.append(ball)
    datas = pin.StdVec_RigidConstraintData()
    datas.append(ball.createData())
    pin.initConstraintDynamics(model, data, models, datas)
    rng = np.random.default_rng(0)
    q = pin.neutral(model)
    v, tau = rng.normal(size=model.nv), rng.normal(size=model.nv)
    if not np.all(np.isfinite(pin.constraintDynamics(model, data, q, v, tau, models, datas))):
        raise RuntimeError("pinocchio constraint peer: non-finite accelerations")

    def calls() -> None:
        for _ in range(n):
            pin.constraintDynamics(model, data, q, v, tau, models, datas)

    per = _best_time(calls) / n * 1e6
    return {"name": name, "value": per, "unit": "us/sample", "target": None,
            "note": f"pinocchio {pin.__version__}, one Python call per sample (C++ inside), "
                    f"best of {REPEATS} x {n} calls, own process"}


def _pinocchio(peer: str = "pinocchio") -> dict[str, Any]:
    """:func:`pinocchio_peer` (or, for ``"constraint"``, :func:`pinocchio_constraint_peer`) in
    a process of its own (numba or anything another benchmark loaded cannot slow it, nor it
    them)."""
    import json
    import subprocess

    out = subprocess.run([sys.executable, __file__, "--peer", peer], check=True,
                         capture_output=True, text=True)
    row: dict[str, Any] = json.loads(out.stdout.strip().splitlines()[-1])
    return row


#: repeats of the side-by-side CSSP / Pinocchio comparison (medians reported)
SIDE_BY_SIDE = 7


def _touch_every_field(motion: Any) -> None:
    """Read every field of every mode (the optional ones are computed on first access)."""
    for md in motion.modes:
        for table in (md.variables, md.velocities, md.accelerations):
            for _ in table.values():
                pass
        _ = md.conf.spherical


def chain_times(samples: int = SAMPLES) -> dict[str, float]:
    """In this process (run by :func:`_chain` in one of its own): CPU time per sample of
    ``solve_motion`` + mode 0's ``inverse_dynamics`` (the chain), of ``solve_motion`` alone and
    of ``solve_motion`` with every field read, once each, after one chain of the same size
    (discarded: a fresh process's first large arrays pay its page faults once; the peer is
    timed warm too, best of its loops)."""
    from screwkit.dynamics import inverse_dynamics
    from screwkit.kinematics.solve_motion import solve_motion

    lk, omega = _cssp()
    theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)

    def chain() -> None:
        inverse_dynamics(lk, solve_motion(lk, theta, rates=omega).modes[0], GRAVITY)

    chain()  # warm-up

    def every_field() -> None:
        _touch_every_field(solve_motion(lk, theta, rates=omega))

    return {"chain": _best_time(chain, 1) / samples * 1e6,
            "both": _best_time(lambda: solve_motion(lk, theta, rates=omega), 1)
            / samples * 1e6,
            "all": _best_time(every_field, 1) / samples * 1e6}


def _chain(samples: int) -> dict[str, float]:
    """:func:`chain_times` in a process of its own, as the peers are timed."""
    import json
    import subprocess

    out = subprocess.run([sys.executable, __file__, "--chain", str(samples)], check=True,
                         capture_output=True, text=True)
    times: dict[str, float] = json.loads(out.stdout.strip().splitlines()[-1])
    return times


def solve_motion_rows(lk: Any, theta: np.ndarray, omega: float, dyn: float,
                      peer: dict[str, Any]) -> list[dict[str, Any]]:
    """CSSP kinematics through ``solve_motion`` (both modes: the route the pipeline and the
    CLI take; its optional per-sample fields — ball-joint rotations, rates and rotation
    vectors, Rahman's angles — are computed on first access, so also with every field read),
    and kinematics + mode 0's inverse dynamics, end to end, against Pinocchio's
    ``constraintDynamics`` per sample (issue 30: target <= 0.5x). Side by side: each of
    ``SIDE_BY_SIDE`` rounds times the peer and :func:`chain_times`, each in a process of its
    own, one after the other; the rows give the medians of the rounds (the machine is shared:
    its load moves single runs by 2x)."""
    rounds: dict[str, list[float]] = {"peer": [], "chain": [], "both": [], "all": []}
    for _ in range(SIDE_BY_SIDE):
        if peer.get("value"):
            rounds["peer"].append(_pinocchio("constraint")["value"])
        for key, value in _chain(theta.size).items():
            rounds[key].append(value)
    med = {k: float(np.median(v)) if v else math.nan for k, v in rounds.items()}
    from screwkit.kinematics.solve_motion import solve_motion

    floor = motion_memory_floor(solve_motion(lk, theta, rates=omega))
    rows = [{"name": "CSSP kinematics through solve_motion (both modes)",
             "value": med["both"], "unit": "us/sample", "target": None,
             "note": f"median of {SIDE_BY_SIDE} runs, each in its own process; optional fields "
                     f"computed on first access; {med['all']:.2f} with every field read "
                     "(the eager pass this replaced: ~2.0 against ~2.6 read lazily, side by side "
                     "on 2026-12-06, warm processes; 6.2 before issue 30's fixes, 5.6 in the "
                     "issue)"},
            {"name": "its memory floor: the Motion's bytes written once into fresh memory",
             "value": floor["us"], "unit": "us/sample", "target": None,
             "note": f"{floor['bytes']:.0f} bytes/sample (both modes, every field read); "
                     "np.ones of that size, best of 3: what any route that returns them pays"}]
    if rounds["peer"]:
        ratios = [c / p for c, p in zip(rounds["chain"], rounds["peer"], strict=True)]
        rows.append({"name": "CSSP solve_motion + inverse_dynamics / pinocchio "
                             "constraintDynamics, per sample", "value": float(np.median(ratios)),
                     "unit": "ratio", "target": 0.5,
                     "note": f"end to end (both modes' kinematics, mode 0's dynamics): median "
                             f"{med['chain']:.2f} us/sample against the peer's "
                             f"{med['peer']:.2f} us/call; median of {SIDE_BY_SIDE} side-by-side "
                             f"rounds, each in its own processes, warm "
                             f"({', '.join(f'{r:.2f}' for r in ratios)}); kinematics "
                             f"{_kinematics_route()}"})
    return rows


def motion_memory_floor(motion: Any) -> dict[str, float]:
    """Bytes per sample of a Motion's arrays (every mode: link frames and rates, joint centres
    and axes, configurations, every table) and the CPU time of writing as many bytes once into
    freshly allocated memory (the kernel's zeroed pages and one pass of stores), µs/sample."""
    total = 0
    for md in motion.modes:
        arrays = [md.assembles, md.singular, md.conf.scalars, md.conf.spherical,
                  md.link_rotation, md.link_origin, md.link_angular_velocity,
                  md.link_origin_velocity, md.link_angular_acceleration,
                  md.link_origin_acceleration, md.joint_centres, md.joint_axes,
                  md.closure_residual]
        arrays += [v for t in (md.variables, md.velocities, md.accelerations)
                   for v in t.values()]
        seen: set[int] = set()
        for a in arrays:
            base = a if a.base is None else a.base
            while getattr(base, "base", None) is not None:
                base = base.base
            if id(base) not in seen and not isinstance(base, bytes):
                seen.add(id(base))
                total += int(np.asarray(base).nbytes)
    n = motion.samples
    seconds = _best_time(lambda: np.ones(total // 8))
    return {"bytes": total / n, "us": seconds / n * 1e6}


def _check_finite(label: str, values: dict[str, np.ndarray] | Any) -> None:
    """Refuse to time a peer whose output holds a non-finite number."""
    arrays = values.values() if isinstance(values, dict) else [values]
    for a in arrays:
        if not np.all(np.isfinite(np.asarray(a))):
            raise RuntimeError(f"{label}: non-finite output; not timed")


def _tiled_mode(mode: Any, samples: int) -> Any:
    """A ModeMotion repeated to ``samples`` samples (the loads of a long, periodic sweep)."""
    from dataclasses import replace

    reps = -(-samples // mode.assembles.size)

    def tile(a: np.ndarray) -> np.ndarray:
        return np.tile(a, (reps,) + (1,) * (a.ndim - 1))[:samples]

    return replace(
        mode, assembles=tile(mode.assembles), singular=tile(mode.singular),
        link_rotation=tile(mode.link_rotation), link_origin=tile(mode.link_origin),
        link_angular_velocity=tile(mode.link_angular_velocity),
        link_origin_velocity=tile(mode.link_origin_velocity),
        link_angular_acceleration=tile(mode.link_angular_acceleration),
        link_origin_acceleration=tile(mode.link_origin_acceleration),
        joint_centres=tile(mode.joint_centres), joint_axes=tile(mode.joint_axes),
        variables={k: tile(v) for k, v in mode.variables.items()},
    )


def every_family_memory(samples: int = SAMPLES) -> list[dict[str, Any]]:
    """Peak memory (and CPU time, one run) of the blocked generic ``inverse_dynamics`` on
    ``samples`` samples of each family (random mechanisms of tests/dynamics/mechanisms.py)."""
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "dynamics"))
    from mechanisms import FAMILIES, full_cycle  # type: ignore[import-not-found]

    from screwkit.dynamics import inverse_dynamics

    rows = []
    for family in FAMILIES:
        lk, _, mode = full_cycle(family, 0, samples=72)
        big = _tiled_mode(mode, samples)
        start = time.process_time()

        def generic(lk: Any = lk, big: Any = big) -> Any:
            return inverse_dynamics(lk, big, GRAVITY, closed_form=False)

        peak = _peak_mib(generic)
        spent = (time.process_time() - start) / samples * 1e6
        inputs = sum(getattr(big, f).nbytes for f in (
            "link_rotation", "link_origin", "link_angular_velocity", "link_origin_velocity",
            "link_angular_acceleration", "link_origin_acceleration", "joint_centres",
            "joint_axes")) / 2**20
        rows.append({"name": f"{family}: generic inverse_dynamics peak memory", "value": peak,
                     "unit": "MiB", "target": 2048,
                     "note": f"{samples} samples, blocked; {spent:.2f} us/sample (one run, "
                             f"tracemalloc on); its ModeMotion input holds {inputs:.0f} MiB"})
    return rows


def profile_dynamics(samples: int = SAMPLES, top: int = 14) -> str:
    """cProfile of ``inverse_dynamics`` on the closed-form ModeMotion (sorted by own time)."""
    from screwkit.dynamics import inverse_dynamics
    from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion

    lk, omega = _cssp()
    theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    mode = cssp_mode_motion(lk, theta, omega, 0.0, ball_joints=False)
    prof = cProfile.Profile()
    prof.enable()
    inverse_dynamics(lk, mode, gravity=GRAVITY)
    prof.disable()
    buf = io.StringIO()
    pstats.Stats(prof, stream=buf).sort_stats("tottime").print_stats(top)
    return buf.getvalue()


def _dynamics_on_modes(lk: Any, theta: np.ndarray, omega: float) -> tuple[float, float, float]:
    """inverse_dynamics on the lean and on the default-kinematics ModeMotion: µs/sample of
    each and the peak memory (MiB) of the first."""
    from screwkit.dynamics import inverse_dynamics
    from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion

    lean = cssp_mode_motion(lk, theta, omega, 0.0, ball_joints=False)
    dyn = _best_time(lambda: inverse_dynamics(lk, lean, GRAVITY)) / theta.size * 1e6
    peak = _peak_mib(lambda: inverse_dynamics(lk, lean, GRAVITY))
    full = cssp_mode_motion(lk, theta, omega, 0.0, joint_rotations=False)
    dyn_full = _best_time(lambda: inverse_dynamics(lk, full, GRAVITY)) / theta.size * 1e6
    return dyn, peak, dyn_full


def _kinematics_route() -> str:
    """Which route ran the CSSP's closed-form kinematics (lean pass, rod turn) on 10⁶
    samples."""
    from screwkit.kinematics.closed_forms import cssp_compiled

    return ("compiled (numba)" if cssp_compiled.use_compiled(SAMPLES)
            else "numpy route (numba not installed)")


def _route() -> str:
    """Which route ran the CSSP's blocked statics on 10⁶ samples."""
    from screwkit.dynamics import cssp_compiled

    return ("compiled (numba)" if cssp_compiled.use_compiled(SAMPLES)
            else "numpy route (numba not installed)")


def run(samples: int = SAMPLES, families: bool = True) -> list[dict[str, Any]]:
    from screwkit.dynamics import cssp_inverse_dynamics, inverse_dynamics
    from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion

    lk, omega = _cssp()
    theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    note = f"{samples} samples, numpy, one core, CPU time best of {REPEATS}"
    rows: list[dict[str, Any]] = [
        {"name": "CSSP kinematics, generic solver (motion)", "value":
         _generic_kinematics(lk, omega), "unit": "us/sample", "target": None,
         "note": "72-sample sweep, all assembly modes"}]
    inverse_dynamics(lk, cssp_mode_motion(lk, theta[:2000], omega, 0.0), GRAVITY)  # warm-up
    kin: dict[str, float] = {}
    options: dict[str, dict[str, bool]] = {
        "default": {}, "joint_rotations=False": {"joint_rotations": False},
        "ball_joints=False": {"ball_joints": False}}
    for label, kwargs in options.items():

        def kinematics(kw: dict[str, bool] = kwargs) -> Any:
            return cssp_mode_motion(lk, theta, omega, 0.0, **kw)

        kin[label] = _best_time(kinematics) / samples * 1e6
        rows.append({"name": f"CSSP kinematics, closed form (cssp_mode_motion, {label})",
                     "value": kin[label], "unit": "us/sample", "target": None, "note": note})
    sample = theta[:: max(1, samples // 2000)]
    ref = inverse_dynamics(lk, cssp_mode_motion(lk, sample, omega, 0.0), GRAVITY)
    _check_finite("screwkit inverse_dynamics", {"f": ref.shaking_force, "m": ref.shaking_moment,
                                                **{k: e for k, e in ref.efforts.items()}})
    _check_finite("screwkit cssp_inverse_dynamics",
                  cssp_inverse_dynamics(lk, sample, omega, 0.0, GRAVITY).shaking_force)
    _check_finite("prototype kernel", fused_cssp_dynamics(lk, sample, omega, 0.0, GRAVITY))
    dyn, dyn_peak, dyn_full = _dynamics_on_modes(lk, theta, omega)
    chain_peak = _peak_mib(lambda: inverse_dynamics(
        lk, cssp_mode_motion(lk, theta, omega, 0.0, ball_joints=False), GRAVITY))
    fused = _best_time(lambda: cssp_inverse_dynamics(lk, theta, omega, 0.0, GRAVITY))
    fused_peak = _peak_mib(lambda: cssp_inverse_dynamics(lk, theta, omega, 0.0, GRAVITY))
    few = theta[:: max(1, samples // 100_000)]
    generic = _best_time(lambda: inverse_dynamics(
        lk, cssp_mode_motion(lk, few, omega, 0.0, ball_joints=False), GRAVITY,
        closed_form=False), 1) / few.size * 1e6
    agreement = _check_fused(lk, omega, GRAVITY)
    fused_cssp_dynamics(lk, theta[:BLOCK], omega, 0.0, GRAVITY)  # warm-up
    proto = _best_time(lambda: fused_cssp_dynamics(lk, theta, omega, 0.0, GRAVITY))
    rows += [
        {"name": "CSSP inverse_dynamics on it (closed-form statics, blocked)", "value": dyn,
         "unit": "us/sample", "target": 1.0,
         "note": f"{note}; {dyn_full:.3f} on the default-kinematics ModeMotion"},
        {"name": "CSSP inverse_dynamics peak memory (tracemalloc)", "value": dyn_peak,
         "unit": "MiB", "target": 2048, "note": "outputs + one block; the ModeMotion excluded"},
        {"name": "CSSP chain: cssp_mode_motion(ball_joints=False) + inverse_dynamics",
         "value": kin["ball_joints=False"] + dyn, "unit": "us/sample", "target": 1.0,
         "note": f"with the default kinematics (rotation vectors skipped): "
                 f"{kin['joint_rotations=False'] + dyn_full:.3f}"},
        {"name": "CSSP chain peak memory (tracemalloc)", "value": chain_peak, "unit": "MiB",
         "target": 2048, "note": "ModeMotion + loads + one block"},
        {"name": "CSSP fused kinematics + dynamics (cssp_inverse_dynamics)",
         "value": fused / samples * 1e6, "unit": "us/sample", "target": 1.0, "note": note},
        {"name": "CSSP fused peak memory (tracemalloc)", "value": fused_peak, "unit": "MiB",
         "target": 2048, "note": "loads + joint centres + one block"},
        {"name": "CSSP generic loop statics (closed_form=False), per sample", "value": generic,
         "unit": "us/sample", "target": None,
         "note": f"{few.size} samples, one run, kinematics included"},
        {"name": "prototype fused SoA CSSP kernel (benchmark only)", "value":
         proto / samples * 1e6, "unit": "us/sample", "target": None,
         "note": f"axisymmetric rod only; max |Δ| vs library {agreement:.1e} of peak"},
    ]
    rnea = _pinocchio()
    rows.append(rnea)
    if rnea.get("value"):
        rows.append({"name": "CSSP inverse_dynamics (closed-form statics, blocked) / pinocchio rnea, per "
                             "sample", "value": dyn / rnea["value"], "unit": "ratio",
                     "target": 0.34, "note": f"rnea {rnea['value']:.2f} us/call (issue 30: "
                                             "the dynamics step alone stays at 0.34x); "
                                             f"{_route()}"})
    constraint = _pinocchio("constraint")
    rows += [constraint, *solve_motion_rows(lk, theta, omega, dyn, constraint)]
    if families:
        rows += every_family_memory(samples)
    return rows


if __name__ == "__main__":
    if sys.argv[1:2] == ["--chain"]:
        import json

        print(json.dumps(chain_times(int(sys.argv[2]))))
        sys.exit(0)
    if sys.argv[1:2] == ["--peer"]:
        import json

        print(json.dumps(pinocchio_peer() if sys.argv[2] == "pinocchio"
                         else pinocchio_constraint_peer()))
        sys.exit(0)
    for row in run(families="--no-families" not in sys.argv[1:]):
        value = row["value"]
        text = f"{value:.3f}" if isinstance(value, float) else str(value)
        print(f"{row['name']}: {text} {row['unit']} (target {row['target']}) - {row['note']}")
    if "--profile" in sys.argv[1:]:
        print(profile_dynamics())

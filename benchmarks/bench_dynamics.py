"""Speed and memory of CSSP inverse dynamics over 10⁶ samples, with Pinocchio's RNEA where
installed.

``run()`` returns a list of measurements ``{name, value, unit, target, note}``;
``python benchmarks/bench_dynamics.py --profile`` also prints where the dynamics spends its time.

* generic path: ``motion`` (Newton + continuation) on a 72-sample sweep, per sample;
* fast path: ``cssp_mode_motion`` (closed form, SPEC §1.2) on ``SAMPLES`` crank angles, then
  ``inverse_dynamics`` on that ModeMotion — timed separately and together, with the
  tracemalloc peak of the two together;
* prototype: ``fused_cssp_dynamics`` below — the same physics for the CSSP in
  structure-of-arrays form (one (N,) array per vector component, processed in cache-sized
  blocks), checked against the library on every sample before it is timed. It shows what a
  specialised kernel achieves; it is not library code.
* Pinocchio ``rnea`` on a 3-link open chain (R, S, P) per call, if ``pinocchio`` imports.
"""

from __future__ import annotations

import cProfile
import io
import pstats
import sys
import time
import tracemalloc
from typing import Any

import numpy as np

SAMPLES = 1_000_000
BLOCK = 16_384  # samples per block of the fused kernel (its temporaries stay in L2 cache)
INCH = 0.0254


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
    out = {k: np.empty((n, 3)) for k in ("shaking_force", "shaking_moment", "crank.force",
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
    from screwkit.kinematics.cssp_motion import cssp_mode_motion

    theta = np.linspace(0.0, 2 * np.pi, 20_000, endpoint=False)
    ref = inverse_dynamics(lk, cssp_mode_motion(lk, theta, omega, 0.0), gravity=gravity)
    got = fused_cssp_dynamics(lk, theta, omega, 0.0, gravity)
    forces = [(got["shaking_force"], ref.shaking_force)]
    moments = [(got["shaking_moment"], ref.shaking_moment),
               (got["input_torque"], ref.efforts["crank.theta"])]
    for joint in ("crank", "pin", "ball", "slider"):
        forces.append((got[f"{joint}.force"], ref.reactions[joint]["force"]))
        # ball joints carry no moment: the prototype does not store one
        mine = got.get(f"{joint}.moment", np.zeros_like(ref.reactions[joint]["moment"]))
        moments.append((mine, ref.reactions[joint]["moment"]))
    worst = 0.0
    for group in (forces, moments):
        scale = max(float(np.abs(b).max()) for _, b in group)
        worst = max(worst, max(float(np.abs(a - b).max()) for a, b in group) / scale)
    return worst


# ---------------------------------------------------------------------------------------------
def _generic_kinematics(lk: Any, omega: float) -> float:
    from screwkit.kinematics.motion import motion

    base = 72
    t0 = time.perf_counter()
    motion(lk, np.linspace(0.0, 2 * np.pi, base, endpoint=False), omega, 0.0)
    return (time.perf_counter() - t0) / base * 1e6


def _pinocchio() -> dict[str, Any]:
    try:
        import pinocchio as pin  # type: ignore[import-not-found]
    except ImportError:
        return {"name": "pinocchio rnea, 3-link open chain (R, S, P)", "value": None,
                "unit": "us/sample", "target": None, "note": "pin not installed"}
    model = pin.Model()
    parent = 0
    for k, joint in enumerate([pin.JointModelRZ(), pin.JointModelSpherical(),
                               pin.JointModelPX()]):
        place = pin.SE3(np.eye(3), np.array([0.05 * (k > 0), 0.0, 0.0]))
        parent = model.addJoint(parent, joint, place, f"j{k}")
        model.appendBodyToJoint(parent, pin.Inertia.Random(), pin.SE3.Identity())
    data = model.createData()
    q = pin.randomConfiguration(model)
    v = np.random.default_rng(0).normal(size=model.nv)
    a = np.random.default_rng(1).normal(size=model.nv)
    n = 100_000
    t0 = time.perf_counter()
    for _ in range(n):
        pin.rnea(model, data, q, v, a)
    per = (time.perf_counter() - t0) / n * 1e6
    return {"name": "pinocchio rnea, 3-link open chain (R, S, P)", "value": per,
            "unit": "us/sample", "target": None,
            "note": f"pinocchio {pin.__version__}, one call per sample from Python (C++ inside)"}


def fast_path_in_blocks(lk: Any, theta: np.ndarray, omega: float, gravity: list[float],
                        block: int = 131_072) -> dict[str, np.ndarray]:
    """The library fast path (cssp_mode_motion + inverse_dynamics) run block by block, the
    results concatenated: the same numbers with a bounded working set."""
    from screwkit.dynamics import inverse_dynamics
    from screwkit.kinematics.cssp_motion import cssp_mode_motion

    parts: dict[str, list[np.ndarray]] = {}
    for start in range(0, theta.shape[0], block):
        th = theta[start:start + block]
        dyn = inverse_dynamics(lk, cssp_mode_motion(lk, th, omega, 0.0, joint_rotations=False),
                               gravity=gravity)
        items = {"shaking_force": dyn.shaking_force, "shaking_moment": dyn.shaking_moment,
                 "input_torque": dyn.efforts["crank.theta"]}
        for joint, r in dyn.reactions.items():
            items[f"{joint}.force"] = r["force"]
            items[f"{joint}.moment"] = r["moment"]
        for key, value in items.items():
            parts.setdefault(key, []).append(value)
    return {key: np.concatenate(value) for key, value in parts.items()}


def profile_dynamics(samples: int = SAMPLES, top: int = 14) -> str:
    """cProfile of ``inverse_dynamics`` on the fast-path ModeMotion (sorted by own time)."""
    from screwkit.dynamics import inverse_dynamics
    from screwkit.kinematics.cssp_motion import cssp_mode_motion

    lk, omega = _cssp()
    theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    mode = cssp_mode_motion(lk, theta, omega, 0.0, joint_rotations=False)
    prof = cProfile.Profile()
    prof.enable()
    inverse_dynamics(lk, mode, gravity=[0.0, 0.0, -9.80665])
    prof.disable()
    buf = io.StringIO()
    pstats.Stats(prof, stream=buf).sort_stats("tottime").print_stats(top)
    return buf.getvalue()


def run(samples: int = SAMPLES) -> list[dict[str, Any]]:
    from screwkit.dynamics import inverse_dynamics
    from screwkit.kinematics.cssp_motion import cssp_mode_motion

    lk, omega = _cssp()
    gravity = [0.0, 0.0, -9.80665]
    theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    generic = _generic_kinematics(lk, omega)
    inverse_dynamics(lk, cssp_mode_motion(lk, theta[:1000], omega, 0.0))  # warm-up
    t0 = time.perf_counter()
    mode = cssp_mode_motion(lk, theta, omega, 0.0, joint_rotations=False)
    t1 = time.perf_counter()
    dyn = inverse_dynamics(lk, mode, gravity=gravity)
    t2 = time.perf_counter()
    assert np.all(np.isfinite(dyn.shaking_force))
    del mode, dyn
    kin_us, dyn_us = (t1 - t0) / samples * 1e6, (t2 - t1) / samples * 1e6
    tracemalloc.start()
    dyn = inverse_dynamics(lk, cssp_mode_motion(lk, theta, omega, 0.0, joint_rotations=False),
                           gravity=gravity)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    del dyn
    t4 = time.perf_counter()
    fast_path_in_blocks(lk, theta, omega, gravity)
    blocks_us = (time.perf_counter() - t4) / samples * 1e6
    tracemalloc.start()
    fast_path_in_blocks(lk, theta, omega, gravity)
    _, blocks_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    agreement = _check_fused(lk, omega, gravity)
    fused_cssp_dynamics(lk, theta[:BLOCK], omega, 0.0, gravity)  # warm-up
    t3 = time.perf_counter()
    fused = fused_cssp_dynamics(lk, theta, omega, 0.0, gravity)
    fused_us = (time.perf_counter() - t3) / samples * 1e6
    assert np.all(np.isfinite(fused["input_torque"]))
    del fused
    tracemalloc.start()
    fused_cssp_dynamics(lk, theta, omega, 0.0, gravity)
    _, fused_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    note = f"{samples} samples, numpy, single process"
    return [
        {"name": "CSSP kinematics, generic solver (motion)", "value": generic,
         "unit": "us/sample", "target": None, "note": "72-sample sweep, all assembly modes"},
        {"name": "CSSP kinematics, closed form (cssp_mode_motion)", "value": kin_us,
         "unit": "us/sample", "target": None, "note": note + ", joint_rotations=False"},
        {"name": "CSSP inverse dynamics on it (inverse_dynamics)", "value": dyn_us,
         "unit": "us/sample", "target": None, "note": note},
        {"name": "CSSP kinematics + inverse dynamics (fast path)", "value": kin_us + dyn_us,
         "unit": "us/sample", "target": 1.0, "note": note},
        {"name": "CSSP fast path peak memory (tracemalloc)", "value": peak / 2**20,
         "unit": "MiB", "target": 2048, "note": f"{peak / samples:.0f} bytes/sample"},
        {"name": "fast path in blocks of 131072 samples", "value": blocks_us,
         "unit": "us/sample", "target": 1.0, "note": "fast_path_in_blocks, results concatenated"},
        {"name": "fast path in blocks, peak memory (tracemalloc)", "value": blocks_peak / 2**20,
         "unit": "MiB", "target": 2048, "note": "bounded working set + the (N, ·) results"},
        {"name": "prototype fused SoA CSSP kinematics + dynamics", "value": fused_us,
         "unit": "us/sample", "target": 1.0,
         "note": f"max |Δ| vs library {agreement:.1e} of peak (20k samples); blocks of {BLOCK}"},
        {"name": "prototype fused kernel peak memory (tracemalloc)", "value": fused_peak / 2**20,
         "unit": "MiB", "target": 2048, "note": "outputs (N, 3) float64 ×8 + (N,)"},
        _pinocchio(),
    ]


if __name__ == "__main__":
    for row in run():
        print(row)
    if "--profile" in sys.argv[1:]:
        print(profile_dynamics())

"""Inverse dynamics on mechanism graphs (issue 28), side by side in one run:

* a single loop two ways — a four-bar and the spatial RSSR of examples/rssr_spatial.toml with
  their mass properties, 3 600 samples: ``graph_inverse_dynamics`` on the loop as a graph
  (``mechanism_from_loop``, its bodies' masses carried to the drawing) against the single-loop
  ``inverse_dynamics`` on the same motion; the efforts and shaking loads are checked equal
  (1e-9 relative) before timing. Target: graph ≤ 2× the loop path. Kinematics are solved
  before timing (each path on its own motion); only the loads are timed;
* the Stewart platform driven by its pose (examples/mechanisms/stewart_platform_pose.toml:
  heave, roll and surge, here over 2 000 samples with exact rates and accelerations): the six
  leg forces by ``graph_inverse_dynamics`` against Pinocchio (validation/pinocchio/stewart.py:
  RNEA on six U–P legs and a free-flying platform, the balls closed by point constraints,
  one Python call per sample, C++ inside), both checked equal (1e-9 relative) first. Target:
  screwkit ≤ 1× Pinocchio per sample.

Times are the best CPU time of a few repeats, with BLAS held to one thread (set before numpy
loads; Pinocchio's Eigen is single-threaded too): on a shared machine a multi-threaded LAPACK
call on many small matrices spends most of its CPU time waiting (a batched 108 × 108 SVD took
10× longer with two threads than with one).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

import screwkit as sk  # noqa: E402
from screwkit.dynamics.graph_inverse import graph_inverse_dynamics  # noqa: E402
from screwkit.kinematics.graph import solve_mechanism  # noqa: E402
from screwkit.kinematics.graph.from_loop import mechanism_from_loop  # noqa: E402
from screwkit.model.mass import MassProperties  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
STEWART = ROOT / "examples" / "mechanisms" / "stewart_platform_pose.toml"
SAMPLES = 3600
STEWART_SAMPLES = 2000
REPEATS = 3
G = np.array([0.0, 0.0, -9.80665])


def _best(fn: Any, repeats: int = REPEATS) -> float:
    best = math.inf
    for _ in range(repeats):
        t = time.process_time()
        fn()
        best = min(best, time.process_time() - t)
    return best


def _fourbar() -> Any:
    lk = sk.fourbar(a=4.0, d1=1.0, d2=3.5, d3=3.0)
    rng = np.random.default_rng(3)
    return lk.with_links([sk.Link(link.name, MassProperties(
        rng.uniform(0.5, 2.0), rng.standard_normal(3) * 0.3, np.diag(rng.uniform(0.01, 0.02, 3))))
        for link in lk.links])


def loop_rows(name: str, lk: Any, x: np.ndarray) -> dict[str, Any]:
    """One loop's loads by both paths over ``x`` (its input from the drawing's sample 0)."""
    loop = sk.solve_motion(lk, x, rates=2.0, accelerations=0.5)
    md0 = loop.mode(0)
    mech = mechanism_from_loop(loop, 0, 0)
    bodies = []
    for k, link in enumerate(lk.links):  # the graph's bodies are drawn at sample 0
        R0, p0 = md0.link_rotation[0, k], md0.link_origin[0, k]
        m = link.mass
        bodies.append(sk.Body(link.name, MassProperties(m.mass, R0 @ m.com + p0,
                                                        R0 @ m.inertia @ R0.T)))
    mech = mech.with_bodies(bodies)
    graph = solve_mechanism(mech, x - x[0], rates=2.0, accelerations=0.5)
    direct = sk.inverse_dynamics(loop, 0, gravity=G)
    dyn = graph_inverse_dynamics(graph, gravity=G)
    ok = dyn.ok & direct.ok if hasattr(direct, "ok") else dyn.ok
    for ours, theirs in ((dyn.efforts[:, 0], direct.efforts[lk.inputs[0]]),
                         (dyn.shaking_force, direct.shaking_force),
                         (dyn.shaking_moment, direct.shaking_moment)):
        miss = np.abs(ours[ok] - theirs[ok]).max() / np.abs(theirs[ok]).max()
        if not miss <= 1e-9:
            raise RuntimeError(f"{name}: graph and loop loads differ by {miss:.2e}")
    t_graph = _best(lambda: graph_inverse_dynamics(graph, gravity=G))
    t_loop = _best(lambda: sk.inverse_dynamics(loop, 0, gravity=G))
    n = x.size
    return {"name": f"{name}, {n} samples: graph inverse dynamics / single-loop path",
            "value": t_graph / t_loop, "unit": "x", "target": 2.0,
            "note": f"graph {t_graph / n * 1e6:.3g} µs/sample, loop {t_loop / n * 1e6:.3g} "
                    "µs/sample (loads only; efforts and shaking loads equal to 1e-9)"}


def stewart_motion(spec: Any, n: int) -> Any:
    """The example's trajectory (heave 30 (1 − cos 2πs)/2 mm, roll 6 sin 2πs deg, surge
    10 sin 2πs mm, s = t/1 s) at ``n`` samples with exact rates and accelerations."""
    s = np.linspace(0.0, 1.0, n)
    w = 2 * np.pi
    x = np.zeros((n, 6))
    xd, xdd = np.zeros_like(x), np.zeros_like(x)
    for col, amp, kind in ((0, 0.010, "sin"), (2, 0.015, "cos"), (3, math.radians(6.0), "sin")):
        if kind == "sin":
            x[:, col] = amp * np.sin(w * s)
            xd[:, col] = amp * w * np.cos(w * s)
            xdd[:, col] = -amp * w * w * np.sin(w * s)
        else:  # amp (1 − cos)
            x[:, col] = amp * (1 - np.cos(w * s))
            xd[:, col] = amp * w * np.sin(w * s)
            xdd[:, col] = amp * w * w * np.cos(w * s)
    return solve_mechanism(spec.mechanism, x, rates=xd, accelerations=xdd)


def stewart_rows() -> list[dict[str, Any]]:
    spec = sk.load_spec(STEWART)
    motion = stewart_motion(spec, STEWART_SAMPLES)
    dyn = graph_inverse_dynamics(motion, gravity=spec.gravity_vector)
    ok = np.nonzero(dyn.ok)[0]
    n = ok.size
    t_ours = _best(lambda: graph_inverse_dynamics(motion, gravity=spec.gravity_vector))
    rows: list[dict[str, Any]] = [{
        "name": f"Stewart platform leg forces, {n} samples: screwkit graph_inverse_dynamics",
        "value": t_ours / n * 1e6, "unit": "µs/sample", "target": None,
        "note": "every reaction and the shaking loads too; motion solved before timing"}]
    try:
        sys.path.insert(0, str(ROOT / "validation" / "pinocchio"))
        import pinocchio  # noqa: F401
        import stewart
    except ImportError:
        rows.append({"name": "Stewart platform: screwkit / Pinocchio", "value": float("nan"),
                     "unit": "x", "target": 1.0, "note": "pin not installed (make bench)"})
        return rows
    mech = spec.mechanism
    pm = stewart.build(mech, spec.gravity_vector)
    md = motion.modes[0]
    states = [stewart.state(pm, mech, md, int(k)) for k in ok]
    theirs = np.array([stewart.leg_forces(pm, *s) for s in states])
    miss = np.abs(theirs - dyn.efforts[ok]).max() / np.abs(dyn.efforts[ok]).max()
    if not miss <= 1e-9:
        raise RuntimeError(f"Stewart platform: Pinocchio's leg forces differ by {miss:.2e}")

    def pinocchio_all() -> None:
        for s in states:
            stewart.leg_forces(pm, *s)

    t_pin = _best(pinocchio_all)
    rows.append({"name": "Stewart platform leg forces: screwkit time / Pinocchio time",
                 "value": t_ours / t_pin, "unit": "x", "target": 1.0,
                 "note": f"Pinocchio {t_pin / n * 1e6:.3g} µs/sample (RNEA, joint Jacobians, "
                         "an 18×18 solve for the ball forces; one Python call per sample); "
                         f"leg forces agree to {miss:.1e}"})
    return rows


def run() -> list[dict[str, Any]]:
    x = np.radians(np.arange(SAMPLES) * 0.1)
    rows = [loop_rows("four-bar", _fourbar(), x)]
    rssr = sk.load_spec(ROOT / "examples" / "rssr_spatial.toml")
    rows.append(loop_rows("RSSR", rssr.linkage, x))
    return rows + stewart_rows()


if __name__ == "__main__":
    for row in run():
        print(row)

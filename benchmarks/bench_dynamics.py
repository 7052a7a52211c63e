"""Speed and memory of screwkit.dynamics, side by side with Pinocchio's RNEA where installed.

``run()`` returns a list of measurements ``{name, value, unit, target, note}``.

* CSSP (Rahman 1996 §1 geometry, SI units): kinematics by ``motion`` on 72 samples (the generic
  solver, timed per sample), then the same motion tiled to ``SAMPLES`` samples and full inverse
  dynamics (inertia wrenches, freedom screws, loop statics, reactions, efforts, shaking loads)
  timed on it; peak memory of the dynamics call by tracemalloc.
* Pinocchio ``rnea`` on a 3-link open chain (revolute, spherical, prismatic — the CSSP's
  joints opened at the slider), per call, if ``pinocchio`` imports; else noted.
"""

from __future__ import annotations

import time
import tracemalloc
from dataclasses import replace
from typing import Any

import numpy as np

SAMPLES = 1_000_000


def _cssp_mode(samples: int) -> tuple[Any, Any, float]:
    from screwkit.kinematics.motion import motion
    from screwkit.model.families import cssp
    from screwkit.model.linkage import Link
    from screwkit.model.mass import MassProperties

    inch = 0.0254
    lk = cssp(2 * inch, 8 * inch, 1 * inch, np.radians(250.0), 0.4 * inch)
    lk = lk.with_links([
        Link("crank", MassProperties(0.5, [0.02, 0.0, 0.0], np.diag([1e-4, 2e-4, 2.5e-4]))),
        Link("rod", MassProperties(0.8, [0.1, 0.0, 0.0], np.diag([0.0, 3e-3, 3e-3]))),
        Link("slider", MassProperties(1.0, [0.0, 0.0, 0.0], np.diag([1e-3, 1e-3, 1e-3]))),
    ])
    base = 72
    t0 = time.perf_counter()
    mo = motion(lk, np.linspace(0.0, 2 * np.pi, base, endpoint=False), 314.159, 0.0)
    kin = (time.perf_counter() - t0) / base
    mode = mo.modes[0]
    reps = -(-samples // base)

    def tile(a: np.ndarray) -> np.ndarray:
        return np.tile(a, (reps,) + (1,) * (a.ndim - 1))[:samples]

    big = replace(
        mode,
        assembles=tile(mode.assembles), singular=tile(mode.singular),
        link_rotation=tile(mode.link_rotation), link_origin=tile(mode.link_origin),
        link_angular_velocity=tile(mode.link_angular_velocity),
        link_origin_velocity=tile(mode.link_origin_velocity),
        link_angular_acceleration=tile(mode.link_angular_acceleration),
        link_origin_acceleration=tile(mode.link_origin_acceleration),
        joint_centres=tile(mode.joint_centres), joint_axes=tile(mode.joint_axes),
        variables={k: tile(v) for k, v in mode.variables.items()},
    )
    return lk, big, kin


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


def run(samples: int = SAMPLES) -> list[dict[str, Any]]:
    from screwkit.dynamics import inverse_dynamics

    lk, big, kin = _cssp_mode(samples)
    inverse_dynamics(lk, big)  # warm-up (imports, page faults)
    t0 = time.perf_counter()
    dyn = inverse_dynamics(lk, big, gravity=[0.0, 0.0, -9.80665])
    per = (time.perf_counter() - t0) / samples * 1e6
    tracemalloc.start()
    inverse_dynamics(lk, big, gravity=[0.0, 0.0, -9.80665])
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert np.all(np.isfinite(dyn.shaking_force))
    return [
        {"name": "CSSP kinematics (motion, generic solver)", "value": kin * 1e6,
         "unit": "us/sample", "target": None, "note": "72-sample sweep, all assembly modes"},
        {"name": "CSSP inverse dynamics", "value": per, "unit": "us/sample", "target": 1.0,
         "note": f"{samples} samples, numpy batched, single process"},
        {"name": "CSSP inverse dynamics peak memory", "value": peak / samples,
         "unit": "bytes/sample", "target": None,
         "note": f"tracemalloc peak {peak / 2**20:.0f} MiB for {samples} samples"},
        _pinocchio(),
    ]


if __name__ == "__main__":
    for row in run():
        print(row)

"""The bundled graph examples (examples/mechanisms/, issue 26): each loads, assembles over its
whole stated range with every loop closed at round-off, and its rates and accelerations are the
derivatives of its positions (central differences of two further solves at x ± h·d, h = 1e-5,
whose truncation error h²/6·q‴ is ~1e-11 of q)."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.io.mechanism_spec import GraphSpec
from screwkit.kinematics.graph import solve_mechanism

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
NAMES = ["watt_sixbar", "stephenson3_sixbar", "jansen_leg", "double_wishbone",
         "stewart_platform", "delta_robot"]
H = 1e-5  # rad for angle inputs, m for slides


@cache
def _spec(name: str) -> GraphSpec:
    spec = sk.load_spec(EXAMPLES / f"{name}.toml")
    assert isinstance(spec, GraphSpec)
    return spec


def _direction(n_in: int) -> np.ndarray:
    """A fixed direction in input space that moves every input (unit rate for one input)."""
    return np.array([1.0, -0.7, 0.45, 0.8, -0.35, 0.6][:n_in])


@pytest.mark.parametrize("name", NAMES)
def test_example_assembles_and_closes(name: str) -> None:
    spec = _spec(name)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                             accelerations=spec.acceleration)
    md = motion.modes[0]
    assert md.assembles.all(), md.events
    assert not md.singular.any(), md.events
    assert md.events == []
    assert np.max(md.closure_residual) <= 1e-12
    assert motion.samples == spec.inputs.shape[0]
    for pname, path in md.points.items():
        assert np.all(np.isfinite(path)), pname
    # a sweep that starts at the drawing starts with the drawing itself
    if not np.any(spec.inputs[0]):
        for pt in spec.mechanism.points:
            np.testing.assert_allclose(md.points[pt.name][0], pt.at, rtol=0, atol=1e-15)
        centres = np.array([j.at for j in spec.mechanism.joints])
        np.testing.assert_allclose(md.joint_centres[0], centres, rtol=0, atol=1e-15)


def _idle_bodies(mech: sk.Mechanism) -> set[int]:
    """Bodies held only by two balls (a rod's spin about its own line is idle)."""
    out = set()
    for k, b in enumerate(mech.body_names):
        if [j.kind for j in mech.joints if b in j.bodies] == ["S", "S"]:
            out.add(k)
    return out


def _wrapped(a: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * a))


def _skew(w: np.ndarray) -> np.ndarray:
    W = np.zeros((*w.shape[:-1], 3, 3))
    W[..., 0, 1], W[..., 0, 2], W[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    return W - np.swapaxes(W, -1, -2)


@pytest.mark.parametrize("name", NAMES)
def test_rates_and_accelerations_are_derivatives(name: str) -> None:
    spec = _spec(name)
    mech = spec.mechanism
    X = spec.inputs[:: max(1, spec.inputs.shape[0] // 40)]
    d = _direction(X.shape[1])
    mid, plus, minus = (solve_mechanism(mech, X + s * H * d, rates=d, accelerations=0.0).modes[0]
                        for s in (0.0, 1.0, -1.0))
    for m in (mid, plus, minus):
        assert m.assembles.all() and not m.singular.any()
    scale = mech.length_scale
    for f in mid.velocities:
        if f not in mid.variables:
            continue  # a ball's freedoms: body increments, checked through the poses below
        slide = f.endswith(".s")
        dq = plus.variables[f] - minus.variables[f]
        fd = (dq if slide else _wrapped(dq)) / (2 * H)
        unit = scale if slide else 1.0
        np.testing.assert_allclose(mid.velocities[f], fd, rtol=0, err_msg=f,
                                   atol=1e-8 * max(unit, float(np.max(np.abs(fd)))))
        fd2 = (plus.velocities[f] - minus.velocities[f]) / (2 * H)
        np.testing.assert_allclose(mid.accelerations[f], fd2, rtol=0, err_msg=f,
                                   atol=1e-7 * max(unit, float(np.max(np.abs(fd2)))))
    for p in mid.points:
        fd = (plus.points[p] - minus.points[p]) / (2 * H)
        np.testing.assert_allclose(mid.point_velocities[p], fd, rtol=0, err_msg=p,
                                   atol=1e-8 * max(scale, float(np.max(np.abs(fd)))))
        fd2 = (plus.point_velocities[p] - minus.point_velocities[p]) / (2 * H)
        np.testing.assert_allclose(mid.point_accelerations[p], fd2, rtol=0, err_msg=p,
                                   atol=1e-7 * max(scale, float(np.max(np.abs(fd2)))))
    keep = sorted(set(range(len(mech.bodies))) - _idle_bodies(mech))
    # body poses: d(origin)/dx is the velocity of the body point at the origin, dR/dx = [ω]× R
    fd = (plus.link_origin - minus.link_origin)[:, keep] / (2 * H)
    np.testing.assert_allclose(mid.link_origin_velocity[:, keep], fd, rtol=0,
                               atol=1e-8 * max(scale, float(np.max(np.abs(fd)))))
    dR = (plus.link_rotation - minus.link_rotation)[:, keep] / (2 * H)
    R = mid.link_rotation[:, keep]
    np.testing.assert_allclose(_skew(mid.link_angular_velocity[:, keep]) @ R, dR, rtol=0,
                               atol=1e-8 * max(1.0, float(np.max(np.abs(dR)))))
    fd2 = (plus.link_angular_velocity - minus.link_angular_velocity)[:, keep] / (2 * H)
    np.testing.assert_allclose(mid.link_angular_acceleration[:, keep], fd2, rtol=0,
                               atol=1e-7 * max(1.0, float(np.max(np.abs(fd2)))))
    fd2 = (plus.link_origin_velocity - minus.link_origin_velocity)[:, keep] / (2 * H)
    np.testing.assert_allclose(mid.link_origin_acceleration[:, keep], fd2, rtol=0,
                               atol=1e-7 * max(scale, float(np.max(np.abs(fd2)))))


# (loops, Grübler–Kutzbach, freedoms, rank, redundant, idle), counted by hand: a planar loop
# drawn in 3-D leaves 3 of its 6 closure rows redundant (planar mobility 3(n−1) − 2j = 1);
# a rod between two balls spins idly; the Stewart legs' U joints stop that spin.
TOPOLOGY = {
    "watt_sixbar": (2, 6 * 5 - 5 * 7, 7, 6, 6, 0),
    "stephenson3_sixbar": (2, 6 * 5 - 5 * 7, 7, 6, 6, 0),
    "jansen_leg": (3, 6 * 7 - 5 * 10, 10, 9, 9, 0),
    "double_wishbone": (2, 6 * 4 - 2 * 5 - 4 * 3, 14, 12, 0, 1),
    "stewart_platform": (5, 6 * 13 - 6 * (4 + 5 + 3), 36, 30, 0, 0),
    "delta_robot": (5, 6 * 10 - 3 * 5 - 12 * 3, 39, 30, 0, 6),
}
MOBILITY = {"watt_sixbar": 1, "stephenson3_sixbar": 1, "jansen_leg": 1, "double_wishbone": 1,
            "stewart_platform": 6, "delta_robot": 3}


@pytest.mark.parametrize("name", NAMES)
def test_example_topology_and_mobility(name: str) -> None:
    t = _spec(name).topology
    loops, grubler, freedoms, rank, redundant, idle = TOPOLOGY[name]
    assert (len(t.loops), t.grubler, t.freedoms, t.rank) == (loops, grubler, freedoms, rank)
    assert (t.redundant_count, len(t.idle)) == (redundant, idle)
    assert t.mobility == MOBILITY[name] + idle == len(_spec(name).mechanism.inputs) + idle
    assert t.free == [] and all(r == rank for r in t.ranks_at_samples)

"""Inverse dynamics of *random* graphs (issue 28, "Checks"), not only the bundled examples:
seeded planar six-bars and Jansen legs with every hardpoint moved in their plane, random spatial
RSSR loops, double wishbones and Stewart platforms with moved hardpoints, each with random mass
properties, random input rates and accelerations and a random gravity, checked per sample by
laws that hold exactly (no finite differences), to 1e-9 relative:

* every moving body's Newton–Euler balance: the reactions of its joints (``reaction_force``,
  ``reaction_moment`` about the joint centre) plus its weight equal m·a_c and dH_c/dt, both
  computed here from the body's pose, twist and acceleration (not by dynamics/inertia.py);
* input power Σ τ·q̇ = d(KE + PE)/dt, with d(KE)/dt = Σ m v_c·a_c + ω·(I α + ω × I ω) and
  d(PE)/dt = −Σ m g·v_c from the same body motion;
* shaking force = weight − dP/dt and shaking moment (about the origin) = Σ c × m g − dH_O/dt;
* the regressor times the stacked inertial parameters = the direct efforts.

The body accelerations these laws use are checked against a five-point finite difference of
the body velocities along a trajectory with the same rates and accelerations (the one place
where a difference quotient is the independent route), to 1e-6 relative.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.dynamics.graph_inverse import graph_inverse_dynamics, graph_regressor
from screwkit.kinematics.graph import solve_mechanism
from screwkit.model.mass import MassProperties
from screwkit.model.mechanism import GROUND, Mechanism, MechanismJoint

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
SEEDS = (11, 12, 13)


def _moved(name: str, rng: np.random.Generator, amount: float, planar: bool) -> Mechanism:
    """The bundled example ``name`` with every joint's point moved by up to ``amount`` of its
    size (in the x–y plane when ``planar``): any drawing closes, so each is a valid new
    mechanism of the same topology."""
    mech = sk.load_spec(EXAMPLES / f"{name}.toml").mechanism
    L = mech.length_scale
    joints = []
    for j in mech.joints:
        d = rng.uniform(-amount, amount, 3) * L
        d[2] = 0.0 if planar else d[2]
        joints.append(dataclasses.replace(j, at=j.at + d))
    return Mechanism(f"moved {name}", mech.bodies, tuple(joints), mech.inputs)


def _rssr(rng: np.random.Generator) -> Mechanism:
    """A random spatial RSSR: random axes and ball centres, a short crank."""
    def joint(n: str, kind: str, a: str, b: str, at: np.ndarray,
              axis: np.ndarray | None = None) -> MechanismJoint:
        return MechanismJoint(n, kind, (a, b), at, rng.normal(size=3) if axis is None else axis)

    O, A, B, D = (rng.uniform(-1.0, 1.0, 3) for _ in range(4))
    A = O + 0.3 * (A - O) / np.linalg.norm(A - O)
    return Mechanism("random RSSR", (sk.Body("crank"), sk.Body("rod"), sk.Body("rocker")),
                     (joint("O", "R", GROUND, "crank", O), joint("A", "S", "crank", "rod", A),
                      joint("B", "S", "rod", "rocker", B), joint("D", "R", "rocker", GROUND, D)),
                     ("O.theta",))


def _random(shape: str, seed: int) -> Mechanism:
    rng = np.random.default_rng(seed)
    if shape == "RSSR":
        return _rssr(rng)
    planar = shape in ("watt_sixbar", "stephenson3_sixbar", "jansen_leg")
    return _moved(shape, rng, 0.03 if planar else 0.02, planar)


def _with_masses(mech: Mechanism, rng: np.random.Generator) -> Mechanism:
    """Random, physically consistent mass properties (drawing = world axes). A rod between two
    balls spins idly, so its centre of mass is on its axis and its inertia symmetric about it
    (else no joint could hold its spin and the loads would not balance)."""
    bodies = []
    for b in mech.bodies:
        mass = rng.uniform(0.2, 2.0)
        unit = 0.02 * mass * mech.length_scale ** 2  # inertia comparable with m·ℓ²
        joints = [j for j in mech.joints if b.name in j.bodies]
        pts = [j.at for j in joints]
        if len(joints) == 2 and all(j.kind == "S" for j in joints):
            u = (pts[1] - pts[0]) / np.linalg.norm(pts[1] - pts[0])
            com = pts[0] + rng.uniform(0.3, 0.7) * (pts[1] - pts[0])
            inertia = rng.uniform(0.5, 2.0) * unit * (np.eye(3) - 0.9 * np.outer(u, u))
        else:
            com = np.mean(pts, axis=0) + 0.1 * mech.length_scale * rng.standard_normal(3)
            q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
            s = rng.uniform(0.2, 1.0, 3) * unit  # second moments of the mass along q's axes
            moments = np.array([s[1] + s[2], s[0] + s[2], s[0] + s[1]])  # a real body's
            inertia = q @ np.diag(moments) @ q.T
        bodies.append(sk.Body(b.name, MassProperties(mass, com, inertia)))
    return mech.with_bodies(bodies)


def _trajectory(mech: Mechanism, rng: np.random.Generator, t: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inputs x(t) = v t + a t²/2 from the drawing, rates v + a t and accelerations a (one
    row per time), with random v and a in the inputs' units (m for a slide, rad else)."""
    n = len(mech.driven_names)
    slide = np.array(mech.driven_is_translation(), dtype=bool)
    scale = np.where(slide, 0.05 * mech.length_scale, 1.0)
    v = rng.uniform(0.5, 1.5, n) * rng.choice([-1.0, 1.0], n) * scale
    a = rng.uniform(-2.0, 2.0, n) * scale
    return (v * t[:, None] + 0.5 * a * t[:, None] ** 2, v + a * t[:, None],
            np.broadcast_to(a, (len(t), n)).copy())


def _body_motion(mech: Mechanism, md: object) -> list[dict[str, np.ndarray]]:
    """Per moving body: centre of mass c, its velocity and acceleration, ω, α and the inertia
    I in world axes, from the pose, twist and acceleration of the body frame."""
    out = []
    for k, b in enumerate(mech.bodies):
        R, p = md.link_rotation[:, k], md.link_origin[:, k]  # type: ignore[attr-defined]
        w = md.link_angular_velocity[:, k]  # type: ignore[attr-defined]
        al = md.link_angular_acceleration[:, k]  # type: ignore[attr-defined]
        r = np.einsum("nij,j->ni", R, b.mass.com)
        out.append({"m": b.mass.mass, "c": p + r, "w": w, "al": al,
                    "v": md.link_origin_velocity[:, k] + np.cross(w, r),  # type: ignore[attr-defined]
                    "a": md.link_origin_acceleration[:, k] + np.cross(al, r)  # type: ignore[attr-defined]
                    + np.cross(w, np.cross(w, r)),
                    "I": np.einsum("nij,jk,nlk->nil", R, b.mass.inertia, R)})
    return out


def _dH(body: dict[str, np.ndarray]) -> np.ndarray:
    """dH_c/dt = I α + ω × I ω (Euler; world axes)."""
    Iw = np.einsum("nij,nj->ni", body["I"], body["w"])
    return np.einsum("nij,nj->ni", body["I"], body["al"]) + np.cross(body["w"], Iw)


SHAPES = ["watt_sixbar", "stephenson3_sixbar", "jansen_leg", "RSSR", "double_wishbone",
          "stewart_platform"]


@pytest.mark.parametrize("shape", SHAPES)
def test_random_graphs_obey_newton_euler_power_and_momentum(shape: str) -> None:
    checked = 0
    for seed in SEEDS:
        rng = np.random.default_rng(seed + 1000)
        mech = _with_masses(_random(shape, seed), rng)
        g = rng.normal(size=3) * 5.0
        x, xd, xdd = _trajectory(mech, rng, np.linspace(0.0, 0.3, 7))
        motion = solve_mechanism(mech, x, rates=xd, accelerations=xdd)
        md = motion.modes[0]
        dyn = graph_inverse_dynamics(motion, gravity=g)
        ok = dyn.ok
        assert ok.sum() >= 5, (shape, seed)
        assert np.nanmax(dyn.residual) < 1e-9
        bodies = _body_motion(mech, md)
        weight = sum(bd["m"] * g for bd in bodies)
        F = np.abs(weight).max() + max(np.abs(bd["m"] * bd["a"]).max() for bd in bodies)
        Mscale = F * mech.length_scale
        # each body: Σ reactions on it (by first on second) + weight = m a_c, dH_c/dt
        names = mech.body_names
        for k, bd in enumerate(bodies):
            force = bd["m"] * g - bd["m"] * bd["a"]
            moment = np.cross(bd["c"], bd["m"] * g) - np.cross(bd["c"], bd["m"] * bd["a"]) \
                - _dH(bd)
            for j, joint in enumerate(mech.joints):
                if names[k] not in joint.bodies:
                    continue
                sign = 1.0 if joint.bodies[1] == names[k] else -1.0
                f = dyn.reaction_force[:, j]
                m_origin = dyn.reaction_moment[:, j] + np.cross(md.joint_centres[:, j], f)
                force = force + sign * f
                moment = moment + sign * m_origin
            assert np.abs(force[ok]).max() <= 1e-9 * F, (shape, seed, names[k])
            assert np.abs(moment[ok]).max() <= 1e-9 * Mscale, (shape, seed, names[k])
        # input power = d(KE + PE)/dt, every term analytic
        power = np.einsum("nk,nk->n", dyn.efforts, motion.input_rates)
        dE = sum(bd["m"] * np.einsum("ni,ni->n", bd["v"], bd["a"] - g)
                 + np.einsum("ni,ni->n", bd["w"], _dH(bd)) for bd in bodies)
        P = F * max(np.abs(bd["v"]).max() + np.abs(bd["w"]).max() * mech.length_scale
                    for bd in bodies)
        assert np.abs(power - dE)[ok].max() <= 1e-9 * P, (shape, seed)
        # shaking force and moment (about the origin) = weight − dP/dt, Σ c × m g − dH_O/dt
        dP = sum(bd["m"] * bd["a"] for bd in bodies)
        dHO = sum(np.cross(bd["c"], bd["m"] * bd["a"]) + _dH(bd) for bd in bodies)
        moment_g = sum(np.cross(bd["c"], bd["m"] * g) for bd in bodies)
        assert np.abs(dyn.shaking_force - (weight - dP))[ok].max() <= 1e-9 * F
        assert np.abs(dyn.shaking_moment - (moment_g - dHO))[ok].max() <= 1e-9 * Mscale
        # regressor · π = the direct efforts
        Y = graph_regressor(motion, gravity=g)
        pi = np.concatenate([b.mass.inertial_parameters() for b in mech.bodies])
        E = np.abs(dyn.efforts[ok]).max()
        assert np.abs(Y @ pi - dyn.efforts)[ok].max() <= 1e-9 * E
        checked += int(ok.sum())
    assert checked >= 15


@pytest.mark.parametrize("shape", ["stephenson3_sixbar", "RSSR", "stewart_platform"])
def test_body_accelerations_are_the_derivatives_of_the_velocities(shape: str) -> None:
    """The second route for the accelerations the laws above use: along x(t) = v t + a t²/2, a
    five-point difference of the solver's ω of every body equals its α, and that of the
    velocity of every joint's point on each of its bodies (v_o + ω × (P − o)) equals the
    point's acceleration (a_o + α × r + ω × (ω × r)). Points on joints, not the body-frame
    origin: a rod between two balls has an idle spin, which its twist leaves out (ω ⊥ the rod)
    and its pose does not, so the velocity of its frame's origin (off the rod's axis) is not
    the derivative of the origin's path; points on the axis are unaffected, and so are loads."""
    mech = _random(shape, SEEDS[0])
    rng = np.random.default_rng(5)
    h = 1e-3
    x, xd, xdd = _trajectory(mech, rng, 0.1 + h * np.arange(-2.0, 3.0))
    md = solve_mechanism(mech, x, rates=xd, accelerations=xdd).modes[0]
    assert md.assembles.all() and not md.singular.any()
    five = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) / (12.0 * h)
    w, al = md.link_angular_velocity, md.link_angular_acceleration
    fd = np.tensordot(five, w, axes=(0, 0))
    assert np.abs(fd - al[2]).max() <= 1e-6 * (np.abs(al[2]).max() + np.abs(w).max())
    names = mech.body_names
    size = mech.length_scale * (np.abs(w).max() ** 2 + np.abs(al).max() + np.abs(w).max())
    checked = 0
    for j, joint in enumerate(mech.joints):
        if joint.kind not in "RSU":
            continue  # a slide's point moves along its second body
        P = md.joint_centres[:, j]
        for body in joint.bodies:
            if body == GROUND:
                continue
            k = names.index(body)
            r = P - md.link_origin[:, k]
            v = md.link_origin_velocity[:, k] + np.cross(w[:, k], r)
            a = md.link_origin_acceleration[2, k] + np.cross(al[2, k], r[2]) + np.cross(
                w[2, k], np.cross(w[2, k], r[2]))
            assert np.abs(np.tensordot(five, v, axes=(0, 0)) - a).max() <= 1e-6 * size, (
                shape, joint.name, body)
            checked += 1
    assert checked >= 6

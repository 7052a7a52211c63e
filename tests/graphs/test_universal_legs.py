"""U–P–S legs in the point formulation (modes/spatial_point_legs.py ``UniversalLeg``): each leg
one sphere of its ball's centre about its U's. Checked on a 3-UPS/S orientation wrist (a
platform on a central ball, turned by three U–P–S legs) against Newton on the platform's
rotation from many random starts and against the graph tracker's drawn mode (joint for joint:
the U roots nearer the drawing), and on the 6-UPS Stewart example against the Stewart route
(Study coordinates, elimination template)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from tests.graphs.newton_poses import newton_poses

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.modes.every_mode import (
    closure_formulation,
    every_mode,
    solve_formulation,
)
from screwkit.kinematics.modes.spatial_points import SpatialPointFormulation
from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation
from screwkit.model.mechanism import Body, Mechanism, MechanismJoint

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


def _wrist(rng: np.random.Generator) -> Mechanism:
    """A 3-UPS/S wrist (m): a platform on a ball at the origin 0.3 up, three legs from U joints
    on the ground (first axis horizontal and square to the leg, second square to it and the
    leg) to balls on the platform, each driven at its slide; joints moved at random."""
    th = np.radians([90.0, 210.0, 330.0]) + rng.uniform(-0.2, 0.2, 3)
    base = np.stack([0.25 * np.cos(th), 0.25 * np.sin(th), np.zeros(3)], 1)
    top = np.stack([0.12 * np.cos(th + 0.3), 0.12 * np.sin(th + 0.3), 0.3 + np.zeros(3)], 1)
    top += rng.uniform(-0.02, 0.02, (3, 3))
    centre = np.array([0.0, 0.0, 0.3])
    bodies = [Body(f"{n}{i}") for i in (1, 2, 3) for n in ("cylinder", "piston")]
    joints = [MechanismJoint("O", "S", ("ground", "platform"), centre, np.array([0, 0, 1.0]))]
    for i in range(3):
        d = (top[i] - base[i]) / np.linalg.norm(top[i] - base[i])
        e1 = np.cross([0.0, 0.0, 1.0], d)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(d, e1)
        joints += [MechanismJoint(f"U{i + 1}", "U", ("ground", f"cylinder{i + 1}"), base[i], e1,
                                  axis2=e2),
                   MechanismJoint(f"P{i + 1}", "P", (f"cylinder{i + 1}", f"piston{i + 1}"),
                                  (base[i] + top[i]) / 2, d),
                   MechanismJoint(f"S{i + 1}", "S", (f"piston{i + 1}", "platform"), top[i],
                                  np.array([0, 0, 1.0]))]
    return Mechanism("3-UPS/S wrist", (*bodies, Body("platform")), tuple(joints),
                     ("P1.s", "P2.s", "P3.s"))


def _rotations(mech: Mechanism, s: np.ndarray, rng: np.random.Generator, starts: int
               ) -> np.ndarray:
    """Every platform rotation (rows of 9) at the slides s: Newton (least squares) on the
    rotation vector from random starts, each ball R (q_i − O) + O at its leg's slid length
    from its U's centre."""
    O = mech.joint("O").at
    B = np.array([mech.joint(f"U{i}").at for i in (1, 2, 3)])
    q = np.array([mech.joint(f"S{i}").at for i in (1, 2, 3)])
    u = np.array([mech.joint(f"P{i}").axis for i in (1, 2, 3)])
    length2 = np.sum((q - B + s[:, None] * u) ** 2, axis=1)

    def F(R: np.ndarray, c: np.ndarray) -> np.ndarray:
        return (np.sum(((q - O) @ R.T + c - B) ** 2, axis=1) - length2) / 0.01

    return newton_poses(F, O, rng, starts, turn_only=True, residual=1e-11)[:, :9]


def test_every_wrist_mode_is_newtons_and_the_drawn_one_is_the_trackers() -> None:
    """Two random wrists at three slides each: the point formulation (9 unknowns, its legs as
    spheres) gives exactly the platform rotations Newton finds from 200 random starts, every
    mode certified and closing to 1e-10; the drawing's inputs give the tracker's drawn mode
    joint for joint among them."""
    for seed in (3, 4):
        rng = np.random.default_rng(seed)
        mech = _wrist(rng)
        form = closure_formulation(mech)
        assert isinstance(form, SpatialPointFormulation)
        assert len(form.universals) == 3 and form.system.n == 9
        X = np.array([[0.0, 0.0, 0.0], [0.02, -0.01, 0.015], [-0.01, 0.01, 0.0]])
        found = every_mode(mech, X)
        assert found.worst_closure <= 1e-10 * mech.length_scale
        lay = graph_layout(mech)
        k = lay.body_of["platform"]
        for n, s in enumerate(X):
            conf = found.configurations[n]
            assert conf.size >= 1 and found.certified[n].all()
            assert found.found[n] == found.generic_count == 8  # a 3-UPS/S wrist's 8
            ours = graph_forward(mech, lay, conf).R[:, k].reshape(-1, 9)
            theirs = _rotations(mech, s, rng, 200)
            assert len(ours) == len(theirs), (seed, n, len(ours), len(theirs))
            assert all(np.abs(theirs - x).max(1).min() <= 1e-8 for x in ours)
        drawn = solve_mechanism(mech, X[:1]).modes[0].conf
        assert np.abs(found.configurations[0].scalars - drawn.scalars[0]).max(1).min() <= 1e-9


def test_the_stewart_example_by_points_is_the_stewart_route() -> None:
    """The 6-UPS example by points (six spheres, 18 unknowns, 40 by monodromy) against the
    Stewart route that every_mode picks for it: the same platform poses at two inputs, and
    the same leg joints (both decode a U on its root nearer the drawing)."""
    spec = sk.load_spec(EXAMPLES / "stewart_platform.toml")
    mech = spec.mechanism
    form = spatial_point_formulation(mech)
    assert len(form.universals) == 6 and form.system.n == 18
    assert form.start().generic_count == 40
    X = spec.inputs[[0, 20]]
    sol = solve_formulation(form, form.parameters(X))
    stewart = every_mode(mech, X)
    lay = graph_layout(mech)
    for n in range(len(X)):
        conf, _ = form.configuration(sol.x[(sol.instance == n) & sol.real], X[n])
        theirs = stewart.configurations[n]
        assert conf.size == theirs.size >= 2
        gap = np.abs(conf.scalars[:, None, :] - theirs.scalars[None, :, :]).max(axis=2)
        assert gap.min(axis=1).max() <= 1e-8 * max(1.0, mech.length_scale)
        assert np.abs(graph_forward(mech, lay, conf).residual).max() <= 1e-10

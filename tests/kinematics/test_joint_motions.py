"""The table-driven forward kinematics of a graph (kinematics/graph/joint_motions.py, used by
closure.graph_forward) against an independent construction: every joint's 4 × 4 transform
from scipy's rotation vectors, composed by hand along the spanning tree; and every freedom's
world screw against central differences of the body it moves."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.newton import increment
from screwkit.kinematics.tracker.loop import Configuration, closure_twist, rotation_matrix
from screwkit.model.mechanism import GROUND, Body, Mechanism, MechanismJoint

KINDS = "RPCHUS"


def _mechanism(rng: np.random.Generator) -> Mechanism:
    """Two loops through every joint kind on random lines, some joints listed against the tree,
    some made off their drawing (seat offsets), an H with a random pitch."""
    bodies = [Body(f"b{i}") for i in range(1, 8)]
    names = [GROUND, *(b.name for b in bodies)]
    # a chain ground–b1–…–b7 and two chords back to the ground and to b2
    pairs = [(names[i], names[i + 1]) for i in range(7)] + [(names[7], GROUND), (names[5], "b2")]
    joints = []
    for i, (a, b) in enumerate(pairs):
        kind = KINDS[i % len(KINDS)]
        if rng.random() < 0.4:
            a, b = b, a
        joints.append(MechanismJoint(
            f"j{i}", kind, (a, b), rng.normal(size=3), rng.normal(size=3),
            axis2=rng.normal(size=3) if kind == "U" else None,
            pitch=float(rng.normal()) if kind == "H" else 0.0,
            seat_offset=rng.normal(size=3) * 0.1 if rng.random() < 0.3 else None))
    return Mechanism("every kind", tuple(bodies), tuple(joints), ("j0.theta",))


def _transform(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


def _joint_transform(j: MechanismJoint, values: list[float], ball: np.ndarray | None
                     ) -> np.ndarray:
    """M_j(q) as a 4 × 4 matrix: a screw motion about the joint's line through ``at``
    (scipy's rotation vectors), then the seat offset."""
    c, u = j.at, j.axis
    if j.kind == "S":
        assert ball is not None
        R, slide = ball, 0.0
    elif j.kind == "P":
        R, slide = np.eye(3), values[0]
    elif j.kind == "U":
        assert j.axis2 is not None
        R = (Rotation.from_rotvec(u * values[0]) * Rotation.from_rotvec(j.axis2 * values[1])
             ).as_matrix()
        slide = 0.0
    else:
        R = Rotation.from_rotvec(u * values[0]).as_matrix()
        slide = {"R": 0.0, "C": values[1] if len(values) > 1 else 0.0,
                 "H": j.pitch * values[0]}[j.kind]
    T = _transform(np.eye(3), c + slide * u) @ _transform(R, np.zeros(3)) \
        @ _transform(np.eye(3), -c)
    if j.seat_offset is not None:
        T = T @ _transform(np.eye(3), j.seat_offset)
    return T


def _by_hand(mech: Mechanism, conf: Configuration, n: int) -> dict[str, np.ndarray]:
    lay = graph_layout(mech)
    poses = {GROUND: np.eye(4)}
    for k, parent, child in mech.topology.tree:
        j = mech.joints[k]
        f0 = lay.first_freedom[k]
        values = [float(conf.scalars[n, lay.scalar_col[f0 + i]])
                  for i in range(len(j.freedoms)) if lay.scalar_col[f0 + i] >= 0]
        ball = conf.spherical[n, lay.spherical_of_joint[k]] if j.kind == "S" else None
        M = _joint_transform(j, values, ball)
        poses[child] = poses[parent] @ (M if j.bodies[0] == parent else np.linalg.inv(M))
    return poses


@pytest.mark.parametrize("seed", range(4))
def test_body_poses_and_closures_are_the_hand_composed_transforms(seed: int) -> None:
    rng = np.random.default_rng(seed)
    mech = _mechanism(rng)
    assert sorted({j.kind for j in mech.joints}) == sorted(KINDS)
    lay = graph_layout(mech)
    N = 5
    conf = Configuration(rng.normal(size=(N, lay.n_scalar)), rotation_matrix(
        rng.normal(size=(N * lay.n_spherical, 3))).reshape(N, lay.n_spherical, 3, 3))
    fr = graph_forward(mech, lay, conf)
    for n in range(N):
        poses = _by_hand(mech, conf, n)
        for name, T in poses.items():
            b = lay.body_of[name]
            assert np.abs(fr.R[n, b] - T[:3, :3]).max() <= 1e-13
            assert np.abs(fr.p[n, b] - T[:3, 3]).max() <= 1e-12
        for l, k in enumerate(mech.topology.chords):  # E = T_a M_j T_b⁻¹, its logarithm
            j = mech.joints[k]
            f0 = lay.first_freedom[k]
            values = [float(conf.scalars[n, lay.scalar_col[f0 + i]])
                      for i in range(len(j.freedoms)) if lay.scalar_col[f0 + i] >= 0]
            ball = conf.spherical[n, lay.spherical_of_joint[k]] if j.kind == "S" else None
            E = poses[j.bodies[0]] @ _joint_transform(j, values, ball) \
                @ np.linalg.inv(poses[j.bodies[1]])
            twist = closure_twist(E[None, :3, :3], E[None, :3, 3])[0]
            assert np.abs(fr.residual[n, l] - twist).max() <= 1e-11


@pytest.mark.parametrize("seed", range(2))
def test_each_screw_is_the_motion_of_the_body_its_freedom_moves(seed: int) -> None:
    """S_f is ± the world twist (ω; v at the origin) the tree child of freedom f's joint gains
    per unit of q_f: central differences of its pose, h = 1e-6."""
    rng = np.random.default_rng(10 + seed)
    mech = _mechanism(rng)
    lay = graph_layout(mech)
    conf = Configuration(rng.normal(size=(1, lay.n_scalar)), rotation_matrix(
        rng.normal(size=(lay.n_spherical, 3))).reshape(1, lay.n_spherical, 3, 3))
    fr = graph_forward(mech, lay, conf)
    h = 1e-6
    for k, parent, child in mech.topology.tree:
        sign = 1.0 if mech.joints[k].bodies[0] == parent else -1.0
        b = lay.body_of[child]
        for f in range(lay.first_freedom[k], lay.first_freedom[k] + len(mech.joints[k].freedoms)):
            ends = []
            for s in (h, -h):
                delta = np.zeros((1, lay.m))
                delta[0, f] = s
                g = graph_forward(mech, lay, increment(conf, delta, lay))
                ends.append((g.R[0, b], g.p[0, b]))
            (Ra, pa), (Rb, pb) = ends
            ER = Ra @ Rb.T
            twist = closure_twist(ER[None], (pa - ER @ pb)[None])[0] / (2 * h)
            assert np.abs(sign * fr.screws[0, :, f] - twist).max() <= 1e-7, (k, f)

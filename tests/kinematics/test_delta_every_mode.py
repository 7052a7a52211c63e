"""Every mode of the bundled Delta robot (modes/delta.py): the closed-form plate positions and
leg branches against the rod-length law, the homotopy's modes against Newton's method from
many random plate poses, the fold where the two plate positions meet against the closed form's
discriminant, and every mode along a short motion through the front door and the CLI."""

from __future__ import annotations

import json
from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq
from typer.testing import CliRunner

import screwkit as sk
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.graph.motion import build_mode, solve_mechanism
from screwkit.kinematics.modes.along import pose_vectors
from screwkit.kinematics.modes.delta import (
    DeltaFormulation,
    arm_angles,
    delta_configuration,
    delta_from_mechanism,
    plate_positions,
)
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.model.mechanism import Mechanism

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


@lru_cache(maxsize=1)
def _spec():  # type: ignore[no-untyped-def]
    return sk.load_spec(EXAMPLES / "delta_robot.toml")


def _rod_lengths(dm, X, R, t):  # type: ignore[no-untyped-def]
    """‖R P_k + t − E_k‖ (N, 6): the rod-length law, from the poses alone."""
    ends = np.einsum("nij,kj->nki", R, dm.feet) + t[:, None, :]
    return np.linalg.norm(ends - dm.elbows(X), axis=2)


def _rotation(w: np.ndarray) -> np.ndarray:
    th = np.linalg.norm(w, axis=1)[:, None, None]
    k = w / np.maximum(np.linalg.norm(w, axis=1), 1e-300)[:, None]
    K = np.zeros((len(w), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * (K @ K)


def _spheres(c: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """Both points (2N, 3) on three spheres (centres c (N, 3, 3), squared radii r2 (3,)),
    the real part where they miss: Newton's starts."""
    n = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    M = np.stack([2 * (c[:, 1] - c[:, 0]), 2 * (c[:, 2] - c[:, 0]), n], axis=1)
    cc = np.sum(c * c, axis=2)
    rhs = np.stack([cc[:, 1] - cc[:, 0] - r2[1] + r2[0], cc[:, 2] - cc[:, 0] - r2[2] + r2[0],
                    np.sum(n * c[:, 0], axis=1)], axis=1)
    t0 = np.linalg.solve(M, rhs[..., None])[..., 0]
    lam = np.sqrt(np.abs(r2[0] - np.sum((t0 - c[:, 0]) ** 2, axis=1)) / np.sum(n * n, axis=1))
    return np.concatenate([t0 + lam[:, None] * n, t0 - lam[:, None] * n])


def _newton_poses(dm, x: np.ndarray, per_triple: int, seed: int  # type: ignore[no-untyped-def]
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Every distinct real plate pose Newton's method reaches from random starts: uniform
    random rotations, each with the two translations that fit three of the rods (one per arm,
    all eight choices), then Gauss–Newton on the six rod equations
    ‖R P_k + t − E_k‖² = L_k², R ← exp(δ) R, t ← t + δt (brute force, independent of the
    Study system)."""
    rng = np.random.default_rng(seed)
    E, L2 = dm.elbows(x[None])[0], dm.lengths ** 2
    Rs, ts = [], []
    for trip in ([0, 2, 4], [0, 2, 5], [0, 3, 4], [0, 3, 5], [1, 2, 4], [1, 2, 5], [1, 3, 4],
                 [1, 3, 5]):
        q = rng.normal(size=(per_triple, 4))
        q /= np.linalg.norm(q, axis=1, keepdims=True)
        R = _rotation(2 * np.arctan2(np.linalg.norm(q[:, 1:], axis=1), q[:, 0])[:, None]
                      * q[:, 1:] / np.linalg.norm(q[:, 1:], axis=1, keepdims=True))
        c = E[None, trip] - np.einsum("nij,kj->nki", R, dm.feet[trip])
        Rs.append(np.concatenate([R, R]))
        ts.append(_spheres(c, L2[trip]))
    R, t = np.concatenate(Rs), np.concatenate(ts)
    for _ in range(40):
        a = np.einsum("nij,kj->nki", R, dm.feet)
        d = a + t[:, None, :] - E
        f = np.sum(d * d, axis=2) - L2
        J = np.concatenate([2 * np.cross(a, d), 2 * d], axis=2)
        JT = np.swapaxes(J, 1, 2)
        step = -np.linalg.solve(JT @ J + 1e-30 * np.eye(6), JT @ f[..., None])[..., 0]
        step = np.clip(step, -0.3, 0.3)
        R = _rotation(step[:, :3]) @ R
        t = t + step[:, 3:]
    d = np.einsum("nij,kj->nki", R, dm.feet) + t[:, None, :] - E
    ok = np.abs(np.sum(d * d, axis=2) - L2).max(axis=1) < 1e-12 * L2.max()
    R, t = R[ok], t[ok]
    keep: list[int] = []
    for i in range(len(R)):
        if all(max(np.abs(R[i] - R[j]).max(), np.abs(t[i] - t[j]).max()) > 1e-6 for j in keep):
            keep.append(i)
    return R[keep], t[keep]


def _plate_pose(mech, conf):  # type: ignore[no-untyped-def]
    lay = graph_layout(mech)
    fr = graph_forward(mech, lay, conf)
    b = lay.body_of[delta_from_mechanism(mech).plate]
    return fr.R[:, b], fr.p[:, b], fr


def test_recognised_from_the_graph_and_refused_with_the_reason() -> None:
    mech = _spec().mechanism
    form = closure_formulation(mech)
    assert isinstance(form, DeltaFormulation)
    dm = form.delta
    assert [a.body for a in dm.arms] == ["arm1", "arm2", "arm3"] and dm.plate == "plate"
    assert {r for a in dm.arms for r in a.rods} == {f"rod{i}{s}" for i in "123" for s in "ab"}
    # renamed bodies are still recognised: the structure is read, not the names
    names = {b.name: f"b{k}" for k, b in enumerate(mech.bodies)}
    renamed = replace(mech, bodies=tuple(replace(b, name=names[b.name]) for b in mech.bodies),
                      joints=tuple(replace(j, bodies=tuple(names.get(x, x) for x in j.bodies))
                                   for j in mech.joints),
                      points=tuple(replace(p, body=names[p.body]) for p in mech.points))
    assert delta_from_mechanism(renamed).plate == names["plate"]
    with pytest.raises(CapabilityError, match="parallelogram"):
        delta_from_mechanism(_skewed(mech))


def _skewed(mech: Mechanism) -> Mechanism:
    """The Delta with one plate ball moved 5 mm: its drawing still closes, but arm 1's rods
    are no parallelogram."""
    joints = tuple(replace(j, at=j.at + np.array([0.0, 0.0, 0.005])) if j.name == "P1a" else j
                   for j in mech.joints)
    return replace(mech, joints=joints)


def test_plate_positions_close_and_inverse_kinematics_gives_the_arms_back() -> None:
    spec = _spec()
    mech, dm = spec.mechanism, delta_from_mechanism(spec.mechanism)
    rng = np.random.default_rng(7)
    X = np.concatenate([np.asarray(spec.inputs)[::7], rng.uniform(-0.6, 0.6, size=(8, 3))])
    pp = plate_positions(dm, X)
    assert pp.real.all() and not pp.singular.any()
    N = len(X)
    R = np.broadcast_to(np.eye(3), (N, 3, 3))
    for k in range(2):
        np.testing.assert_allclose(_rod_lengths(dm, X, R, pp.t[:, k]),
                                   np.broadcast_to(dm.lengths, (N, 6)), rtol=0, atol=1e-12)
        conf = delta_configuration(dm, X, R, pp.t[:, k])
        Rp, tp, fr = _plate_pose(mech, conf)
        assert np.abs(fr.residual).max() < 1e-10
        np.testing.assert_allclose(tp, pp.t[:, k], atol=1e-12)
    np.testing.assert_allclose(pp.t[0, 1], 0.0, atol=1e-12)  # the drawing's position
    # inverse kinematics: one of each arm's two branches is the input, the other closes too
    ik = arm_angles(dm, pp.t[:, 1])
    assert ik.real.all()
    gap = np.angle(np.exp(1j * (ik.angles - X[:, :, None])))
    assert np.abs(gap).min(axis=2).max() < 1e-10
    other = np.where(np.abs(gap[..., 0]) < np.abs(gap[..., 1]), ik.angles[..., 1],
                     ik.angles[..., 0])
    assert np.abs(np.angle(np.exp(1j * (other - X)))).min() > 1e-3  # a distinct branch
    back = plate_positions(dm, other)
    assert np.min(np.abs(back.t - pp.t[:, 1][:, None, :]).max(axis=2), axis=1).max() < 1e-10


@lru_cache(maxsize=1)
def _modes_at_second_row():  # type: ignore[no-untyped-def]
    spec = _spec()
    x = np.asarray(spec.inputs)[1]
    return x, every_mode(spec.mechanism, x[None])


def test_every_mode_against_newton_from_many_starts() -> None:
    mech = _spec().mechanism
    dm = delta_from_mechanism(mech)
    x, modes = _modes_at_second_row()
    conf = modes.configurations[0]
    assert modes.worst_closure <= 1e-10 * mech.length_scale
    Rp, tp, fr = _plate_pose(mech, conf)
    assert np.abs(fr.residual).max() < 1e-10
    np.testing.assert_allclose(_rod_lengths(dm, x[None], Rp, tp),
                               np.broadcast_to(dm.lengths, (conf.size, 6)), atol=1e-12)
    assert conf.size == 16  # 2 translating modes, 14 with the plate turned
    Rn, tn = _newton_poses(dm, x, 200, 27)
    gap = np.maximum(np.abs(Rp[:, None] - Rn[None]).max(axis=(2, 3)),
                     np.abs(tp[:, None] - tn[None]).max(axis=2))
    # Newton from 3200 starts reaches exactly the homotopy's 16 poses: one to one
    assert len(Rn) == 16
    assert gap.min(axis=0).max() < 1e-8 and gap.min(axis=1).max() < 1e-8
    # the translating ones are the closed form's two plate positions
    level = np.abs(Rp - np.eye(3)).max(axis=(1, 2)) < 1e-9
    pp = plate_positions(dm, x[None])
    assert level.sum() == 2
    assert np.abs(tp[level][:, None] - pp.t[0][None]).max(axis=2).min(axis=1).max() < 1e-10
    # the drawn mode, followed from the drawing by the graph tracker, is one of them
    lay = graph_layout(mech)
    drawn = follow_drawn_mode(mech, lay, x[None])
    d = np.abs(pose_vectors(mech, lay, conf) - pose_vectors(mech, lay, drawn.conf)).max(axis=1)
    assert d.min() < 1e-9


def test_the_two_plate_positions_meet_at_a_fold() -> None:
    """Arm 1 turned with the others held: the closed form's discriminant crosses zero near
    120°; there the two positions are one (reported singular, and an output singularity of
    the graph), and the homotopy's level modes go from two to none across it."""
    mech = _spec().mechanism
    dm = delta_from_mechanism(mech)

    def disc(th: float) -> float:
        return float(plate_positions(dm, [[th, 0.0, 0.0]]).discriminant[0])

    th = brentq(disc, np.radians(110.0), np.radians(125.0), xtol=1e-14)
    at = plate_positions(dm, [[th, 0.0, 0.0]])
    assert at.singular[0] and np.abs(at.t[0, 0] - at.t[0, 1]).max() < 1e-6
    # the graph's singularity classes call it an output singularity; 0.05 rad back, regular
    lay = graph_layout(mech)
    Xs = np.array([[th, 0.0, 0.0], [th - 0.05, 0.0, 0.0]])
    conf = delta_configuration(dm, Xs, np.broadcast_to(np.eye(3), (2, 3, 3)),
                               plate_positions(dm, Xs).t[:, 0])
    md = build_mode(mech, lay, conf, np.ones(2, dtype=bool), Xs, np.zeros_like(Xs),
                    np.zeros_like(Xs))
    assert list(md.singular_class) == ["output", ""]
    assert md.jacobian_condition["passive"][0] > 1e8 > 1e4 > md.jacobian_condition["passive"][1]
    side = np.radians(0.5)
    X = np.array([[th - side, 0.0, 0.0], [th + side, 0.0, 0.0]])
    pp = plate_positions(dm, X)
    assert list(pp.real) == [True, False] and not pp.singular.any()
    modes = every_mode(mech, X)
    level = []
    for x, conf in zip(X, modes.configurations, strict=True):
        Rp, tp, _ = _plate_pose(mech, conf)
        level.append(int((np.abs(Rp - np.eye(3)).max(axis=(1, 2)) < 1e-9).sum()))
        Rn, tn = _newton_poses(dm, x, 200, 5)  # and all of them, one to one with Newton's
        gap = np.maximum(np.abs(Rp[:, None] - Rn[None]).max(axis=(2, 3)),
                         np.abs(tp[:, None] - tn[None]).max(axis=2))
        assert len(Rn) == conf.size and gap.min(axis=1).max() < 1e-8
    assert level == [2, 0]


def test_every_mode_along_a_short_motion_through_the_front_door() -> None:
    """Samples 4–8 of the bundled motion (anchors at both ends): two modes with the plate
    turned die together between samples 6 and 7 (one circuit); the drawn mode is the plain
    solve's; every mode closes and has its Jacobian condition number."""
    spec = _spec()
    mech = spec.mechanism
    X = np.asarray(spec.inputs)[4:9]
    motion = solve_mechanism(mech, X, every_mode=True)
    assert motion.method == "graph (homotopy at anchors, tracking between)"
    assert motion.modes[0].label == "drawn" and len(motion.modes) == 16
    plain = solve_mechanism(mech, X)
    for name, v in plain.modes[0].variables.items():
        np.testing.assert_allclose(motion.modes[0].variables[name], v, atol=1e-10)
    dying = []
    for k, md in enumerate(motion.modes):
        assert not any(e.startswith("cut after") for e in md.events), md.events
        assert np.nanmax(md.closure_residual[md.assembles]) < 1e-9
        cond = md.jacobian_condition["passive"][md.assembles]
        assert np.all(np.isfinite(cond)) and np.all(cond >= 1.0)
        if any(e.startswith("dies at") for e in md.events):
            dying.append(k)
            assert list(md.assembles) == [True, True, True, False, False]
    assert len(dying) == 2
    assert "{" + ", ".join(map(str, dying)) + "}" in motion.notes[-1]


def test_the_cli_lists_every_mode(tmp_path: Path) -> None:
    from screwkit.cli.main import app

    text = (EXAMPLES / "delta_robot.toml").read_text()
    head, rest = text.split("rows = [", 1)
    rows = rest.split("]\nspeed", 1)[1]
    spec = tmp_path / "delta3.toml"
    spec.write_text(head + "rows = [\n  [0, 0, 0],\n  [-1.2102863008, 0.5939728062, "
                    "0.7318354071],\n]\nspeed" + rows)
    r = CliRunner().invoke(app, ["analyze", str(spec), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    labels = [m["label"] for m in doc["modes"]]
    assert labels[0] == "drawn" and len(labels) >= 16
    assert doc["notes"][0].startswith("every mode along the motion")
    assert all("jacobian_condition" in m for m in doc["modes"])


def test_the_front_door_verbs() -> None:
    spec = _spec()
    X = np.asarray(spec.inputs)[:3]
    fk = sk.delta_forward(spec.mechanism, X)
    np.testing.assert_allclose(fk.t, plate_positions(delta_from_mechanism(spec.mechanism),
                                                     X).t, atol=0)
    ik = sk.delta_inverse(spec.mechanism, fk.t[:, 1])
    assert np.abs(np.angle(np.exp(1j * (ik.angles - X[:, :, None])))).min(axis=2).max() < 1e-10
    with pytest.raises(sk.ScrewkitError, match="arm angles"):
        sk.delta_forward(spec.mechanism, np.zeros((2, 2)))
    with pytest.raises(CapabilityError, match="not a Delta robot"):
        sk.delta_forward(sk.load_spec(EXAMPLES / "stewart_platform.toml").mechanism, X)

"""Pivoted legs (modes/spatial_point_legs.py): the R–P–S legs of a 3-RPS parallel robot as two
equations on each ball's centre. Checked against an independent solve of the platform's pose
(rotation vector and position, the six leg equations written here from the geometry, Newton
from many random poses), and the legs' decoded joints against the inputs and the R axes."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from tests.graphs.newton_poses import newton_poses
from tests.graphs.three_rps import PATH, write_spec

import screwkit as sk
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.kinematics.modes.spatial_points import SpatialPointFormulation
from screwkit.model.mechanism_drives import BodyDrive


def _platform_poses(mech: sk.Mechanism, s: np.ndarray, rng: np.random.Generator,
                    starts: int) -> np.ndarray:
    """Every platform pose (rows: rotation entries, position / length scale) at the slides s,
    by Newton (least squares) on the pose from random starts: each ball Q_i = R q_i + t on
    its leg's circle about the R axis, (Q_i − A_i)·a_i = (q_i + s_i u_i − A_i)·a_i and
    ‖Q_i − A_i‖ = ‖q_i + s_i u_i − A_i‖ (the leg turns about its axis and slides along u_i)."""
    L = mech.length_scale
    A = np.array([mech.joint(f"R{i}").at for i in (1, 2, 3)]) / L
    a = np.array([mech.joint(f"R{i}").axis for i in (1, 2, 3)])
    q = np.array([mech.joint(f"S{i}").at for i in (1, 2, 3)]) / L
    sign = np.array([1.0 if mech.joint(f"P{i}").bodies[1] == f"piston{i}" else -1.0
                     for i in (1, 2, 3)])
    u = np.array([mech.joint(f"P{i}").axis for i in (1, 2, 3)]) * sign[:, None]
    arm = q + (s / L)[:, None] * u - A
    h, r2 = np.einsum("ij,ij->i", arm, a), np.einsum("ij,ij->i", arm, arm)
    centre = q.mean(0)

    def F(R: np.ndarray, c: np.ndarray) -> np.ndarray:
        Q = (q - centre) @ R.T + c - A
        return np.concatenate([np.einsum("ij,ij->i", Q, a) - h, np.einsum("ij,ij->i", Q, Q) - r2])

    return newton_poses(F, centre, rng, starts)


@pytest.mark.parametrize("seed", [None, 5])
def test_every_3rps_mode_is_newtons(seed: int | None, tmp_path: Path) -> None:
    """At three inputs, every real mode of the 3-RPS (tests/graphs/three_rps.py: the example's,
    and a general one; one P joint drawn the other way) by the point formulation (9 unknowns;
    generic count 16, the 3-RPS's forward kinematics) has a platform pose that Newton on the
    pose finds from 300 random starts, and Newton finds none that the homotopy misses; the
    sliders slide by the inputs, each arm turns about its R axis and every mode closes."""
    path = tmp_path / "rps.toml"
    write_spec(path, None if seed is None else np.random.default_rng(seed), reversed_leg=1)
    spec = sk.load_spec(path)
    mech = spec.mechanism
    form = closure_formulation(mech)
    assert isinstance(form, SpatialPointFormulation)
    assert len(form.pivots) == 3 and form.system.n == 9
    X = spec.inputs[[0, 6, 20]]
    found = every_mode(mech, X)
    assert found.generic_count == 16
    assert found.worst_closure <= 1e-10 * mech.length_scale
    lay = graph_layout(mech)
    k = lay.body_of["platform"]
    rng = np.random.default_rng(0)
    for n, s in enumerate(X):
        conf = found.configurations[n]
        assert found.certified[n].all() and conf.size >= 2
        fr = graph_forward(mech, lay, conf)
        ours = np.concatenate([fr.R[:, k].reshape(-1, 9), fr.p[:, k] / mech.length_scale], 1)
        theirs = _platform_poses(mech, s, rng, 300)
        assert len(ours) == len(theirs), (n, len(ours), len(theirs))
        assert all(np.abs(theirs - x).max(1).min() <= 1e-8 for x in ours)
        for i in (1, 2, 3):
            col = lay.scalar_col[lay.names.index(f"P{i}.s")]
            np.testing.assert_allclose(conf.scalars[:, col], s[i - 1],
                                       atol=1e-9 * mech.length_scale)
            r = mech.joint(f"R{i}")
            arm = fr.R[:, lay.body_of[f"cylinder{i}"]]
            np.testing.assert_allclose(arm @ r.axis, np.broadcast_to(r.axis, (len(arm), 3)),
                                       atol=1e-12)
            np.testing.assert_allclose(arm, fr.R[:, lay.body_of[f"piston{i}"]], atol=1e-12)


def test_a_3rps_driven_at_its_platforms_height_roll_and_pitch() -> None:
    """The 3-RPS driven, as such robots are specified, at its platform's height, roll and pitch
    (x, y and yaw follow): its legs' slides passive and square to their R axes, so each leg
    is one equation, its ball in its plane; two of the drives are turns. At three inputs every
    real mode is a pose Newton finds from 200 random starts on equations written here (each
    ball in its leg's plane; the centre's height; R Rx(−ρ) with third row (−sin φ, 0, cos φ),
    the rotation being Rz(ψ) Ry(φ) Rx(ρ) for some ψ), and Newton finds none the homotopy
    misses; each mode's pose has that height, roll and pitch, and the slides read off the
    balls' distances put each ball where its arm holds it (the closure)."""
    legs = sk.load_spec(PATH).mechanism  # the example: its slides square to their R axes
    L = legs.length_scale
    q = np.array([legs.joint(f"S{i}").at for i in (1, 2, 3)])
    centre = q.mean(0)
    mech = replace(legs, inputs=(), drives=(
        BodyDrive("platform.z", "platform", "z", centre),
        BodyDrive("platform.roll", "platform", "roll"),
        BodyDrive("platform.pitch", "platform", "pitch")))
    form = closure_formulation(mech)
    assert isinstance(form, SpatialPointFormulation)
    assert [pv.column for pv in form.pivots] == [None] * 3
    X = np.array([[0.0, 0.0, 0.0], [0.1 * L, 0.09, -0.05], [-0.15 * L, -0.17, 0.14]])
    found = every_mode(mech, X)
    assert found.worst_closure <= 1e-10 * L
    lay = graph_layout(mech)
    k = lay.body_of["platform"]
    A = np.array([legs.joint(f"R{i}").at for i in (1, 2, 3)]) / L
    a = np.array([legs.joint(f"R{i}").axis for i in (1, 2, 3)])
    h = np.einsum("ij,ij->i", q / L - A, a)
    c0 = centre / L
    rng = np.random.default_rng(0)
    for n, (z, rho, phi) in enumerate(X):
        conf = found.configurations[n]
        assert conf.size >= 1 and found.certified[n].all()
        fr = graph_forward(mech, lay, conf)
        ours = np.concatenate([fr.R[:, k].reshape(-1, 9), fr.p[:, k] / L], 1)
        c, s_ = np.cos(rho), np.sin(rho)
        unroll = np.array([[1.0, 0.0, 0.0], [0.0, c, s_], [0.0, -s_, c]])  # Rx(−ρ)

        def F(R: np.ndarray, p: np.ndarray, unroll: np.ndarray = unroll, z: float = z,
              phi: float = phi) -> np.ndarray:
            Q = (q / L - c0) @ R.T + p - A
            row = (R @ unroll)[2]
            return np.concatenate([np.einsum("ij,ij->i", Q, a) - h, [p[2] - c0[2] - z / L],
                                   [row[0] + np.sin(phi), row[1]]])

        theirs = newton_poses(F, c0, rng, 200)
        pitch_ok = [(R.reshape(3, 3) @ unroll)[2, 2] > 0.0 for R in theirs[:, :9]]
        theirs = theirs[np.array(pitch_ok, dtype=bool)]
        assert len(ours) == len(theirs), (n, len(ours), len(theirs))
        assert all(np.abs(theirs - x).max(1).min() <= 1e-8 for x in ours)
        R = fr.R[:, k]  # its pose is Trans · Rz(ψ) Ry(φ) Rx(ρ) at the driven height
        np.testing.assert_allclose((R @ unroll)[:, 2], np.broadcast_to(
            [-np.sin(phi), 0.0, np.cos(phi)], (len(R), 3)), atol=1e-10)
        np.testing.assert_allclose((R @ centre + fr.p[:, k])[:, 2] - centre[2], z,
                                   atol=1e-10 * L)


def test_the_example_is_its_generators() -> None:
    """examples/mechanisms/three_rps.toml is what tests/graphs/three_rps.py writes."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        assert write_spec(Path(folder) / "rps.toml") == PATH.read_text(encoding="utf-8")

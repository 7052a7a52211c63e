"""Pivoted legs (modes/spatial_point_legs.py): the R–P–S legs of a 3-RPS parallel robot as two
equations on each ball's centre. Checked against an independent solve of the platform's pose
(rotation vector and position, the six leg equations written here from the geometry, Newton
from many random poses), and the legs' decoded joints against the inputs and the R axes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tests.graphs.newton_poses import newton_poses
from tests.graphs.three_rps import PATH, write_spec

import screwkit as sk
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.kinematics.modes.spatial_points import SpatialPointFormulation


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


def test_the_example_is_its_generators() -> None:
    """examples/mechanisms/three_rps.toml is what tests/graphs/three_rps.py writes."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        assert write_spec(Path(folder) / "rps.toml") == PATH.read_text(encoding="utf-8")

"""Gimballed legs (modes/spatial_point_legs.py ``GimbalLeg``): the U–P–U legs of the
translational 3-UPU (examples/mechanisms/three_upu.toml) as two equations on each top U's
centre and platform arm. Checked against an independent solve of the platform's pose
(rotation vector and position, the leg conditions written here from the joints' geometry,
Newton from many random poses), against the graph tracker's drawn mode (the same joint
values: the decoded U roots are the drawing's), and by every mode's loop closure."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from tests.graphs.newton_poses import newton_poses
from tests.graphs.three_upu import write_tilted

import screwkit as sk
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.kinematics.modes.spatial_points import SpatialPointFormulation
from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation
from screwkit.model.mechanism_drives import BodyDrive

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "mechanisms" / "three_upu.toml"


def _platform_poses(mech: sk.Mechanism, s: np.ndarray, rng: np.random.Generator,
                    starts: int) -> np.ndarray:
    """Every platform pose (rows: rotation entries, position / length scale) at the slides s
    by Newton (least squares) on the pose from random starts. Leg i: its base U at C_i turns
    about e1 (the ground's axis) then e2 (the cylinder's), square to e1, to the leg and to
    the slide; the top U's piston axis is e2 too and its platform axis a_i square to it. So
    the leg vector Q_i − C_i keeps its slid length, and e2 ∝ e1 × (Q_i − C_i) is square to the
    platform's turned a_i."""
    L = mech.length_scale
    C = np.array([mech.joint(f"Ub{i}").at for i in (1, 2, 3)]) / L
    e1 = np.array([mech.joint(f"Ub{i}").axis for i in (1, 2, 3)])
    q = np.array([mech.joint(f"Up{i}").at for i in (1, 2, 3)]) / L
    a = np.array([mech.joint(f"Up{i}").axis2 for i in (1, 2, 3)])
    u = np.array([mech.joint(f"P{i}").axis for i in (1, 2, 3)])
    length2 = np.sum((q - C + (s / L)[:, None] * u) ** 2, axis=1)
    centre = q.mean(0)

    def F(R: np.ndarray, c: np.ndarray) -> np.ndarray:
        d = (q - centre) @ R.T + c - C
        return np.concatenate([np.sum(d * d, axis=1) - length2,
                               np.einsum("ij,ij->i", np.cross(e1, d), a @ R.T)])

    return newton_poses(F, centre, rng, starts)


@pytest.fixture(scope="module")
def upu() -> tuple[sk.Spec, object]:
    spec = sk.load_spec(EXAMPLE)
    X = spec.inputs[[0, 10, 25]]
    return spec, every_mode(spec.mechanism, X)


def test_every_3upu_mode_is_newtons_and_closes(upu: tuple[sk.Spec, object]) -> None:
    """At three inputs every real mode by the point formulation (18 unknowns; its generic
    count by monodromy) is a platform pose that Newton on the pose finds from 400 random
    starts, none missing on either side, every mode certified and closing to 1e-10; the
    translational mode among them (the platform square to the drawing) and rotated ones (the
    3-UPU's other operation modes)."""
    spec, found = upu
    mech = spec.mechanism
    form = closure_formulation(mech)
    assert isinstance(form, SpatialPointFormulation)
    assert len(form.gimbals) == 3 and form.system.n == 18
    assert found.generic_count >= 80  # type: ignore[attr-defined]
    assert found.worst_closure <= 1e-10 * mech.length_scale  # type: ignore[attr-defined]
    lay = graph_layout(mech)
    k = lay.body_of["platform"]
    rng = np.random.default_rng(1)
    for n, s in enumerate(spec.inputs[[0, 10, 25]]):
        conf = found.configurations[n]  # type: ignore[attr-defined]
        assert found.certified[n].all() and conf.size >= 4  # type: ignore[attr-defined]
        fr = graph_forward(mech, lay, conf)
        ours = np.concatenate([fr.R[:, k].reshape(-1, 9), fr.p[:, k] / mech.length_scale], 1)
        theirs = _platform_poses(mech, s, rng, 400)
        assert len(ours) == len(theirs), (n, len(ours), len(theirs))
        assert all(np.abs(theirs - x).max(1).min() <= 1e-8 for x in ours)
        turned = np.degrees(np.arccos(np.clip((np.trace(fr.R[:, k], axis1=1, axis2=2) - 1) / 2,
                                              -1, 1)))
        assert (turned < 1e-6).any() and (turned > 1.0).any()


def test_the_drawn_mode_is_the_trackers_joint_for_joint(upu: tuple[sk.Spec, object]) -> None:
    """The tracker's drawn mode is one of the modes with the same joint values (every U
    angle too): the legs are decoded on the U joints' roots nearer the drawing."""
    spec, found = upu
    X = spec.inputs[[0, 10, 25]]
    drawn = solve_mechanism(spec.mechanism, spec.inputs).modes[0].conf
    for n, row in enumerate((0, 10, 25)):
        conf = found.configurations[n]  # type: ignore[attr-defined]
        gap = np.abs(conf.scalars - drawn.scalars[row]).max(axis=1)
        assert gap.min() <= 1e-8, (n, gap.min())
        assert np.allclose(X[n], spec.inputs[row])


def test_legs_whose_axes_are_not_square_are_written_as_points(tmp_path: Path) -> None:
    """A platform U axis tilted off square to its piston axis: that leg is no gimballed leg
    and is written as points (one tilted: 42 unknowns, two legs gimballed); all three tilted:
    90 unknowns, refused by name."""
    def tilted(legs: tuple[int, ...]) -> sk.Mechanism:
        return sk.load_spec(write_tilted(tmp_path / f"tilted{len(legs)}.toml", legs)).mechanism

    one = spatial_point_formulation(tilted((1,)))
    assert (one.system.n, len(one.gimbals)) == (42, 2)
    with pytest.raises(CapabilityError, match="90 unknowns, more than 48"):
        spatial_point_formulation(tilted((1, 2, 3)))


def test_a_3upu_driven_at_its_platforms_travel_has_its_operation_modes(tmp_path: Path) -> None:
    """The 3-UPU driven at its platform's x, y and z (its legs' slides passive: each leg one
    equation, ((E − C) × (Q − C))·(A − Q) = g, the slide read off ‖Q − C‖): at three travels
    the platform rotations of its modes are exactly those Newton finds on the rotation (the
    centre held at its travel) from 300 random starts on the leg condition written as in
    :func:`_platform_poses`; the translational mode (no turn) is among them, and rotated
    ones (the 3-UPU's other operation modes)."""
    legs = sk.load_spec(EXAMPLE).mechanism
    L = legs.length_scale
    q = np.array([legs.joint(f"Up{i}").at for i in (1, 2, 3)])
    centre = q.mean(0)
    mech = replace(legs, inputs=(), drives=tuple(
        BodyDrive(f"platform.{f}", "platform", f, centre) for f in "xyz"))
    form = closure_formulation(mech)
    assert isinstance(form, SpatialPointFormulation)
    assert [gl.column for gl in form.gimbals] == [None] * 3
    X = np.array([[0.0, 0.0, 0.0], [0.05 * L, -0.02 * L, 0.1 * L], [-0.1 * L, 0.07 * L, -0.2 * L]])
    found = every_mode(mech, X)
    assert found.worst_closure <= 1e-10 * L
    lay = graph_layout(mech)
    k = lay.body_of["platform"]
    C = np.array([legs.joint(f"Ub{i}").at for i in (1, 2, 3)]) / L
    e1 = np.array([legs.joint(f"Ub{i}").axis for i in (1, 2, 3)])
    a = np.array([legs.joint(f"Up{i}").axis2 for i in (1, 2, 3)])
    c0 = centre / L
    rng = np.random.default_rng(2)
    for n, v in enumerate(X):
        conf = found.configurations[n]
        assert conf.size >= 2 and found.certified[n].all()
        R = graph_forward(mech, lay, conf).R[:, k]

        def F(Rn: np.ndarray, _: np.ndarray, v: np.ndarray = v) -> np.ndarray:
            d = (q / L - c0) @ Rn.T + c0 + v / L - C
            return np.einsum("ij,ij->i", np.cross(e1, d), a @ Rn.T)

        theirs = newton_poses(F, c0, rng, 300, turn_only=True)[:, :9]
        ours = R.reshape(-1, 9)
        assert len(ours) == len(theirs), (n, len(ours), len(theirs))
        assert all(np.abs(theirs - x).max(1).min() <= 1e-8 for x in ours)
        # the turn from ‖R − I‖_F = 2√2 sin(θ/2): good to rounding at θ ≈ 0, where arccos of
        # (tr R − 1)/2 loses half the digits (a last-bit change reads as ~1e-6°)
        gap = np.linalg.norm(R - np.eye(3), axis=(1, 2)) / (2.0 * np.sqrt(2.0))
        turned = np.degrees(2.0 * np.arcsin(np.clip(gap, 0.0, 1.0)))
        assert (turned < 1e-6).any() and (turned > 1.0).any()

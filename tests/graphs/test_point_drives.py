"""Driven body translations in the point formulation (modes/spatial_point_drives.py): the
double wishbone driven by its wheel centre's vertical travel, every mode checked against the
arm-driven double wishbone's closed-form dyads (the same hardpoints) scanned over the lower
arm's whole turn; and a driven turn refused by name."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closed_modes import every_mode as closed_every_mode
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.drives import augmented
from screwkit.kinematics.graph.subchains import decompose
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.kinematics.modes.spatial_points import SpatialPointFormulation

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


def _wheel(mech: sk.Mechanism, lay: object, conf: object) -> tuple[np.ndarray, np.ndarray]:
    """The wheel centre (N, 3) and the upright's pose rows (N, 12: rotation, position / L)."""
    fr = graph_forward(mech, lay, conf)  # type: ignore[arg-type]
    k = lay.body_of["upright"]  # type: ignore[attr-defined]
    w0 = next(p.at for p in mech.points if p.name == "wheel_centre")
    R, p = fr.R[:, k], fr.p[:, k]
    return (np.einsum("nij,j->ni", R, w0) + p,
            np.concatenate([R.reshape(-1, 9), p / mech.length_scale], axis=1))


def test_every_travel_mode_is_an_arm_mode_at_that_travel() -> None:
    """At three wheel travels, every mode of the travel-driven corner (the point formulation
    with one linear equation on the wheel centre) puts the wheel centre at that travel, and
    is, at its own lower-arm angle, one of the arm-driven corner's closed-form modes (the same
    upright pose); and their number is the number of times any closed-form mode's wheel travel
    crosses the value over the arm's whole turn (3,600 samples): none missing."""
    travel = sk.load_spec(EXAMPLES / "double_wishbone_travel.toml").mechanism
    arm = sk.load_spec(EXAMPLES / "double_wishbone.toml").mechanism
    whole = augmented(travel)
    form = closure_formulation(whole)
    assert isinstance(form, SpatialPointFormulation) and len(form.drives) == 1
    lay = graph_layout(whole)
    hinge = lay.scalar_col[lay.names.index(arm.inputs[0])]
    arm_lay = graph_layout(arm)
    dec = decompose(arm)
    theta = np.linspace(-np.pi, np.pi, 3601)
    closed = closed_every_mode(arm, arm_lay, dec, theta[:, None])
    M, N, k = closed.count, theta.size, arm_lay.body_of["upright"]
    ok = closed.assembles(N)
    R = closed.placement.R.reshape(M, N, *closed.placement.R.shape[1:])[:, :, k]
    p = closed.placement.p.reshape(M, N, *closed.placement.p.shape[1:])[:, :, k]
    w0 = next(q.at for q in arm.points if q.name == "wheel_centre")
    z0 = w0[2]
    with np.errstate(invalid="ignore"):
        heights = np.where(ok, (np.einsum("mnij,j->mni", R, w0) + p)[..., 2] - z0, np.nan)
    values = np.array([-0.040, 0.0021, 0.035])  # (not 0: the drawn mode is there on a sample)
    found = every_mode(whole, values[:, None])
    assert found.worst_closure <= 1e-10 * travel.length_scale
    for n, v in enumerate(values):
        conf = found.configurations[n]
        assert conf.size >= 2 and found.certified[n].all()
        centre, pose = _wheel(whole, lay, conf)
        np.testing.assert_allclose(centre[:, 2] - z0, v, atol=1e-10 * travel.length_scale)
        for row, th in enumerate(conf.scalars[:, hinge]):
            at = closed_every_mode(arm, arm_lay, dec, np.array([[th]]))
            good = at.assembles(1)[:, 0]
            theirs = np.concatenate([at.placement.R[good, k].reshape(-1, 9),
                                     at.placement.p[good, k] / arm.length_scale], axis=1)
            assert np.abs(theirs - pose[row]).max(axis=1).min() <= 1e-8, (v, th)
        crossings = 0
        for z in heights:  # each closed-form mode's wheel travel over the arm's turn
            d = z - v
            ok = np.isfinite(d[:-1]) & np.isfinite(d[1:])
            crossings += int(np.count_nonzero(ok & (np.sign(d[:-1]) != np.sign(d[1:]))))
        assert crossings == conf.size, (v, crossings, conf.size)


def test_the_travel_driven_modes_along_the_motion_keep_the_drawn_one() -> None:
    """Along the spec's travel the homotopy route gives every mode; mode 0 is the tracker's
    own drawn mode."""
    spec = sk.load_spec(EXAMPLES / "double_wishbone_travel.toml")
    x = spec.inputs[::4]
    every = solve_mechanism(spec.mechanism, x, every_mode=True)
    drawn = solve_mechanism(spec.mechanism, x)
    assert every.method.startswith("graph (homotopy") and len(every.modes) >= 2
    a, b = every.modes[0], drawn.modes[0]
    assert a.assembles.all() and b.assembles.all()
    np.testing.assert_allclose(a.link_rotation, b.link_rotation, atol=1e-9)
    np.testing.assert_allclose(a.link_origin, b.link_origin,
                               atol=1e-9 * spec.mechanism.length_scale)


def test_a_driven_turn_is_refused_by_name() -> None:
    mech = sk.load_spec(EXAMPLES / "stewart_platform_pose.toml").mechanism
    with pytest.raises(CapabilityError, match="driven at platform's roll, a turn"):
        from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation

        spatial_point_formulation(augmented(mech))


def test_every_mode_of_a_driven_mechanism_is_its_augmented_ones_restricted() -> None:
    """every_mode on the mechanism itself (inputs: its drives) gives the augmented
    mechanism's modes with the virtual chains left out: the real joints' variables."""
    from screwkit.kinematics.graph.drives import real_configuration

    travel = sk.load_spec(EXAMPLES / "double_wishbone_travel.toml").mechanism
    X = np.array([[-0.02], [0.01]])
    ours, whole = every_mode(travel, X), every_mode(augmented(travel), X)
    assert ours.mechanism is travel and ours.generic_count == whole.generic_count
    for a, b in zip(ours.configurations, whole.configurations, strict=True):
        assert a.size == b.size >= 2
        np.testing.assert_array_equal(a.scalars, real_configuration(travel, b).scalars)
        assert a.scalars.shape[1] == graph_layout(travel).n_scalar

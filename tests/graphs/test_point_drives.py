"""Driven body freedoms in the point formulation (modes/spatial_point_drives.py): the
double wishbone driven by its wheel centre's vertical travel, every mode checked against the
arm-driven double wishbone's closed-form dyads (the same hardpoints) scanned over the lower
arm's whole turn; the corner driven by its upright's roll (a driven turn) the same way; and
the Stewart platform driven at its whole pose."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closed_modes import every_mode as closed_every_mode
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.drives import augmented
from screwkit.kinematics.graph.subchains import decompose
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.kinematics.modes.spatial_points import SpatialPointFormulation
from screwkit.model.mechanism_drives import BodyDrive

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


def _wheel(mech: sk.Mechanism, lay: object, conf: object) -> tuple[np.ndarray, np.ndarray]:
    """The wheel centre (N, 3) and the upright's pose rows (N, 12: rotation, position / L)."""
    fr = graph_forward(mech, lay, conf)  # type: ignore[arg-type]
    k = lay.body_of["upright"]  # type: ignore[attr-defined]
    w0 = next(p.at for p in mech.points if p.name == "wheel_centre")
    R, p = fr.R[:, k], fr.p[:, k]
    return (np.einsum("nij,j->ni", R, w0) + p,
            np.concatenate([R.reshape(-1, 9), p / mech.length_scale], axis=1))


def _arm_scan(arm: sk.Mechanism) -> tuple[np.ndarray, np.ndarray, object, object]:
    """The arm-driven corner's closed-form modes over the lower arm's whole turn (3,600
    samples): the upright's rotation R (M, N, 3, 3) and position p (M, N, 3), NaN where a
    mode does not assemble."""
    arm_lay = graph_layout(arm)
    dec = decompose(arm)
    theta = np.linspace(-np.pi, np.pi, 3601)
    closed = closed_every_mode(arm, arm_lay, dec, theta[:, None])
    M, N, k = closed.count, theta.size, arm_lay.body_of["upright"]
    ok = closed.assembles(N)[..., None]
    R = closed.placement.R.reshape(M, N, *closed.placement.R.shape[1:])[:, :, k]
    p = closed.placement.p.reshape(M, N, *closed.placement.p.shape[1:])[:, :, k]
    return np.where(ok[..., None], R, np.nan), np.where(ok, p, np.nan), arm_lay, dec


def _crossings(values: np.ndarray, R: np.ndarray) -> int:
    """The zeros of the closed-form modes' ``values`` (M, N) over the arm's turn: sign changes
    between assembled samples of a mode, and sign changes across a fold, between the last
    samples of the two modes that meet there (paired by the nearest upright rotation R
    (M, N, 3, 3)): a zero between the last sample and the fold is on the path from one
    to the other."""
    fin = np.isfinite(values)
    ok = fin[:, :-1] & fin[:, 1:]
    count = int(np.count_nonzero(ok & (np.sign(values[:, :-1]) != np.sign(values[:, 1:]))))
    for i in range(values.shape[1] - 1):
        for n in (i, i + 1):  # modes ending after sample i, or starting at sample i + 1
            ends = list(np.nonzero(fin[:, n] & ~fin[:, 2 * i + 1 - n])[0])
            while len(ends) >= 2:
                d = {(a, b): np.abs(R[a, n] - R[b, n]).max() for a in ends for b in ends
                     if a < b}
                a, b = min(d, key=d.__getitem__)
                count += int(np.sign(values[a, n]) != np.sign(values[b, n]))
                ends.remove(a)
                ends.remove(b)
    return count


def _check_arm_modes(whole: sk.Mechanism, arm: sk.Mechanism, conf: object, pose: np.ndarray,
                     arm_lay: object, dec: object) -> None:
    """Each of the configurations ``conf`` of the body-driven corner (upright pose rows
    ``pose``) is, at its own lower-arm angle, one of the arm-driven corner's closed-form
    modes."""
    lay = graph_layout(whole)
    hinge = lay.scalar_col[lay.names.index(arm.inputs[0])]
    k = arm_lay.body_of["upright"]  # type: ignore[attr-defined]
    for row, th in enumerate(conf.scalars[:, hinge]):  # type: ignore[attr-defined]
        at = closed_every_mode(arm, arm_lay, dec, np.array([[th]]))  # type: ignore[arg-type]
        good = at.assembles(1)[:, 0]
        theirs = np.concatenate([at.placement.R[good, k].reshape(-1, 9),
                                 at.placement.p[good, k] / arm.length_scale], axis=1)
        assert np.abs(theirs - pose[row]).max(axis=1).min() <= 1e-8, th


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
    R, p, arm_lay, dec = _arm_scan(arm)
    w0 = next(q.at for q in arm.points if q.name == "wheel_centre")
    heights = (np.einsum("mnij,j->mni", R, w0) + p)[..., 2] - w0[2]
    values = np.array([-0.040, 0.0021, 0.035])  # (not 0: the drawn mode is there on a sample)
    found = every_mode(whole, values[:, None])
    assert found.worst_closure <= 1e-10 * travel.length_scale
    for n, v in enumerate(values):
        conf = found.configurations[n]
        assert conf.size >= 2 and found.certified[n].all()
        centre, pose = _wheel(whole, lay, conf)
        np.testing.assert_allclose(centre[:, 2] - w0[2], v, atol=1e-10 * travel.length_scale)
        _check_arm_modes(whole, arm, conf, pose, arm_lay, dec)
        crossings = _crossings(heights - v, R)
        assert crossings == conf.size, (v, crossings, conf.size)


def test_every_camber_mode_is_an_arm_mode_at_that_roll() -> None:
    """The corner driven by its upright's roll (a driven turn: one quadratic equation in the
    upright's base points, modes/spatial_point_drives.py). At three rolls every mode has that
    roll, read back on the virtual chain, and is, at its own lower-arm angle, one of the
    arm-driven corner's closed-form modes; their number is the number of times any closed-form
    mode's (R Rx(−ρ))₃₂ = R₃₂ cos ρ − R₃₃ sin ρ changes sign over the arm's whole turn (the
    chain's roll is ρ exactly where it is zero): none missing."""
    travel = sk.load_spec(EXAMPLES / "double_wishbone_travel.toml").mechanism
    arm = sk.load_spec(EXAMPLES / "double_wishbone.toml").mechanism
    mech = replace(travel, drives=(BodyDrive("upright.roll", "upright", "roll"),))
    whole = augmented(mech)
    form = closure_formulation(whole)
    assert isinstance(form, SpatialPointFormulation) and form.drives[0].is_turn
    lay = graph_layout(whole)
    roll_col = lay.scalar_col[lay.names.index(whole.inputs[0])]
    R, _, arm_lay, dec = _arm_scan(arm)
    values = np.radians([-4.0, 1.3, 6.0])
    found = every_mode(whole, values[:, None])
    assert found.worst_closure <= 1e-10 * travel.length_scale
    for n, rho in enumerate(values):
        conf = found.configurations[n]
        assert conf.size >= 2 and found.certified[n].all()
        np.testing.assert_allclose(np.angle(np.exp(1j * (conf.scalars[:, roll_col] - rho))), 0.0,
                                   atol=1e-10)
        _, pose = _wheel(whole, lay, conf)
        Rs = pose[:, :9].reshape(-1, 3, 3)
        np.testing.assert_allclose(Rs[:, 2, 1] * np.cos(rho) - Rs[:, 2, 2] * np.sin(rho), 0.0,
                                   atol=1e-10)
        _check_arm_modes(whole, arm, conf, pose, arm_lay, dec)
        crossings = _crossings(R[..., 2, 1] * np.cos(rho) - R[..., 2, 2] * np.sin(rho), R)
        assert crossings == conf.size, (rho, crossings, conf.size)


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


def test_a_platform_driven_at_its_whole_pose_has_one_mode_the_trackers() -> None:
    """The Stewart platform driven at its pose (x, y, z, roll, pitch, yaw): its U–P–S legs are
    struts of free length (no equation), the platform's three turns three quadrics. Those
    also hold three more rotations, each turn taken from the other Tait–Bryan triple
    (found, then dropped: their turns read back are not the inputs), so every row has one
    mode, the graph tracker's, joint for joint, with its legs' slides."""
    spec = sk.load_spec(EXAMPLES / "stewart_platform_pose.toml")
    mech = spec.mechanism
    form = closure_formulation(mech)
    assert isinstance(form, SpatialPointFormulation)
    assert [d.is_turn for d in form.drives] == [False] * 3 + [True] * 3
    assert len(form.universals) == 6 and all(ul.column is None for ul in form.universals)
    X = spec.inputs[::10]
    found = every_mode(mech, X)
    assert found.worst_closure <= 1e-10 * mech.length_scale
    assert (found.found >= 4).all()
    drawn = solve_mechanism(mech, X)
    assert drawn.modes[0].assembles.all()
    lay = graph_layout(mech)
    for n, conf in enumerate(found.configurations):
        assert conf.size == 1 and found.certified[n].all()
        np.testing.assert_allclose(conf.scalars[0], drawn.modes[0].conf.scalars[n], atol=1e-9)
        np.testing.assert_allclose(conf.spherical[0], drawn.modes[0].conf.spherical[n],
                                   atol=1e-9)
    assert lay.n_scalar == found.configurations[0].scalars.shape[1]


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


def test_a_turn_of_a_body_without_a_rotation_is_refused_by_name() -> None:
    """A driven turn of a body the point formulation writes no base triangle for (the model
    refuses the usual ways in: a rod's turn, a turn of a body the inputs place) is refused
    by name, not a StopIteration from the compiler."""
    from screwkit.errors import CapabilityError
    from screwkit.kinematics.modes.spatial_point_drives import PointDrive, check_turns

    mech = sk.load_spec(EXAMPLES / "double_wishbone_travel.toml").mechanism
    roll = PointDrive("upright", "roll", np.zeros(3), 0)
    check_turns(mech, (roll,), {"upright"})
    with pytest.raises(CapabilityError, match="driven at upright's roll, a turn, but the "
                                              "formulation writes no rotation for upright"):
        check_turns(mech, (roll,), {"lower_arm"})

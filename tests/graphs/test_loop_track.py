"""A single loop without a closed form, drawn as a graph, has its drawn mode followed by the loop
engine (graph/loop_track.py: the generic loop solver's continuation, issue 26's one solving
path), checked against the same engine on the graph's stacked closure (graph/follow.py: another
closure system, other variables and equations), the closed form where there is one, finite
differences and the closure."""

from __future__ import annotations

import numpy as np
import pytest

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.kinematics.graph.loop_subchain import loop_chain
from screwkit.kinematics.graph.loop_track import follow_drawn_loop
from screwkit.kinematics.graph.motion import build_mode
from screwkit.kinematics.graph.newton import scaled_residual
from screwkit.kinematics.tracker.loop import rotation_vector
from screwkit.model.mechanism import Body, Mechanism, MechanismJoint

Z = np.array([0.0, 0.0, 1.0])
X_AXIS = np.array([1.0, 0.0, 0.0])
#: the second axis of the U joint: ⟂ its first axis (z) and the rod B→C
V = np.array([1.0, -1.0, 0.0]) / np.sqrt(2.0)


def _joint(name: str, kind: str, a: str, b: str, at: list[float], axis: np.ndarray = Z,
           **kw: object) -> MechanismJoint:
    return MechanismJoint(name, kind, (a, b), np.array(at, float), np.array(axis, float),
                          **kw)  # type: ignore[arg-type]


def _rssh(rod_backwards: bool = False) -> Mechanism:
    """An R–S–S–H loop (an RSSR whose output turns on a screw: no closed form), the rod between
    the balls (an idle spin); ``rod_backwards`` names the balls' bodies the other way round."""
    B = ("rod", "crank") if rod_backwards else ("crank", "rod")
    C = ("rocker", "rod") if rod_backwards else ("rod", "rocker")
    return Mechanism("rssh", (Body("crank"), Body("rod"), Body("rocker")),
                     (_joint("A", "R", "ground", "crank", [0, 0, 0]),
                      _joint("B", "S", *B, [1, 0, 0]),
                      _joint("C", "S", *C, [3, 2, 1]),
                      _joint("D", "H", "rocker", "ground", [3, 0, 1], X_AXIS, pitch=0.2)),
                     ("A.theta",))


def _rusr(u_backwards: bool = False) -> Mechanism:
    """An R–U–S–R loop (no closed form); ``u_backwards`` names the U joint's bodies (and so its
    two axes) the other way round: the same mechanism."""
    U = (_joint("B", "U", "rod", "crank", [1, 0, 0], V, axis2=Z) if u_backwards
         else _joint("B", "U", "crank", "rod", [1, 0, 0], Z, axis2=V))
    return Mechanism("rusr", (Body("crank"), Body("rod"), Body("rocker")),
                     (_joint("A", "R", "ground", "crank", [0, 0, 0]), U,
                      _joint("C", "S", "rod", "rocker", [3, 2, 1]),
                      _joint("D", "R", "rocker", "ground", [3, 0, 1], X_AXIS)), ("A.theta",))


def _closure(mech: Mechanism, md: object) -> float:
    lay = graph_layout(mech)
    ok = np.flatnonzero(md.assembles)  # type: ignore[attr-defined]
    fr = graph_forward(mech, lay, md.conf.take(ok))  # type: ignore[attr-defined]
    return float(np.abs(scaled_residual(mech, lay, fr)).max())


@pytest.mark.parametrize("make", [_rssh, _rusr])
def test_a_loop_without_a_closed_form_is_followed_by_the_loop_engine(make) -> None:
    mech = make()
    assert loop_chain(mech) is None and loop_chain(mech, generic=True) is not None
    x = np.radians(np.arange(0.0, 120.0, 2.0)) + 0.1  # the first row off the drawing
    seen: list[tuple[int, int]] = []
    motion = solve_mechanism(mech, x, progress=lambda d, t: seen.append((d, t)))
    assert "loop engine" in motion.solver and motion.method == "graph"
    assert [d for d, _ in seen] == sorted(d for d, _ in seen) and seen[-1] == (x.size, x.size)
    md = motion.modes[0]
    lay = graph_layout(mech)
    other = follow_drawn_mode(mech, lay, x[:, None])  # the graph's own continuation
    assert np.array_equal(md.assembles, other.mask) and md.assembles.sum() > 10
    ok = md.assembles
    np.testing.assert_allclose(md.conf.scalars[ok], other.conf.scalars[ok], atol=1e-9)
    tracked = build_mode(mech, lay, other.conf, other.mask, x[:, None], np.ones((x.size, 1)),
                         np.zeros((x.size, 1)), other.frames)
    np.testing.assert_allclose(md.joint_centres[ok], tracked.joint_centres[ok],
                               atol=1e-9 * mech.length_scale)
    assert _closure(mech, md) <= 1e-12
    # named the other way round, the same mechanism: the same joint lines at every sample
    flipped = solve_mechanism(make(True), x).modes[0]
    assert np.array_equal(flipped.assembles, ok) and _closure(make(True), flipped) <= 1e-12
    np.testing.assert_allclose(flipped.joint_centres[ok], md.joint_centres[ok],
                               atol=1e-9 * mech.length_scale)
    if make is _rusr:  # M_B⁻¹ = Rot(V, −θ2) Rot(z, −θ1): the two angles swap and turn sign
        for a, b in (("theta1", "theta2"), ("theta2", "theta1")):
            np.testing.assert_allclose(flipped.variables[f"B.{a}"][ok],
                                       -md.variables[f"B.{b}"][ok], atol=1e-9)


def test_the_rod_between_two_balls_turns_as_its_angular_velocity_says() -> None:
    """The rod's pose holds its idle spin at zero (its rotation differentiates to the reported
    angular velocity, which has no spin) and equals the closed form's on an RSSR followed in frame
    form by the loop engine; the spin the graph tracker's minimum-norm steps leave is not that."""
    lk = sk.rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.3)
    theta = np.linspace(0.0, 2 * np.pi, 721)
    mech = mechanism_from_loop(sk.solve_motion(lk, theta[:2]))
    lay = graph_layout(mech)
    X = theta[:, None]
    chain = loop_chain(mech, generic=True)
    assert chain is not None
    f = follow_drawn_loop(mech, lay, chain, X)
    assert f.mask.all() and f.stopped_after is None
    md = build_mode(mech, lay, f.conf, f.mask, X, np.ones_like(X), np.zeros_like(X), f.frames)
    closed = solve_mechanism(mech, theta)
    assert closed.method == "graph (loop, closed)"
    np.testing.assert_allclose(md.link_rotation, closed.modes[0].link_rotation, atol=1e-10)
    h = theta[1] - theta[0]
    rod = mech.body_names.index("coupler")
    R, w = md.link_rotation[:, rod], md.link_angular_velocity[:, rod]
    step = rotation_vector(np.einsum("nji,njk->nik", R[:-2], R[2:]))  # body axes
    fd = np.einsum("nij,nj->ni", R[1:-1], step) / (2 * h)
    assert np.abs(fd - w[1:-1]).max() <= 1e-4  # central differences: O(h²) ≈ 1e-5 here
    spin = np.einsum("ni,ni->n", w, md.joint_centres[:, 2] - md.joint_centres[:, 1])
    assert np.abs(spin).max() <= 1e-10


def test_the_drawn_mode_ends_at_its_first_fold_as_on_the_graph_tracker() -> None:
    """A crank that cannot turn round: the loop engine's drawn mode stops where the graph
    tracker's does (within a sample), with the stop in the events."""
    mech = _rssh()
    x = np.radians(np.arange(0.0, 360.0, 3.0))
    md = solve_mechanism(mech, x).modes[0]
    other = follow_drawn_mode(mech, graph_layout(mech), x[:, None])
    assert not other.mask.all() and 10 < md.assembles.sum() < x.size
    assert not md.assembles[int(md.assembles.sum()):].any()  # one run from the drawing
    assert abs(int(md.assembles.sum()) - int(other.mask.sum())) <= 1
    assert md.events and md.events[0].startswith("stops assembling after input")

"""The general single-loop closure of R, P and C joints (kinematics/modes/general_loop.py and
general_loop_system.py, issue 27), checked without solving it: the system and the whole loop's
product vanish where a random complex instance is built to close, the graph tracker's
configurations of random loops are roots and decode back to themselves, and every mode the 6R
formulation finds for a 7R loop is a root of the general system too."""

from __future__ import annotations

import numpy as np
import pytest

from modes_helpers import random_loop, random_r_loop, relative_residual, tilted
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.closure import graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.modes.every_mode import every_mode
from screwkit.kinematics.modes.general_loop import general_loop
from screwkit.kinematics.modes.general_loop_system import (
    full_closure_residual,
    general_loop_system,
    random_closing_instance,
    rx,
    rz,
    split_link,
    trans,
)
from screwkit.model.mechanism import Mechanism, MechanismJoint

#: (mechanism joints, driven freedoms, free joints round the loop from the first free one)
TOPOLOGIES = [("RRPRRRR", ["j0.theta"], "RPRRRR"), ("RRRCRR", ["j0.theta"], "RRCRR"),
              ("CCRR", [], "CCRR"), ("RCRCR", ["j0.theta"], "CRCR"),
              ("RCRCR", ["j1.s"], "RRRCR"), ("RUPUR", ["j0.theta"], "RRPRRR")]
#: the input value of the tracked configurations (rad or m from the drawing)
INPUT = 0.3


@pytest.mark.parametrize("kinds", ["RPRRRR", "RRCRR", "CCRR", "RRRRRR", "PRRPRR", "CRCR"])
def test_the_system_and_the_whole_loop_vanish_at_a_closing_instance(kinds: str) -> None:
    rng = np.random.default_rng(5)
    S = general_loop_system(kinds)
    for _ in range(5):
        p, x = random_closing_instance(kinds, rng)
        assert relative_residual(S, x, p[0]) <= 1e-12
        assert full_closure_residual(kinds, x[0], p[0]) <= 1e-12


def test_a_loop_without_six_free_freedoms_is_refused() -> None:
    rng = np.random.default_rng(6)
    with pytest.raises(CapabilityError, match="six freedoms"):
        general_loop(random_loop(rng, "RRPRRR", ["j0.theta"]))
    with pytest.raises(CapabilityError, match="not R, P, C or U"):
        general_loop(random_loop(rng, "RSRR", ["j0.theta"]))


def _parallel_pair(mech: Mechanism) -> Mechanism:
    """``mech`` with joint 2's axis made parallel to joint 1's (a link of zero twist)."""
    joints = list(mech.joints)
    j = joints[2]
    joints[2] = MechanismJoint(j.name, j.kind, j.bodies, j.at, joints[1].axis)
    return Mechanism(mech.name, mech.bodies, tuple(joints), mech.inputs)


@pytest.mark.parametrize(("joints", "inputs", "kinds"), TOPOLOGIES)
@pytest.mark.parametrize("parallel", [False, True])
def test_the_tracked_configuration_is_a_root_and_decodes_back(
        joints: str, inputs: list[str], kinds: str, parallel: bool) -> None:
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(10):
        mech = random_loop(rng, joints, inputs)
        mech = _parallel_pair(mech) if parallel else mech
        form = general_loop(mech)
        assert form.kinds == kinds
        lay = graph_layout(mech)
        if inputs:
            followed = follow_drawn_mode(mech, lay, np.linspace(0.0, INPUT, 7)[:, None])
            if not followed.mask.all():
                continue  # a limit position before INPUT
            conf, row = followed.conf.take(slice(6, 7)), [INPUT]
        else:  # a structure: its drawing
            conf = follow_drawn_mode(mech, lay, np.zeros((1, 0))).conf
            row = []
        x = form.unknowns(conf.scalars, row)
        p = form.parameters([row])
        assert relative_residual(form.system, x.astype(complex), p[0].astype(complex)) <= 1e-12
        assert full_closure_residual(kinds, x[0].astype(complex), p[0].astype(complex)) <= 1e-12
        back, _ = form.configuration(x, row)
        assert np.allclose(back.scalars, conf.scalars, atol=1e-9)
        checked += 1
    assert checked >= 5


def test_every_mode_of_the_6r_formulation_is_a_root_of_the_general_system() -> None:
    rng = np.random.default_rng(8)
    modes = 0
    for _ in range(10):
        mech = random_r_loop(rng, 7, [0])
        form = general_loop(mech)
        assert form.kinds == "RRRRRR"
        found = every_mode(mech, [[INPUT]])
        conf = found.configurations[0]
        if not len(conf.scalars):
            continue
        x = form.unknowns(conf.scalars, [INPUT]).astype(complex)
        p = form.parameters([[INPUT]])[0].astype(complex)
        assert relative_residual(form.system, x, p) <= 1e-9
        for xi in x:
            assert full_closure_residual("RRRRRR", xi, p) <= 1e-9
        back, _ = form.configuration(x, [INPUT])
        assert np.allclose(np.angle(np.exp(1j * (back.scalars - conf.scalars))), 0.0,
                           atol=1e-8)
        modes += len(x)
    assert modes >= 10


@pytest.mark.parametrize("alpha", [1e-3, 1e-5, 1e-7, np.pi - 1e-7])
def test_a_link_of_small_twist_splits_and_recomposes(alpha: float) -> None:
    """split_link of Rz(φ) Tz(b) Tx(a) Rx(α) Rz(ψ) Tz(e) with α near 0 or π gives sin α to a
    few ulps and recomposes the link to round-off. Before the fix sin α came from
    √(1 − cos²α), which keeps only ~1e-16/sin²α of it (a relative error 1e-2 at α = 1e-7):
    the normal's angle φ and the offsets b, e were then wrong, and a loop with two axes 1e-7
    rad from parallel was solved as another loop (its tracked mode's closure residual 7e-3;
    found by a review probe of near-parallel axes)."""
    phi, b, a, psi, e = 0.7, 0.3, 0.8, -1.1, -0.4
    H = (rz(np.cos(phi), np.sin(phi)) @ trans(2, b) @ trans(0, a)
         @ rx(np.cos(alpha), np.sin(alpha)) @ rz(np.cos(psi), np.sin(psi)) @ trans(2, e))
    (cp, sp), b2, a2, (ca, sa), (cs, ss), e2 = split_link(H)
    assert abs(sa - np.sin(alpha)) <= 1e-9 * np.sin(alpha)
    assert abs(cp * cp + sp * sp - 1) <= 1e-12 and abs(cs * cs + ss * ss - 1) <= 1e-12
    back = (rz(cp, sp) @ trans(2, b2) @ trans(0, a2) @ rx(ca, sa) @ rz(cs, ss) @ trans(2, e2))
    assert np.abs(back - H).max() <= 1e-12 * (1.0 + abs(b2) + abs(e2))


@pytest.mark.parametrize("twist", [1e-7, 1e-5])
def test_a_nearly_parallel_pair_is_read_to_round_off(twist: float) -> None:
    """A 7R loop driven at j0 with j2's axis ``twist`` rad from j1's: the tracked
    configuration closes the general system's whole loop to round-off of its largest DH value
    (the common normal of nearly parallel axes is ~1/twist away, so the offsets are large).
    Before split_link read sin α from the third column the residual was 7e-3 at 1e-7
    (3e-7 at 1e-5): the loop read was another loop."""
    rng = np.random.default_rng(8)
    checked = 0
    for _ in range(6):
        mech = tilted(random_loop(rng, "RRRPRRR", ["j0.theta"]), 2, 1, twist)
        lay = graph_layout(mech)
        followed = follow_drawn_mode(mech, lay, np.linspace(0.0, INPUT, 7)[:, None])
        if not followed.mask.all():
            continue  # a limit position before INPUT
        form = general_loop(mech)
        x = form.unknowns(followed.conf.scalars[6:7], [INPUT])
        p = form.parameters([[INPUT]])
        size = float(np.abs(p).max())
        assert size >= 0.1 / twist  # the offsets are large, as they must be
        assert full_closure_residual(form.kinds, x[0].astype(complex),
                                     p[0].astype(complex)) <= 1e-13 * size
        checked += 1
    assert checked >= 3

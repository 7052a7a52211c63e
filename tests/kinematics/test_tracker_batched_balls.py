"""Every ball joint at once (issue 27, the Delta's every-mode speed): the batched increments,
differences and line screws of the graph tracker are the one-ball-at-a-time arithmetic bit for
bit, so the tracker's steps (and a rod's idle spin, which round-off steers) are unchanged.

The references are written here the way tracker/loop.py and graph/closure.py wrote them before
(a ``rotation_matrix`` / ``rotation_vector`` / ``cross`` call per ball and per column)."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.dual.spatial import cross
from screwkit.kinematics.graph.closure import GraphLayout, graph_forward, graph_layout
from screwkit.kinematics.tracker.loop import (
    Configuration,
    apply_increment,
    configuration_difference,
    rotation_matrix,
    rotation_vector,
)
from screwkit.model.mechanism import Mechanism

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


@lru_cache(maxsize=1)
def _delta() -> tuple[Mechanism, GraphLayout]:
    mech = sk.load_spec(EXAMPLES / "delta_robot.toml").mechanism
    return mech, graph_layout(mech)


def _balls(lay: GraphLayout) -> list[tuple[int, list[int]]]:
    return [(k, [f for f, jj in enumerate(lay.joint_of) if jj == j])
            for j, k in lay.spherical_of_joint.items()]


def _random_conf(lay: GraphLayout, N: int, rng: np.random.Generator) -> Configuration:
    w = rng.normal(size=(N * lay.n_spherical, 3))
    return Configuration(rng.normal(size=(N, lay.n_scalar)),
                         rotation_matrix(w).reshape(N, lay.n_spherical, 3, 3))


@pytest.mark.parametrize("N", [1, 2, 3, 5, 8, 17, 130])
def test_increments_and_differences_are_the_one_ball_arithmetic(N: int) -> None:
    mech, lay = _delta()
    assert lay.n_spherical == 12
    rng = np.random.default_rng(N)
    conf = _random_conf(lay, N, rng)
    for scale in (1e-7, 1e-3, 1.0):  # the series branch, small and large turns
        for delta in (rng.normal(size=(N, lay.m)) * scale,  # C order and a transposed view
                      np.asfortranarray(rng.normal(size=(N, lay.m)) * scale)):
            got = apply_increment(conf, delta, lay)
            ref = conf.spherical.copy()
            for k, idx in _balls(lay):
                ref[:, k] = ref[:, k] @ rotation_matrix(delta[:, idx])
            assert np.array_equal(got.spherical, ref)
            diff = configuration_difference(got, conf, lay)
            for k, idx in _balls(lay):
                rel = np.swapaxes(conf.spherical[:, k], -1, -2) @ got.spherical[:, k]
                assert np.array_equal(diff[:, idx], rotation_vector(rel))
            # and the difference undoes the increment (to round-off) while every turn is
            # under a half turn: an independent check of both
            cols = [f for _, i in _balls(lay) for f in i]
            if scale < 1.0:
                assert np.abs(diff[:, cols] - delta[:, cols]).max() < 1e-13


def test_ball_screws_are_the_line_screws_per_column() -> None:
    mech, lay = _delta()
    rng = np.random.default_rng(3)
    for N in (1, 4, 33):
        fr = graph_forward(mech, lay, _random_conf(lay, N, rng))
        for i, j in enumerate(mech.joints):
            if j.kind != "S":
                continue
            b = lay.body_of[j.bodies[1]]
            f = lay.first_freedom[i]
            for k in range(3):
                u = fr.R[:, b, :, k]
                ref = np.concatenate([u, cross(fr.centres[:, i], u)], -1)
                assert np.array_equal(fr.screws[:, :, f + k], ref)


@pytest.mark.parametrize("example", ["delta_robot", "stewart_platform"])
def test_loop_residuals_are_the_one_chord_arithmetic(example: str) -> None:
    """Every chord's closure twist at once is the one-chord computation bit for bit (exact
    logarithm and first-order form), at configurations off closure."""
    from screwkit.kinematics.graph.closure import joint_motion, loop_residuals
    from screwkit.kinematics.tracker.loop import closure_error, closure_twist

    mech = sk.load_spec(EXAMPLES / f"{example}.toml").mechanism
    lay = graph_layout(mech)
    rng = np.random.default_rng(5)
    for N in (1, 2, 7, 40):
        conf = _random_conf(lay, N, rng)
        conf = Configuration(0.1 * conf.scalars, conf.spherical)
        fr = graph_forward(mech, lay, conf)
        for exact in (True, False):
            got = loop_residuals(mech, lay, conf, fr.R, fr.p, exact)
            assert got.shape == (N, len(mech.topology.chords), 6)
            for l, k in enumerate(mech.topology.chords):
                Mr, Mp = joint_motion(mech, lay, conf, k)
                a, b = (lay.body_of[x] for x in mech.joints[k].bodies)
                ER = (fr.R[:, a] @ Mr) @ np.swapaxes(fr.R[:, b], -1, -2)
                Ep = (np.einsum("nij,nj->ni", fr.R[:, a], Mp) + fr.p[:, a]
                      - np.einsum("nij,nj->ni", ER, fr.p[:, b]))
                ref = closure_twist(ER, Ep) if exact else closure_error(ER, Ep)
                assert np.array_equal(got[:, l], ref)


@pytest.mark.parametrize("example", ["delta_robot", "stewart_platform"])
def test_loop_jacobian_and_twists_are_the_per_joint_arithmetic(example: str) -> None:
    """The stacked Jacobian from the sign table equals the per-loop, per-joint assembly bit
    for bit and in C order (the solvers' BLAS calls follow the strides: a transposed layout
    changed the Delta's rod spins), and the twists' velocity-product terms are each joint's
    bracket."""
    from screwkit.kinematics.graph.closure import body_twists, loop_jacobian
    from screwkit.kinematics.tracker.loop import lie_bracket

    mech = sk.load_spec(EXAMPLES / f"{example}.toml").mechanism
    lay = graph_layout(mech)
    rng = np.random.default_rng(9)
    for N in (1, 6):
        fr = graph_forward(mech, lay, _random_conf(lay, N, rng))
        got = loop_jacobian(mech, lay, fr.screws)
        ref = np.zeros((N, 6 * len(mech.topology.loops), lay.m))
        for l, loop in enumerate(mech.topology.loops):
            for k, sign in loop:
                f0, n = lay.first_freedom[k], len(mech.joints[k].freedoms)
                ref[:, 6 * l:6 * l + 6, f0:f0 + n] = sign * fr.screws[:, :, f0:f0 + n]
        assert np.array_equal(got, ref) and np.array_equal(np.signbit(got), np.signbit(ref))
        assert got.flags.c_contiguous
        qd = rng.normal(size=(N, lay.m))
        V, bias = body_twists(mech, lay, fr.screws, qd)
        for i, j in enumerate(mech.joints):
            f, n = lay.first_freedom[i], len(j.freedoms)
            rel = np.einsum("nkf,nf->nk", fr.screws[:, :, f:f + n], qd[:, f:f + n])
            want = lie_bracket(V[:, lay.body_of[j.bodies[0]]], rel)
            if j.kind != "U":
                assert np.array_equal(bias[:, i], want)

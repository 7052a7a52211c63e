"""Every mode of the bundled Stewart–Gough graph spec (modes/stewart_decode.py): platform
poses decoded into the graph's joint variables close every loop, the homotopy's modes at an
input row are each a closed assembly whose legs have the commanded lengths, and the graph
tracker started from each one stays on the branch the decoder gives."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import screwkit as sk
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.kinematics.modes.stewart_decode import StewartFormulation, decode_poses

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


def _spec():  # type: ignore[no-untyped-def]
    return sk.load_spec(EXAMPLES / "stewart_platform.toml")


def _rotation(v: np.ndarray) -> np.ndarray:
    th = np.linalg.norm(v, axis=1)[:, None, None]
    k = v / np.linalg.norm(v, axis=1)[:, None]
    K = np.zeros((len(v), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * (K @ K)


def _platform_pose(mech, lay, conf, platform: str):  # type: ignore[no-untyped-def]
    fr = graph_forward(mech, lay, conf)
    b = lay.body_of[platform]
    return fr, fr.R[:, b], fr.p[:, b]


def test_decoded_poses_close_every_loop_and_give_the_pose_back() -> None:
    mech = _spec().mechanism
    form = closure_formulation(mech)
    assert isinstance(form, StewartFormulation)
    sm, lay = form.stewart, graph_layout(mech)
    rng = np.random.default_rng(27)
    for _ in range(20):
        R = _rotation(rng.normal(size=(1, 3)) * 0.2)
        t = rng.normal(size=(1, 3)) * 0.03
        L = np.linalg.norm(sm.top @ R[0].T + t[0] - sm.base, axis=1)
        x = np.zeros(6)
        x[list(sm.input_columns)] = L - np.linalg.norm(sm.top - sm.base, axis=1)
        conf = decode_poses(sm, R, t, x)
        fr, Rp, tp = _platform_pose(mech, lay, conf, sm.platform)
        assert np.abs(fr.residual).max() < 1e-10
        np.testing.assert_allclose(Rp, R, atol=1e-12)
        np.testing.assert_allclose(tp, t, atol=1e-12)
        # the inputs are the joint variables the decoder wrote
        np.testing.assert_allclose(conf.scalars[0, [lay.scalar_col[f] for f in lay.inputs]],
                                   x, atol=1e-12)
    # the drawing decodes to every joint variable 0
    zero = decode_poses(sm, np.eye(3)[None], np.zeros((1, 3)), np.zeros(6))
    assert np.abs(zero.scalars).max() < 1e-12
    assert np.abs(zero.spherical - np.eye(3)).max() < 1e-12


def test_every_homotopy_mode_closes_and_the_tracker_stays_on_it() -> None:
    spec = _spec()
    mech = spec.mechanism
    lay = graph_layout(mech)
    sm = closure_formulation(mech).stewart  # type: ignore[attr-defined]
    X = spec.inputs[:3]
    solved = every_mode(mech, X[:1])
    modes = solved.configurations[0]
    assert solved.generic_count == 40
    assert 2 <= modes.size <= 40 and modes.size % 2 == 0  # mirror pairs through the base plane
    assert solved.certified[0].all() and solved.worst_closure < 1e-10
    fr, R, t = _platform_pose(mech, lay, modes, sm.platform)
    assert np.abs(fr.residual).max() < 1e-10
    # the legs have the commanded lengths: from the poses, not from the polynomial system
    drawn = np.linalg.norm(sm.top - sm.base, axis=1)
    lengths = np.linalg.norm(np.einsum("nij,kj->nki", R, sm.top) + t[:, None] - sm.base,
                             axis=2)
    np.testing.assert_allclose(lengths, (drawn + X[0, list(sm.input_columns)])[None].repeat(
        modes.size, 0), atol=1e-12)
    # the drawn pose is one of them
    assert np.min(np.abs(R - np.eye(3)).max(axis=(1, 2)) + np.abs(t).max(axis=1)) < 1e-10
    # poses pairwise distinct
    flat = np.concatenate([R.reshape(modes.size, -1), t], axis=1)
    d = np.abs(flat[:, None] - flat[None]).max(axis=2) + np.eye(modes.size)
    assert d.min() > 1e-6
    for m in range(modes.size):
        start = modes.take(slice(m, m + 1))
        f = follow_drawn_mode(mech, lay, X[1:], start=start, start_inputs=X[0])
        assert f.mask.all()
        _, Rm, tm = _platform_pose(mech, lay, f.conf, sm.platform)
        for k in range(2):
            again = decode_poses(sm, Rm[k:k + 1], tm[k:k + 1], X[1 + k])
            np.testing.assert_allclose(again.scalars, f.conf.scalars[k:k + 1], atol=1e-8)
            np.testing.assert_allclose(again.spherical, f.conf.spherical[k:k + 1], atol=1e-8)

"""The LU routes of the graph statics (dynamics/graph_statics.py ``_lu_solve``) give the
least-norm least-squares solution the SVD gives (numpy's ``pinv``, an independent route):
square, wide (full row rank) and tall (full column rank) systems, and a batch holding a
singular sample, which falls back to the SVD."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.dynamics.graph_statics import _lu_solve


def _pinv_solution(A: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    return np.stack([np.linalg.pinv(a) @ b for a, b in zip(A, rhs, strict=True)])


@pytest.mark.parametrize("shape", [(12, 12), (9, 12), (12, 9)])
def test_lu_routes_equal_the_pseudo_inverse(shape: tuple[int, int]) -> None:
    rng = np.random.default_rng(4)
    A = rng.normal(size=(6, *shape))
    x = rng.normal(size=(6, shape[1], 2))
    rhs = A @ x  # consistent, so every route's residual is round-off
    y, res = _lu_solve(A, rhs)
    np.testing.assert_allclose(y, _pinv_solution(A, rhs), atol=1e-10)
    np.testing.assert_allclose(res, A @ y - rhs, atol=1e-12)
    assert np.abs(res).max() < 1e-10


def test_a_singular_sample_falls_back_to_the_svd() -> None:
    rng = np.random.default_rng(5)
    A = rng.normal(size=(4, 8, 8))
    A[2, 3] = A[2, 5]  # sample 2: two equal rows, LU is singular
    rhs = A @ rng.normal(size=(4, 8, 1))
    y, res = _lu_solve(A, rhs)
    np.testing.assert_allclose(y, _pinv_solution(A, rhs), atol=1e-9)
    assert np.abs(res).max() < 1e-9


def test_the_spanning_tree_route_equals_the_full_system(monkeypatch) -> None:
    """The Stewart platform (square, full rank) goes through the spanning tree
    (graph_tree_statics.py); forcing every sample back to the full system (a residual
    threshold no sample meets, so the full system's LU defers to its SVD too) gives the same
    wrenches and efforts."""
    from pathlib import Path

    import screwkit as sk
    import screwkit.dynamics.graph_statics as gs
    from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
    from screwkit.kinematics.graph import solve_mechanism

    spec = sk.load_spec(Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
                        / "stewart_platform_pose.toml")
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                             accelerations=np.linspace(-1.0, 1.0, 6))
    calls: list[int] = []
    dense = gs._dense

    def counted(*args):  # type: ignore[no-untyped-def]
        calls.append(len(args[7]))
        return dense(*args)

    monkeypatch.setattr(gs, "_dense", counted)
    tree = graph_inverse_dynamics(motion, gravity=spec.gravity_vector)
    assert calls == []  # no sample needed the full system
    monkeypatch.setattr(gs, "LU_RESIDUAL", -1.0)  # every sample: the full system's SVD
    full = graph_inverse_dynamics(motion, gravity=spec.gravity_vector)
    assert calls == [int(tree.ok.sum())]
    scale = np.abs(tree.reaction_force).max()
    np.testing.assert_allclose(tree.reaction_force, full.reaction_force, atol=1e-11 * scale)
    np.testing.assert_allclose(tree.reaction_moment, full.reaction_moment,
                               atol=1e-11 * scale * spec.mechanism.length_scale)
    np.testing.assert_allclose(tree.efforts, full.efforts, atol=1e-11 * scale)
    assert np.nanmax(tree.residual) < 1e-12


def test_loads_along_an_idle_spin_fall_back_to_the_full_least_squares(monkeypatch) -> None:
    """An RSSR whose rod's centre of mass is off its axis: its load works along the rod's idle
    spin, so no wrenches balance it exactly. The spanning-tree route (full column rank) sees the
    residual and hands every such sample to the full system, whose least-squares answer (and
    residual) the test gets again by forcing the SVD everywhere."""
    import screwkit as sk
    import screwkit.dynamics.graph_statics as gs
    from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
    from screwkit.kinematics.graph import solve_mechanism
    from screwkit.model.mass import MassProperties
    from screwkit.model.mechanism import Mechanism, MechanismJoint

    rng = np.random.default_rng(8)
    O, A, B, D = (rng.uniform(-1.0, 1.0, 3) for _ in range(4))
    A = O + 0.3 * (A - O) / np.linalg.norm(A - O)
    joints = (MechanismJoint("O", "R", ("ground", "crank"), O, rng.normal(size=3)),
              MechanismJoint("A", "S", ("crank", "rod"), A, np.array([0.0, 0.0, 1.0])),
              MechanismJoint("B", "S", ("rod", "rocker"), B, np.array([0.0, 0.0, 1.0])),
              MechanismJoint("D", "R", ("rocker", "ground"), D, rng.normal(size=3)))
    bodies = tuple(sk.Body(n, MassProperties(1.0, c, 0.01 * np.eye(3)))
                   for n, c in (("crank", O), ("rod", (A + B) / 2 + 0.1), ("rocker", D)))
    mech = Mechanism("lopsided RSSR", bodies, joints, ("O.theta",))
    motion = solve_mechanism(mech, np.linspace(0.0, 0.5, 9), rates=1.5, accelerations=0.3)
    calls: list[int] = []
    dense = gs._dense

    def counted(*args):  # type: ignore[no-untyped-def]
        calls.append(len(args[7]))
        return dense(*args)

    monkeypatch.setattr(gs, "_dense", counted)
    tree = graph_inverse_dynamics(motion, gravity=[0.0, 0.0, -9.8])
    assert calls == [int(tree.ok.sum())]  # every sample handed to the full system
    assert np.nanmin(tree.residual) > 1e-6  # the idle spin's load is left over
    monkeypatch.setattr(gs, "LU_RESIDUAL", -1.0)
    full = graph_inverse_dynamics(motion, gravity=[0.0, 0.0, -9.8])
    np.testing.assert_allclose(tree.efforts, full.efforts, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(tree.residual, full.residual, rtol=1e-12)

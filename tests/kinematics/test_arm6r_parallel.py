"""Inverse kinematics of industrial 6R arms with parallel axes (modes/arm6r_parallel.py): UR5,
UR10, PUMA 560 and a KUKA-like arm from their published Denavit–Hartenberg tables.

Checked independently of the route: each arm's forward kinematics is the DH chain product
Π Rz(θ) Tz(d) Tx(a) Rx(α) (not the product of exponentials the solver uses), the generating
joint values must be among the solutions, the complex count must be the known 8 (Pieper's
decoupled wrist for PUMA/KUKA, Hawkins' closed form for UR arms), and Gauss–Newton on the DH
chain from 200 random joint-space starts per target finds no real solution that was missed.

``SCREWKIT_ARM_TARGETS`` sets the number of random targets per arm (default 50).
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from screwkit.algebraic.solve import Solutions
from screwkit.errors import CapabilityError
from screwkit.kinematics.modes.arm6r import arm6r_instance, arm_forward, arm_inverse_kinematics
from screwkit.kinematics.modes.arm6r_parallel import (
    ROUTE,
    ArmContinuation,
    complex_joint_values,
)
from screwkit.kinematics.modes.loop6r_solve import solve_loop6r

TARGETS = int(os.environ.get("SCREWKIT_ARM_TARGETS", "50"))
CLOSE = 1e-10
PI2 = np.pi / 2
#: (a, d, α) per joint, standard DH (metres, radians)
ARMS = {
    "UR5": ([0, -0.425, -0.39225, 0, 0, 0], [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
            [PI2, 0, 0, PI2, -PI2, 0]),
    "UR10": ([0, -0.612, -0.5723, 0, 0, 0], [0.1273, 0, 0, 0.163941, 0.1157, 0.0922],
             [PI2, 0, 0, PI2, -PI2, 0]),
    "PUMA560": ([0, 0.4318, 0.0203, 0, 0, 0], [0, 0, 0.15005, 0.4318, 0, 0],
                [PI2, 0, -PI2, PI2, -PI2, 0]),
    "KUKA-like": ([0.26, 0.68, 0.035, 0, 0, 0], [0.675, 0, 0, 0.67, 0, 0.115],
                  [-PI2, 0, PI2, -PI2, PI2, 0]),
}


def _dh_forward(dh: tuple, theta: np.ndarray) -> np.ndarray:
    """The DH chain's tool pose (N, 4, 4) at joint angles θ (N, 6)."""
    a, d, al = (np.asarray(v, dtype=float) for v in dh)
    N = len(theta)
    T = np.broadcast_to(np.eye(4), (N, 4, 4)).copy()
    for i in range(6):
        c, s = np.cos(theta[:, i]), np.sin(theta[:, i])
        ca, sa = np.cos(al[i]), np.sin(al[i])
        A = np.zeros((N, 4, 4))
        A[:, 0] = np.stack([c, -s * ca, s * sa, a[i] * c], -1)
        A[:, 1] = np.stack([s, c * ca, -c * sa, a[i] * s], -1)
        A[:, 2] = [0.0, sa, ca, d[i]]
        A[:, 3] = [0.0, 0.0, 0.0, 1.0]
        T = T @ A
    return T


def _joint_lines(dh: tuple) -> tuple[np.ndarray, np.ndarray, tuple]:
    """The joint lines at θ = 0 (joint i about frame i−1's z through its origin) and the tool."""
    frames = [np.eye(4)]
    for i in range(6):
        frames.append(_partial(dh, i + 1))
    C = np.array([F[:3, 3] for F in frames[:6]])
    U = np.array([F[:3, 2] for F in frames[:6]])
    return C, U, (frames[6][:3, :3], frames[6][:3, 3])


def _partial(dh: tuple, n: int) -> np.ndarray:
    """Frame n of the chain at θ = 0."""
    a, d, al = (np.asarray(v, dtype=float) for v in dh)
    T = np.eye(4)
    for i in range(n):
        A = np.eye(4)
        ca, sa = np.cos(al[i]), np.sin(al[i])
        A[:3, :3] = [[1, 0, 0], [0, ca, -sa], [0, sa, ca]]
        A[:3, 3] = [a[i], 0, d[i]]
        T = T @ A
    return T


def _wrap(q: np.ndarray) -> np.ndarray:
    return np.mod(q + np.pi, 2 * np.pi) - np.pi


def _dense_newton(dh: tuple, target: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Gauss–Newton on the 12 entries of T(θ) − T_target (finite-difference Jacobian) from
    every start; the converged real solutions."""
    q = starts.copy()
    h = 1e-7
    for _ in range(40):
        r = (_dh_forward(dh, q) - target)[:, :3].reshape(len(q), 12)
        J = np.stack([((_dh_forward(dh, q + h * np.eye(6)[j]) - target)[:, :3]
                       .reshape(len(q), 12) - r) / h for j in range(6)], -1)
        q = q - np.einsum("nij,nj->ni", np.linalg.pinv(J), r)
    r = np.abs((_dh_forward(dh, q) - target)[:, :3]).max(axis=(1, 2))
    return _wrap(q[r < 1e-11])


def _contains(sols: np.ndarray, q: np.ndarray, tol: float) -> np.ndarray:
    """Whether each q (M, 6) is among sols (N, 6) mod 2π."""
    if len(sols) == 0:
        return np.zeros(len(q), dtype=bool)
    d = np.abs(_wrap(q[:, None, :] - sols[None, :, :])).max(-1)
    return d.min(1) < tol


@pytest.mark.parametrize("name", list(ARMS))
def test_industrial_arm_every_solution(name: str) -> None:
    dh = ARMS[name]
    C, U, home = _joint_lines(dh)
    rng = np.random.default_rng(sum(map(ord, name)))
    # the joint lines reproduce the DH chain (the PoE with q = θ from home)
    th = rng.uniform(-np.pi, np.pi, (5, 6))
    for t in th:
        R, p = arm_forward(C, U, home, t)
        T = _dh_forward(dh, t[None])[0]
        assert np.abs(R - T[:3, :3]).max() < 1e-12 and np.abs(p - T[:3, 3]).max() < 1e-12
    real_counts = []
    certified = 0
    for _ in range(TARGETS):
        q0 = rng.uniform(-np.pi, np.pi, 6)
        target = arm_forward(C, U, home, q0)
        sols, res = arm_inverse_kinematics(C, U, home, target)
        assert isinstance(res, ArmContinuation) and res.route == (ROUTE,)
        assert res.found == 8 == res.converged, (res.found, res.converged, q0.tolist())
        assert res.real_count == len(sols) and len(sols) % 2 == 0
        # the α-test may fail only near a singularity (two solutions close together)
        assert (res.certified | (res.condition > 1e3)).all(), (res.note, res.condition)
        assert (res.radius[res.certified] < 1e-6).all()
        certified += int(res.certified.sum())
        T = _dh_forward(dh, sols)
        Tt = _dh_forward(dh, q0[None])[0]
        assert np.abs(T - Tt).max() <= CLOSE
        assert res.residual.max() <= CLOSE
        assert _contains(sols, q0[None], 1e-8).all()
        d = np.abs(_wrap(sols[:, None] - sols[None])).max(-1) + np.eye(len(sols)) * 9
        assert d.min() > 1e-6  # distinct
        dense = _dense_newton(dh, Tt, rng.uniform(-np.pi, np.pi, (200, 6)))
        assert _contains(sols, dense, 1e-6).all(), "dense Newton found a missed solution"
        real_counts.append(len(sols))
    assert max(real_counts) == 8  # all 8 real at some targets
    assert certified >= 0.95 * sum(real_counts), (certified, sum(real_counts))


def test_ur5_repro_no_longer_raises() -> None:
    C, U, home = _joint_lines(ARMS["UR5"])
    q0 = np.array([0.3, -1.1, 1.4, -0.6, 0.9, 2.0])
    sols, res = arm_inverse_kinematics(C, U, home, arm_forward(C, U, home, q0))
    assert res.parallel == ((2, 3), (3, 4)) and _contains(sols, q0[None], 1e-8).all()


def test_collinear_consecutive_joints_are_a_capability_error() -> None:
    C, U, home = _joint_lines(ARMS["PUMA560"])
    C = C.copy()
    U = U.copy()
    U[1], C[1] = U[0], C[0] + 0.3 * U[0]  # joint 2 on joint 1's line
    with pytest.raises(CapabilityError, match="joints 1 and 2"):
        arm_inverse_kinematics(C, U, home, home)


def test_the_6r_loop_of_a_parallel_arm_is_a_capability_error_naming_the_joints() -> None:
    C, U, home = _joint_lines(ARMS["UR5"])
    with pytest.raises(CapabilityError, match="joints 2 and 3 .*arm_inverse_kinematics") as e:
        arm6r_instance(C, U, home, home)
    assert "planar" not in str(e.value)


def test_general_arm_keeps_the_elimination_route() -> None:
    rng = np.random.default_rng(5)
    C, U = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    U /= np.linalg.norm(U, axis=1)[:, None]
    home = (np.eye(3), rng.normal(size=3))
    q0 = rng.uniform(-np.pi, np.pi, 6)
    target = arm_forward(C, U, home, q0)
    sols, res = arm_inverse_kinematics(C, U, home, target)
    assert isinstance(res, Solutions) and res.route[0].startswith("elimination")
    # the complex joint values agree with the real reading on the real solutions
    inst = arm6r_instance(C, U, home, target)
    sol = solve_loop6r(inst.params)
    qc = complex_joint_values(inst.params, sol.x, inst.base_ref, inst.tool_ref,
                              inst.home_angles)
    real = qc[sol.real]
    assert np.abs(real.imag).max() < 1e-8
    assert np.abs(_wrap(real.real - sols)).max() < 1e-8
    assert np.isfinite(qc).all() and len(qc) == 16


def test_general_arm_with_joint_6_parallel_to_joint_1_at_the_target() -> None:
    """A general arm whose tool pose puts joint 6 parallel to joint 1 (the loop's ground link):
    the 6R loop cannot be set up there, the perturbation route answers, checked by the
    forward kinematics and by the generic answer at a nearby target."""
    rng = np.random.default_rng(11)
    C, U = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    U /= np.linalg.norm(U, axis=1)[:, None]
    home = (np.eye(3), rng.normal(size=3))
    # joint 6's axis at q0 is R_{<6}(q0) u6 (the first five joints' rotation): make it u1
    q0 = rng.uniform(-np.pi, np.pi, 6)
    R5, _ = arm_forward(C[:5], U[:5], (np.eye(3), np.zeros(3)), q0[:5])
    U[5] = R5.T @ U[0]
    target = arm_forward(C, U, home, q0)
    Rt = target[0]
    sols, res = arm_inverse_kinematics(C, U, home, target)
    assert isinstance(res, ArmContinuation) and (6, 1) in res.parallel
    assert res.found == res.converged and _contains(sols, q0[None], 1e-8).all()
    for q in sols:
        R, p = arm_forward(C, U, home, q)
        assert np.abs(R - Rt).max() <= CLOSE and np.abs(p - target[1]).max() <= CLOSE
    dense_real = _dense_poe(C, U, home, target, rng.uniform(-np.pi, np.pi, (300, 6)))
    assert _contains(sols, dense_real, 1e-6).all()


def _dense_poe(C: np.ndarray, U: np.ndarray, home: tuple, target: tuple,
               starts: np.ndarray) -> np.ndarray:
    """Gauss–Newton on arm_forward's 12 pose entries (finite differences) from every start."""
    def resid(q: np.ndarray) -> np.ndarray:
        out = []
        for qi in q:
            R, p = arm_forward(C, U, home, qi)
            out.append(np.concatenate([(R - target[0]).ravel(), p - target[1]]))
        return np.array(out)

    q = starts.copy()
    for _ in range(30):
        r = resid(q)
        J = np.stack([(resid(q + 1e-7 * np.eye(6)[j]) - r) / 1e-7 for j in range(6)], -1)
        q = q - np.einsum("nij,nj->ni", np.linalg.pinv(J), r)
    return _wrap(q[np.abs(resid(q)).max(-1) < 1e-11])


def test_nearly_parallel_arm_agrees_with_the_elimination_route() -> None:
    """A UR5 with joint 3 tilted 5e-3 rad (sin α < PARALLEL_SIN: routed here) is also a general
    arm the elimination can solve: the two methods give the same real solutions."""
    C, U, home = _joint_lines(ARMS["UR5"])
    U = U.copy()
    U[2] = np.cos(5e-3) * U[2] + np.sin(5e-3) * np.array([1.0, 0.0, 0.0])
    rng = np.random.default_rng(3)
    for _ in range(5):
        q0 = rng.uniform(-np.pi, np.pi, 6)
        target = arm_forward(C, U, home, q0)
        sols, res = arm_inverse_kinematics(C, U, home, target)
        assert isinstance(res, ArmContinuation) and res.parallel == ((2, 3), (3, 4))
        inst = arm6r_instance(C, U, home, target)
        sol = solve_loop6r(inst.params)
        other = inst.joint_values(sol.x[sol.real])
        assert len(other) == len(sols) and _contains(sols, q0[None], 1e-8).all()
        assert _contains(sols, other, 1e-6).all() and _contains(other, sols, 1e-6).all()

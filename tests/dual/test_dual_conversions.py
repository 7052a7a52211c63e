"""Round trips ScrewMatrix ↔ 4×4 ↔ DualQuaternion ↔ scipy Rotation / RigidTransform, the dual
quaternion algebra, and agreement with scipy's own rotations and dual quaternions."""

from __future__ import annotations

import numpy as np
import pytest
from dual_strategies import SETTINGS, assert_screw_close, cases, random_screw, rng_for
from hypothesis import given
from scipy.spatial.transform import Rotation

import screwkit.dual as sd
from screwkit.dual import Dual, DualQuaternion, ScrewMatrix


def assert_dq_same_displacement(a: DualQuaternion, b: DualQuaternion, atol: float = 1e-12) -> None:
    assert np.all(a.isclose(b, atol=atol)), (a, b)


@SETTINGS
@given(cases)
def test_screw_matrix_transform_round_trip(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    S = random_screw(rng_for(seed), shape)
    T = sd.transform_from_screw_matrix(S)
    assert T.shape == (*shape, 4, 4)
    np.testing.assert_array_equal(T[..., 3, :], np.broadcast_to([0.0, 0.0, 0.0, 1.0], (*shape, 4)))
    assert_screw_close(sd.screw_matrix_from_transform(T), S, atol=1e-13)
    assert_screw_close(ScrewMatrix.from_transform(S.as_transform()), S, atol=1e-13)


@SETTINGS
@given(cases)
def test_dual_quaternion_round_trips(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    S = random_screw(rng_for(seed), shape)
    q = sd.dual_quaternion_from_screw_matrix(S)
    assert q.shape == shape
    sd.check_unit_dual_quaternion(q.real, q.dual, tol=1e-13)
    assert np.all(q.real[..., 0] >= 0)
    assert_screw_close(sd.screw_matrix_from_dual_quaternion(q), S, atol=1e-12)
    T = S.as_transform()
    np.testing.assert_allclose(sd.transform_from_dual_quaternion(q), T, atol=1e-12)
    assert_dq_same_displacement(sd.dual_quaternion_from_transform(T), q)
    assert_dq_same_displacement(DualQuaternion.from_array(q.as_array()), q, atol=0)
    # q̂ and −q̂ are the same displacement
    assert_screw_close(DualQuaternion(-q.real, -q.dual).as_screw_matrix(), S, atol=1e-12)


@SETTINGS
@given(cases)
def test_dual_quaternion_algebra_matches_screw_matrices(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    A, B, C = (random_screw(rng, shape) for _ in range(3))
    qa, qb, qc = (DualQuaternion.from_screw_matrix(X) for X in (A, B, C))
    assert_screw_close((qa @ qb).as_screw_matrix(), A @ B, atol=1e-12)
    assert_screw_close(qa.multiply(qb).as_screw_matrix(), A @ B, atol=1e-12)
    assert_dq_same_displacement((qa @ qb) @ qc, qa @ (qb @ qc))
    ident = DualQuaternion.identity(shape)
    assert_dq_same_displacement(qa @ qa.conjugate(), ident)
    assert_dq_same_displacement(qa.inverse(), qa.conjugate())
    assert_screw_close(qa.conjugate().as_screw_matrix(), A.inverse(), atol=1e-12)
    n2 = qa.norm_squared()
    np.testing.assert_allclose(n2.real, 1.0, atol=1e-14)
    np.testing.assert_allclose(n2.dual, 0.0, atol=1e-13)
    p = rng.normal(size=(*shape, 3))
    np.testing.assert_allclose(qa.transform_points(p), A.transform_points(p), atol=1e-12)
    # The dual-number conjugate r − εd of a pure translation is the opposite translation.
    qt = DualQuaternion.from_rotation_translation(np.eye(3), p)
    np.testing.assert_allclose(qt.dual_conjugate().translation, -p, atol=1e-13)


@SETTINGS
@given(cases)
def test_normalisation(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    S = random_screw(rng, shape)
    q = DualQuaternion.from_screw_matrix(S)
    k = Dual(rng.uniform(0.5, 3.0, size=shape), rng.normal(size=shape))
    # scale by a dual scalar k̂: (k0 + εk1)(r + εd) — the same displacement once normalised
    scaled = DualQuaternion(
        k.real[..., None] * q.real, k.real[..., None] * q.dual + k.dual[..., None] * q.real
    )
    n = scaled.normalized()
    sd.check_unit_dual_quaternion(n.real, n.dual, tol=1e-13)
    assert_dq_same_displacement(n, q, atol=1e-12)
    norm = scaled.norm()
    np.testing.assert_allclose(norm.real, k.real, rtol=1e-13)
    np.testing.assert_allclose(norm.dual, k.dual, atol=1e-12)


@SETTINGS
@given(cases)
def test_scipy_round_trips(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    S = random_screw(rng_for(seed), shape)
    rot = sd.rotation_from_screw_matrix(S)
    assert rot.shape == shape
    np.testing.assert_allclose(rot.as_matrix(), S.real, atol=1e-14)
    pure = sd.screw_matrix_from_rotation(rot)
    np.testing.assert_allclose(pure.real, S.real, atol=1e-14)
    np.testing.assert_array_equal(pure.dual, 0.0)
    assert_screw_close(sd.screw_matrix_from_rotation(rot, S.translation), S, atol=1e-13)

    tf = sd.rigid_transform_from_screw_matrix(S)
    assert tf.shape == shape
    np.testing.assert_allclose(tf.translation, S.translation, atol=1e-14)
    assert_screw_close(sd.screw_matrix_from_rigid_transform(tf), S, atol=1e-13)

    # scipy's own dual quaternion (scalar first) is ours, up to the sign of q̂.
    q_scipy = sd.dual_quaternion_from_rigid_transform(tf)
    assert_dq_same_displacement(q_scipy, DualQuaternion.from_screw_matrix(S))
    back = sd.rigid_transform_from_dual_quaternion(DualQuaternion.from_screw_matrix(S))
    np.testing.assert_allclose(back.as_matrix(), S.as_transform(), atol=1e-12)


@SETTINGS
@given(cases)
def test_elementary_rotations_agree_with_scipy(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    t = rng.uniform(-np.pi, np.pi, size=shape)
    for axis, name in enumerate("xyz"):
        ours = ScrewMatrix.about_axis(Dual(t, 0.7), axis)
        theirs = Rotation.from_rotvec(t[..., None] * np.eye(3)[axis]).as_matrix()
        np.testing.assert_allclose(ours.real, theirs, atol=1e-14)
        np.testing.assert_allclose(
            ours.translation, np.broadcast_to(0.7 * np.eye(3)[axis], (*shape, 3)), atol=1e-14
        )
        # scipy lower-case = extrinsic; a single axis is the same either way
        np.testing.assert_allclose(
            ours.real, Rotation.from_euler(name, t[..., None]).as_matrix(), atol=1e-14
        )


def test_conversion_error_paths() -> None:
    T = np.eye(4)
    T[3, 0] = 0.5
    with pytest.raises(ValueError, match=r"last row must be \(0, 0, 0, 1\)"):
        sd.screw_matrix_from_transform(T)
    T = np.eye(4)
    T[0, 0] = 2.0
    with pytest.raises(ValueError, match="rotation block of transform is not orthogonal"):
        sd.dual_quaternion_from_transform(T)
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 4, 4\); got shape \(3, 3\)"):
        sd.screw_matrix_from_transform(np.eye(3))
    with pytest.raises(ValueError, match="expected a scipy.spatial.transform.Rotation"):
        sd.screw_matrix_from_rotation(np.eye(3))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="expected a scipy.spatial.transform.RigidTransform"):
        sd.screw_matrix_from_rigid_transform(np.eye(4))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="expected a scipy.spatial.transform.RigidTransform"):
        sd.dual_quaternion_from_rigid_transform(Rotation.identity())  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="not orthogonal"):
        sd.rotation_from_screw_matrix(ScrewMatrix(2.0 * np.eye(3)))
    with pytest.raises(ValueError, match="not orthogonal"):
        sd.rigid_transform_from_screw_matrix(ScrewMatrix(2.0 * np.eye(3)))
    with pytest.raises(ValueError, match=r"not a unit quaternion.*normalized"):
        sd.rigid_transform_from_dual_quaternion(DualQuaternion([2.0, 0, 0, 0]))
    with pytest.raises(ValueError, match=r"real·dual"):
        sd.check_unit_dual_quaternion([1.0, 0, 0, 0], [1.0, 0, 0, 0])
    with pytest.raises(ValueError, match=r"trailing shape \(4,\)"):
        DualQuaternion(np.zeros(3))
    with pytest.raises(ValueError, match=r"trailing shape \(8,\)"):
        DualQuaternion.from_array(np.zeros(7))
    with pytest.raises(ValueError, match="zero real part"):
        DualQuaternion(np.zeros(4), [1.0, 0, 0, 0]).normalized()
    with pytest.raises(ValueError, match="zero real part"):
        DualQuaternion(np.zeros(4), [1.0, 0, 0, 0]).inverse()

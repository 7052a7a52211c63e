"""MassProperties: constructors, inertial parameters, pseudo-inertia, consistency checks."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from screwkit.model.mass import (
    MassProperties,
    PhysicalConsistencyError,
    PointMassModel,
    check_physical_consistency,
    mass_properties_from_point_masses,
    physical_consistency_violations,
)

SETTINGS = settings(derandomize=True, max_examples=60, deadline=None)

finite = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)


@st.composite
def rigid_bodies(draw: st.DrawFn) -> MassProperties:
    """Random physically consistent bodies: λ from non-negative second moments σ (so the
    triangle inequalities hold), random principal axes, random CoM."""
    mass = draw(st.floats(1e-3, 50.0))
    sigma = np.array([draw(st.floats(0.0, 1.0)) for _ in range(3)]) * mass
    moments = np.array([sigma[1] + sigma[2], sigma[0] + sigma[2], sigma[0] + sigma[1]])
    quat = np.array([draw(finite) for _ in range(4)]) + np.array([1e-3, 0, 0, 0])
    axes = Rotation.from_quat(quat).as_matrix()
    com = np.array([draw(finite) for _ in range(3)])
    return MassProperties.from_principal(mass, com, moments, axes)


def test_from_principal_columns_vs_rows() -> None:
    axes = Rotation.from_euler("zyx", [0.3, -0.7, 1.1]).as_matrix()
    moments = np.array([1.0, 2.0, 2.5])
    by_columns = MassProperties.from_principal(2.0, np.zeros(3), moments, axes)
    by_rows = MassProperties.from_principal(2.0, np.zeros(3), moments, axes.T, axes_as="rows")
    np.testing.assert_allclose(by_columns.inertia, axes @ np.diag(moments) @ axes.T, atol=1e-15)
    np.testing.assert_allclose(by_rows.inertia, by_columns.inertia, atol=1e-15)
    # the principal axis k is column k: I a_k = λ_k a_k
    for k in range(3):
        np.testing.assert_allclose(
            by_columns.inertia @ axes[:, k], moments[k] * axes[:, k], atol=1e-14
        )
    got_moments, got_axes = by_columns.principal()
    np.testing.assert_allclose(got_moments, moments, rtol=1e-14)
    np.testing.assert_allclose(np.abs(got_axes.T @ axes), np.eye(3), atol=1e-12)
    assert np.linalg.det(got_axes) == pytest.approx(1.0)


def test_from_principal_rejects_non_orthonormal_axes() -> None:
    with pytest.raises(ValueError, match="orthonormal"):
        MassProperties.from_principal(1.0, np.zeros(3), [1, 1, 1], np.diag([1.0, 1.0, 1.1]))
    with pytest.raises(ValueError, match="axes_as"):
        MassProperties.from_principal(1.0, np.zeros(3), [1, 1, 1], axes_as="diagonal")  # type: ignore[arg-type]


def test_from_weight_and_radii_of_gyration() -> None:
    body = MassProperties.from_weight(19.6133, [0.1, 0, 0], radii_of_gyration=[0.2, 0.25, 0.3])
    assert body.mass == pytest.approx(2.0, rel=1e-15)  # 19.6133 N / 9.80665 m/s²
    np.testing.assert_allclose(
        np.diag(body.inertia), 2.0 * np.array([0.04, 0.0625, 0.09]), rtol=1e-15
    )
    np.testing.assert_allclose(body.radii_of_gyration(), [0.2, 0.25, 0.3], rtol=1e-14)
    moon = MassProperties.from_weight(3.24, np.zeros(3), inertia=np.eye(3), gravity=1.62)
    assert moon.mass == pytest.approx(2.0, rel=1e-15)
    with pytest.raises(ValueError, match="exactly one"):
        MassProperties.from_weight(1.0, np.zeros(3))
    with pytest.raises(ValueError, match="exactly one"):
        MassProperties.from_weight(1.0, np.zeros(3), inertia=np.eye(3), radii_of_gyration=[1, 1, 1])
    with pytest.raises(ValueError, match="gravity"):
        MassProperties.from_weight(1.0, np.zeros(3), inertia=np.eye(3), gravity=0.0)
    with pytest.raises(ValueError, match="weight"):
        MassProperties.from_weight(-1.0, np.zeros(3), inertia=np.eye(3))
    with pytest.raises(ValueError, match=">= 0"):
        MassProperties.from_weight(1.0, np.zeros(3), radii_of_gyration=[1, -1, 1])


@SETTINGS
@given(rigid_bodies())
def test_inertial_parameters_round_trip(body: MassProperties) -> None:
    pi = body.inertial_parameters()
    assert pi.shape == (10,)
    assert pi[0] == body.mass
    np.testing.assert_allclose(pi[1:4], body.mass * body.com, rtol=1e-15)
    back = MassProperties.from_inertial_parameters(pi)
    scale = np.max(np.abs(body.inertia_about(np.zeros(3))))
    assert back.mass == body.mass
    np.testing.assert_allclose(back.com, body.com, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(back.inertia, body.inertia, rtol=0, atol=1e-13 * scale)


def test_inertial_parameter_order() -> None:
    inertia = np.array([[3.0, -0.1, -0.2], [-0.1, 4.0, -0.3], [-0.2, -0.3, 5.0]])
    body = MassProperties(2.0, np.zeros(3), inertia)
    np.testing.assert_allclose(
        body.inertial_parameters(), [2.0, 0, 0, 0, 3.0, 4.0, 5.0, -0.1, -0.2, -0.3]
    )
    with pytest.raises(ValueError, match=r"shape \(10,\)"):
        MassProperties.from_inertial_parameters(np.ones(9))
    with pytest.raises(PhysicalConsistencyError, match="mass must be > 0"):
        MassProperties.from_inertial_parameters([0.0, 0, 0, 0, 1, 1, 1, 0, 0, 0])
    with pytest.raises(ValueError, match="finite"):
        MassProperties.from_inertial_parameters([1.0, 0, 0, 0, np.nan, 1, 1, 0, 0, 0])
    # a unit mass at (1, 0, 0) has I_O = diag(0, 1, 1); I_yy = 0.5 leaves a central I_yy < 0
    with pytest.raises(PhysicalConsistencyError, match="parallel-axis shift"):
        MassProperties.from_inertial_parameters([1.0, 1.0, 0, 0, 0.0, 0.5, 1.0, 0, 0, 0])


@SETTINGS
@given(rigid_bodies(), st.lists(finite, min_size=3, max_size=3))
def test_parallel_axis_against_point_cloud(body: MassProperties, point: list[float]) -> None:
    """inertia_about(P) equals the sum over the body's point-mass equivalent about P."""
    from screwkit.model.mass import equivalent_point_masses

    cloud = equivalent_point_masses(body)
    p = np.asarray(point)
    r = cloud.positions - p
    direct = sum(
        m * (ri @ ri * np.eye(3) - np.outer(ri, ri)) for m, ri in zip(cloud.masses, r, strict=True)
    )
    scale = np.max(np.abs(direct)) + 1e-300
    np.testing.assert_allclose(body.inertia_about(p), direct, rtol=0, atol=1e-12 * scale)


@SETTINGS
@given(rigid_bodies())
def test_pseudo_inertia_is_psd_and_matches_point_masses(body: MassProperties) -> None:
    from screwkit.model.mass import equivalent_point_masses

    cloud = equivalent_point_masses(body)
    homogeneous = np.hstack([cloud.positions, np.ones((cloud.positions.shape[0], 1))])
    expected = np.einsum("k,ki,kj->ij", cloud.masses, homogeneous, homogeneous)
    got = body.pseudo_inertia()
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * np.max(np.abs(expected)))
    assert np.min(np.linalg.eigvalsh(got)) >= -1e-12 * np.max(np.abs(got))


def test_consistency_errors_name_the_condition_and_amount() -> None:
    with pytest.raises(PhysicalConsistencyError, match=r"mass must be > 0, got -1 kg"):
        MassProperties(-1.0, np.zeros(3), np.eye(3))
    asym = np.eye(3)
    asym[0, 1] = 1e-3
    with pytest.raises(
        PhysicalConsistencyError, match=r"not symmetric: max \|I - I\^T\| = 1\.000e-03"
    ):
        MassProperties(1.0, np.zeros(3), asym)
    with pytest.raises(PhysicalConsistencyError, match="not positive semidefinite") as info:
        MassProperties(1.0, np.zeros(3), np.diag([-1.0, 2.0, 2.0]))
    assert "triangle inequality" in str(info.value)  # λ2 <= λ1 + λ3 fails too: 2 > 1
    # triangle fails while the tensor is positive definite: 3 > 1 + 1 by 1
    with pytest.raises(PhysicalConsistencyError, match=r"λ3 <= λ1 \+ λ2 fails by 1\.000000e\+00"):
        MassProperties(1.0, np.zeros(3), np.diag([1.0, 1.0, 3.0]))
    assert physical_consistency_violations(1.0, np.diag([1.0, 1.0, 2.0])) == []  # flat body
    with pytest.raises(PhysicalConsistencyError, match="crank: mass properties"):
        check_physical_consistency(0.0, np.eye(3), where="crank")
    with pytest.raises(ValueError, match="shape"):
        physical_consistency_violations(1.0, np.eye(2))


def test_constructor_shape_and_finiteness_errors() -> None:
    with pytest.raises(ValueError, match=r"com must have shape \(3,\)"):
        MassProperties(1.0, np.zeros(2), np.eye(3))
    with pytest.raises(ValueError, match=r"inertia must have shape \(3, 3\)"):
        MassProperties(1.0, np.zeros(3), np.eye(2))
    with pytest.raises(ValueError, match="finite"):
        MassProperties(1.0, np.array([0.0, np.inf, 0.0]), np.eye(3))


def test_mass_properties_is_immutable() -> None:
    body = MassProperties(1.0, np.zeros(3), np.eye(3))
    with pytest.raises(ValueError, match="read-only"):
        body.com[0] = 1.0
    with pytest.raises(AttributeError):
        body.mass = 2.0  # type: ignore[misc]


def test_point_masses_to_rigid_body_by_hand() -> None:
    """Two 1 kg masses at x = ±1: m = 2, c = 0, I = diag(0, 2, 2)."""
    body = mass_properties_from_point_masses([[1.0, 0, 0], [-1.0, 0, 0]], [1.0, 1.0])
    assert body.mass == 2.0
    np.testing.assert_allclose(body.com, 0.0, atol=0)
    np.testing.assert_allclose(body.inertia, np.diag([0.0, 2.0, 2.0]), atol=0)


def test_point_mass_model_errors() -> None:
    with pytest.raises(ValueError, match=r"positions must have shape \(k, 3\)"):
        PointMassModel(np.zeros((2, 2)), np.ones(2))
    with pytest.raises(ValueError, match=r"masses must have shape \(2,\)"):
        PointMassModel(np.zeros((2, 3)), np.ones(3))
    with pytest.raises(PhysicalConsistencyError, match=r"masses \(1\) \(counted from 0\) are \(-1\) kg"):
        PointMassModel(np.zeros((2, 3)), [1.0, -1.0])
    with pytest.raises(PhysicalConsistencyError, match="positive total mass"):
        PointMassModel(np.zeros((2, 3)), [0.0, 0.0])
    with pytest.raises(ValueError, match="finite"):
        PointMassModel(np.full((1, 3), np.nan), [1.0])

"""Rahman's equivalent point-mass model (Rahman 1996 §2.2; SPEC §2): exact equivalence with the
rigid body, the seed example's numbers, split errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pint
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from screwkit.model.mass import (
    EQUIVALENT_POINT_LABELS,
    MassProperties,
    PointMassSplitError,
    equivalent_point_masses,
    point_mass_distances,
)

SETTINGS = settings(derandomize=True, max_examples=60, deadline=None)
DATA = json.loads(
    (Path(__file__).parents[1] / "data" / "rahman1996" / "cssp_example.json").read_text()
)
UREG: pint.UnitRegistry = pint.UnitRegistry()
finite = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)


@st.composite
def rigid_bodies(draw: st.DrawFn) -> MassProperties:
    mass = draw(st.floats(1e-3, 50.0))
    sigma = np.array([draw(st.floats(1e-6, 1.0)) for _ in range(3)]) * mass
    moments = np.array([sigma[1] + sigma[2], sigma[0] + sigma[2], sigma[0] + sigma[1]])
    quat = np.array([draw(finite) for _ in range(4)]) + np.array([1e-3, 0, 0, 0])
    com = np.array([draw(finite) for _ in range(3)])
    return MassProperties.from_principal(mass, com, moments, Rotation.from_quat(quat).as_matrix())


@st.composite
def splits(draw: st.DrawFn, mass: float) -> np.ndarray:
    weights = np.array([draw(st.floats(0.05, 1.0)) for _ in range(4)])
    split = mass * weights / weights.sum()
    split[3] = mass - split[:3].sum()
    return split


def assert_same_body(a: MassProperties, b: MassProperties) -> None:
    scale = np.max(np.abs(a.inertia)) + a.mass * float(a.com @ a.com)
    assert b.mass == pytest.approx(a.mass, rel=1e-14)
    np.testing.assert_allclose(b.com, a.com, rtol=0, atol=1e-13 * (1 + np.max(np.abs(a.com))))
    np.testing.assert_allclose(b.inertia, a.inertia, rtol=0, atol=1e-12 * scale)


@SETTINGS
@given(st.data(), rigid_bodies())
def test_round_trip_any_split(data: st.DataObject, body: MassProperties) -> None:
    split = data.draw(splits(body.mass))
    model = equivalent_point_masses(body, split)
    assert model.positions.shape == (7, 3)
    np.testing.assert_allclose(model.masses[[0, 2, 4]] * 2, split[:3], rtol=1e-15)
    np.testing.assert_allclose(model.masses[6], split[3], rtol=1e-15)
    assert_same_body(body, model.to_mass_properties())
    # each pair is centred on the CoM, so new pair masses never move it (SPEC §2)
    new_masses = model.masses * np.array([1.3, 1.3, 0.7, 0.7, 1.1, 1.1, 0.5])
    moved = model.with_masses(new_masses).to_mass_properties()
    np.testing.assert_allclose(
        moved.com, body.com, rtol=0, atol=1e-13 * (1 + float(np.max(np.abs(body.com))))
    )


def test_default_split_is_quarter_masses_on_link_axes() -> None:
    body = MassProperties(4.0, [1.0, 0, 0], np.diag([1.0, 3.0, 3.0]))
    model = equivalent_point_masses(body)
    assert EQUIVALENT_POINT_LABELS == ("+X", "-X", "+Y", "-Y", "+Z", "-Z", "CoM")
    np.testing.assert_allclose(model.masses, [0.5] * 6 + [1.0])
    # m1 X² = ½(−1 + 3 + 3) = 2.5 with m1 = 1 → X = √2.5; Y = Z = √0.5; along the link axes even
    # though λ2 = λ3 (an eigen-solver could rotate that pair)
    x, yz = np.sqrt(2.5), np.sqrt(0.5)
    expected = np.array(
        [[1 + x, 0, 0], [1 - x, 0, 0], [1, yz, 0], [1, -yz, 0], [1, 0, yz], [1, 0, -yz], [1, 0, 0]]
    )
    np.testing.assert_allclose(model.positions, expected, rtol=0, atol=1e-15)
    # Rahman's program gives each point of a pair the full m_k (SPEC §3.2): 7/4 of the mass
    seed_program = model.with_masses(np.array([1.0] * 6 + [1.0])).to_mass_properties()
    assert seed_program.mass == pytest.approx(7 / 4 * body.mass)
    assert not np.allclose(seed_program.inertia, body.inertia)


def test_explicit_axes_and_rejection_of_non_principal_axes() -> None:
    axes = Rotation.from_euler("xyz", [0.2, 0.4, -0.9]).as_matrix()
    body = MassProperties.from_principal(2.0, [0, 1.0, 0], [1.0, 2.0, 2.5], axes)
    model = equivalent_point_masses(body, axes=axes)
    direction = model.positions[0] - model.positions[1]
    np.testing.assert_allclose(direction / np.linalg.norm(direction), axes[:, 0], atol=1e-14)
    assert_same_body(body, model.to_mass_properties())
    with pytest.raises(ValueError, match="do not diagonalise"):
        equivalent_point_masses(body, axes=np.eye(3))
    with pytest.raises(ValueError, match="orthonormal"):
        equivalent_point_masses(body, axes=2 * np.eye(3))


def test_split_errors() -> None:
    body = MassProperties(4.0, np.zeros(3), np.diag([1.0, 3.0, 3.0]))
    with pytest.raises(PointMassSplitError, match="sum to the link mass"):
        equivalent_point_masses(body, [1.0, 1.0, 1.0, 2.0])
    with pytest.raises(PointMassSplitError, match=">= 0"):
        equivalent_point_masses(body, [2.0, 2.0, 1.0, -1.0])
    with pytest.raises(PointMassSplitError, match="four finite masses"):
        equivalent_point_masses(body, [2.0, 2.0])
    with pytest.raises(
        PointMassSplitError, match=r"m2 = 0 but the Y-pair must supply m2·Y² = 5\.0"
    ):
        equivalent_point_masses(body, [1.0, 0.0, 1.0, 2.0])


def test_zero_pair_mass_allowed_for_a_flat_body() -> None:
    """λ3 = λ1 + λ2 (a lamina in the xy-plane) needs no Z-pair: m3 = 0 is a valid split."""
    body = MassProperties(3.0, np.zeros(3), np.diag([1.0, 2.0, 3.0]))
    model = equivalent_point_masses(body, [1.0, 1.0, 0.0, 1.0])
    assert_same_body(body, model.to_mass_properties())


def test_point_mass_distances_by_hand_and_impossible_moments() -> None:
    # λ = (1, 3, 3), pair masses 1: X² = 2.5, Y² = Z² = 0.5
    np.testing.assert_allclose(
        point_mass_distances([1.0, 3.0, 3.0], [1.0, 1.0, 1.0]), np.sqrt([2.5, 0.5, 0.5])
    )
    # λ3 = 3 > λ1 + λ2 = 2: m3 Z² = ½(1 + 1 − 3) < 0
    with pytest.raises(PointMassSplitError, match=r"m3·Z² = -5\.000000e-01 kg m\^2 < 0"):
        point_mass_distances([1.0, 1.0, 3.0], [1.0, 1.0, 1.0])
    with pytest.raises(PointMassSplitError, match=">= 0"):
        point_mass_distances([1.0, 1.0, 1.0], [1.0, -1.0, 1.0])


def _seed_body(link: str) -> MassProperties:
    rec = DATA[link]
    weight = (rec["weight_lbf"] * UREG.lbf).to("N").magnitude
    gravity = (DATA["gravity_in_per_s2"] * UREG("inch/s**2")).to("m/s**2").magnitude
    com = (np.array([rec["com_x_in"], 0.0, 0.0]) * UREG.inch).to("m").magnitude
    radii = (np.array(rec["radii_of_gyration_cg_in"]) * UREG.inch).to("m").magnitude
    return MassProperties.from_weight(weight, com, radii_of_gyration=radii, gravity=gravity)


@pytest.mark.parametrize("link", ["crank", "rod"])
def test_seed_example_point_masses(link: str) -> None:
    """Rahman's crank and rod (SPEC §2, §5): masses m/4 and distances X, Y = Z as printed."""
    rec = DATA[link]
    body = _seed_body(link)
    mass_unit = UREG("lbf*s**2/inch")
    quarter = (body.mass / 4 * UREG.kg).to(mass_unit).magnitude
    # the seed prints 7 significant digits
    assert quarter == pytest.approx(rec["quarter_mass_lbf_s2_per_in"], rel=5e-7)
    inertia = (np.diag(body.inertia) * UREG("kg*m**2")).to("lbf*s**2*inch").magnitude
    # printed to 6-7 significant digits (0.105310): half a unit of the last digit is 4.7e-6
    np.testing.assert_allclose(inertia, rec["inertia_cg_lbf_s2_in"], rtol=5e-6)
    model = equivalent_point_masses(body)
    offsets = (model.positions - body.com) / 0.0254
    distances = np.linalg.norm(offsets[[0, 2, 4]], axis=1)
    np.testing.assert_allclose(distances, rec["point_mass_distances_in"], rtol=2e-6)
    np.testing.assert_allclose(offsets[0], [distances[0], 0, 0], atol=1e-15)
    assert_same_body(body, model.to_mass_properties())


# --- dynamic equivalence under an arbitrary rigid motion -------------------------------------
def _elementary(axis: int, angle: float) -> np.ndarray:
    return Rotation.from_rotvec(angle * np.eye(3)[axis]).as_matrix()


def _generator(axis: int) -> np.ndarray:
    k = np.zeros((3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    k[j, i], k[i, j] = 1.0, -1.0
    return k


def rigid_motion(coef: np.ndarray, t: float) -> tuple[np.ndarray, ...]:
    """R(t) = Rz(a) Ry(b) Rx(c) with quadratic a, b, c and p(t) quadratic; exact Ṙ, R̈, ṗ, p̈."""
    angles = coef[:3, 0] + coef[:3, 1] * t + coef[:3, 2] * t**2
    rates = coef[:3, 1] + 2 * coef[:3, 2] * t
    accels = 2 * coef[:3, 2]
    factors, firsts, seconds = [], [], []
    for axis, ang, rate, acc in zip((2, 1, 0), angles, rates, accels, strict=True):
        r, k = _elementary(axis, ang), _generator(axis)
        factors.append(r)
        firsts.append(rate * r @ k)
        seconds.append(acc * r @ k + rate**2 * r @ k @ k)
    a, b, c = factors
    ad, bd, cd = firsts
    add, bdd, cdd = seconds
    rot = a @ b @ c
    rot_d = ad @ b @ c + a @ bd @ c + a @ b @ cd
    rot_dd = add @ b @ c + a @ bdd @ c + a @ b @ cdd + 2 * (ad @ bd @ c + ad @ b @ cd + a @ bd @ cd)
    p = coef[3:, 0] + coef[3:, 1] * t + coef[3:, 2] * t**2
    pd = coef[3:, 1] + 2 * coef[3:, 2] * t
    pdd = 2 * coef[3:, 2]
    return rot, rot_d, rot_dd, p, pd, pdd


def _vee(m: np.ndarray) -> np.ndarray:
    return np.array([m[2, 1], m[0, 2], m[1, 0]])


@SETTINGS
@given(
    st.data(),
    rigid_bodies(),
    st.lists(st.floats(-3.0, 3.0), min_size=18, max_size=18),
    st.floats(-1.0, 1.0),
)
def test_point_mass_model_is_dynamically_equivalent(
    data: st.DataObject, body: MassProperties, coef: list[float], t: float
) -> None:
    """Σ m ẍ, Σ x × m ẍ (about the fixed origin) and ½Σ m|ẋ|² of the 7 points equal the rigid
    body's m a_c, c × m a_c + I α + ω × I ω and ½ m |v_c|² + ½ ωᵀ I ω (SPEC §2, §8.2)."""
    split = data.draw(splits(body.mass))
    model = equivalent_point_masses(body, split)
    rot, rot_d, rot_dd, p, pd, pdd = rigid_motion(np.asarray(coef).reshape(6, 3), t)

    # point masses: positions from R, p and their exact derivatives only
    x = p + model.positions @ rot.T
    xd = pd + model.positions @ rot_d.T
    xdd = pdd + model.positions @ rot_dd.T
    m = model.masses
    force_pts = m @ xdd
    moment_pts = np.sum(m[:, None] * np.cross(x, xdd), axis=0)
    energy_pts = 0.5 * np.sum(m * np.einsum("ki,ki->k", xd, xd))

    # rigid body: Newton–Euler with ω, α from Ṙ Rᵀ and its derivative
    omega = _vee(rot_d @ rot.T)
    alpha = _vee(rot_dd @ rot.T + rot_d @ rot_d.T)
    inertia_w = rot @ body.inertia @ rot.T
    c = p + rot @ body.com
    vc = pd + rot_d @ body.com
    ac = pdd + rot_dd @ body.com
    force = body.mass * ac
    moment = np.cross(c, body.mass * ac) + inertia_w @ alpha + np.cross(omega, inertia_w @ omega)
    energy = 0.5 * body.mass * vc @ vc + 0.5 * omega @ inertia_w @ omega

    force_scale = (
        body.mass * (np.linalg.norm(pdd) + np.linalg.norm(rot_dd) * np.linalg.norm(body.com))
        + 1e-300
    )
    moment_scale = (
        np.linalg.norm(c) * force_scale
        + np.abs(body.inertia).max() * (np.linalg.norm(alpha) + np.linalg.norm(omega) ** 2)
        + 1e-300
    )
    energy_scale = body.mass * vc @ vc + np.abs(body.inertia).max() * omega @ omega + 1e-300
    np.testing.assert_allclose(force_pts, force, rtol=0, atol=1e-10 * float(force_scale))
    np.testing.assert_allclose(moment_pts, moment, rtol=0, atol=1e-10 * moment_scale)
    assert abs(energy_pts - energy) <= 1e-10 * energy_scale

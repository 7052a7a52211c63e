"""3×3 screw matrices: Rahman's link transform M̂ = Z(θ̂)X(α̂) expanded term by term (Rahman
1996 eq. 2.2; reference/rahman1996/SPEC.md §1.1) and its crank/rod/slider/frame matrices,
Bagci's factorisations (eqs. 2.6–2.11), the group axioms and transference."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from dual_strategies import (
    SETTINGS,
    assert_screw_close,
    cases,
    random_rotation,
    random_screw,
    random_translation,
    rng_for,
)
from hypothesis import given

from screwkit.dual import Dual, ScrewMatrix, skew, vee


def angles(rng: np.random.Generator, shape: tuple[int, ...], n: int) -> list[np.ndarray]:
    return [rng.uniform(-np.pi, np.pi, size=shape) for _ in range(n)]


def lengths(rng: np.random.Generator, shape: tuple[int, ...], n: int) -> list[np.ndarray]:
    return [rng.normal(scale=3.0, size=shape) for _ in range(n)]


def mat(rows: list[list[Any]], shape: tuple[int, ...]) -> np.ndarray:
    """Stack a 3×3 nested list of scalars/arrays into (*shape, 3, 3)."""
    return np.stack([np.stack([np.broadcast_to(x, shape) for x in row], -1) for row in rows], -2)


@SETTINGS
@given(cases)
def test_rahman_link_transform_expanded(case: tuple[tuple[int, ...], int]) -> None:
    """Rahman eq. 2.2: M_n = Z(θ̂_n)X(α̂_n), dual part as printed in SPEC §1.1."""
    shape, seed = case
    rng = rng_for(seed)
    th, al = angles(rng, shape, 2)
    s, a = lengths(rng, shape, 2)
    M = ScrewMatrix.hartenberg_denavit(Dual(th, s), Dual(al, a))
    ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(al), np.sin(al)
    real = mat([[ct, -st * ca, st * sa], [st, ct * ca, -ct * sa], [0, sa, ca]], shape)
    dual = mat(
        [
            [-s * st, a * sa * st - s * ca * ct, a * ca * st + s * sa * ct],
            [s * ct, -a * sa * ct - s * ca * st, -a * ca * ct + s * sa * st],
            [0, a * ca, -a * sa],
        ],
        shape,
    )
    np.testing.assert_allclose(M.real, real, atol=1e-14)
    np.testing.assert_allclose(M.dual, dual, atol=1e-13)
    # Transference gives the HD origin offset: a along the rotated x, s along z.
    np.testing.assert_allclose(M.translation, np.stack([a * ct, a * st, s], -1), atol=1e-13)


@SETTINGS
@given(cases)
def test_rahman_crank_rod_slider_frame(case: tuple[tuple[int, ...], int]) -> None:
    """The four matrices of Rahman SPEC §1.1 (crank M1, rod L2, slider L3, frame M4)."""
    shape, seed = case
    rng = rng_for(seed)
    th1, th2, eta2, th3, eta3, al4 = angles(rng, shape, 6)
    s1, a1, a2, s4, a4 = lengths(rng, shape, 5)
    c, s = np.cos, np.sin

    M1 = ScrewMatrix.hartenberg_denavit(Dual(th1, s1), Dual(0.0 * th1, a1))
    np.testing.assert_allclose(M1.real, ScrewMatrix.rot_z(th1).real, atol=1e-15)
    np.testing.assert_allclose(
        M1.dual,
        mat(
            [
                [-s1 * s(th1), -s1 * c(th1), a1 * s(th1)],
                [s1 * c(th1), -s1 * s(th1), -a1 * c(th1)],
                [0, a1, 0],
            ],
            shape,
        ),
        atol=1e-13,
    )

    L2 = ScrewMatrix.rot_z(th2) @ ScrewMatrix.rot_y(eta2) @ ScrewMatrix.rot_x(Dual(0.0, a2))
    np.testing.assert_allclose(
        L2.real,
        mat(
            [
                [c(th2) * c(eta2), -s(th2), c(th2) * s(eta2)],
                [s(th2) * c(eta2), c(th2), s(th2) * s(eta2)],
                [-s(eta2), 0, c(eta2)],
            ],
            shape,
        ),
        atol=1e-15,
    )
    np.testing.assert_allclose(
        L2.dual,
        mat(
            [
                [0, a2 * c(th2) * s(eta2), a2 * s(th2)],
                [0, a2 * s(th2) * s(eta2), -a2 * c(th2)],
                [0, a2 * c(eta2), 0],
            ],
            shape,
        ),
        atol=1e-13,
    )

    L3 = ScrewMatrix.rot_z(th3) @ ScrewMatrix.rot_y(eta3) @ ScrewMatrix.rot_x(np.pi / 2)
    np.testing.assert_allclose(
        L3.real,
        mat(
            [
                [c(th3) * c(eta3), c(th3) * s(eta3), s(th3)],
                [s(th3) * c(eta3), s(th3) * s(eta3), -c(th3)],
                [-s(eta3), c(eta3), 0],
            ],
            shape,
        ),
        atol=1e-15,
    )
    np.testing.assert_array_equal(L3.dual, 0.0)

    M4 = ScrewMatrix.hartenberg_denavit(Dual(0.0 * s4, s4), Dual(al4, a4))
    np.testing.assert_allclose(M4.real, ScrewMatrix.rot_x(al4).real, atol=1e-15)
    np.testing.assert_allclose(
        M4.dual,
        mat(
            [
                [0, -s4 * c(al4), s4 * s(al4)],
                [s4, -a4 * s(al4), -a4 * c(al4)],
                [0, a4 * c(al4), -a4 * s(al4)],
            ],
            shape,
        ),
        atol=1e-13,
    )


def test_rahman_frame_slider_axis() -> None:
    """Rahman SPEC §1: with α4 = 250°, k4 = (0, sin α4, cos α4) = (0, −0.9397, −0.3420) in {1}.
    M4R = R_{4←1} (SPEC §1.1), so k4 in {1} is its third row (not its third column)."""
    M4 = ScrewMatrix.hartenberg_denavit(Dual(0.0, 7.0), Dual(np.deg2rad(250.0), 1.0))
    np.testing.assert_allclose(
        M4.real[2, :], [0.0, -0.9397, -0.3420], atol=5e-5
    )  # 4 printed digits


@SETTINGS
@given(cases)
def test_bagci_factorisations(case: tuple[tuple[int, ...], int]) -> None:
    """Bagci eqs. 2.7–2.11: T̂_α̂ = T̂_α1 T_α0 = T_α0 T̂_α1 = T_α0 + ε α1 D T_α0, D = [e]×."""
    shape, seed = case
    rng = rng_for(seed)
    (t0,), (t1,) = angles(rng, shape, 1), lengths(rng, shape, 1)
    for axis in range(3):
        e = np.eye(3)[axis]
        full = ScrewMatrix.about_axis(Dual(t0, t1), axis)
        rot = ScrewMatrix.about_axis(t0, axis)
        slide = ScrewMatrix.translation_only(t1[..., None] * e)
        assert_screw_close(full, slide @ rot, atol=1e-13)
        assert_screw_close(full, rot @ slide, atol=1e-13)
        np.testing.assert_allclose(
            full.dual, t1[..., None, None] * (skew(e) @ rot.real), atol=1e-13
        )
        # The derivative operator of A.27: dT(α)/dα = D T(α) (complex step, h = 1e-30).
        h = 1e-30
        c, s = np.cos(t0 + 1j * h), np.sin(t0 + 1j * h)
        table: dict[int, list[list[Any]]] = {
            0: [[1, 0, 0], [0, c, -s], [0, s, c]],
            1: [[c, 0, s], [0, 1, 0], [-s, 0, c]],
            2: [[c, -s, 0], [s, c, 0], [0, 0, 1]],
        }
        rows = table[axis]
        complex_matrix = np.stack(
            [
                np.stack([np.broadcast_to(np.asarray(x, dtype=complex), shape) for x in r], -1)
                for r in rows
            ],
            -2,
        )
        np.testing.assert_allclose(np.imag(complex_matrix) / h, skew(e) @ rot.real, atol=1e-14)


@SETTINGS
@given(cases)
def test_translations_commute_and_add(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    t1, t2 = random_translation(rng, shape), random_translation(rng, shape)
    A, B = ScrewMatrix.translation_only(t1), ScrewMatrix.translation_only(t2)
    assert_screw_close(A @ B, ScrewMatrix.translation_only(t1 + t2), atol=1e-13)
    assert_screw_close(A @ B, B @ A, atol=1e-13)


@SETTINGS
@given(cases)
def test_group_axioms(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    A, B, C = (random_screw(rng, shape) for _ in range(3))
    eye = ScrewMatrix.identity(shape)
    assert_screw_close((A @ B) @ C, A @ (B @ C), atol=1e-12)
    assert_screw_close(A @ eye, A, atol=0)
    assert_screw_close(A.T @ A, eye, atol=1e-13)  # Bagci §2.4: T̂ᵀT̂ = I
    assert_screw_close(A @ A.inverse(), eye, atol=1e-13)
    assert_screw_close(A.general_inverse(), A.T, atol=1e-12)
    assert_screw_close((A @ B).T, B.T @ A.T, atol=1e-13)
    assert_screw_close((A @ B).inverse(), B.inverse() @ A.inverse(), atol=1e-13)
    assert np.all(A.orthogonality_error() < 1e-13)
    assert np.all((A @ B).isclose(A @ B))


@SETTINGS
@given(cases)
def test_product_is_the_dual_number_product(case: tuple[tuple[int, ...], int]) -> None:
    """(A @ B)_ik = Σ_j Â_ij B̂_jk with Dual arithmetic (an independent implementation)."""
    shape, seed = case
    rng = rng_for(seed)
    A = ScrewMatrix(rng.normal(size=(*shape, 3, 3)), rng.normal(size=(*shape, 3, 3)))
    B = ScrewMatrix(rng.normal(size=(*shape, 3, 3)), rng.normal(size=(*shape, 3, 3)))
    P = A @ B
    for i in range(3):
        for k in range(3):
            acc = Dual(0.0)
            for j in range(3):
                acc = acc + Dual(A.real[..., i, j], A.dual[..., i, j]) * Dual(
                    B.real[..., j, k], B.dual[..., j, k]
                )
            np.testing.assert_allclose(P.real[..., i, k], acc.real, atol=1e-13)
            np.testing.assert_allclose(P.dual[..., i, k], acc.dual, atol=1e-13)


@SETTINGS
@given(cases)
def test_transference_and_composition_match_4x4(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    R1, R2 = random_rotation(rng, shape), random_rotation(rng, shape)
    d1, d2 = random_translation(rng, shape), random_translation(rng, shape)
    A = ScrewMatrix.from_rotation_translation(R1, d1)
    B = ScrewMatrix.from_rotation_translation(R2, d2)
    np.testing.assert_allclose(A.translation, d1, atol=1e-13)
    np.testing.assert_allclose(vee(A.dual @ np.swapaxes(A.real, -1, -2)), d1, atol=1e-13)
    T = A.as_transform() @ B.as_transform()
    AB = A @ B
    np.testing.assert_allclose(AB.real, T[..., :3, :3], atol=1e-13)
    np.testing.assert_allclose(AB.translation, T[..., :3, 3], atol=1e-12)
    p = rng.normal(size=(*shape, 3))
    np.testing.assert_allclose(
        AB.transform_points(p), A.transform_points(B.transform_points(p)), atol=1e-12
    )


def test_indexing_and_shape() -> None:
    S = ScrewMatrix.rot_z(Dual(np.linspace(0, 1, 6).reshape(2, 3), 1.0))
    assert S.shape == (2, 3)
    assert S[1].shape == (3,)
    assert S[1, 2].shape == ()
    assert_screw_close(S[1, 2], ScrewMatrix.rot_z(Dual(1.0, 1.0)))


def test_screw_matrix_error_paths() -> None:
    with pytest.raises(ValueError, match=r"trailing shape \(3, 3\); got \(3,\)"):
        ScrewMatrix(np.zeros(3))
    bad = ScrewMatrix(np.diag([1.0, 1.0, 1.1]))
    with pytest.raises(ValueError, match="not orthogonal"):
        bad.check()
    with pytest.raises(ValueError, match=r"det = -1.*reflection"):
        ScrewMatrix(np.diag([1.0, 1.0, -1.0])).check()
    not_skew = ScrewMatrix(np.eye(3), np.eye(3))
    with pytest.raises(ValueError, match="not skew-symmetric"):
        not_skew.check()
    batch = ScrewMatrix.identity((2, 3))
    real = batch.real.copy()
    real[1, 2] *= 2.0
    with pytest.raises(ValueError, match=r"batch index \(1, 2\)"):
        ScrewMatrix(real).check()

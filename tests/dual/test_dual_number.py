"""Dual numbers: algebra (ε² = 0, ring axioms), division, powers, and every function against
its derivative computed by the complex step f'(a) = Im f(a + ih)/h (an independent method)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from dual_strategies import SETTINGS, cases, random_dual, rng_for
from hypothesis import given

import screwkit.dual as sd
from screwkit.dual import Dual, DualDivisionError


def as_matrix(x: Dual) -> np.ndarray:
    """The faithful 2×2 representation a + εb ↦ [[a, b], [0, a]] (ε ↦ [[0, 1], [0, 0]])."""
    z = np.zeros_like(x.real)
    return np.stack([np.stack([x.real, x.dual], -1), np.stack([z, x.real], -1)], -2)


def assert_dual_close(a: Dual, b: Dual, rtol: float = 1e-12, atol: float = 1e-12) -> None:
    np.testing.assert_allclose(a.real, b.real, rtol=rtol, atol=atol)
    np.testing.assert_allclose(a.dual, b.dual, rtol=rtol, atol=atol)


def test_epsilon_squared_is_zero() -> None:
    eps = Dual(0.0, 1.0)
    sq = eps * eps
    assert sq.real == 0.0 and sq.dual == 0.0
    # ... and its matrix representation is nilpotent, so the representation test below is
    # a test against an independent algebra.
    assert not np.any(as_matrix(eps) @ as_matrix(eps))


@SETTINGS
@given(cases)
def test_product_matches_matrix_representation(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    x, y = random_dual(rng, shape), random_dual(rng, shape)
    np.testing.assert_allclose(
        as_matrix(x * y), as_matrix(x) @ as_matrix(y), rtol=1e-14, atol=1e-14
    )
    np.testing.assert_allclose(
        as_matrix(x + y), as_matrix(x) + as_matrix(y), rtol=1e-14, atol=1e-14
    )


@SETTINGS
@given(cases)
def test_ring_axioms(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    x, y, z = (random_dual(rng, shape) for _ in range(3))
    assert_dual_close((x * y) * z, x * (y * z))
    assert_dual_close(x * y, y * x)
    assert_dual_close(x * (y + z), x * y + x * z)
    assert_dual_close((x + y) - y, x)
    assert_dual_close(-x + x, Dual(0.0, 0.0))
    assert_dual_close(x.conjugate() * x, Dual(x.real**2, 0.0))


@SETTINGS
@given(cases)
def test_division_inverts_multiplication(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    x, y = random_dual(rng, shape), random_dual(rng, shape)
    y = Dual(np.where(np.abs(y.real) < 0.1, 0.1, y.real), y.dual)  # keep the divisor invertible
    # (x/y)·y: relative rounding grows like 1/|y0|² ≤ 100 here.
    assert_dual_close((x / y) * y, x, rtol=1e-10, atol=1e-10)
    assert_dual_close(1.0 / y, y**-1, rtol=1e-12)


@SETTINGS
@given(cases)
def test_mixed_with_arrays_and_scalars(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    x = random_dual(rng, shape)
    a = rng.normal(size=shape)
    for got in (np.asarray(a) + x, x + a):
        assert isinstance(got, Dual)
        assert_dual_close(got, Dual(a + x.real, x.dual))
    got = np.asarray(a) * x
    assert isinstance(got, Dual)
    assert_dual_close(got, Dual(a * x.real, a * x.dual))
    assert_dual_close(2.0 - x, Dual(2.0 - x.real, -x.dual))


def test_division_by_pure_dual_raises_value_error() -> None:
    with pytest.raises(DualDivisionError, match="pure dual number"):
        Dual(1.0, 2.0) / Dual(0.0, 3.0)
    with pytest.raises(ValueError, match=r"batch index \(1,\)"):
        Dual([1.0, 2.0], 1.0) / Dual([1.0, 0.0], 1.0)
    # also a ZeroDivisionError, for code that catches that
    with pytest.raises(ZeroDivisionError):
        1.0 / Dual(0.0, 1.0)


@SETTINGS
@given(cases)
def test_powers(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    x = random_dual(rng, shape)
    assert_dual_close(x**2, x * x)
    assert_dual_close(x**3, x * x * x, rtol=1e-12)
    assert_dual_close(x**1, x)
    assert_dual_close(x**0, Dual(1.0, 0.0))
    pos = Dual(np.abs(x.real) + 0.5, x.dual)
    assert_dual_close(pos**0.5, sd.sqrt(pos))
    assert_dual_close(pos**-1.5 * pos**1.5, Dual(1.0, 0.0), rtol=1e-12)
    e = random_dual(rng, shape, scale=0.5)
    # d̂^ê = exp(ê ln d̂): real part d0^e0, dual part from the two partial derivatives.
    got = pos**e
    np.testing.assert_allclose(got.real, pos.real**e.real, rtol=1e-12)
    expected_dual = (
        e.real * pos.real ** (e.real - 1) * pos.dual + np.log(pos.real) * pos.real**e.real * e.dual
    )
    np.testing.assert_allclose(got.dual, expected_dual, rtol=1e-10, atol=1e-12)


def test_power_error_paths() -> None:
    with pytest.raises(ValueError, match="non-integer exponent"):
        Dual(-1.0, 1.0) ** 0.5
    with pytest.raises(ValueError, match="infinite"):
        Dual(0.0, 1.0) ** -1
    assert (Dual(-2.0, 1.0) ** 3).real == -8.0


# Complex step: f'(a) = Im f(a + ih)/h to machine precision for analytic f, with no
# subtractive cancellation; h = 1e-30.
H = 1e-30

UNARY: list[
    tuple[str, Callable[[Dual], Dual], Callable[[np.ndarray], np.ndarray], tuple[float, float]]
] = [
    ("sin", sd.sin, np.sin, (-6.0, 6.0)),
    ("cos", sd.cos, np.cos, (-6.0, 6.0)),
    ("tan", sd.tan, np.tan, (-1.4, 1.4)),
    ("exp", sd.exp, np.exp, (-3.0, 3.0)),
    ("log", sd.log, np.log, (0.05, 10.0)),
    ("sqrt", sd.sqrt, np.sqrt, (0.05, 10.0)),
    ("atan", sd.atan, np.arctan, (-5.0, 5.0)),
    ("asin", sd.asin, np.arcsin, (-0.95, 0.95)),
    ("acos", sd.acos, np.arccos, (-0.95, 0.95)),
]


@pytest.mark.parametrize("name, dual_f, real_f, domain", UNARY, ids=[u[0] for u in UNARY])
@SETTINGS
@given(case=cases)
def test_function_is_value_plus_epsilon_derivative(
    name: str,
    dual_f: Callable[[Dual], Dual],
    real_f: Callable[[np.ndarray], np.ndarray],
    domain: tuple[float, float],
    case: tuple[tuple[int, ...], int],
) -> None:
    shape, seed = case
    rng = rng_for(seed)
    a = rng.uniform(*domain, size=shape)
    b = rng.normal(size=shape)
    got = dual_f(Dual(a, b))
    derivative = np.imag(real_f(a + 1j * H)) / H
    np.testing.assert_allclose(got.real, real_f(a), rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(got.dual, b * derivative, rtol=1e-12, atol=1e-14)


@SETTINGS
@given(cases)
def test_atan2_is_value_plus_epsilon_gradient(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    y, x = random_dual(rng, shape), random_dual(rng, shape)
    got = sd.atan2(y, x)

    # atan2 = atan(y/x) + const locally; its complex-step partials (x ≠ 0 away from branch cut):
    def f(yy: np.ndarray, xx: np.ndarray) -> np.ndarray:
        return np.arctan(yy / xx)

    dfdy = np.imag(f(y.real + 1j * H, x.real)) / H
    dfdx = np.imag(f(y.real, x.real + 1j * H)) / H
    np.testing.assert_allclose(got.real, np.arctan2(y.real, x.real), rtol=1e-15)
    np.testing.assert_allclose(got.dual, dfdy * y.dual + dfdx * x.dual, rtol=1e-11, atol=1e-13)
    # cos/sin of the dual angle point along (x̂, ŷ): x̂ sin θ̂ − ŷ cos θ̂ = 0 (both parts).
    resid = x * sd.sin(got) - y * sd.cos(got)
    np.testing.assert_allclose(resid.real, 0.0, atol=1e-12)
    np.testing.assert_allclose(resid.dual, 0.0, atol=1e-11)


@SETTINGS
@given(cases)
def test_dual_trigonometric_identities(case: tuple[tuple[int, ...], int]) -> None:
    shape, seed = case
    rng = rng_for(seed)
    t = random_dual(rng, shape)
    one = sd.sin(t) ** 2 + sd.cos(t) ** 2  # Bagci §2.2: sin²θ̂ + cos²θ̂ = 1
    assert_dual_close(one, Dual(1.0, 0.0), atol=1e-13)
    u = Dual(rng.uniform(-1.2, 1.2, size=shape), t.dual)
    assert_dual_close(sd.tan(u), sd.sin(u) / sd.cos(u), rtol=1e-12, atol=1e-12)
    p = Dual(np.abs(t.real) + 0.2, t.dual)
    assert_dual_close(sd.exp(sd.log(p)), p, rtol=1e-13)
    # Bagci §2.2: constant pitch p gives θ̂ = θ(1 + εp): sin θ̂ = sin θ + εθp cos θ.
    assert_dual_close(
        sd.sin(t.real * Dual(1.0, 0.3)), Dual(np.sin(t.real), 0.3 * t.real * np.cos(t.real))
    )


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: sd.sqrt(Dual([1.0, -1.0], 0.0)), r"sqrt needs a positive real part.*\(1,\)"),
        (lambda: sd.log(Dual(0.0, 1.0)), "log needs a positive real part"),
        (lambda: sd.atan2(Dual(0.0), Dual(0.0)), "both real parts are zero"),
        (lambda: sd.asin(Dual(1.5)), r"\|real part\| < 1"),
        (lambda: sd.acos(Dual(-1.0)), r"\|real part\| < 1"),
        (lambda: abs(Dual(0.0, 1.0)), "real part is 0"),
    ],
)
def test_function_error_paths(call: Callable[[], object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


def test_abs_and_indexing() -> None:
    x = Dual([-2.0, 3.0], [1.0, 1.0])
    assert_dual_close(abs(x), Dual([2.0, 3.0], [-1.0, 1.0]))
    assert x.shape == (2,)
    assert_dual_close(x[1], Dual(3.0, 1.0))

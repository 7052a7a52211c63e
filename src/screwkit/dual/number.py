"""Dual numbers a + εb (ε² = 0) held as a pair of broadcasting numpy arrays.

Arithmetic and functions follow Bagci 1969, App. A (eqs. A.3–A.12, A.31) and Rahman 1996,
App. A (eq. A.1): for any smooth f, f(a + εb) = f(a) + ε b f'(a).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError, InputTypeError

Array = NDArray[np.float64]


def _as_array(x: ArrayLike, part: str = "value") -> Array:
    a = np.asarray(x)
    if a.dtype.kind not in "biufc":  # bool, integers, floats, complex (complex-step derivatives)
        raise InputTypeError(f"a dual number's {part} part must be numbers (float or complex "
                             f"arrays); got {type(x).__name__} of dtype {a.dtype}")
    return np.asarray(a, dtype=np.result_type(a.dtype, np.float64))


class DualDivisionError(InputError, ZeroDivisionError):
    """Division by a dual number with zero real part (a pure dual number εb)."""


@dataclass(frozen=True, eq=False)
class Dual:
    """A (batch of) dual number(s) ``real + ε·dual``.

    Both parts broadcast against each other; every operation broadcasts over leading axes.
    For a dual angle θ̂ = θ + εs the real part is the rotation and the dual part the
    translation along the same line (Bagci eq. 2.1).
    """

    real: Array
    dual: Array

    # numpy must not broadcast a Dual as an object scalar: make ``ndarray + Dual`` call
    # Dual.__radd__ instead.
    __array_ufunc__ = None

    def __init__(self, real: ArrayLike, dual: ArrayLike = 0.0) -> None:
        r = _as_array(real, "real")
        d = _as_array(dual, "dual")
        r, d = np.broadcast_arrays(r, d)
        object.__setattr__(self, "real", np.array(r))
        object.__setattr__(self, "dual", np.array(d))

    # --- construction -------------------------------------------------------------------
    @classmethod
    def coerce(cls, x: Dual | ArrayLike) -> Dual:
        """``x`` itself if it is a Dual, else the pure real dual number ``x + ε0``."""
        return x if isinstance(x, Dual) else cls(x, 0.0)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.real.shape)

    def __getitem__(self, index: Any) -> Dual:
        return Dual(self.real[index], self.dual[index])

    def __repr__(self) -> str:
        return f"Dual(real={self.real!r}, dual={self.dual!r})"

    # --- arithmetic (Bagci A.3–A.9) -------------------------------------------------------
    def __neg__(self) -> Dual:
        return Dual(-self.real, -self.dual)

    def __add__(self, other: Dual | ArrayLike) -> Dual:
        o = Dual.coerce(other)
        return Dual(self.real + o.real, self.dual + o.dual)

    __radd__ = __add__

    def __sub__(self, other: Dual | ArrayLike) -> Dual:
        o = Dual.coerce(other)
        return Dual(self.real - o.real, self.dual - o.dual)

    def __rsub__(self, other: Dual | ArrayLike) -> Dual:
        return Dual.coerce(other) - self

    def __mul__(self, other: Dual | ArrayLike) -> Dual:
        o = Dual.coerce(other)
        return Dual(self.real * o.real, self.real * o.dual + self.dual * o.real)

    __rmul__ = __mul__

    def __truediv__(self, other: Dual | ArrayLike) -> Dual:
        """d̂/ê = d0/e0 + ε(d1e0 − d0e1)/e0² (Bagci A.6). A divisor with zero real part (a pure
        dual number εe1) has no inverse: raises :class:`DualDivisionError`."""
        o = Dual.coerce(other)
        pure = o.real == 0
        if np.any(pure):
            where = np.argwhere(pure)[0] if pure.ndim else ()
            raise DualDivisionError(
                "division by a pure dual number (real part 0"
                + (f" at batch index {tuple(int(i) for i in where)}" if len(where) else "")
                + "): (a + εb)/(εd) has no dual-number value; "
                "rewrite the expression so the divisor has a non-zero real part"
            )
        return Dual(self.real / o.real, (self.dual * o.real - self.real * o.dual) / o.real**2)

    def __rtruediv__(self, other: Dual | ArrayLike) -> Dual:
        return Dual.coerce(other) / self

    def __pow__(self, n: Dual | ArrayLike) -> Dual:
        """d̂ⁿ = d0ⁿ + ε n d0ⁿ⁻¹ d1 (Bagci A.10) for a real exponent n; a dual exponent ê gives
        d̂^ê = exp(ê ln d̂) (A.31).

        Raises ValueError where the power is not a dual number: a non-integer n with d0 ≤ 0,
        or n < 1 (n ≠ 0) with d0 = 0 (infinite derivative).
        """
        if isinstance(n, Dual):
            return exp(n * log(self))
        nn = np.asarray(n, dtype=float)
        integer = nn == np.round(nn)
        bad_sign = (~integer) & (self.real < 0)
        bad_zero = (self.real == 0) & (nn < 1) & (nn != 0)
        if np.any(bad_sign):
            raise InputError(
                "dual power with a non-integer exponent needs a positive real part; got a "
                "negative real part"
            )
        if np.any(bad_zero):
            raise InputError(
                "dual power d̂ⁿ with n < 1 is not defined at real part 0 (its derivative "
                "n·d0ⁿ⁻¹ is infinite)"
            )
        safe = np.where(nn == 0, 1.0, self.real)
        deriv = np.where(nn == 0, 0.0, nn * safe ** (nn - 1))
        return Dual(self.real**nn, deriv * self.dual)

    def __abs__(self) -> Dual:
        """|d̂| = |d0| + ε d1·sign(d0), defined for d0 ≠ 0."""
        if np.any(self.real == 0):
            raise InputError("|d̂| is not a dual number where the real part is 0")
        return Dual(np.abs(self.real), self.dual * np.sign(self.real))

    def conjugate(self) -> Dual:
        """The dual conjugate a − εb."""
        return Dual(self.real, -self.dual)

    def isclose(self, other: Dual | ArrayLike, rtol: float = 1e-9, atol: float = 1e-12) -> Array:
        o = Dual.coerce(other)
        return np.isclose(self.real, o.real, rtol=rtol, atol=atol) & np.isclose(
            self.dual, o.dual, rtol=rtol, atol=atol
        )


# --- functions: f(a + εb) = f(a) + ε b f'(a) (Bagci A.31) ----------------------------------
def batch_index_text(mask: NDArray[Any]) -> str:
    """' at batch index (i, j)' naming the first True entry of ``mask``, for error messages
    (empty for a scalar mask)."""
    if mask.ndim == 0:
        return ""
    return f" at batch index {tuple(int(i) for i in np.argwhere(mask)[0])}"


def sqrt(x: Dual | ArrayLike) -> Dual:
    """√d̂ = √d0 + ε d1/(2√d0) (Bagci A.11); needs d0 > 0."""
    x = Dual.coerce(x)
    bad = x.real <= 0
    if np.any(bad):
        raise InputError(
            f"dual sqrt needs a positive real part; got {x.real[bad].min():.3g}{batch_index_text(bad)}"
        )
    r = np.sqrt(x.real)
    return Dual(r, x.dual / (2.0 * r))


def sin(x: Dual | ArrayLike) -> Dual:
    """sin θ̂ = sin θ + ε s cos θ (Bagci eq. 2.2; Rahman eq. A.1)."""
    x = Dual.coerce(x)
    return Dual(np.sin(x.real), x.dual * np.cos(x.real))


def cos(x: Dual | ArrayLike) -> Dual:
    """cos θ̂ = cos θ − ε s sin θ (Bagci eq. 2.2; Rahman eq. A.1)."""
    x = Dual.coerce(x)
    return Dual(np.cos(x.real), -x.dual * np.sin(x.real))


def tan(x: Dual | ArrayLike) -> Dual:
    """tan θ̂ = tan θ + ε s sec²θ (Bagci eq. 2.2)."""
    x = Dual.coerce(x)
    c = np.cos(x.real)
    return Dual(np.tan(x.real), x.dual / c**2)


def atan2(y: Dual | ArrayLike, x: Dual | ArrayLike) -> Dual:
    """Dual angle θ̂ with (cos θ̂, sin θ̂) ∝ (x̂, ŷ): real part atan2(y0, x0) ∈ (−π, π],
    dual part (x0 y1 − y0 x1)/(x0² + y0²) (A.31 applied to atan2)."""
    y = Dual.coerce(y)
    x = Dual.coerce(x)
    r2 = x.real**2 + y.real**2
    bad = r2 == 0
    if np.any(bad):
        raise InputError(
            f"dual atan2 is undefined where both real parts are zero{batch_index_text(bad)}"
        )
    return Dual(np.arctan2(y.real, x.real), (x.real * y.dual - y.real * x.dual) / r2)


def asin(x: Dual | ArrayLike) -> Dual:
    """asin d̂ = asin d0 + ε d1/√(1 − d0²), needs |d0| < 1."""
    x = Dual.coerce(x)
    bad = np.abs(x.real) >= 1
    if np.any(bad):
        raise InputError(f"dual asin needs |real part| < 1{batch_index_text(bad)}")
    return Dual(np.arcsin(x.real), x.dual / np.sqrt(1.0 - x.real**2))


def acos(x: Dual | ArrayLike) -> Dual:
    """acos d̂ = acos d0 − ε d1/√(1 − d0²), needs |d0| < 1."""
    x = Dual.coerce(x)
    bad = np.abs(x.real) >= 1
    if np.any(bad):
        raise InputError(f"dual acos needs |real part| < 1{batch_index_text(bad)}")
    return Dual(np.arccos(x.real), -x.dual / np.sqrt(1.0 - x.real**2))


def atan(x: Dual | ArrayLike) -> Dual:
    """atan d̂ = atan d0 + ε d1/(1 + d0²)."""
    x = Dual.coerce(x)
    return Dual(np.arctan(x.real), x.dual / (1.0 + x.real**2))


def exp(x: Dual | ArrayLike) -> Dual:
    """e^d̂ = e^d0 (1 + ε d1) (Bagci A.12)."""
    x = Dual.coerce(x)
    e = np.exp(x.real)
    return Dual(e, e * x.dual)


def log(x: Dual | ArrayLike) -> Dual:
    """ln d̂ = ln d0 + ε d1/d0 (Bagci A.12, middle expression corrected); needs d0 > 0."""
    x = Dual.coerce(x)
    bad = x.real <= 0
    if np.any(bad):
        raise InputError(
            f"dual log needs a positive real part; got {x.real[bad].min():.3g}{batch_index_text(bad)}"
        )
    return Dual(np.log(x.real), x.dual / x.real)

"""Structure-of-arrays vector algebra for the blocked fast paths.

A vector over a block of samples is a tuple of its three components, each an (n,) array, or a
Python float when it is the same for every sample of the block: the arithmetic then runs on long
contiguous arrays instead of numpy's slow loops over short trailing axes (``einsum`` on
``(n, 3)``, stacked cross products).

Exact zeros are tracked: a component that is 0.0 in every sample of a block (read with
:func:`rows`, which checks each input row), or a zero entry of a constant (mass properties), is
the float 0.0, and products with it, sums with it, are skipped. The results are bit for bit what
the full arithmetic gives (up to the sign of a zero), but a link that does not turn (a slider),
turns about a world axis (a crank on a vertical shaft), or has a diagonal inertia tensor costs
only the arithmetic it needs.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Union

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Scalar = Union[Array, float]  # noqa: UP007 - a runtime alias, kept readable for mypy
Vec = tuple[Scalar, Scalar, Scalar]
ZERO: Vec = (0.0, 0.0, 0.0)


def mul(a: Scalar, b: Scalar) -> Scalar:
    """a·b, without arithmetic when either is the constant 0.0 or 1.0 (``type(…) is float``:
    a hot path, and constants are always Python floats here)."""
    if type(a) is float:
        if a == 0.0:
            return 0.0
        if a == 1.0:
            return b
    if type(b) is float:
        if b == 0.0:
            return 0.0
        if b == 1.0:
            return a
    return a * b


def plus(a: Scalar, b: Scalar) -> Scalar:
    if type(a) is float and a == 0.0:
        return b
    if type(b) is float and b == 0.0:
        return a
    return a + b


def minus(a: Scalar, b: Scalar) -> Scalar:
    if type(b) is float and b == 0.0:
        return a
    if type(a) is float and a == 0.0:
        return -b
    return a - b


def add(a: Vec, b: Vec) -> Vec:
    return (plus(a[0], b[0]), plus(a[1], b[1]), plus(a[2], b[2]))


def sub(a: Vec, b: Vec) -> Vec:
    return (minus(a[0], b[0]), minus(a[1], b[1]), minus(a[2], b[2]))


def scale(k: Scalar, a: Vec) -> Vec:
    return (mul(k, a[0]), mul(k, a[1]), mul(k, a[2]))


def dot(a: Vec, b: Vec) -> Scalar:
    return plus(plus(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]))


def cross(a: Vec, b: Vec) -> Vec:
    return (
        minus(mul(a[1], b[2]), mul(a[2], b[1])),
        minus(mul(a[2], b[0]), mul(a[0], b[2])),
        minus(mul(a[0], b[1]), mul(a[1], b[0])),
    )


def const(v: Sequence[float] | Array) -> Vec:
    """A constant vector (the same for every sample)."""
    return (float(v[0]), float(v[1]), float(v[2]))


def const_matvec(M: Array, v: Vec) -> Vec:
    """M v for a constant 3×3 matrix M."""
    return (dot(const(M[0]), v), dot(const(M[1]), v), dot(const(M[2]), v))


Rotation = Sequence[Scalar]  # nine components R[3i + j]


def rotate(R: Rotation, v: Vec) -> Vec:
    """R v for a per-sample rotation with components R[3i + j]."""
    return (dot((R[0], R[1], R[2]), v), dot((R[3], R[4], R[5]), v), dot((R[6], R[7], R[8]), v))


def rotate_back(R: Rotation, v: Vec) -> Vec:
    """Rᵀ v for a per-sample rotation with components R[3i + j]."""
    return (dot((R[0], R[3], R[6]), v), dot((R[1], R[4], R[7]), v), dot((R[2], R[5], R[8]), v))


def rows(a: Array, finite: list[bool] | None = None) -> list[Scalar]:
    """The components of an (n, k…) block as k (n,) rows, rows that are zero throughout the
    block as 0.0. Component-major input (each component contiguous over the samples, as
    :func:`screwkit.kinematics.closed_forms.cssp_motion.cssp_mode_motion` stores it) gives views; other
    layouts are copied once, transposed (the fast paths read each row several times).
    With a ``finite`` list, appends whether every entry of the block is finite (a NaN or an
    infinity makes a sample's sum non-finite; a false alarm from overflow only costs the
    caller a slower exact check)."""
    n = a.shape[0]
    comp = a.reshape(n, -1).T
    if comp.strides[1] != comp.itemsize:
        comp = np.ascontiguousarray(comp)
    if finite is not None:
        with np.errstate(over="ignore", invalid="ignore"):
            finite.append(bool(np.isfinite(np.ones(comp.shape[0]) @ comp).all()))
    # a row with a non-zero entry among a few probed samples is not zero; only the others are
    # scanned in full (they are few: the zero components of the motion)
    probed: list[bool] = np.asarray(comp[:, :: max(1, n // 16)].any(axis=1)).tolist()
    return [row if hit or row.any() else 0.0 for row, hit in zip(comp, probed, strict=True)]


def component_major(*shape: int) -> Array:
    """An uninitialised array of the given (n, …) shape whose storage is component-major: each
    component contiguous over the samples (fast to fill row by row; a view, not C-contiguous)."""
    storage = np.empty((*shape[1:], shape[0]))
    return np.moveaxis(storage, -1, 0)


def vec(comp: Sequence[Scalar], start: int) -> Vec:
    """The vector whose components are ``comp[start … start + 2]``."""
    return (comp[start], comp[start + 1], comp[start + 2])


def store(out: Array, v: Vec) -> None:
    """Write a vector into an (n, 3) output, component by component (contiguous writes into a
    :func:`component_major` output)."""
    for k in range(3):
        out[:, k] = v[k]

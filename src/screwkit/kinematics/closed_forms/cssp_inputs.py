"""The checked inputs of a CSSP sweep (:class:`CSSPSweep`): the crank angles with their cosines
and sines, the rates, the s4 quadratic's discriminant b² − c (Rahman 1996 §1.2; reference SPEC
§1.2) and where it assembles, shared by both roots of the quadratic (both assembly modes), and
per root the rod's zero-spin turn (:mod:`screwkit.kinematics.closed_forms.cssp_rod_pose`).

:func:`cssp_sweep` checks and prepares them once; :func:`sweep_for_root` gives the other root's
sweep from the same inputs without computing them again (issue 30: the two modes of a
``solve_motion`` paid for the crank angles' trigonometry twice).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.cssp import (
    SEED_ROOT,
    CSSPAssemblyError,
    CSSPDimensions,
    as_sample_array,
    assembly_message,
    check_root,
)
from screwkit.messages import shown
from screwkit.model.linkage import Linkage

Array = NDArray[np.float64]

_JOINTS = (("R", "C"), ("S",), ("S",), ("P",))


class NotACSSPError(InputError):
    """The linkage given to :func:`cssp_mode_motion` is not a CSSP of the family constructor."""


def cssp_dimensions(linkage: Linkage) -> CSSPDimensions:
    """The :class:`CSSPDimensions` of a linkage built by :func:`screwkit.model.families.cssp`
    (read from ``linkage.parameters``); raises :class:`NotACSSPError` for any other linkage."""
    kinds = tuple(j.kind for j in linkage.joints)
    ok = (
        len(kinds) == 4
        and all(k in allowed for k, allowed in zip(kinds, _JOINTS, strict=True))
        and all(key in linkage.parameters for key in ("a1", "a2", "a4", "alpha4", "s1"))
    )
    if not ok:
        raise NotACSSPError(
            f"cssp_mode_motion needs a CSSP built by screwkit.model.families.cssp (joints "
            f"R|C, S, S, P and parameters a1, a2, a4, alpha4, s1); got {linkage.name!r} "
            f"(family {linkage.family!r}, joints {''.join(kinds)}). Use "
            "screwkit.solve_motion for other loops."
        )
    p = linkage.parameters
    return CSSPDimensions(p["a1"], p["a2"], p["a4"], p["alpha4"], p["s1"])


_RATES = ("theta1_dot", "theta1_ddot", "s1", "s1_dot", "s1_ddot")


@dataclass(frozen=True)
class CSSPSweep:
    """The checked inputs of a CSSP sweep of N samples and where it assembles.

    ``theta1``, ``cos``, ``sin`` (N,); ``given`` holds θ̇1, θ̈1, s1, ṡ1, s̈1 by name, each a
    float where it is the same for every sample (the closed form then does scalar arithmetic
    and leaves zero rows unwritten) or an (N,) array; ``discriminant`` is b² − c, 1 where the
    CSSP does not assemble (a placeholder: those samples are NaN in the results).
    """

    dims: CSSPDimensions
    root: int
    driven_offset: bool
    n: int
    theta1: Array
    cos: Array
    sin: Array
    given: dict[str, float | Array]
    discriminant: Array
    assembles: NDArray[np.bool_]
    rod_turn: Array  # (N,) φ turning Rahman's rod frame {3} about u to the zero-spin frame
    #: the constant inputs as arrays (:meth:`full`), kept for the other root's sweep
    shared: dict[str, Array] = field(default_factory=dict, compare=False, repr=False)

    def block(self, name: str, sel: slice | NDArray[np.intp]) -> float | Array:
        """An input over some samples (a float if it is constant)."""
        value = self.given[name]
        return value if isinstance(value, float) else value[sel]

    def full(self, name: str) -> Array:
        """An input as an (N,) array: where the CSSP assembles at every sample, one array for
        every caller (both roots' modes read the same values; none writes them), else a new
        one (a mode masks its own where it does not assemble)."""
        value = self.given[name]
        if not self.assembles.all():
            if not isinstance(value, float):
                return value.copy()
            return np.zeros(self.n) if value == 0.0 else np.full(self.n, value)
        if not isinstance(value, float):
            return value  # already the sweep's own checked copy
        if name not in self.shared:
            self.shared[name] = np.zeros(self.n) if value == 0.0 else np.full(self.n, value)
        return self.shared[name]


def _given(value: ArrayLike | None, n: int, name: str, default: float) -> float | Array:
    """A scalar input as a float, an (N,) one as a checked array."""
    arr = np.asarray(default if value is None else value, dtype=float)
    if arr.ndim == 0:
        if not np.isfinite(arr):
            raise InputError(f"{name} must be finite, got {float(arr)!r}")
        return float(arr)
    return as_sample_array(arr, n, name, default)


def cssp_sweep(
    linkage: Linkage,
    theta1: ArrayLike,
    theta1_dot: ArrayLike = 0.0,
    theta1_ddot: ArrayLike = 0.0,
    root: int = SEED_ROOT,
    *,
    s1: ArrayLike | None = None,
    s1_dot: ArrayLike = 0.0,
    s1_ddot: ArrayLike = 0.0,
    allow_partial: bool = False,
) -> CSSPSweep:
    """The inputs of :func:`cssp_mode_motion` checked and broadcast over the samples; raises
    ``CSSPAssemblyError`` (naming the crank angles) where the CSSP does not assemble, unless
    ``allow_partial``."""
    dims = cssp_dimensions(linkage)
    driven_offset = linkage.joints[0].kind == "C"
    if not driven_offset and (
        s1 is not None or np.any(np.asarray(s1_dot) != 0) or np.any(np.asarray(s1_ddot) != 0)
    ):
        raise InputError(
            f"{linkage.name}: the crank offset s1 is a constant of this CSSP "
            f"(s1 = {shown(dims.s1, 'length')}); build it with cssp(..., s1_is_input=True) to drive s1"
        )
    root = check_root(root)
    th = np.atleast_1d(np.asarray(theta1, dtype=float))
    if th.ndim != 1:
        raise InputError(f"theta1 must be a scalar or a 1-D array (N,), got shape {th.shape}")
    n = th.shape[0]
    th = as_sample_array(th, n, "theta1", 0.0)
    given = {
        name: _given(value, n, name, default)
        for name, value, default in zip(
            _RATES, (theta1_dot, theta1_ddot, s1, s1_dot, s1_ddot),
            (0.0, 0.0, dims.s1, 0.0, 0.0), strict=True)
    }
    ct, st = np.cos(th), np.sin(th)
    # the s4 quadratic's b² − c (SPEC §1.2; assembly_discriminant, with cos θ1 and sin θ1 kept
    # for the closed form)
    s1v = given["s1"]
    sa, ca = np.sin(dims.alpha4), np.cos(dims.alpha4)
    b = (dims.a1 * sa) * st + ca * s1v
    c = (dims.a4**2 + dims.a1**2 - dims.a2**2) + (2 * dims.a1 * dims.a4) * ct + s1v * s1v
    disc = b * b - c
    # b² = c is a branch point of the two modes: s4 + b = 0 and the rates are unbounded
    ok = disc > 0.0
    if not ok.all():
        if not allow_partial:
            msg = assembly_message(dims, th, ok)
            if np.any(disc == 0.0):
                msg += (" (b² = c exactly at some samples: a branch point where the rates are "
                        "unbounded.)")
            raise CSSPAssemblyError(msg + " Pass allow_partial=True to get NaN there instead.",
                                    ok)
        disc = np.where(ok, disc, 1.0)
    from screwkit.kinematics.closed_forms.cssp_rod_pose import rod_turn

    turn = rod_turn(dims, root, th, ct, st, given, disc, ok)
    return CSSPSweep(dims, root, driven_offset, n, th, ct, st, given, disc, ok, turn)


def sweep_for_root(sw: CSSPSweep, root: int) -> CSSPSweep:
    """The sweep of the same inputs for the root ``root`` of the quadratic in s4: the checked
    inputs, cosines, sines and discriminant shared with ``sw`` (they do not depend on the
    root), the rod's zero-spin turn computed for that root."""
    root = check_root(root)
    if root == sw.root:
        return sw
    from screwkit.kinematics.closed_forms.cssp_rod_pose import rod_turn

    turn = rod_turn(sw.dims, root, sw.theta1, sw.cos, sw.sin, sw.given, sw.discriminant,
                    sw.assembles)
    return replace(sw, root=root, rod_turn=turn)


__all__ = ["CSSPSweep", "NotACSSPError", "cssp_dimensions", "cssp_sweep", "sweep_for_root"]

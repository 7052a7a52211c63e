"""The CSSP's closed-form kinematics compiled by numba (issue 30: the chain ``solve_motion`` +
``inverse_dynamics`` at most 0.5× Pinocchio's ``constraintDynamics`` per sample).

The numpy route runs the closed form (Rahman 1996 §1.2; reference SPEC §1.2) block by block as
a few hundred array operations, each a pass over the block with a temporary, then copies the
rows into their storage; :func:`lean_rows` runs the same formulas one sample at a time in one
compiled loop and writes every row once (the lean pass of
:func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_mode_motion`: link frames and rates,
joint centres and axes, s4, the closure gap), and :func:`rod_steps` the steps of the rod's
zero-spin transport (:mod:`screwkit.kinematics.closed_forms.cssp_rod_pose`). The arithmetic is
the numpy route's in the same order (:mod:`screwkit.kinematics.closed_forms.cssp_kin_kernels`).

The switch is :mod:`screwkit.dynamics.cssp_compiled`'s: numba installed, ``SCREWKIT_NO_NUMBA``
unset, at least :data:`MIN_SAMPLES` samples (below, the numpy route takes a few milliseconds,
less than loading the kernels from numba's cache); the lean pass also needs the linkage base
at the world frame (else the numpy route places the rows).
"""

from __future__ import annotations

import importlib.util
import os
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import GIMBAL_TOL, rot_x
from screwkit.kinematics.closed_forms.cssp import CSSPDimensions

Array = NDArray[np.float64]

#: numba is installed (and not turned off by SCREWKIT_NO_NUMBA); imported on first use only
AVAILABLE = (importlib.util.find_spec("numba") is not None
             and not os.environ.get("SCREWKIT_NO_NUMBA"))

#: the fewest samples the compiled route is used for (that of the compiled dynamics)
MIN_SAMPLES = 50_000


def use_compiled(samples: int) -> bool:
    """Whether the compiled kernels run for a sweep of ``samples`` samples."""
    return AVAILABLE and samples >= MIN_SAMPLES


def _kernels() -> Any:
    from screwkit.kinematics.closed_forms import cssp_kin_kernels

    return cssp_kin_kernels


def closed_form_params(dims: CSSPDimensions) -> Array:
    """The constants of the closed form, computed as the numpy route computes them: a4,
    sin α4, cos α4, a4² + a1² − a2², 1/a2, a1, a2."""
    a1, a2, a4 = dims.a1, dims.a2, dims.a4
    return np.array([a4, np.sin(dims.alpha4), np.cos(dims.alpha4),
                     (a4**2 + a1**2 - a2**2), 1.0 / a2, a1, a2], dtype=float)


def _entries(value: Any) -> Array:
    """An input that is a float (the same at every sample) as one entry, else the array."""
    return np.array([value]) if isinstance(value, float) else np.ascontiguousarray(value)


def lean_rows(sw: Any, stores: list[Array | None], write: list[bool]) -> None:
    """The lean rows of every sample of a sweep (base at the world frame) into their
    component-major storage: ``stores`` rotation (3, 3, 3, N), origin (3, 3, N) or None
    (stored with the centres), velocity, acceleration, angular velocity and acceleration
    (3, 3, N), centres and axes (4, 3, N), s4 (3, N), closure (N,); ``write`` (100 rows) False
    where the numpy route leaves a constant zero unwritten."""
    n = sw.n
    flat = []
    mask = list(write)
    for r0, store, rows in zip((0, 27, 36, 45, 54, 63, 72, 84, 96, 99), stores,
                               (27, 9, 9, 9, 9, 9, 12, 12, 3, 1), strict=True):
        if store is None:
            flat.append(np.empty((rows, 0)))
            mask[r0:r0 + rows] = [False] * rows
        else:
            flat.append(store.reshape(rows, n))
    g = sw.given
    _kernels().lean_rows(
        sw.cos, sw.sin, _entries(g["theta1_dot"]), _entries(g["theta1_ddot"]),
        _entries(g["s1"]), _entries(g["s1_dot"]), _entries(g["s1_ddot"]), sw.discriminant,
        np.ascontiguousarray(sw.rod_turn), closed_form_params(sw.dims), float(sw.root),
        GIMBAL_TOL**2, np.array([float(x) for x in rot_x(np.array(
            -(sw.dims.alpha4 + np.pi / 2))).ravel()]),
        np.array([float(x) for x in sw.dims.slider_axis]), bool(sw.driven_offset),
        np.array(mask, dtype=np.bool_), tuple(flat))


def rod_steps(dims: CSSPDimensions, root: int, ct: Array, st: Array, steps: Array, s1: Any,
              s1_steps: Any, disc: Array, continues: NDArray[np.bool_],
              e_body: Array, out: Array) -> NDArray[np.intp]:
    """The steps φ_k − φ_{k−1} of the rod's zero-spin transport into ``out`` (N,) (0 off
    the runs); returns the samples where u turns by a half turn in one step: there ``out``
    holds only the step's correction c_k (the numpy route finishes them)."""
    n = ct.shape[0]
    opposite = np.empty(n, dtype=np.bool_)
    count = _kernels().rod_steps(
        ct, st, steps, _entries(s1), _entries(s1_steps), disc, continues,
        closed_form_params(dims), float(root), GIMBAL_TOL**2,
        np.array([float(x) for x in e_body]), out, opposite)
    return np.flatnonzero(opposite) if count else np.zeros(0, dtype=np.intp)


__all__ = ["AVAILABLE", "MIN_SAMPLES", "closed_form_params", "lean_rows", "rod_steps",
           "use_compiled"]

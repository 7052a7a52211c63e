"""The CSSP's blocked inverse dynamics compiled by numba (issue 30: the dynamics step at most
0.34× Pinocchio's ``rnea`` per sample).

The numpy route (:func:`screwkit.dynamics.cssp_fused_dynamics.cssp_rows_block`) runs a few
hundred array operations per block, each a pass over the block's samples with a temporary, and
a Python call for each; :func:`block_loads` runs the same formulas — the Newton–Euler link
loads of :mod:`screwkit.dynamics.inertia`, the closed-form statics of
:mod:`screwkit.dynamics.cssp_statics` (Rahman 1996 §2.2) — one sample at a time in one compiled
loop (:mod:`screwkit.dynamics.cssp_kernels`), reading the motion rows where they are and
writing every output once. The arithmetic is the numpy route's, in the same order, so the
loads are the same bit for bit.

numba is optional (the ``fast`` extra): :data:`AVAILABLE` is False without it (or with
``SCREWKIT_NO_NUMBA`` set), and :func:`screwkit.dynamics.inverse_dynamics` then runs the numpy
route; so it does for fewer than :data:`MIN_SAMPLES` samples, where compiling or loading the
kernel costs more than it saves. The kernel is compiled when first used (tens of seconds, once
per array layout: cached on disk by numba next to its module, or in numba's user-wide cache
when that folder is not writable), as :mod:`screwkit.algebraic.compiled`'s are.
"""

from __future__ import annotations

import importlib.util
import math
import os
from typing import Any

import numpy as np

from screwkit.dynamics.cssp_statics import CSSPStatics
from screwkit.dynamics.result import Array
from screwkit.dynamics.sample_blocks import Outputs, Setup
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.mass import MassProperties

#: numba is installed (and not turned off by SCREWKIT_NO_NUMBA); it is imported on the first
#: compiled block only, so that importing screwkit does not pay for it
AVAILABLE = (importlib.util.find_spec("numba") is not None
             and not os.environ.get("SCREWKIT_NO_NUMBA"))

#: the fewest samples the compiled route is used for: below, the numpy route takes a few
#: milliseconds (about 0.4 µs a sample), less than loading the compiled kernel from numba's
#: cache, and much less than compiling it the first time (tens of seconds on a loaded machine)
MIN_SAMPLES = 50_000


def use_compiled(samples: int) -> bool:
    """Whether :func:`mode_loads` runs for a mode of ``samples`` samples."""
    return AVAILABLE and samples >= MIN_SAMPLES


_KERNEL: Any = None


def _kernel() -> Any:
    global _KERNEL
    if _KERNEL is None:
        from screwkit.dynamics import cssp_kernels

        _KERNEL = cssp_kernels.cssp_loads
    return _KERNEL


def _component_rows(a: Array) -> Array:
    """An (N, k…) array as its (k, N) component rows: for component-major storage (as
    :func:`screwkit.kinematics.closed_forms.cssp_motion.cssp_mode_motion` and
    :meth:`~screwkit.dynamics.sample_blocks.Outputs.allocate` make it) the storage itself,
    a strided view of any other layout."""
    n = a.shape[0]
    rows = np.moveaxis(a, 0, -1)
    if rows.flags.c_contiguous:
        return rows.reshape(-1, n)
    return a.reshape(n, -1).T


def _const(values: Any) -> Array:
    return np.array(values, dtype=float)  # a C-contiguous copy, as the kernel reads


def mode_loads(linkage: Any, plan: CSSPStatics, masses: list[MassProperties], s: Setup,
               mode: ModeMotion, out: Outputs, block: int, check_finite: bool) -> bool:
    """The loads of every valid sample of a CSSP mode, without external loads, written into
    ``out`` (:meth:`~screwkit.dynamics.sample_blocks.Outputs.allocate`, NaN filled where a
    sample is not valid): those of :func:`screwkit.dynamics.cssp_fused_dynamics.cssp_mode_block`
    block by block, bit for bit, the largest joint load (``out.scale``) too. With
    ``check_finite``, returns False if the motion of a valid sample is not finite (the outputs
    are then to be discarded)."""
    length = float(linkage.length_scale)
    efforts = {kind: out.efforts[name] for name, kind in plan.crank_inputs}
    unused = np.empty(0)
    outputs = [_component_rows(a) for a in (out.shaking_force, out.shaking_moment,
                                             out.reaction_force, out.reaction_moment)]
    if not all(np.shares_memory(o, a) for o, a in zip(outputs, (
            out.shaking_force, out.shaking_moment, out.reaction_force, out.reaction_moment),
            strict=True)):
        raise AssertionError("the outputs must be component-major (Outputs.allocate)")
    scale2 = _kernel()(
        _component_rows(mode.link_rotation), _component_rows(mode.link_origin),
        _component_rows(mode.link_angular_velocity),
        _component_rows(mode.link_angular_acceleration),
        _component_rows(mode.link_origin_acceleration), _component_rows(mode.joint_centres),
        _component_rows(mode.joint_axes), _component_rows(mode.link_origin_velocity),
        np.ascontiguousarray(s.valid), int(block),
        _const([mp.mass for mp in masses]), _const([mp.com for mp in masses]),
        _const([mp.inertia for mp in masses]), _const(s.gravity), _const(s.reference),
        _const(s.reference - s.moment_point), 1.0 / length**2, math.sqrt(2.0) * length,
        bool(check_finite), *outputs, efforts.get("theta", unused), efforts.get("s", unused),
        "theta" in efforts, "s" in efforts, out.residual)
    if scale2 < 0.0:
        return False
    bad = ~s.valid
    if bad.any():  # computed with the others (each sample on its own): NaN, as allocated
        for a in (out.shaking_force, out.shaking_moment, out.reaction_force,
                  out.reaction_moment, out.residual, *out.efforts.values()):
            a[bad] = np.nan
    out.scale = math.sqrt(scale2)
    return True

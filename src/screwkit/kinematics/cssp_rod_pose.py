"""The CSSP rod's zero-spin pose: the turn φ about the rod axis u that carries Rahman's rod frame
{3} = Z(θ1 + θ2)·Y(η2) (SPEC §1.1) to the zero-spin frame along the branch
(:mod:`screwkit.kinematics.idle_spin`, the generic solver's convention), computed once per sweep
(:func:`~screwkit.kinematics.cssp_motion.cssp_sweep`) from u and its derivatives along each step
(the closed form at the steps' input rates) and applied by the block rows.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import rot_z
from screwkit.kinematics.cssp import CSSPDimensions
from screwkit.kinematics.idle_spin import zero_spin_angle
from screwkit.kinematics.loop import Array


def rod_turn(dims: CSSPDimensions, root: int, theta1: Array, ct: Array, st: Array,
             given: dict[str, Any], disc: Array, ok: NDArray[np.bool_]) -> Array:
    """φ (N,) for a sweep (module docstring): 0 where the CSSP does not assemble."""
    from screwkit.kinematics.cssp_motion import cssp_closed_form_block, rahman_rod_axes

    n = theta1.shape[0]
    if not ok.any():
        return np.zeros(n)
    s1 = given["s1"]
    s1v = np.broadcast_to(np.asarray(s1, dtype=float), (n,))
    steps = np.concatenate([[0.0], np.diff(theta1)])
    s1_steps = np.concatenate([[0.0], np.diff(s1v)])
    k = cssp_closed_form_block(dims, root, ct, st, steps, 0.0, s1, s1_steps, 0.0, disc)
    u, u_dot, u_ddot = (np.stack(k[name], axis=-1) for name in ("u", "u_dot", "u_ddot"))
    y3, z3 = rahman_rod_axes(k["u"])
    rod = np.stack([u, np.stack(y3, axis=-1), np.stack(z3, axis=-1)], axis=-1)
    crank = rot_z(theta1)
    good = ok[:, None]
    safe_u = np.where(good, u, [1.0, 0.0, 0.0])
    phi = zero_spin_angle(safe_u, np.where(good, u_dot, 0.0), np.where(good, u_ddot, 0.0),
                          np.where(good[..., None], rod, np.eye(3)), crank, ok, ok)
    return np.where(ok, phi, 0.0)

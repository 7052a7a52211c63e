"""The CSSP rod's zero-spin pose: the turn φ about the rod axis u that carries Rahman's rod frame
{3} = Z(θ1 + θ2)·Y(η2) (SPEC §1.1) to the zero-spin frame along the branch
(:mod:`screwkit.kinematics.tracker.idle_spin`, the generic solver's convention), computed once per sweep
(:func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_sweep`) from u and its derivatives along each step
(the closed form at the steps' input rates) and applied by the block rows.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.closed_forms.cssp import CSSPDimensions
from screwkit.kinematics.tracker.idle_spin import perpendicular, spin_from_frames
from screwkit.kinematics.tracker.loop import Array


def rod_turn(dims: CSSPDimensions, root: int, theta1: Array, ct: Array, st: Array,
             given: dict[str, Any], disc: Array, ok: NDArray[np.bool_]) -> Array:
    """φ (N,) for a sweep (module docstring): 0 where the CSSP does not assemble."""
    from screwkit.kinematics.closed_forms.cssp_motion import cssp_closed_form_block, rahman_rod_axes

    n = theta1.shape[0]
    if not ok.any():
        return np.zeros(n)
    s1 = given["s1"]
    s1v = np.broadcast_to(np.asarray(s1, dtype=float), (n,))
    steps = np.concatenate([[0.0], np.diff(theta1)])
    s1_steps = np.concatenate([[0.0], np.diff(s1v)])
    k = cssp_closed_form_block(dims, root, ct, st, steps, 0.0, s1, s1_steps, 0.0, disc)
    good = ok[:, None]
    u, u_dot, u_ddot = (np.where(good, np.stack(k[name], axis=-1), fill) for name, fill in
                        (("u", [1.0, 0.0, 0.0]), ("u_dot", 0.0), ("u_ddot", 0.0)))
    y3, z3 = rahman_rod_axes(k["u"])
    # the rod frame {3} = (u, y3, z3) (the identity where it does not assemble) and the crank's
    # Z(θ1), by components: zero_spin_angle's pieces without (N, 3, 3) stacks
    first = int(np.argmax(ok))
    rod_first = np.array([[k["u"][i][first], y3[i][first], z3[i][first]] for i in range(3)])
    u_body = rod_first.T @ u[first]
    e_body = perpendicular(u_body)
    frame_x = np.where(good, np.stack([k["u"][i] * e_body[0] + y3[i] * e_body[1]
                                       + z3[i] * e_body[2] for i in range(3)], -1), e_body)
    ux, uy, uz = u[:, 0], u[:, 1], u[:, 2]

    def from_crank(x: Array) -> Array:  # Z(θ1)·x
        return np.stack([ct * x[:, 0] - st * x[:, 1], st * x[:, 0] + ct * x[:, 1], x[:, 2]], -1)

    u_in_crank = np.stack([ct * ux + st * uy, ct * uy - st * ux, uz], -1)  # Z(θ1)ᵀ·u
    phi = spin_from_frames(u, u_dot, u_ddot, frame_x, u_body, e_body, u_in_crank, from_crank,
                           ok, ok)
    return np.where(ok, phi, 0.0)

"""The CSSP's joint rows for one block of samples, by components (one (n,) array each):
the ball joints' relative rotations, rates and rotation vectors, and Rahman's joint angles with
their exact rates, from the link rows of
:func:`screwkit.kinematics.closed_forms.cssp_motion.cssp_block_rows` (its ``loop`` entries:
crank cos/sin and rates, the rod frame, u, u̇, ü, ω and α of the rod in the loop frame {1}).
The formulas are those of :func:`screwkit.kinematics.tracker.loop.rotation_vector` and
:func:`screwkit.kinematics.closed_forms.cssp.rod_and_slider_angles`, written out by components
(the same values), so that :func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_mode_motion`
computes them block by block while the rows are in the CPU caches.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import GIMBAL_TOL, wrap_angle
from screwkit.kinematics.closed_forms.cssp import CSSPDimensions
from screwkit.kinematics.tracker.loop import Array, rotation_vector


def combine(coefficients: Array, values: tuple[Any, Any, Any]) -> Any:
    """Σ c_k v_k for constants c_k, skipping zero constants (and zero values given as 0.0):
    the slider frame X(−(α4 + π/2)) and the rod frame's y3 have zero entries."""
    total: Any = 0.0
    for c, v in zip(coefficients.tolist(), values, strict=True):
        if c == 0.0 or (type(v) is float and v == 0.0):
            continue
        term = v if c == 1.0 else (-v if c == -1.0 else c * v)
        total = term if type(total) is float and total == 0.0 else total + term
    return total


def _dot3(a: tuple[Any, Any, Any], b: tuple[Any, Any, Any]) -> Any:
    """a·b where an entry of ``a`` may be the constant 0.0 (the rod frame's y3_z)."""
    terms = [x * y for x, y in zip(a, b, strict=True) if not (type(x) is float and x == 0.0)]
    total = terms[0]
    for t in terms[1:]:
        total = total + t
    return total


def ball_joint_block(loop: dict[str, Any], REL_st: Array, RATE_st: Array, sl: slice) -> None:
    """The ball joints' relative rotations and rates for one block (loop frame; the base
    cancels): pin R_crankᵀ R_rod (crank Z(θ1)), ball R_rodᵀ R_slider; rates in the child frame:
    pin R_rod·ω_b = ω_rod − ω_crank and R_rod·ω̇_b = α_rod − α_crank + ω_rod × ω_crank; ball
    (the slider does not turn) R_slider·ω_b = −ω_rod and R_slider·ω̇_b = −α_rod."""
    ct, st, rod = loop["ct"], loop["st"], loop["rod"]
    w_rod, al_rod, w, wd = loop["w_rod"], loop["al_rod"], loop["w"], loop["wd"]
    slider_R = loop["slider_R"]
    for j in range(3):
        REL_st[0, 0, j, sl] = ct * rod[0][j] + st * rod[1][j]
        REL_st[0, 1, j, sl] = ct * rod[1][j] - st * rod[0][j]
        REL_st[0, 2, j, sl] = rod[2][j]
        for i in range(3):
            REL_st[1, i, j, sl] = combine(slider_R[:, j], (rod[0][i], rod[1][i], rod[2][i]))
    rel_w = (w_rod[0], w_rod[1], w_rod[2] - w)
    rel_a = (al_rod[0] + w_rod[1] * w, al_rod[1] - w_rod[0] * w, al_rod[2] - wd)
    St = slider_R.T
    for j in range(3):
        col = (rod[0][j], rod[1][j], rod[2][j])
        RATE_st[0, j, sl] = _dot3(col, rel_w)
        RATE_st[1, j, sl] = _dot3(col, rel_a)
        RATE_st[2, j, sl] = combine(-St[j], w_rod)
        RATE_st[3, j, sl] = combine(-St[j], al_rod)


#: Rahman's joint angles of the rod and the slider ball (SPEC §1.1), with the
#: rows of :func:`seed_angle_block`: each angle, then its rate, then its acceleration
SEED_ANGLES = ("theta2", "eta2", "theta3", "eta3")


def _elevation_azimuth_rows(v: tuple[Array, Array, Array], vd: tuple[Array, Array, Array],
                            vdd: tuple[Array, Array, Array]
                            ) -> tuple[NDArray[np.bool_], Array, Array, Array, Array, Array, Array]:
    """:func:`screwkit.dual.spatial.elevation_azimuth` by components (the same formulas): where
    v is defined (ρ > GIMBAL_TOL), E, Ė, Ë, A, Ȧ, Ä (rates and A NaN elsewhere)."""
    vx, vy, vz = v
    rho = np.sqrt(vx * vx + vy * vy)
    defined = rho > GIMBAL_TOL
    elevation = np.arctan2(vz, rho)
    azimuth = np.where(defined, np.arctan2(vy, vx), np.nan)
    safe_rho = np.where(defined, rho, 1.0)
    safe_rho2 = safe_rho * safe_rho
    e_dot = vd[2] / safe_rho
    e_ddot = (vdd[2] + vz * (e_dot * e_dot)) / safe_rho
    a_dot = (vx * vd[1] - vy * vd[0]) / safe_rho2
    a_ddot = ((vx * vdd[1] - vy * vdd[0]) / safe_rho2
              - 2 * a_dot * (vx * vd[0] + vy * vd[1]) / safe_rho2)
    nan = np.nan
    return (defined, elevation, np.where(defined, e_dot, nan), np.where(defined, e_ddot, nan),
            azimuth, np.where(defined, a_dot, nan), np.where(defined, a_ddot, nan))


def seed_angle_block(dims: CSSPDimensions, th: Array, loop: dict[str, Any], ok: NDArray[np.bool_],
                      SEED_st: Array, sl: slice) -> None:
    """Rahman's θ2, η2 (rod) and θ3, η3 (the rod seen from the slider) with their exact rates
    for one block, from the closed form's u, u̇, ü in the loop frame {1}: the formulas of
    :func:`screwkit.kinematics.closed_forms.cssp.rod_and_slider_angles` by components; rows as
    :data:`SEED_ANGLES`, then their rates, then their accelerations. θ2 is wrapped into
    (−π, π] here; the caller makes each run continuous."""
    u, ud, udd = loop["u"], loop["u_dot"], loop["u_ddot"]
    ca, sa = float(np.cos(dims.alpha4)), float(np.sin(dims.alpha4))  # X(α4) = R_{4←1}, by rows
    seen = [(v[0], ca * v[1] - sa * v[2], sa * v[1] + ca * v[2]) for v in (u, ud, udd)]
    with np.errstate(divide="ignore", invalid="ignore"):  # placeholders where it does not assemble
        rod_ok, elev, e_d, e_dd, phi, phi_d, phi_dd = _elevation_azimuth_rows(u, ud, udd)
        _, th3, th3_d, th3_dd, eta3, eta3_d, eta3_dd = _elevation_azimuth_rows(*seen)
        rod_ok &= ok
        SEED_st[0, sl] = np.where(rod_ok, wrap_angle(phi - th), np.nan)
        np.negative(elev, out=SEED_st[1, sl])
        SEED_st[2, sl], SEED_st[3, sl] = th3, eta3
        SEED_st[4, sl] = phi_d - loop["w"]
        np.negative(e_d, out=SEED_st[5, sl])
        SEED_st[6, sl], SEED_st[7, sl] = th3_d, eta3_d
        SEED_st[8, sl] = phi_dd - loop["wd"]
        np.negative(e_dd, out=SEED_st[9, sl])
        SEED_st[10, sl], SEED_st[11, sl] = th3_dd, eta3_dd


def rotation_vector_block(REL_st: Array, RV_st: Array, ok: NDArray[np.bool_], sl: slice) -> None:
    """The two ball joints' rotation vectors for one block from their relative rotations (the
    block of the component-major storage, read in place): :func:`rotation_vector` (skew part and
    trace, axis from the symmetric part near a half turn); the identity where the CSSP does not
    assemble (NaN afterwards)."""
    for r in range(2):
        R = REL_st[r, :, :, sl]
        if not ok.all():
            rel = np.where(ok[:, None, None], np.nan_to_num(np.moveaxis(R, -1, 0)), np.eye(3))
            RV_st[r, :, sl] = rotation_vector(rel).T
            continue
        # rotation_vector's formulas, by components: the axis from the skew part, the angle
        # from it and the trace
        vee = RV_st[r, :, sl]
        np.subtract(R[2, 1], R[1, 2], out=vee[0])
        np.subtract(R[0, 2], R[2, 0], out=vee[1])
        np.subtract(R[1, 0], R[0, 1], out=vee[2])
        vee *= 0.5
        cos = np.clip(0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0), -1.0, 1.0)
        sin = np.sqrt(vee[0] * vee[0] + vee[1] * vee[1] + vee[2] * vee[2])
        angle = np.arctan2(sin, cos)
        vee *= np.where(sin > 1e-300, angle / np.maximum(sin, 1e-300), 1.0)
        near_half = np.flatnonzero(cos < -0.9)
        if near_half.size:
            vee[:, near_half] = _half_turn_axes(R, vee, cos, angle, near_half)


def _half_turn_axes(R: Array, vee: Array, cos: Array, angle: Array,
                    at: NDArray[np.intp]) -> Array:
    """:func:`rotation_vector` near a half turn (cos θ < −0.9), by components (3, m) at the
    samples ``at``: the axis from the symmetric part (R + Rᵀ)/2 − cos θ·I = (1 − cos θ) u uᵀ,
    its column of largest diagonal entry, signed by the skew part ``vee``."""
    c = cos[at]
    Rh = [[R[i, j][at] for j in range(3)] for i in range(3)]
    # B = (R + Rᵀ)/2 − c I, as rotation_vector forms it
    B = [[0.5 * (Rh[i][j] + Rh[j][i]) - (c if i == j else 0.0) for j in range(3)]
         for i in range(3)]
    k = np.argmax(np.stack([B[0][0], B[1][1], B[2][2]], -1), axis=-1)
    u = [np.where(k == 0, B[i][0], np.where(k == 1, B[i][1], B[i][2])) for i in range(3)]
    norm = np.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
    u = [x / norm for x in u]
    v = vee[:, at]
    sign = np.where(u[0] * v[0] + u[1] * v[1] + u[2] * v[2] < 0, -1.0, 1.0) * angle[at]
    return np.stack([x * sign for x in u])

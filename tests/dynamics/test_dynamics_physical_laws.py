"""Physical laws from positions alone (DESIGN validation level 2).

For a random mechanism of every family turning at a constant input rate, the link frames are
re-computed on a sweep 32 times finer than the analysed one (positions only: loop closure by
Newton, no velocities from the kinematics), and differentiated in time by 8th-order periodic
central differences. Then at every analysed sample:

* shaking force  = −dP/dt + M g          (P total linear momentum),
* shaking moment = −dH_O/dt + Σ p_c × m g (H_O angular momentum about the world origin),
* input power τ·θ̇ = d(T + V)/dt.

The S–S rods are line masses (zero axial moment), so their spin — which positions alone leave
undefined — drops out; their angular velocity is taken as a × ȧ of the rod axis a.

Tolerance: the fine step is Δθ = 2π/768 ≈ 0.008 rad. The error is dominated by the truncation of
the nested 8th-order differences, ~(Δθ)^8 · (9th θ-derivative): measured on the RCCC (the worst
here) it falls 2.3e-4 → 1.4e-6 → 6e-9 of the peak for 192/384/768 samples per turn, the ratio
≈ 2^8 of an 8th-order scheme, so the agreement is the scheme's, not a coincidence. Round-off
(~ε·|p|/Δt²) and the Newton closure tolerance (1e-13) are ~1e-11 relative. We assert 1e-7 of each
load's peak: above the truncation, far below any modelling error (a missing ω × Iω term is O(1)).
"""

from __future__ import annotations

import numpy as np
import pytest
from mechanisms import FAMILIES, ROD, fine_sweep, full_cycle

from screwkit.dynamics import inverse_dynamics

REFINE = 32
RATE = 7.0
GRAVITY = np.array([0.3, -1.2, -9.81])
FD8 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])


def ddt(values: np.ndarray, dt: float) -> np.ndarray:
    """Periodic 8th-order central difference along axis 0."""
    out = np.zeros_like(values)
    for k, c in enumerate(FD8):
        if c:
            out += c * np.roll(values, 4 - k, axis=0)
    return out / dt


def _vee(m: np.ndarray) -> np.ndarray:
    return 0.5 * np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                           m[..., 1, 0] - m[..., 0, 1]], -1)


def momenta_from_positions(family: str):
    linkage, mo, mode = full_cycle(family, 0, rate=RATE)
    R, p = fine_sweep(linkage, mode, REFINE)
    dt = (2 * np.pi / (mode.assembles.size * REFINE)) / RATE
    masses = [lk.mass for lk in linkage.links]
    m = np.array([mp.mass for mp in masses])
    com = np.stack([mp.com for mp in masses])
    inertia = np.stack([mp.inertia for mp in masses])
    p_c = p + np.einsum("nlij,lj->nli", R, com)
    v_c = ddt(p_c, dt)
    omega = _vee(np.einsum("nlij,nlkj->nlik", ddt(R, dt), R))
    if family in ROD:
        # The S–S rod's spin is not defined by positions (Newton leaves it where it started);
        # a line mass does not feel it: use the spin-free angular velocity a × ȧ of its axis.
        axis = R[:, ROD[family][0], :, 0]
        omega[:, ROD[family][0]] = np.cross(axis, ddt(axis, dt))
    I_w = np.einsum("nlij,ljk,nlmk->nlim", R, inertia, R)
    Iw_omega = np.einsum("nlij,nlj->nli", I_w, omega)
    P = np.einsum("l,nli->ni", m, v_c)
    H = np.einsum("l,nli->ni", m, np.cross(p_c, v_c)) + Iw_omega.sum(1)
    T = 0.5 * np.einsum("l,nli,nli->n", m, v_c, v_c) + 0.5 * np.einsum("nli,nli->n", omega, Iw_omega)
    V = -np.einsum("l,nli,i->n", m, p_c, GRAVITY)
    weight_moment = np.einsum("l,nli->ni", m, np.cross(p_c, np.broadcast_to(GRAVITY, p_c.shape)))
    coarse = slice(None, None, REFINE)
    return linkage, mode, {
        "force": (-ddt(P, dt) + m.sum() * GRAVITY)[coarse],
        "moment": (-ddt(H, dt) + weight_moment)[coarse],
        "power": ddt(T + V, dt)[coarse],
    }


@pytest.mark.parametrize("family", FAMILIES)
def test_shaking_loads_are_momentum_rates_and_power_is_energy_rate(family: str) -> None:
    linkage, mode, expected = momenta_from_positions(family)
    dyn = inverse_dynamics(linkage, mode, gravity=GRAVITY)
    for name, got in (("force", dyn.shaking_force), ("moment", dyn.shaking_moment)):
        want = expected[name]
        scale = np.max(np.linalg.norm(want, axis=-1))
        err = np.max(np.abs(got - want)) / scale
        assert err < 1e-7, f"{family} shaking {name}: relative error {err:.2e}"
    power = dyn.efforts[linkage.inputs[0]] * RATE
    scale = np.max(np.abs(expected["power"]))
    err = np.max(np.abs(power - expected["power"])) / scale
    assert err < 1e-7, f"{family} input power vs d(T+V)/dt: relative error {err:.2e}"


def test_shaking_moment_about_another_point() -> None:
    linkage, _, mode = full_cycle("cssp", 0, rate=RATE)
    point = np.array([0.1, -0.2, 0.3])
    d0 = inverse_dynamics(linkage, mode, gravity=GRAVITY)
    d1 = inverse_dynamics(linkage, mode, gravity=GRAVITY, moment_point=point)
    np.testing.assert_allclose(
        d1.shaking_moment, d0.shaking_moment - np.cross(point, d0.shaking_force), atol=1e-12
    )
    np.testing.assert_array_equal(d1.moment_point, point)

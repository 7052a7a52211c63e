"""The RSRC's folds written independently of screwkit's closed form (Bagci 1969 eqs. 3.58/3.59:
the closure as a quartic in tan(φ0/2) interpolated at 5 points, its discriminant from its roots
by np.roots, zeros by brentq, each root tracked on a 1e-4 rad grid), and two RSRCs whose folds
fall two in one sample step; shared by tests/graphs/test_quartic_folds.py and
tests/kinematics/test_rsrc_loop_folds.py."""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

#: an RSRC (seeded random dimensions of the family's property tests, rounded) whose modes 0, 1
#: are born at θ0 ≈ 53.85° and modes 2, 3 at ≈ 57.59°: both inside the 5° step 53.5° → 58.5°
P = dict(d1=1.407, d2=2.402, d3=0.566, a=1.617, b=-0.256, e=-0.046, delta0=-1.117, lambda0=-0.832)
#: drawn at 58.5° (where every mode assembles), a turn in 5° steps: the last step holds both
X = np.radians(np.arange(58.5, 58.5 + 361.0, 5.0))


def closure(phi: np.ndarray, theta: float, P: dict[str, float] = P) -> np.ndarray:
    """W1² + (W2 / cos δ0)² − d2² (Bagci eqs. 3.58/3.59: W1 = d2 cos χ0, W2 = d2 cos δ0 sin
    χ0), zero where the loop closes at output angle φ0 and input θ0."""
    m0 = P["b"] * np.sin(P["lambda0"]) - P["d1"] * np.cos(P["lambda0"]) * np.sin(theta)
    n0 = P["a"] - P["d1"] * np.cos(theta)
    w1 = m0 * np.sin(phi) + n0 * np.cos(phi) + P["d3"]
    w2 = n0 * np.sin(phi) - m0 * np.cos(phi) - P["e"] * np.sin(P["delta0"])
    return w1 * w1 + (w2 / np.cos(P["delta0"])) ** 2 - P["d2"] ** 2


def quartic(theta: float, P: dict[str, float] = P) -> np.ndarray:
    """The closure times (1 + τ²)² as a quartic in τ = tan(φ0/2): interpolated at 5 points."""
    tau = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
    return np.polyfit(tau, closure(2 * np.arctan(tau), theta, P) * (1 + tau * tau) ** 2, 4)


def discriminant(theta: float, P: dict[str, float] = P) -> float:
    """The quartic's discriminant up to a positive factor: ∏ (τi − τj)² over its roots."""
    r = np.roots(quartic(theta, P))
    return float(np.real(np.prod([(r[i] - r[j]) ** 2 for i in range(4) for j in range(i)])))


def real_roots(theta: float, P: dict[str, float]) -> np.ndarray:
    r = np.roots(quartic(theta, P))
    return np.sort(2 * np.arctan(np.real(r[np.abs(np.imag(r)) < 1e-9])))


def track(phi: float, start: float, end: float, folds: list[float],
           P: dict[str, float] = P) -> float | None:
    """Follow the root at φ0 = ``phi`` from θ0 = ``start`` towards ``end`` on a grid of 1e-4
    rad, the nearest root each step; where the count of real roots drops and this root is one
    of the two closest roots just before (the pair that turns complex), the fold of ``folds``
    inside that grid step (None: it reaches ``end``)."""
    grid = np.linspace(start, end, int(np.ceil(abs(end - start) / 1e-4)) + 1)
    for t0, t1 in zip(grid, grid[1:], strict=False):
        now, nxt = real_roots(t0, P), real_roots(t1, P)
        phi = float(now[np.argmin(np.abs(np.angle(np.exp(1j * (now - phi)))))])
        if nxt.size < now.size:
            d = np.abs(np.angle(np.exp(1j * (now[:, None] - now[None, :])))) + np.eye(now.size) * 9
            i, j = np.unravel_index(np.argmin(d), d.shape)
            if phi in (now[i], now[j]):
                return next(f for f in folds if min(t0, t1) <= f <= max(t0, t1))
    return None


def zeros(lo: float, hi: float, P: dict[str, float] = P) -> list[float]:
    """The discriminant's zeros on [lo, hi] (sign changes on a fine grid, brentq)."""
    grid = np.linspace(lo, hi, 2001)
    D = np.array([discriminant(t, P) for t in grid])
    change = np.flatnonzero(np.sign(D[:-1]) != np.sign(D[1:]))
    return [brentq(discriminant, grid[i], grid[i + 1], args=(P,), xtol=1e-15) for i in change]


#: an RSRC (seeded random dimensions, rounded) with four modes, two of which (all that assemble
#: there) have a 3.7° gap at θ0 ≈ 337.19°–340.89°, and a pair born at ≈ 15.94° whose roots die with
#: different partners at ≈ 22.56° (one of them on no sample of a 10° sweep)
Q = dict(d1=2.093, d2=2.189, d3=1.232, a=1.986, b=-0.759, e=0.529, delta0=1.320, lambda0=0.795)
#: drawn at 4°, 10° steps: the steps 334° → 344° and 14° → 24° each hide two folds
XQ = np.radians(np.arange(4.0, 364.0, 10.0))

"""Every platform pose a set of pose equations has, by Newton's method (Levenberg–Marquardt
least squares) from many random poses: the independent second method of the leg tests
(test_pivot_legs.py, test_gimbal_legs.py, test_universal_legs.py)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation


def newton_poses(F: Callable[[np.ndarray, np.ndarray], np.ndarray], centre: np.ndarray,
                 rng: np.random.Generator, starts: int, turn_only: bool = False,
                 residual: float = 1e-12) -> np.ndarray:
    """The distinct poses (rows: rotation entries, then position) where F(R, c) vanishes,
    R the platform's rotation about ``centre`` and c (3,) the centre's new place (left at
    ``centre`` when ``turn_only``): Newton from ``starts`` random rotations (and places within
    3 of the centre), a root kept where every |F| ≤ ``residual``, two apart by 1e-6."""

    def pose(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        R = Rotation.from_rotvec(z[:3]).as_matrix()
        return R, centre if turn_only else centre + z[3:]

    def G(z: np.ndarray) -> np.ndarray:
        return F(*pose(z))

    found: list[np.ndarray] = []
    for _ in range(starts):
        z0 = Rotation.random(random_state=rng).as_rotvec()
        if not turn_only:
            z0 = np.concatenate([z0, rng.uniform(-3.0, 3.0, 3)])
        z = least_squares(G, z0, xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm").x
        if np.abs(G(z)).max() > residual:
            continue
        R, c = pose(z)
        row = np.concatenate([R.ravel(), c - R @ centre])
        if all(np.abs(row - f).max() > 1e-6 for f in found):
            found.append(row)
    return np.array(found)

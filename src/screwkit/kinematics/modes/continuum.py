"""Telling a continuum of solutions from isolated ones at a singular end point.

A parameter homotopy ends singular both at an isolated multiple root and on a
positive-dimensional component (a 4R deltoid with its crank on the frame: the coupler and the
rocker turn freely together). On a component of dimension ≥ 1 the solution set continues along
a null vector v of ∂F/∂x; at an isolated root it does not. So from x + h·v, Gauss–Newton on F
together with the hyperplane v·(y − x − h v) = 0 (which the root x itself does not satisfy)
converges to a solution only when there is one at distance ~h: the local-dimension test by
sampling (Sommese & Wampler 2005, §15.2, in its simplest form).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic.polynomial import Complex, PolynomialSystem


def on_a_continuum(system: PolynomialSystem, x: Complex, p: Complex, step: float = 1e-3,
                   tolerance: float = 1e-10) -> NDArray[np.bool_]:
    """For each singular end point x (B, n) with parameters p (B, k) or (k,): does a curve of
    solutions pass through it (True) or is it an isolated (multiple) root (False)?"""
    x = np.atleast_2d(np.asarray(x, dtype=complex))
    _, J, _ = system.evaluate(x, p, want_jp=False)
    _, _, vh = np.linalg.svd(J)
    v = np.conj(vh[:, -1, :])  # the right singular vector of the smallest singular value
    scale = 1.0 + np.abs(x).max(axis=1)
    target = x + (step * scale)[:, None] * v
    y = target.copy()
    for _ in range(30):
        F, J, _ = system.evaluate(y, p, want_jp=False)
        G = np.concatenate([F, np.einsum("bi,bi->b", np.conj(v), y - target)[:, None]], 1)
        A = np.concatenate([J, np.conj(v)[:, None, :]], 1)
        dy = np.stack([np.linalg.lstsq(A[b], G[b], rcond=None)[0] for b in range(len(y))])
        y = y - dy
    F, _, _ = system.evaluate(y, p, want_jp=False)
    moved = np.abs(y - x).max(axis=1) > 0.1 * step * scale
    return (np.abs(F).max(axis=1) <= tolerance * scale) & moved

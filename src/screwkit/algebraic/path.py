"""The predictor–corrector core of the homotopy tracker, vectorised over paths.

A homotopy here is F^h(y; p(σ)) = 0 together with a random affine patch a·y = 1, where F^h is
the homogenised system (:meth:`PolynomialSystem.homogenized`, unknowns y = (h, h·x)) and the
parameters move as p(σ) = p_start + σ·(p_target − p_start). The complex number σ itself runs
along a curve σ(τ), τ real: the straight segment σ = τ for the main leg, the circle
σ = 1 − r·e^{iτ} for the Cauchy endgame. Working on the patch keeps paths that go to infinity
finite (they end with h → 0), Sommese & Wampler, *The Numerical Solution of Systems of
Polynomials*, 2005, §3.2 and ch. 7.

One step for all active paths: a fourth-order Runge–Kutta predictor on dy/dτ = −J⁻¹·∂H/∂τ,
then two Newton corrections at the new τ; the step is accepted when the first correction (the
predictor's error) is within ``predictor_tolerance`` and the second is within
``corrector_tolerance`` and at most ``contraction`` times the first (Newton converging fast,
the guard against landing on a neighbouring path; waived when both are at most ``converged``,
at the rounding floor where the contraction says nothing); the next step is sized from the error as
(tolerance / error)^(1/5), between ½× and 2×, a rejected one at most ½×. The main leg
(s up to 1 − ``endgame_radius``) runs with the looser pair of tolerances (1e-2, 1e-4), the rest
and the Cauchy endgame with the tighter one (1e-3, 1e-5) (:meth:`TrackOptions.near_end`).
Every step is a handful of batched numpy calls over the active paths (one ``np.linalg.solve``
over (B, n+1, n+1) per stage); no Python loop runs over the paths.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic import compiled
from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.quadrics import DenseBlock, DenseQuadrics

Real = NDArray[np.float64]
Index = NDArray[np.intp]
#: σ(τ) and dσ/dτ for the rows of a path set
Curve = Callable[[Real, Index], tuple[Complex, Complex]]


@dataclass(frozen=True)
class TrackOptions:
    """Step control and classification thresholds of :func:`track_parameter_homotopy`.

    Tolerances are relative to 1 + ‖y‖∞ on the patch (where ‖y‖∞ is of order one)."""

    initial_step: float = 0.05
    max_step: float = 0.2
    min_step: float = 1e-13
    max_steps: int = 2000
    #: the first Newton correction (the predictor's error) must be within this, on the main
    #: leg s ∈ [0, 1 − endgame_radius] (1e-3 before issue 27's tuning: 1e-2 with the corrector
    #: tolerance below takes ~23 % fewer steps on the Stewart and 6R systems, with every one
    #: of 200 seeded instances complete, measured)
    predictor_tolerance: float = 1e-2
    #: the second Newton correction must end within this: when Newton converges
    #: quadratically, the point's remaining error is of the order of its square
    corrector_tolerance: float = 1e-4
    #: the two tolerances from s = 1 − endgame_radius on (the last leg and the Cauchy
    #: endgame, whose estimates must agree to ``endgame_tolerance``)
    end_predictor_tolerance: float = 1e-3
    end_corrector_tolerance: float = 1e-5
    #: the second Newton correction must be at most this fraction of the first
    contraction: float = 0.1
    #: ... unless both are at most this (relative): then they are at the rounding floor and
    #: the contraction says nothing. 1e-12 (the first alone) before: an ill-conditioned point's
    #: floor is higher (the trace test's far-out witnesses, corrections of 1e-11 to 3e-11 at
    #: κ ≈ 2e6; a root 1e-4 from another, tests/algebraic/test_track.py), every step there
    #: was rejected and the step collapsed. The 3-UPU's every mode along its motion is the
    #: same with 1e-9 (every number of its JSON to 1e-9) and takes 30 s instead of 33
    converged: float = 1e-9
    #: the endgame starts on the circle |1 − σ| = endgame_radius and shrinks it by 4 a level
    endgame_radius: float = 0.05
    endgame_levels: int = 5
    endgame_tolerance: float = 1e-10
    samples_per_loop: int = 12
    max_winding: int = 8
    #: steps a path may take in the endgame before it is given up (failed)
    endgame_max_steps: int = 20000
    #: an endpoint with cond(J) above this (on the patch) is treated as singular
    max_condition: float = 1e9
    #: an endpoint with |h| ≤ infinity_threshold·‖y‖∞ is at infinity (|x| ≳ 1/threshold)
    infinity_threshold: float = 1e-9
    #: endpoints of one instance closer than this (relative) are the same point
    same_point_tolerance: float = 1e-7
    retrack: bool = True
    #: paths whose tracking failed are tracked again through a random complex parameter point
    detour: bool = True
    seed: int = 0
    #: paths tracked together (larger batches run in chunks of this many)
    chunk: int = 512
    #: evaluate a system of quadrics densely (:mod:`.quadrics`); False: the sparse term table
    dense: bool = True
    #: run the step loop of a dense homotopy compiled (:mod:`.compiled`, numba: the ``fast``
    #: extra) when numba is installed; False: the numpy route (the same algorithm)
    compiled: bool = True

    def tighter(self) -> TrackOptions:
        """The options for a retrack after suspected path jumping: 10× smaller steps, 100×
        tighter predictor tolerance and 10× tighter corrector tolerance on the main leg."""
        from dataclasses import replace

        return replace(self, max_step=self.max_step / 10, initial_step=self.initial_step / 10,
                       predictor_tolerance=self.predictor_tolerance / 100,
                       corrector_tolerance=self.corrector_tolerance / 10, retrack=False)

    def near_end(self) -> TrackOptions:
        """The options from s = 1 − endgame_radius on: the end tolerances."""
        from dataclasses import replace

        return replace(self, predictor_tolerance=self.end_predictor_tolerance,
                       corrector_tolerance=self.end_corrector_tolerance)


@dataclass(frozen=True)
class Homotopy:
    """F^h(y; p_start + σ·direction) with the patch row a·y − 1, for a set of paths (rows).

    With ``dense`` (a system of quadrics, :mod:`.quadrics`) and ``instance`` (each row's index
    into it) the system is evaluated densely, one matrix product per instance; otherwise by
    the sparse term table of :class:`PolynomialSystem`. Both evaluate the same homotopy."""

    system: PolynomialSystem  # homogenised: n+1 unknowns, n equations
    patch: Complex  # (n+1,)
    p_start: Complex  # (P, k)
    direction: Complex  # (P, k)
    dense: DenseQuadrics | None = None
    instance: Index | None = None
    block: DenseBlock | None = None

    def restricted(self, rows: Index) -> Homotopy:
        """The homotopy of the paths ``rows`` only (their parameters gathered once)."""
        if self.dense is not None and self.instance is not None:
            instance = self.instance[rows]
            return Homotopy(self.system, self.patch, self.p_start[rows], self.direction[rows],
                            self.dense, instance, self.dense.block(instance))
        return Homotopy(self.system, self.patch, self.p_start[rows], self.direction[rows])

    def _evaluate(self, y: Complex, rows: Index | None, sigma: Complex,
                  dsigma: Complex | None) -> tuple[Complex, Complex, Complex | None]:
        """F^h (B, n), ∂F^h/∂y (B, n, n+1) and (∂F^h/∂σ)·dσ/dτ (B, n) or None."""
        if self.dense is not None and self.instance is not None:
            if rows is not None:
                return self.restricted(rows)._evaluate(y, None, sigma, dsigma)
            block = self.block
            if block is None:
                block = self.dense.block(self.instance)
                object.__setattr__(self, "block", block)
            return block.evaluate(y, sigma, dsigma)
        d = self.direction if rows is None else self.direction[rows]
        p = (self.p_start if rows is None else self.p_start[rows]) + sigma[:, None] * d
        F, Jy, Fd = self.system.evaluate_directional(y, p, None if dsigma is None else d)
        return F, Jy, (None if Fd is None or dsigma is None else Fd * dsigma[:, None])

    def parts(self, y: Complex, rows: Index | None, sigma: Complex,
              dsigma: Complex | None = None) -> tuple[Complex, Complex, Complex | None]:
        """H (B, n+1), ∂H/∂y (B, n+1, n+1) and, when ``dsigma`` is given, ∂H/∂τ (B, n+1), for
        the paths ``rows`` (None: every path of this homotopy, in order)."""
        F, Jy, Ft = self._evaluate(y, rows, sigma, dsigma)
        B, m = y.shape
        H = np.empty((B, m), dtype=complex)
        H[:, :-1] = F
        H[:, -1] = y @ self.patch - 1.0
        J = np.empty((B, m, m), dtype=complex)
        J[:, :-1] = Jy
        J[:, -1] = self.patch
        if dsigma is None:
            return H, J, None
        assert Ft is not None
        Ht = np.zeros((B, m), dtype=complex)
        Ht[:, :-1] = Ft
        return H, J, Ht

    def to_patch(self, x: Complex) -> Complex:
        """Affine points x (P, n) as points y = (1, x)/(a·(1, x)) of the patch."""
        y = np.concatenate([np.ones((x.shape[0], 1), dtype=complex), x], axis=1)
        return y / (y @ self.patch)[:, None]


def line(tau: Real, rows: Index) -> tuple[Complex, Complex]:
    """σ = τ: the straight parameter segment."""
    sigma: Complex = tau.astype(complex)
    return sigma, np.ones(len(tau), dtype=complex)


class circle:  # noqa: N801 - used like the function ``line``
    """σ = 1 − r·e^{iτ} (r per path, indexed by row): the endgame's loop around σ = 1."""

    def __init__(self, radius: Real) -> None:
        self.radius = radius

    def __call__(self, tau: Real, rows: Index) -> tuple[Complex, Complex]:
        turn = (self.radius[rows] * np.exp(1j * tau)).astype(complex)
        return (1.0 - turn).astype(complex), (-1j * turn).astype(complex)


def _solve(J: Complex, b: Complex) -> Complex:
    """J⁻¹b for stacks J (B, m, m) and b (B, m) or (B, m, r); NaN where J is singular."""
    column = b.ndim == 2
    rhs = b[..., None] if column else b
    with np.errstate(all="ignore"):
        try:
            out = np.linalg.solve(J, rhs).astype(complex, copy=False)
        except np.linalg.LinAlgError:  # rare: one matrix at a time, NaN for the singular
            out = np.full_like(rhs, np.nan)
            for i in range(len(J)):
                try:
                    out[i] = np.linalg.solve(J[i], rhs[i])
                except np.linalg.LinAlgError:
                    pass
    return out[..., 0] if column else out


def _velocity(hom: Homotopy, curve: Curve, y: Complex, rows: Index, tau: Real) -> Complex:
    """dy/dτ of the paths of ``hom`` (restricted to ``rows``, which the curve still needs)."""
    sigma, dsigma = curve(tau, rows)
    _, J, Ht = hom.parts(y, None, sigma, dsigma)
    assert Ht is not None
    return -_solve(J, Ht)


def _rk4(hom: Homotopy, curve: Curve, y: Complex, rows: Index, tau: Real, h: Real,
         k1: Complex) -> Complex:
    """The classical fourth-order Runge–Kutta step from y at τ, given its first stage k1."""
    hc = h[:, None]
    k2 = _velocity(hom, curve, y + 0.5 * hc * k1, rows, tau + 0.5 * h)
    k3 = _velocity(hom, curve, y + 0.5 * hc * k2, rows, tau + 0.5 * h)
    k4 = _velocity(hom, curve, y + hc * k3, rows, tau + h)
    return y + hc / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def newton(hom: Homotopy, y: Complex, rows: Index | None, sigma: Complex,
           iterations: int) -> tuple[Complex, list[Real]]:
    """``iterations`` Newton corrections at fixed σ; the ∞-norm of each correction."""
    sizes = []
    for _ in range(iterations):
        H, J, _ = hom.parts(y, rows, sigma)
        dy = _solve(J, H)
        y = y - dy
        sizes.append(np.abs(dy).max(axis=1))
    return y, sizes


def _correct(hom: Homotopy, curve: Curve, y: Complex, rows: Index,
             tau: Real) -> tuple[Complex, Real, Real, Complex]:
    """Two Newton corrections of y at τ: the corrected point, the ∞-norms of both corrections,
    and dy/dτ at the once-corrected point, from the second evaluation (one more right-hand
    side in its solve). That velocity serves as the next step's first RK4 stage: it is taken
    at a point within the second correction of the accepted one, an error far below the
    predictor tolerance."""
    sigma, dsigma = curve(tau, rows)
    H, J, _ = hom.parts(y, None, sigma)
    d1 = _solve(J, H)
    y1 = y - d1
    H, J, Ht = hom.parts(y1, None, sigma, dsigma)
    assert Ht is not None
    both = _solve(J, np.stack([H, Ht], axis=-1))
    return (y1 - both[..., 0], np.abs(d1).max(axis=1), np.abs(both[..., 0]).max(axis=1),
            -both[..., 1])


def track(hom: Homotopy, curve: Curve, y0: Complex, rows: Index, tau0: Real, tau1: Real,
          options: TrackOptions) -> tuple[Complex, NDArray[np.bool_], NDArray[np.int64]]:
    """Track the paths ``rows`` (start points y0 at τ = tau0) to τ = tau1 (per path).

    Returns the end points, whether each path reached tau1, and the steps taken (accepted
    and rejected). A dense homotopy on the line or the circle runs compiled when numba is
    installed and ``options.compiled`` (:mod:`.compiled`: the same steps, one compiled loop
    per path)."""
    m = len(rows)
    if (options.compiled and compiled.AVAILABLE and hom.dense is not None
            and hom.instance is not None and (curve is line or isinstance(curve, circle))):
        t0 = np.broadcast_to(np.asarray(tau0, dtype=float), (m,))
        t1 = np.broadcast_to(np.asarray(tau1, dtype=float), (m,))
        kind = compiled.LINE if curve is line else compiled.CIRCLE
        radius = curve.radius[rows] if isinstance(curve, circle) else np.zeros(m)
        return compiled.track_compiled(hom.dense, hom.instance[rows], hom.patch, y0, t0, t1,
                                       kind, radius, options)
    y = np.array(y0, dtype=complex)
    tau = np.array(tau0, dtype=float)
    span = np.abs(np.asarray(tau1, dtype=float) - tau)
    h = np.minimum(options.initial_step, options.max_step) * np.ones(m)
    steps = np.zeros(m, dtype=np.int64)
    reached = span == 0
    active = np.flatnonzero(~reached)
    velocity = np.zeros_like(y)
    if active.size:
        velocity[active] = _velocity(hom.restricted(rows[active]), curve, y[active],
                                     rows[active], tau[active])
    while active.size:
        a = active
        left = tau1[a] - tau[a]
        hs = np.minimum(h[a], left)
        last = hs >= left
        ya = y[a]
        sub = hom.restricted(rows[a])
        with np.errstate(all="ignore"):
            yp = _rk4(sub, curve, ya, rows[a], tau[a], hs, velocity[a])
            yc, first, second, v_new = _correct(sub, curve, yp, rows[a], tau[a] + hs)
            scale = 1.0 + np.abs(ya).max(axis=1)
            first, second = first / scale, second / scale
            tol_c = options.corrector_tolerance
            # Newton must contract fast (quadratic convergence from the predicted point, the
            # guard against converging onto a neighbouring path) and end within tol_c
            accept = ((first <= options.predictor_tolerance) & (second <= tol_c)
                      & ((second <= options.contraction * first)
                         | (np.maximum(first, second) <= options.converged)))
            accept &= np.isfinite(yc).all(axis=1)
            # the first correction is the RK4 predictor's error, O(h^5): aim the next step at
            # 0.6^5 ≈ 0.08 of the tolerance (fewer rejections than 0.8, measured), growing at
            # most 2× and shrinking at least 2×
            ratio = 0.6 * (options.predictor_tolerance / np.maximum(first, 1e-300)) ** 0.2
            ratio = np.where(np.isfinite(ratio), ratio, 0.25)
        acc = a[accept]
        y[acc] = yc[accept]
        velocity[acc] = v_new[accept]
        tau[acc] = np.where(last[accept], tau1[acc], tau[acc] + hs[accept])
        reached[acc[last[accept]]] = True
        h[a] = np.where(accept,
                        np.minimum(np.maximum(hs, h[a]) * np.clip(ratio, 1.0, 2.0),
                                   options.max_step),
                        hs * np.clip(ratio, 0.25, 0.5))
        steps[a] += 1
        alive = ~reached[a] & (h[a] >= options.min_step * np.maximum(span[a], 1.0)) \
            & (steps[a] < options.max_steps)
        active = a[alive]
    return y, reached, steps

"""Smale's α-test: which approximate solutions provably converge to a true, distinct, real zero.

For a square polynomial system f and a point x (Blum, Cucker, Shub & Smale, *Complexity and Real
Computation*, 1998, ch. 8; Hauenstein & Sottile, "alphaCertified: certifying solutions to
polynomial systems", ACM TOMS 38(4), 2012, §1–2):

- β(f, x) = ‖Df(x)⁻¹ f(x)‖ (the Newton step), γ(f, x) = sup_{k≥2} ‖Df(x)⁻¹ D^k f(x)/k!‖^(1/(k−1)),
  α = β·γ;
- γ is bounded from the coefficients and degrees alone (Shub & Smale, the bound used by
  alphaCertified): γ ≤ μ(f, x)·D^(3/2) / (2‖x‖₁), where ‖x‖₁ = √(1 + ‖x‖²), D = max d_i,
  μ(f, x) = max(1, ‖f‖·‖Df(x)⁻¹·Δ(x)‖), Δ = diag(√d_i·‖x‖₁^(d_i − 1)), and ‖f‖ the
  Bombieri–Weyl norm: ‖f_i‖² = Σ_α |c_α|²·α₀!α₁!…α_n!/d_i! with α₀ = d_i − |α|;
- if α < α₀ = (13 − 3√17)/4 ≈ 0.157671, Newton's method from x converges quadratically to a
  zero ξ with ‖x − ξ‖ ≤ 2β (x is a *certified approximate solution*);
- two certified points x₁, x₂ belong to distinct zeros if ‖x₁ − x₂‖ > 2(β₁ + β₂);
- for a real system (real coefficients at real parameters): if ‖x − x̄‖ > 4β the zero is not
  real (ξ real would put both x and x̄ within 2β of it); if α < 0.03 and ‖x − x̄‖ < 1/(20γ), x̄
  is an approximate solution with the same associated zero as x, whose conjugate it also is,
  so ξ = ξ̄ is real (Hauenstein & Sottile 2012, the real-solution test).

**What this certifies, honestly.** The quantities are computed in double precision, not in
exact rational or interval arithmetic as alphaCertified does. β and γ are inflated by stated
rounding margins (the evaluation error of f bounded by 8·(terms + degree + factors)·u·Σ|terms|,
and the linear solves' relative error by 10·n·κ·u, u the unit round-off, κ the condition
number); the rounding of Df(x) itself and of the norm computations is not bounded separately.
So a certificate here is a floating-point α-test with a rounding allowance: strong evidence,
rigorous under the assumption that those margins cover the rounding, but not a computer proof.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import sqrt

import numpy as np
from numpy.typing import NDArray
from scipy.special import gammaln

from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.track import same_points

#: Smale's constant (13 − 3√17)/4
ALPHA_0 = (13.0 - 3.0 * sqrt(17.0)) / 4.0
#: α below which the real-solution and same-zero tests apply (Hauenstein & Sottile 2012)
ALPHA_REAL = 0.03
UNIT_ROUNDOFF = np.finfo(float).eps / 2


@dataclass(frozen=True)
class Certificate:
    """Per point (P,): ``certified`` (α < α₀), ``alpha``, ``beta``, ``gamma`` (the upper
    bounds used), ``radius`` = 2β (a true zero lies within it, in the 2-norm), ``real``
    (certified to be a real zero), ``not_real`` (certified non-real), ``newton`` the Newton
    point x − Df⁻¹f (P, n)."""

    certified: NDArray[np.bool_]
    alpha: NDArray[np.float64]
    beta: NDArray[np.float64]
    gamma: NDArray[np.float64]
    radius: NDArray[np.float64]
    real: NDArray[np.bool_]
    not_real: NDArray[np.bool_]
    newton: Complex
    #: F(x) (P, N) and Σ|terms| of each F_i(x) (P, N), as evaluated for the test (so that a
    #: caller's residual needs no second evaluation)
    value: Complex | None = None
    terms: NDArray[np.float64] | None = None


def bombieri_weyl_norm(system: PolynomialSystem, p: Complex) -> NDArray[np.float64]:
    """‖f‖ (B,) of the system at each parameter vector of p (B, k); compiled when numba is
    there (:func:`.compiled.bombieri_weyl`: the same sums, one parameter row at a time)."""
    from screwkit.algebraic import compiled

    if compiled.AVAILABLE and len(system.eq):
        plan = system.__dict__.get("_bw_plan")
        if plan is None:
            eq, exps, _ = system.coefficients_at(np.zeros(system.k, dtype=complex))
            _, order, heads = system.monomial_plan()
            group = np.repeat(np.arange(len(heads)), np.diff(np.append(heads, len(order))))
            term_group = np.empty(len(order), dtype=np.int64)
            term_group[order] = group
            plan = (order.astype(np.int64), term_group, _weights(system, eq, exps))
            object.__setattr__(system, "_bw_plan", plan)
        return compiled.bombieri_weyl(system, p, *plan)
    eq, exps, coef = system.coefficients_at(p)
    if not len(eq):
        return np.zeros(len(coef))
    return np.sqrt((np.abs(coef) ** 2 * _weights(system, eq, exps)).sum(axis=1))


def _weights(system: PolynomialSystem, eq: NDArray[np.intp], exps: NDArray[np.intp]
             ) -> NDArray[np.float64]:
    """The Bombieri–Weyl weights α₀!α₁!…α_n!/d_i! of the monomials (eq, exps) of
    :meth:`.PolynomialSystem.coefficients_at`: fixed by the system, so kept on it."""
    kept = system.__dict__.get("_bw_weights")
    if kept is None:
        degree = np.asarray(system.degrees)[eq]
        alpha0 = degree - exps.sum(axis=1)

        def log_fact(v: NDArray[np.intp]) -> NDArray[np.float64]:  # log v!, elementwise
            return np.asarray(gammaln(np.asarray(v, dtype=float) + 1.0), dtype=float)

        kept = np.exp(log_fact(alpha0) + log_fact(exps).sum(axis=1) - log_fact(degree))
        object.__setattr__(system, "_bw_weights", kept)
    return kept  # type: ignore[no-any-return]


def _norms(system: PolynomialSystem, p: Complex) -> NDArray[np.float64]:
    """:func:`bombieri_weyl_norm` per row of p (P, k), computed once per distinct row (the
    points of one instance share their parameters)."""
    if len(p) and bool((p == p[:1]).all()):
        return np.repeat(bombieri_weyl_norm(system, p[:1]), len(p))
    rows, inverse = np.unique(p, axis=0, return_inverse=True)
    return bombieri_weyl_norm(system, rows)[inverse.reshape(-1)]


def term_magnitude(system: PolynomialSystem, x: Complex, p: Complex) -> NDArray[np.float64]:
    """Σ_t |c_t·x^α·p^β| per equation (P, N): the scale of each F_i(x), against which a
    residual or a rounding error is measured."""
    from dataclasses import replace

    moduli = system.__dict__.get("_moduli")  # kept on the system: its evaluation plan too
    if moduli is None:
        moduli = replace(system, coef=np.abs(system.coef).astype(complex))
        object.__setattr__(system, "_moduli", moduli)
    F_abs, _, _ = moduli.evaluate(np.abs(x).astype(complex), np.abs(p).astype(complex),
                                  want_jp=False)
    return np.asarray(F_abs.real, dtype=float)


def _evaluation_error(system: PolynomialSystem, magnitude: NDArray[np.float64]
                      ) -> NDArray[np.float64]:
    """A bound on the rounding error of each F_i(x) (P, N): 8·(terms + degree + factors)·u
    times Σ|terms| (``magnitude``, :func:`term_magnitude`; Higham, *Accuracy and Stability of
    Numerical Algorithms*, 2002, §3.1, for sums and products, with a factor 2 to spare)."""
    return magnitude * _error_factor(system)


def _error_factor(system: PolynomialSystem) -> NDArray[np.float64]:
    """8·(terms + degree + factors)·u per equation (:func:`_evaluation_error`), kept on the
    system."""
    factor = system.__dict__.get("_error_factor")
    if factor is None:
        terms = np.diff(np.append(system.starts, len(system.eq)))
        factor = 8.0 * (terms + np.asarray(system.degrees) + system.sym.shape[1]) * UNIT_ROUNDOFF
        object.__setattr__(system, "_error_factor", factor)
    return factor  # type: ignore[no-any-return]


def certify(system: PolynomialSystem, x: Complex, p: Complex, fast: bool = False,
            norm_f: NDArray[np.float64] | None = None,
            dense: tuple[Complex, Complex, NDArray[np.intp]] | None = None) -> Certificate:
    """The α-test of the points x (P, n) for F(·; p) = 0, p (k,) or (P, k).

    ``fast``: one inverse of Df(x) per point instead of two singular value decompositions,
    with every 2-norm replaced by the Frobenius norm, which bounds it from above (so σ_min,
    κ and ‖Df⁻¹Δ‖ are bounded on the safe side: the test is as rigorous, only more
    conservative, by at most √n in γ; compiled when numba is there, :func:`.compiled.alpha_test`,
    the same arithmetic point by point). ``norm_f``: ‖f‖ (P,) when the caller has it (one per
    parameter vector, repeated), else computed here. ``dense``: for a system of quadrics, its
    symmetric matrices (Q, |Q|, inst) (:func:`.compiled.alpha_test_quadrics`): with ``fast``
    and numba, F, Df and Σ|terms| are evaluated from them (the same values to rounding: the
    rounding allowance per Σ|terms|, sized for the term table's longer sums, covers the dense
    sums of ≤ (n + 1)² products too) and the rest of the test is unchanged."""
    from screwkit.algebraic import compiled

    x = np.asarray(x, dtype=complex)
    P, n = x.shape
    p = np.broadcast_to(np.asarray(p, dtype=complex), (P, system.k))
    if fast and compiled.AVAILABLE:  # the same test, one compiled pass per point
        real_p = np.all(p.imag == 0, axis=1) & bool(np.all(system.coef.imag == 0))
        if dense is not None:
            return Certificate(*compiled.alpha_test_quadrics(
                system, dense, x, _error_factor(system),
                _norms(system, p) if norm_f is None else norm_f, real_p, ALPHA_0, ALPHA_REAL,
                UNIT_ROUNDOFF))
        return Certificate(*compiled.alpha_test(
            system, x, p, _error_factor(system), _norms(system, p) if norm_f is None else norm_f,
            real_p, ALPHA_0, ALPHA_REAL, UNIT_ROUNDOFF))
    d = np.asarray(system.degrees, dtype=float)
    norm1 = np.sqrt(1.0 + np.linalg.norm(x, axis=1) ** 2)
    delta = np.sqrt(d)[None, :] * norm1[:, None] ** (d - 1.0)[None, :]
    F, J, _ = system.evaluate(x, p, want_jp=False)
    magnitude = term_magnitude(system, x, p)
    with np.errstate(all="ignore"):
        finite = np.asarray(np.isfinite(J).all(axis=(1, 2)) & np.isfinite(F).all(axis=1),
                            dtype=bool)
        Jsafe = np.where(finite[:, None, None], J, np.eye(n))
        Fsafe = np.where(finite[:, None], F, 0.0)
        Jinv = None
        if fast:
            try:
                Jinv = np.linalg.inv(Jsafe)
            except np.linalg.LinAlgError:  # an exactly singular Df somewhere: the SVD route
                Jinv = None
        if Jinv is not None:
            inv_norm = np.linalg.norm(Jinv, axis=(1, 2))  # ≥ ‖J⁻¹‖₂ = 1/σ_min
            s_min = 1.0 / inv_norm
            kappa = np.linalg.norm(Jsafe, axis=(1, 2)) * inv_norm
            step = np.einsum("pij,pj->pi", Jinv, Fsafe)
            scaled_norm = np.linalg.norm(Jinv * delta[:, None, :], axis=(1, 2))  # ≥ ‖J⁻¹Δ‖₂
        else:
            s = np.linalg.svd(Jsafe, compute_uv=False)
            singular = ~(s[:, -1] > s[:, 0] * n * np.finfo(float).eps)  # no certificate there
            s_min = np.where(singular, 0.0, s[:, -1])
            kappa = s[:, 0] / s_min
            Jsafe = np.where(singular[:, None, None], np.eye(n), Jsafe)  # a solve would raise
            step = np.linalg.solve(Jsafe, Fsafe[..., None])[..., 0]
            scaled = np.linalg.solve(Jsafe, delta[:, :, None] * np.eye(n)[None])  # J⁻¹Δ
            scaled_norm = np.linalg.norm(scaled, ord=2, axis=(1, 2))
    return _alpha_test(system, x, p, F, magnitude, finite, s_min, kappa, step, scaled_norm,
                       norm1, d, norm_f)


def _alpha_test(system: PolynomialSystem, x: Complex, p: Complex, F: Complex,
                magnitude: NDArray[np.float64], finite: NDArray[np.bool_],
                s_min: NDArray[np.float64], kappa: NDArray[np.float64], step: Complex,
                scaled_norm: NDArray[np.float64], norm1: NDArray[np.float64],
                d: NDArray[np.float64], norm_f: NDArray[np.float64] | None) -> Certificate:
    """The α-test (module docstring) from F, Σ|terms|, σ_min and κ of Df (or bounds on the
    safe side), the Newton step and ‖Df⁻¹Δ‖ of the points x at p."""
    n = x.shape[1]
    err = _evaluation_error(system, magnitude)
    with np.errstate(all="ignore"):
        solve_margin = 1.0 + 10.0 * n * kappa * UNIT_ROUNDOFF
        beta = (np.linalg.norm(step, axis=1) + np.linalg.norm(err, axis=1) / s_min) \
            * solve_margin
        norm_scaled = scaled_norm * solve_margin
        if norm_f is None:
            norm_f = _norms(system, p)
        mu = np.maximum(1.0, norm_f * norm_scaled)
        gamma = mu * d.max(initial=1.0) ** 1.5 / (2.0 * norm1)
        alpha = beta * gamma
        ok = finite & np.isfinite(alpha) & (s_min > 0)
        certified = ok & (alpha < ALPHA_0)
        gap = np.linalg.norm(x - x.conj(), axis=1)
        real_system = bool(np.all(system.coef.imag == 0)) and np.all(p.imag == 0, axis=1)
        real = certified & real_system & (alpha < ALPHA_REAL) & (gap < 1.0 / (20.0 * gamma))
        not_real = certified & real_system & (gap > 4.0 * beta)
    bad = ~ok
    alpha[bad], beta[bad], gamma[bad] = np.inf, np.inf, np.inf
    return Certificate(certified, alpha, beta, gamma, 2.0 * beta, real, not_real, x - step, F,
                       magnitude)


def distinct(x: Complex, radius: NDArray[np.float64],
             groups: NDArray[np.intp]) -> NDArray[np.intp]:
    """A label per point: points of one group whose balls (‖x_i − x_j‖∞ ≤ radius_i + radius_j,
    radius = 2β) overlap share the label of the first of them. Two certified points with
    disjoint balls are proved to be distinct zeros; overlapping ones are counted once."""
    return same_points(x, groups, 0.0, absolute=radius)

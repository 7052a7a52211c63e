"""Residuals of the generated screw and their exact first derivatives (Bagci 1969, §5.1, App. E).

R_phi(i) = psi_d0(theta_i) - s_out [phi_g(theta_i) - phi_g(0)]   (wrapped to (-pi, pi])
R_S(i)   = [S_d(theta_i) - (S_g(theta_i) - S_g(0))] / L

phi_g comes from the closed form (`rsrc_positions`) on one assembly mode; S_g from eq. 3.60 in its
chi-free form S = b cos l0 + d1 sin l0 sin th0 + e cos d0 - tan d0 W2 (SPEC §11: this keeps the
branch sign that App. E's +sqrt(d2^2 - W1^2) drops).

Derivatives (App. E by the implicit-function theorem): with G = (cos^2 d0 (W1^2 - d2^2) + W2^2)/2
(eq. 3.61, G_phi = Q5), d phi/dx = -G_x / G_phi and dS/dx = S_x + S_phi d phi/dx.  G and S are
explicit, so their partials G_x, S_x (through the derived d3, a, b of eqs. 5.19-5.21 too) are
taken by complex-step differentiation, exact to rounding — no finite differences.

Assembly mode.  Along a continuous branch Q5 keeps its sign (it vanishes only at a dead centre,
where the branch ends), so a mode is held as sigma = sign(Q5); where two roots share that sign
(four real roots) the one nearest the previous evaluation is taken.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import wrap_angle
from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_positions
from screwkit.kinematics.closed_forms.rsrc.loop_equation import RSRCDimensionArrays, loop_equation
from screwkit.synthesis.problem import RSRCSynthesisProblem

__all__ = [
    "Evaluation",
    "NotAssembled",
    "ResidualModel",
    "dimensions_of",
    "loop_residual",
    "rotation_rate_numerator",
    "translation",
]

FloatArray = NDArray[np.float64]
Array = NDArray[Any]
_STEP = 1e-30  # complex step: exact first derivatives to rounding, any step this small works


class NotAssembled(InputError):
    """The mechanism does not close (or locks) at a design point on the chosen mode."""


def _dimension_arrays(p: dict[str, Array]) -> RSRCDimensionArrays:
    """The batch of mechanisms in ``p`` (one row each) as columns (B, 1) against angles (B, N)."""
    return RSRCDimensionArrays.from_arrays(
        **{n: p[n][:, None] for n in ("d1", "d2", "d3", "a", "b", "e", "delta0", "lambda0")})


def _real_dimension_arrays(p: dict[str, Array]) -> RSRCDimensionArrays:
    """The real part of row 0 of ``p`` as one mechanism (floats)."""
    return RSRCDimensionArrays.from_arrays(
        **{n: float(np.real(p[n][0]))
           for n in ("d1", "d2", "d3", "a", "b", "e", "delta0", "lambda0")})


def loop_residual(p: dict[str, Array], theta0: Array, phi: Array) -> Array:
    """G = (cos^2 d0 (W1^2 - d2^2) + W2^2) / 2, eq. 3.61 (zero on every assembly); (B, N)."""
    return loop_equation(_dimension_arrays(p), theta0, phi).residual


def _loop_and_q5(p: dict[str, Array], theta0: FloatArray, phi: FloatArray
                 ) -> tuple[FloatArray, FloatArray]:
    """G (eq. 3.61, halved) and G_phi = Q5 = W2 M1 + cos^2 d0 W1 M2 (§3.5) at real (N,) angles."""
    eq = loop_equation(_real_dimension_arrays(p), theta0, phi)
    return eq.residual, eq.slope


def translation(p: dict[str, Array], theta0: Array, phi: Array) -> Array:
    """S = b cos l0 + d1 sin l0 sin th0 + e cos d0 - tan d0 W2 (eq. 3.60, chi-free); (B, N)."""
    w2 = loop_equation(_dimension_arrays(p), theta0, phi).w2
    lam, d0 = p["lambda0"][:, None], p["delta0"][:, None]
    return (p["b"][:, None] * np.cos(lam) + p["d1"][:, None] * np.sin(lam) * np.sin(theta0)
            + p["e"][:, None] * np.cos(d0) - np.tan(d0) * w2)


def rotation_rate_numerator(p: dict[str, Array], theta0: Array, phi: Array) -> Array:
    """Q4 = W2 L1 + cos^2 d0 W1 L2 (eq. 3.77: d phi0/d theta0 = -d1 Q4 / Q5); (B, N)."""
    eq = loop_equation(_dimension_arrays(p), theta0, phi)
    lam = p["lambda0"][:, None]
    st, ct, sp, cp = np.sin(theta0), np.cos(theta0), np.sin(phi), np.cos(phi)
    l1 = st * sp + np.cos(lam) * ct * cp
    l2 = st * cp - np.cos(lam) * ct * sp
    return eq.w2 * l1 + np.cos(p["delta0"][:, None]) ** 2 * eq.w1 * l2


def dimensions_of(p: dict[str, Array], row: int = 0) -> RSRCDimensions:
    """The real RSRCDimensions of batch row ``row``; raises ValueError if not a mechanism."""
    vals = {n: float(np.real(p[n][row])) for n in ("d1", "d2", "d3", "a", "b", "e", "delta0",
                                                    "lambda0")}
    if abs(math.cos(vals["delta0"])) < 1e-6:
        raise NotAssembled("delta0 = +-90 deg: the translation (eq. 3.60) is not defined by this "
                           "closed form; bound delta0 away from 90 deg")
    return RSRCDimensions(**vals)


@dataclass(frozen=True)
class Evaluation:
    """One evaluation at an unknown vector: configuration and residuals (and Jacobian)."""

    x: FloatArray
    params: dict[str, float]
    theta: FloatArray  # all design points (theta = 0 first)
    theta0: FloatArray
    phi: FloatArray
    S: FloatArray
    sigma: float
    residuals: FloatArray
    jacobian: FloatArray | None
    phi_jacobian: FloatArray | None = None  # (N, n) d phi_g(theta_i) / dx


class ResidualModel:
    """Residual vector r(x) and exact Jacobian for an `RSRCSynthesisProblem` on one mode.

    The mode is fixed at construction from the start: ``inversion`` (program label) at theta = 0,
    or, with parameters of constraint, the constructed configuration at theta = 0.
    """

    def __init__(self, problem: RSRCSynthesisProblem, inversion: int | None = None) -> None:
        self.problem = problem
        tgt = problem.target
        self.theta = tgt.theta_all
        idx = {float(t): i for i, t in enumerate(self.theta)}
        self.rot_idx = np.array([idx[float(t)] for t in tgt.theta_rotation], dtype=np.int64)
        self.tr_idx = np.array([idx[float(t)] for t in tgt.theta_translation], dtype=np.int64)
        self.psi_d = tgt.desired_rotation(tgt.theta_rotation)
        self.s_d = tgt.desired_translation(tgt.theta_translation)
        self.n_residuals = self.rot_idx.size + self.tr_idx.size
        self.sigma: float = 0.0
        self.phi_ref: FloatArray | None = None
        x0 = problem.start_vector()
        label = inversion if inversion is not None else problem.inversion
        self._init_mode(x0, label)

    # -- mode ------------------------------------------------------------------------------
    def _theta0(self, p: dict[str, Array]) -> Array:
        return p["theta01"][:, None] + self.problem.input_direction * self.theta[None, :]

    def _init_mode(self, x0: FloatArray, label: int | None) -> None:
        p = self.problem.parameters(x0[None, :])
        dims = dimensions_of(p)
        theta0 = np.real(self._theta0(p))[0]
        if self.problem.construction is not None:
            phi1 = float(np.real(p["phi1"][0]))
            g = loop_residual(p, theta0[:1][None, :], np.array([[phi1]]))
            scale = dims.length_scale ** 2
            if abs(float(np.real(g[0, 0]))) > 1e-8 * scale:
                raise NotAssembled("the constructed configuration does not close the loop at "
                                   "theta = 0; check the constraint points")
            q5 = self._q5(p, theta0[:1], np.array([phi1]))[0]
            self.sigma = 1.0 if q5 > 0 else -1.0
            self.phi_ref = np.full(self.theta.size, phi1)
            return
        pos = rsrc_positions(dims, theta0[:1])
        if label is None:
            label = int(np.flatnonzero(pos.assembles[0])[0]) + 1 if pos.assembles[0].any() else 1
        if not pos.assembles[0, label - 1]:
            raise NotAssembled(
                f"the start does not assemble in inversion {label} at theta01 = "
                f"{math.degrees(float(theta0[0])):.4f} deg ({int(pos.n_assemblies[0])} inversions "
                "exist there); change the start or the inversion")
        phi0 = float(pos.phi0[0, label - 1])
        q5 = self._q5(p, theta0[:1], np.array([phi0]))[0]
        self.sigma = 1.0 if q5 > 0 else -1.0
        self.phi_ref = np.full(self.theta.size, phi0)

    @staticmethod
    def _q5(p: dict[str, Array], theta0: FloatArray, phi: FloatArray) -> FloatArray:
        """G_phi = Q5 (§3.5) at real angles."""
        return _loop_and_q5(p, theta0, phi)[1]

    # -- configuration -----------------------------------------------------------------------
    def _follow(self, p: dict[str, Array], theta0: FloatArray, scale: float) -> FloatArray | None:
        """Newton on G(phi) = 0 from the previous configuration (the branch, followed).

        Returns None (then the closed form decides) unless every point converges, keeps the
        sign of Q5 and moves less than 0.5 rad: a step that large may have jumped branches.
        """
        if self.phi_ref is None:
            return None
        phi = self.phi_ref.copy()
        converged = False
        for _ in range(12):
            g, g_phi = _loop_and_q5(p, theta0, phi)
            if np.any(self.sigma * g_phi <= 1e-9 * scale):
                return None
            step = g / g_phi
            phi = phi - step
            if converged:  # one more step after 1e-10: quadratic convergence, full precision
                break
            converged = bool(np.all(np.abs(step) <= 1e-10))
        else:
            return None
        g, g_phi = _loop_and_q5(p, theta0, phi)
        if (np.any(np.abs(g) > 1e-13 * scale) or np.any(np.abs(phi - self.phi_ref) > 0.5)
                or np.any(self.sigma * g_phi <= 1e-9 * scale)):
            return None
        return phi

    def configuration(self, x: FloatArray) -> tuple[dict[str, Array], FloatArray, FloatArray]:
        """(parameters, theta0, phi) on the mode at every design point; raises NotAssembled.

        The configuration is followed from the previous one by Newton's method on the loop
        equation (fast, and it stays on the branch); where that does not converge cleanly the
        closed form (`rsrc_positions`) is solved and the root of the mode taken.
        """
        p = self.problem.parameters(np.asarray(x, dtype=np.float64)[None, :])
        dims = dimensions_of(p)
        theta0 = np.real(self._theta0(p))[0]
        followed = self._follow(p, theta0, dims.length_scale ** 2)
        if followed is not None:
            return p, theta0, followed
        pos = rsrc_positions(dims, theta0)
        cand = pos.assembles.copy()
        phis = np.where(cand, pos.phi0, 0.0)
        q5 = self._q5(p, np.repeat(theta0, 4), phis.reshape(-1)).reshape(-1, 4)
        scale = dims.length_scale ** 2
        cand &= self.sigma * q5 > 1e-9 * scale
        if not cand.any(axis=1).all():
            bad = int(np.flatnonzero(~cand.any(axis=1))[0])
            raise NotAssembled(
                f"no assembly on the chosen mode at theta = "
                f"{math.degrees(float(self.theta[bad])):.4f} deg (theta0 = "
                f"{math.degrees(float(theta0[bad])):.4f} deg)")
        ref = self.phi_ref if self.phi_ref is not None else phis[:, 0]
        dist = np.where(cand, np.abs(wrap_angle(phis - ref[:, None])), np.inf)
        col = np.argmin(dist, axis=1)
        phi = phis[np.arange(theta0.size), col]
        return p, theta0, phi

    def evaluate(self, x: FloatArray, *, jacobian: bool = True, remember: bool = True) -> Evaluation:
        """Residuals (and the exact Jacobian) at x; raises NotAssembled off the mode."""
        x = np.asarray(x, dtype=np.float64)
        p, theta0, phi = self.configuration(x)
        s = np.real(translation(p, theta0[None, :], phi[None, :]))[0]
        pr = self.problem
        r_phi = wrap_angle(self.psi_d - pr.output_direction * (phi[self.rot_idx] - phi[0]))
        r_s = (self.s_d - (s[self.tr_idx] - s[0])) / pr.length_scale
        residuals = np.concatenate([r_phi, r_s])
        jac = None
        dphi_out = None
        if jacobian:
            n = x.size
            xc = x[None, :] + 1j * _STEP * np.eye(n)
            pc = pr.parameters(xc)
            th0c = self._theta0(pc)
            g_x = np.imag(loop_residual(pc, th0c, phi[None, :])) / _STEP  # (n, N)
            s_x = np.imag(translation(pc, th0c, phi[None, :])) / _STEP
            g_phi = self._q5(p, theta0, phi)
            s_phi = np.imag(translation(p, theta0[None, :], phi[None, :] + 1j * _STEP))[0] / _STEP
            dphi = -g_x / g_phi[None, :]  # (n, N)
            ds = s_x + s_phi[None, :] * dphi
            j_phi = -pr.output_direction * (dphi[:, self.rot_idx] - dphi[:, :1]).T
            j_s = -(ds[:, self.tr_idx] - ds[:, :1]).T / pr.length_scale
            jac = np.vstack([j_phi, j_s])
            dphi_out = dphi.T
        if remember:
            self.phi_ref = phi
        params = {k: float(np.real(v[0])) for k, v in p.items()}
        return Evaluation(x, params, self.theta, theta0, phi, s, self.sigma, residuals, jac,
                          dphi_out)

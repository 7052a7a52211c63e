"""Dual Euler angles z–x–z (Bagci 1969, eqs. 2.12–2.16; SPEC §2.5, verified convention).

T̂_R = Z(φ̂) X(θ̂) Z(ψ̂): dual angle φ̂ about Z, then θ̂ about the new X′, then ψ̂ about the new
Z″ (intrinsic). The Bagci text at L427 swaps the x and z roles; the verified convention is φ, ψ
about z and θ about x. For a body displaced to (X01, Y01, Z01) with real angles φ0, θ0, ψ0,
T̂_L T_R = T̂_R gives (eqs. 2.14–2.16)

    θ1 = X01 cos φ0 + Y01 sin φ0
    ψ1 = (X01 sin φ0 − Y01 cos φ0) / sin θ0
    φ1 = Z01 − ψ1 cos θ0

Degenerate rule (θ0 = 0 or π, where Z and Z″ are the same line and only φ ± ψ is defined):
the node line (the θ̂ axis) must carry the in-plane translation, so
* φ0 = atan2(Y01, X01) when (X01, Y01) ≠ 0 (then θ1 = |(X01, Y01)| ≥ 0); otherwise ψ0 = 0 and
  φ0 takes the whole z-rotation;
* ψ0 follows from φ0 + ψ0 (θ0 = 0) or φ0 − ψ0 (θ0 = π);
* the whole translation along z goes to φ̂: φ1 = Z01, ψ1 = 0 (Bagci: φ1 + ψ1 = Z01 at θ0 = 0,
  φ1 − ψ1 = Z01 at θ0 = π).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from screwkit.dual.number import Dual
from screwkit.dual.screw_matrix import ScrewMatrix
from screwkit.dual.spatial import wrap_angle

#: sin θ0 below this counts as the degenerate case θ0 = 0 or π. Above it the general formulas
#: are used; they reconstruct the displacement to rounding even for small sin θ0.
DEFAULT_SINGULAR_TOL = 1e-12


@dataclass(frozen=True, eq=False)
class DualEulerAngles:
    """Dual z–x–z Euler angles φ̂, θ̂, ψ̂ (each a :class:`Dual` of the batch shape); θ0 ∈ [0, π],
    φ0, ψ0 ∈ (−π, π]."""

    phi: Dual
    theta: Dual
    psi: Dual

    def as_screw_matrix(self) -> ScrewMatrix:
        """T̂_R = Z(φ̂) X(θ̂) Z(ψ̂) (Bagci eq. 2.12)."""
        return screw_matrix_from_dual_euler(self.phi, self.theta, self.psi)


def screw_matrix_from_dual_euler(phi: Dual, theta: Dual, psi: Dual) -> ScrewMatrix:
    """T̂_R = Z(φ̂) X(θ̂) Z(ψ̂) (Bagci eq. 2.12, z–x–z, intrinsic)."""
    return ScrewMatrix.rot_z(phi) @ ScrewMatrix.rot_x(theta) @ ScrewMatrix.rot_z(psi)


def dual_euler_from_screw_matrix(
    screw: ScrewMatrix, singular_tol: float = DEFAULT_SINGULAR_TOL
) -> DualEulerAngles:
    """Dual z–x–z Euler angles of a proper screw matrix (Bagci eqs. 2.12–2.16; degenerate
    rule in the module docstring).

    Real parts from R = Z(φ0)X(θ0)Z(ψ0): θ0 = atan2(√(R13² + R23²), R33),
    φ0 = atan2(R13, −R23), ψ0 = atan2(R31, R32). Dual parts from eqs. 2.14–2.16 with
    (X01, Y01, Z01) = d, the translation recovered by transference.
    """
    from screwkit.dual.checks import check_screw_matrix_parts

    R, _ = check_screw_matrix_parts(screw.real, screw.dual)
    X, Y, Z = np.moveaxis(screw.translation, -1, 0)
    sin_t = np.hypot(R[..., 0, 2], R[..., 1, 2])
    theta0 = np.arctan2(sin_t, R[..., 2, 2])
    singular = sin_t < singular_tol
    near_zero = singular & (R[..., 2, 2] > 0)

    # General case.
    phi0 = np.arctan2(R[..., 0, 2], -R[..., 1, 2])
    psi0 = np.arctan2(R[..., 2, 0], R[..., 2, 1])

    # Degenerate case: R = Z(γ) (θ0 = 0) or Z(γ)X(π) (θ0 = π), γ = φ0 ± ψ0.
    gamma = np.arctan2(R[..., 1, 0], R[..., 0, 0])
    in_plane = np.hypot(X, Y) > 0
    phi0_s = np.where(in_plane, np.arctan2(Y, X), gamma)
    psi0_s = np.where(near_zero, gamma - phi0_s, phi0_s - gamma)
    theta0 = np.where(singular, np.where(near_zero, 0.0, np.pi), theta0)
    phi0 = np.where(singular, phi0_s, phi0)
    psi0 = wrap_angle(np.where(singular, psi0_s, psi0))

    cf, sf = np.cos(phi0), np.sin(phi0)
    theta1 = X * cf + Y * sf
    safe_sin = np.where(singular, 1.0, np.sin(theta0))
    psi1 = np.where(singular, 0.0, (X * sf - Y * cf) / safe_sin)
    phi1 = Z - psi1 * np.cos(theta0)
    return DualEulerAngles(Dual(phi0, phi1), Dual(theta0, theta1), Dual(psi0, psi1))


__all__ = [
    "DEFAULT_SINGULAR_TOL",
    "DualEulerAngles",
    "dual_euler_from_screw_matrix",
    "screw_matrix_from_dual_euler",
]

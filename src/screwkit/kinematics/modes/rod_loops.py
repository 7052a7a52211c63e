"""The RSSR and RSRC loops at one input value as small polynomial systems.

Both are driven at a ground R joint, so the crank's ball centre P is known; the output body turns
(and, for the C joint, slides) about its ground axis (c, w). A rotation by φ about w is linear
in (cos φ, sin φ): Rot(v) = (w·v) w + cos φ (v − (w·v) w) + sin φ (w × v), so with the circle
cos²φ + sin²φ = 1 the closures are (derivations in docs/kinematics.md, "Closures as polynomials"):

- RSSR (the S–S rod of length L): ‖P − Q(φ)‖² = L², Q(φ) the output ball centre; since
  ‖Rot(v) − (w·v)w‖² = ‖v − (w·v)w‖², the quadratic terms in (cos φ, sin φ) are the circle's,
  which leaves h − α cos φ − β sin φ = 0: 2 solutions (Bagci 1971's RSSR displacement equation
  in another form).
- RSRC (the coupler's R line at distance ρ from P and P at axial offset κ along it, the output
  sliding s along w): (P − r)·a = κ (linear in cos φ, sin φ, s) and ‖P − r‖² = ρ² + κ²
  (quadratic: s² plus terms linear in cos φ, sin φ, s), r and a the R line at (φ, s):
  4 solutions, the roots of the RSRC quartic (Bagci 1969).

The parameters are the equations' coefficients (α, β, h; μ0..μ3, ν0..ν3), free, so every real
instance is a generic member. The way back builds every body's pose and each joint's value (the
S joints' rotations from the bodies' poses) for the graph tracker's checks.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.graph.closure import GraphLayout, graph_layout
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]


def rotation(w: Array, angle: ArrayLike) -> Array:
    """Rotations (N, 3, 3) by ``angle`` (N,) about the unit axis w (Rodrigues)."""
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    a = np.asarray(angle, dtype=float)
    return (np.eye(3) + np.multiply.outer(np.sin(a), K)
            + np.multiply.outer(1.0 - np.cos(a), K @ K))


def _split(w: Array, v: ArrayLike) -> tuple[Array, Array, Array]:
    """Rot_w(φ) v = A + cos φ B + sin φ C (module docstring)."""
    v = np.asarray(v, dtype=float)
    A = np.multiply.outer(v @ w, w)
    return A, v - A, np.cross(w, v)


@lru_cache(maxsize=1)
def rssr_system() -> PolynomialSystem:
    """cos φ, sin φ; parameters α, β, h: c² + s² = 1, h − α c − β s = 0."""
    c, s, al, be, h = (Poly.variable(i) for i in range(5))
    return compile_system([c * c + s * s - 1.0, h - al * c - be * s], ("cos_phi", "sin_phi"),
                          ("alpha", "beta", "h"))


@lru_cache(maxsize=1)
def rsrc_system() -> PolynomialSystem:
    """cos φ, sin φ, s; parameters μ0..μ3, ν0..ν3 (module docstring)."""
    c, s, d, m0, m1, m2, m3, n0, n1, n2, n3 = (Poly.variable(i) for i in range(11))
    eqs = [c * c + s * s - 1.0, m0 + m1 * c + m2 * s + m3 * d,
           d * d + n1 * d + n2 * c + n3 * s + n0]
    return compile_system(eqs, ("cos_phi", "sin_phi", "slide"),
                          ("mu0", "mu1", "mu2", "mu3", "nu0", "nu1", "nu2", "nu3"))


def walk_loop(mech: Mechanism, kinds: str) -> list[tuple[int, bool]]:
    """The loop's joints from the driven ground joint, each with whether the walk runs from
    its first body to its second."""
    name = f"{kinds[0]}{kinds[1:]}"
    if (len(mech.topology.loops) != 1 or len(mech.joints) != len(kinds)
            or len(mech.inputs) != 1):
        raise CapabilityError(f"{mech.name}: the {name} formulation takes a single {name} loop "
                              "with one input")
    k = [i for i, j in enumerate(mech.joints) if f"{j.name}.theta" == mech.inputs[0]]
    if not k or GROUND not in mech.joints[k[0]].bodies:
        raise CapabilityError(f"{mech.name}: the {name} formulation needs the input at a "
                              "ground R joint")
    out, body, i = [], GROUND, k[0]
    for _ in kinds:
        j = mech.joints[i]
        forward = j.bodies[0] == body
        out.append((i, forward))
        body = j.bodies[1] if forward else j.bodies[0]
        i = next((m for m, jm in enumerate(mech.joints) if body in jm.bodies and m != i), -1)
    if [mech.joints[i].kind for i, _ in out] != list(kinds) or body != GROUND:
        raise CapabilityError(f"{mech.name}: the loop's joints from the input are "
                              f"{[mech.joints[i].kind for i, _ in out]}, not a {name}")
    return out


@dataclass(frozen=True)
class RodLoop:
    """An RSSR or RSRC mechanism as its small system: the loop walked from the input
    (joint index, forward) and the system for its kind."""

    mechanism: Mechanism
    kind: str
    walk: tuple[tuple[int, bool], ...]
    system: PolynomialSystem

    def _axis(self, step: int) -> tuple[Array, Array]:
        """Joint ``step``'s point and its axis oriented so the next body turns positively."""
        k, forward = self.walk[step]
        j = self.mechanism.joints[k]
        return j.at, (j.axis if forward else -j.axis)

    def _crank(self, q: Array) -> tuple[Array, Array]:
        c, w = self._axis(0)
        R = rotation(w, q)
        return R, c - R @ c

    def _output(self, phi: Array, slide: Array) -> tuple[Array, Array]:
        c, w = self._axis(len(self.walk) - 1)
        w = -w  # the output turns relative to the ground about the last joint, walked back
        R = rotation(w, phi)
        return R, c - R @ c + np.multiply.outer(slide, w)

    def parameters(self, input_values: ArrayLike) -> Array:
        """The system's parameters (N, k) at input values (N,) (radians from the drawing)."""
        q = np.atleast_1d(np.asarray(input_values, dtype=float)).reshape(-1)
        Rc, pc = self._crank(q)
        ball = self.mechanism.joints[self.walk[1][0]].at
        D = Rc @ ball + pc - self._axis(len(self.walk) - 1)[0]
        c, w = self._axis(len(self.walk) - 1)
        w = -w
        if self.kind == "RSSR":
            v = self.mechanism.joints[self.walk[2][0]].at - c
            A, B, C = _split(w, v)
            L2 = float(np.sum((self.mechanism.joints[self.walk[2][0]].at - ball) ** 2))
            Dm = D - A
            return np.stack([2 * Dm @ B, 2 * Dm @ C, np.sum(Dm * Dm, -1) + B @ B - L2], -1)
        r0, a0 = (self.mechanism.joints[self.walk[2][0]].at,
                  self.mechanism.joints[self.walk[2][0]].axis)
        e = r0 - c
        kappa = float((ball - r0) @ a0)
        rk2 = float((ball - r0) @ (ball - r0))
        Aa, Ba, Ca = _split(w, a0)
        Ae, Be, Ce = _split(w, e)
        N = D.shape[0]
        return np.stack([D @ Aa - e @ a0 - kappa, D @ Ba, D @ Ca, np.full(N, -(w @ a0)),
                         np.sum(D * D, -1) + e @ e - rk2 - 2 * D @ Ae,
                         -2 * D @ w + 2 * (w @ e), -2 * D @ Be, -2 * D @ Ce], -1)

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """The graph tracker's configurations (N) of real solutions (N, n) at the inputs."""
        sol = np.real(np.asarray(solutions))
        N = sol.shape[0]
        q = np.broadcast_to(np.asarray(input_values, dtype=float).reshape(-1), (N,))
        phi = np.arctan2(sol[:, 1], sol[:, 0])
        slide = sol[:, 2] if self.kind == "RSRC" else np.zeros(N)
        pose = {GROUND: (np.broadcast_to(np.eye(3), (N, 3, 3)), np.zeros((N, 3)))}
        mech, walk = self.mechanism, self.walk
        bodies = [GROUND]
        for k, forward in walk[:-1]:
            bodies.append(mech.joints[k].bodies[1 if forward else 0])
        pose[bodies[1]] = self._crank(q)
        pose[bodies[-1]] = self._output(phi, slide)
        ball = mech.joints[walk[1][0]].at
        P = np.einsum("nij,j->ni", pose[bodies[1]][0], ball) + pose[bodies[1]][1]
        if self.kind == "RSSR":  # the rod: the least rotation from its drawn direction
            Q0 = mech.joints[walk[2][0]].at
            Q = np.einsum("nij,j->ni", pose[bodies[3]][0], Q0) + pose[bodies[3]][1]
            R = least_rotation(Q0 - ball, Q - P)
        else:  # the coupler turns about its R line on the output until it carries the ball
            r0, a0 = mech.joints[walk[2][0]].at, mech.joints[walk[2][0]].axis
            Ro, po = pose[bodies[3]]
            local = np.einsum("nji,nj->ni", Ro, P - po)  # the ball in the output's drawing
            u0 = (ball - r0) - ((ball - r0) @ a0) * a0
            u1 = (local - r0) - np.multiply.outer((local - r0) @ a0, a0)
            psi = np.arctan2(np.cross(u0, u1) @ a0, u1 @ u0)
            Rp = rotation(a0, psi)
            pose[bodies[2]] = (Ro @ Rp, np.einsum("nij,nj->ni", Ro, r0 - Rp @ r0) + po)
        if self.kind == "RSSR":
            pose[bodies[2]] = (R, P - np.einsum("nij,j->ni", R, ball))
        return _joint_values(mech, pose, q, phi, slide, walk), graph_layout(mech)


def least_rotation(d0: Array, d: Array) -> Array:
    """The rotations (N, 3, 3) turning d0 (3,) or (N, 3) onto d (N, 3) about d0 × d (equal
    lengths). Where d is d0 reversed, the half turn about an axis square to d0 (the identity
    would not turn d0 onto d)."""
    u = np.broadcast_to(d0 / np.linalg.norm(d0, axis=-1, keepdims=True), np.shape(d))
    v = d / np.linalg.norm(d, axis=-1)[:, None]
    axis = np.cross(u, v)
    s = np.linalg.norm(axis, axis=-1)
    cosine = np.einsum("ni,ni->n", u, v)
    reversed_ = (s <= 1e-15) & (cosine < 0.0)
    if reversed_.any():  # any axis square to u: u × (the world axis least along u)
        ur = u[reversed_]
        pick = np.eye(3)[np.argmin(np.abs(ur), axis=1)]
        axis[reversed_] = np.cross(ur, pick)
        s = np.where(reversed_, 0.0, s)
    size = np.linalg.norm(axis, axis=-1)
    axis = axis / np.maximum(size, 1e-300)[:, None]
    angle = np.arctan2(s, cosine)
    K = np.zeros((len(d), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    return np.asarray(np.eye(3) + np.sin(angle)[:, None, None] * K
                      + (1 - np.cos(angle))[:, None, None] * (K @ K))


def _joint_values(mech: Mechanism, pose: dict[str, tuple[Array, Array]], q: Array, phi: Array,
                  slide: Array, walk: tuple[tuple[int, bool], ...]) -> Configuration:
    lay = graph_layout(mech)
    N = q.shape[0]
    scalars = np.zeros((N, lay.n_scalar))
    spherical = np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)).copy()
    last = walk[-1][0]
    for k, j in enumerate(mech.joints):
        f = lay.first_freedom[k]
        Ra, Rb = pose[j.bodies[0]][0], pose[j.bodies[1]][0]
        if j.kind == "S":
            spherical[:, lay.spherical_of_joint[k]] = np.swapaxes(Ra, 1, 2) @ Rb
            continue
        if k == walk[0][0]:
            value = q
        elif k == last:
            value = phi
        else:  # the coupler's R joint: the angle of Ra⁻¹Rb about its axis
            rel = np.swapaxes(Ra, 1, 2) @ Rb
            K = np.array([[0.0, -j.axis[2], j.axis[1]], [j.axis[2], 0.0, -j.axis[0]],
                          [-j.axis[1], j.axis[0], 0.0]])
            # rel = I + sin ψ K + (1 − cos ψ) K²: Σ rel ⊙ K = 2 sin ψ, tr rel = 1 + 2 cos ψ
            value = np.arctan2(np.einsum("nij,ij->n", rel, K) / 2,
                               (np.trace(rel, axis1=1, axis2=2) - 1) / 2)
        scalars[:, lay.scalar_col[f]] = value
        if j.kind == "C":
            scalars[:, lay.scalar_col[f + 1]] = slide
    return Configuration(scalars, spherical)


def rod_loop(mech: Mechanism) -> RodLoop:
    """The RSSR or RSRC system of ``mech`` (a single loop driven at a ground R joint)."""
    kinds = "".join(sorted(j.kind for j in mech.joints))
    if kinds == "RRSS":
        return RodLoop(mech, "RSSR", tuple(walk_loop(mech, "RSSR")), rssr_system())
    if kinds == "CRRS":
        return RodLoop(mech, "RSRC", tuple(walk_loop(mech, "RSRC")), rsrc_system())
    raise InputError(f"{mech.name}: joints {[j.kind for j in mech.joints]} are neither an RSSR "
                     "nor an RSRC loop")

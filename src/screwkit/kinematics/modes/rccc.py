"""The RCCC loop at one input value in Plücker coordinates: 2 solutions.

Driven at its ground R joint, the loop's C2 line (on the crank) and C4 line (on the ground) are
known; what is unknown is the line of C3, as its unit direction z and moment m (Plücker
coordinates: m = c × z for a point c on it). Link 2 keeps the angle and the distance between
the C2 and C3 lines, link 3 between C3 and C4: for two lines (z_a, m_a), (z_b, m_b) the cosine
z_a·z_b and the mutual moment z_a·m_b + z_b·m_a = −d sin α are invariant under rigid motion
(the mutual moment of two lines; Hunt, *Kinematic Geometry of Mechanisms*, 1978). So

    z·z = 1,  z·m = 0,  z₂·z = cos α₂,  z₄·z = cos α₃,
    z₂·m + m₂·z = μ₂,  z₄·m + m₄·z = μ₃

Two linear equations in z and the unit sphere give two directions, and for each the moment
follows linearly: 2 solutions, the closed form's two modes (Bagci 1971's RCCC). The slides are
not unknowns, so roots at slides far from the drawing (a small twist α₂ puts them at many link
lengths) are as easy as any. The parameters (the two known lines, the cosines and the mutual
moments: 16) are free. The way back places each moving link by its two lines (the frame of
their common normal) and reads every joint's angle and slide.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.kinematics.graph.closure import GraphLayout, graph_layout
from screwkit.kinematics.modes.rod_loops import rotation, walk_loop
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]


@lru_cache(maxsize=1)
def rccc_system() -> PolynomialSystem:
    """Unknowns z, m of the C3 line; parameters z2, m2, z4, m4, cos α2, cos α3, μ2, μ3."""
    s = [Poly.variable(i) for i in range(6 + 16)]
    z, m = s[0:3], s[3:6]
    z2, m2, z4, m4 = s[6:9], s[9:12], s[12:15], s[15:18]
    c2, c3, mu2, mu3 = s[18:22]

    def dot(a: list[Poly], b: list[Poly]) -> Poly:
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

    eqs = [dot(z, z) - 1.0, dot(z, m), dot(z2, z) - c2, dot(z4, z) - c3,
           dot(z2, m) + dot(m2, z) - mu2, dot(z4, m) + dot(m4, z) - mu3]
    names = [f"{w}_{c}" for w in ("z2", "m2", "z4", "m4") for c in "xyz"]
    return compile_system(eqs, [f"{w}_{c}" for w in "zm" for c in "xyz"],
                          [*names, "cos_alpha2", "cos_alpha3", "mu2", "mu3"])


def _plucker(point: Array, direction: Array) -> tuple[Array, Array]:
    return direction, np.cross(point, direction)


def _frame(za: Array, ca: Array, zb: Array, cb: Array) -> tuple[Array, Array]:
    """The frame (R (N, 3, 3), origin (N, 3)) of two lines: origin at the foot of their common
    normal on the first, z along the first, x along z_a × z_b."""
    c = np.einsum("ni,ni->n", za, zb)
    d = cb - ca
    foot = np.einsum("ni,ni->n", d, za) - np.einsum("ni,ni->n", d, zb) * c
    origin = ca + (foot / (1.0 - c * c))[:, None] * za
    x = np.cross(za, zb)
    x = x / np.linalg.norm(x, axis=1)[:, None]
    return np.stack([x, np.cross(za, x), za], axis=-1), origin


@dataclass(frozen=True)
class RCCCLoop:
    """An RCCC mechanism (a single loop driven at a ground R joint) as its system."""

    mechanism: Mechanism
    walk: tuple[tuple[int, bool], ...]
    system: PolynomialSystem

    def _line(self, step: int) -> tuple[Array, Array]:
        k, forward = self.walk[step]
        j = self.mechanism.joints[k]
        return j.at, (j.axis if forward else -j.axis)

    def _crank(self, q: Array) -> tuple[Array, Array]:
        c, w = self._line(0)
        R = rotation(w, q)
        return R, c - R @ c

    def parameters(self, input_values: ArrayLike) -> Array:
        """The parameters (N, 16) at input values (N,) (radians from the drawing)."""
        q = np.atleast_1d(np.asarray(input_values, dtype=float)).reshape(-1)
        R, p = self._crank(q)
        (c2, u2), (c3, u3), (c4, u4) = self._line(1), self._line(2), self._line(3)
        z2, m2 = _plucker(R @ c2 + p, R @ u2)
        z4, m4 = _plucker(c4, u4)
        _, m3 = _plucker(c3, u3)
        N = len(q)
        const = [u2 @ u3, u3 @ u4, u2 @ m3 + u3 @ np.cross(c2, u2),
                 u4 @ m3 + u3 @ np.cross(c4, u4)]
        return np.concatenate([z2, m2, np.tile(z4, (N, 1)), np.tile(m4, (N, 1)),
                               np.tile(const, (N, 1))], axis=1)

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """The graph tracker's configurations (N) of real solutions (N, 6) at the inputs."""
        sol = np.real(np.asarray(solutions))
        N = sol.shape[0]
        q = np.broadcast_to(np.asarray(input_values, dtype=float).reshape(-1), (N,))
        z, m = sol[:, :3], sol[:, 3:]
        c3 = np.cross(z, m) / np.einsum("ni,ni->n", z, z)[:, None]
        R1, p1 = self._crank(q)
        lines = [self._line(i) for i in range(4)]
        now = {1: (np.einsum("nij,j->ni", R1, lines[1][0]) + p1, R1 @ lines[1][1]),
               2: (c3, z), 3: (np.tile(lines[3][0], (N, 1)), np.tile(lines[3][1], (N, 1)))}
        bodies = [GROUND]
        for k, forward in self.walk[:-1]:
            bodies.append(self.mechanism.joints[k].bodies[1 if forward else 0])
        pose = {GROUND: (np.broadcast_to(np.eye(3), (N, 3, 3)), np.zeros((N, 3))),
                bodies[1]: (R1, p1)}
        for link in (2, 3):  # link i carries lines i−1 and i of the walk (joints 1..3)
            a, b = link - 1, link
            Fd, od = _frame(*(np.tile(v, (N, 1)) for v in (lines[a][1], lines[a][0],
                                                            lines[b][1], lines[b][0])))
            Fn, on = _frame(now[a][1], now[a][0], now[b][1], now[b][0])
            R = Fn @ np.swapaxes(Fd, 1, 2)
            pose[bodies[link]] = (R, on - np.einsum("nij,nj->ni", R, od))
        return _joint_values(self.mechanism, pose), graph_layout(self.mechanism)


def _joint_values(mech: Mechanism, pose: dict[str, tuple[Array, Array]]) -> Configuration:
    """Every joint's angle (and slide) from its two bodies' poses: T_a⁻¹ T_b = M_j(θ, s)."""
    lay = graph_layout(mech)
    N = next(iter(pose.values()))[0].shape[0]
    scalars = np.zeros((N, lay.n_scalar))
    for k, j in enumerate(mech.joints):
        (Ra, pa), (Rb, pb) = pose[j.bodies[0]], pose[j.bodies[1]]
        rel = np.swapaxes(Ra, 1, 2) @ Rb
        rel_p = np.einsum("nji,nj->ni", Ra, pb - pa)
        u = j.axis
        K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
        f = lay.first_freedom[k]
        scalars[:, lay.scalar_col[f]] = np.arctan2(np.einsum("nij,ij->n", rel, K) / 2,
                                                   (np.trace(rel, axis1=1, axis2=2) - 1) / 2)
        if j.kind == "C":  # the slide: what is left of the offset after the turn about c
            scalars[:, lay.scalar_col[f + 1]] = (rel_p - (j.at - rel @ j.at)) @ u
    return Configuration(scalars, np.zeros((N, 0, 3, 3)))


def rccc_loop(mech: Mechanism) -> RCCCLoop:
    """The RCCC system of ``mech``: a single R–C–C–C loop driven at its ground R joint."""
    walk = walk_loop(mech, "RCCC")
    return RCCCLoop(mech, tuple(walk), rccc_system())

"""A single loop of R, P and C joints with six free freedoms as quadrics in its joint axes
(issue 27): the axes formulation of :mod:`.loop6r` with slides and fixed joint angles.

The free joints j = 0..n−1 are taken round the loop in the Denavit–Hartenberg form of
:mod:`.general_loop_system` (∏_j Z_j(q_j) Rz(φ_j) Tz(b_j) Tx(a_j) Rx(α_j) = I), in the frame
of joint 0 before its motion. With z_j the unit axis of joint j, link j keeps
z_j·z_{j+1} = cos α_j and its common normal a_j x_j = k_j z_j × z_{j+1} (k_j = a_j / sin α_j);
the last link (joint n−1 → joint 0) is the ground, so z_0, z_{n−1} and x_{n−1} are known. Joint
j keeps the distance s_j along z_j between the feet of x_{j−1} and x_j: a parameter b_j of an R
joint, an unknown d_j of a P or C joint. The loop closes when

    g + Σ_{j=0..n−2} k_j z_j × z_{j+1} + Σ_{R, 0<j<n−1} b_j z_j + Σ_{P, C} d_j z_j = 0,
    g = a_{n−1} x_{n−1} + (b_0 z_0, b_{n−1} z_{n−1} where those joints are R)

(the loop equation of Duffy 1980, ch. 2, as in :mod:`.loop6r`). A P joint's angle θ_j (from
x_{j−1} to x_j about z_j) is fixed: with z_j·z_j = 1,
(z_{j−1} × z_j)·(z_j × z_{j+1}) = cos α_{j−1} cos α_j − z_{j−1}·z_{j+1}, so

    z_{j−1}·z_{j+1} = cos α_{j−1} cos α_j − sin α_{j−1} sin α_j cos θ_j       (a quadric),

which fixes θ_j up to its sign: the system's solutions are the loop's and those of its mirrors
(θ_j → −θ_j at some P joints). :func:`mirrored` tells them apart by the sign of
det(z_{j−1}, z_j, z_{j+1}) = sin α_{j−1} sin α_j sin θ_j (the target ``v_j`` is a parameter
that no equation uses). Unknowns: the moving axes z_1..z_{n−2} and the slides d_j; equations:
n−2 unit axes, n−1 link angles, one per P joint and the closure (3). It is square exactly when
#R + #P + 2·#C = 6 (n + #C = 6). Every equation has degree ≤ 2, so the dense compiled tracker
runs it (algebraic/quadrics.py). The parameters (the axes z_0 and z_{n−1}, cos α_0..n−2,
k_0..n−2, b_j, the P targets c_j and v_j, g) are free: any complex values are an instance.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.errors import CapabilityError
from screwkit.kinematics.modes.general_loop_system import (
    SLIDES,
    TURNS,
    freedom_count,
    loop_layout,
    loop_transforms,
    pair_angle,
)

Complex = NDArray[np.complex128]
#: |sin α| of a moving link below this (relative): the link's axes are parallel and k = a/sin α
#: has no finite value; the formulation refuses the loop (CapabilityError)
PARALLEL = 1e-6


@dataclass(frozen=True)
class QuadricLayout:
    """Where each symbol of the system is. Unknowns: z_j at ``axis[j]`` (3 columns; −1 for the
    ground axes j = 0, n−1), slide d_j at ``slide[j]`` (or −1). Parameters (indices into p):
    ``z0``, ``zl`` (3 each), ``cos_a[j]`` and ``k[j]`` (j < n−1), ``b[j]`` (moving R joints,
    else −1), ``c[j]`` and ``v[j]`` (P joints, else −1), ``g`` (3)."""

    kinds: str
    axis: tuple[int, ...]
    slide: tuple[int, ...]
    z0: int
    zl: int
    cos_a: tuple[int, ...]
    k: tuple[int, ...]
    b: tuple[int, ...]
    c: tuple[int, ...]
    v: tuple[int, ...]
    g: int
    n_unknowns: int
    n_parameters: int


def quadric_layout(kinds: str) -> QuadricLayout:
    """The layout of the system of free joints ``kinds`` (module docstring)."""
    if set(kinds) - set(TURNS) or freedom_count(kinds) != 6 or len(kinds) < 3:
        raise CapabilityError(f"the R/P/C loop formulation takes free R, P and C joints with "
                              f"six freedoms in all; got {kinds!r}")
    n = len(kinds)
    axis = tuple(-1 if j in (0, n - 1) else 3 * (j - 1) for j in range(n))
    col, slide = 3 * (n - 2), []
    for kind in kinds:
        slide.append(col if SLIDES[kind] else -1)
        col += 1 if SLIDES[kind] else 0
    cos_a = tuple(6 + j for j in range(n - 1))
    k = tuple(6 + n - 1 + j for j in range(n - 1))
    p = 6 + 2 * (n - 1)
    b, c, v = [], [], []
    for j, kind in enumerate(kinds):
        b.append(p if kind == "R" and 0 < j < n - 1 else -1)
        p += 1 if b[-1] >= 0 else 0
    for kind in kinds:
        c.append(p if kind == "P" else -1)
        v.append(p + 1 if kind == "P" else -1)
        p += 2 if kind == "P" else 0
    return QuadricLayout(kinds, axis, tuple(slide), 0, 3, cos_a, k, tuple(b), tuple(c),
                         tuple(v), p, col, p + 3)


def _cross(a: list[Poly], b: list[Poly]) -> list[Poly]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a: list[Poly], b: list[Poly]) -> Poly:
    return sum((a[r] * b[r] for r in range(3)), Poly())


@lru_cache(maxsize=32)
def rpc_system(kinds: str) -> PolynomialSystem:
    """The compiled system of free joints ``kinds`` (module docstring)."""
    lay = quadric_layout(kinds)
    n, nu = len(kinds), lay.n_unknowns
    s = [Poly.variable(i) for i in range(nu + lay.n_parameters)]

    def par(i: int) -> Poly:
        return s[nu + i]

    z = [[par(lay.z0 + r) for r in range(3)] if j == 0 else
         [par(lay.zl + r) for r in range(3)] if j == n - 1 else
         s[lay.axis[j]: lay.axis[j] + 3] for j in range(n)]
    eqs = [_dot(z[j], z[j]) - 1.0 for j in range(1, n - 1)]
    eqs += [_dot(z[j], z[j + 1]) - par(lay.cos_a[j]) for j in range(n - 1)]
    eqs += [_dot(z[j - 1], z[(j + 1) % n]) - par(lay.c[j]) for j in range(n) if lay.c[j] >= 0]
    for r in range(3):
        e = par(lay.g + r)
        for j in range(n - 1):
            e = e + par(lay.k[j]) * _cross(z[j], z[j + 1])[r]
        for j in range(n):
            if lay.b[j] >= 0:
                e = e + par(lay.b[j]) * z[j][r]
            if lay.slide[j] >= 0:
                e = e + s[lay.slide[j]] * z[j][r]
        eqs.append(e)
    names = [f"z{j}_{c}" for j in range(1, n - 1) for c in "xyz"]
    names += [f"d{j}" for j in range(n) if lay.slide[j] >= 0]
    params = [f"z0_{c}" for c in "xyz"] + [f"z{n - 1}_{c}" for c in "xyz"]
    params += [f"cos_alpha{j}" for j in range(n - 1)] + [f"k{j}" for j in range(n - 1)]
    params += [f"b{j}" for j in range(n) if lay.b[j] >= 0]
    params += [f"{name}{j}" for j in range(n) if lay.c[j] >= 0 for name in ("c", "v")]
    params += [f"g_{c}" for c in "xyz"]
    return compile_system(eqs, names, params)


def _dh(kinds: str, p_dh: Complex) -> dict[str, Complex]:
    """The Denavit–Hartenberg values of rows of :mod:`.general_loop_system` parameters (B, k):
    cos α, sin α, a (B, n), b (B, n; 0 where not a parameter), cos φ, sin φ (B, n; 1, 0 where
    not a parameter)."""
    g = loop_layout(kinds)
    nu, B, n = g.n_unknowns, p_dh.shape[0], len(kinds)
    out = {key: np.zeros((B, n), dtype=complex) for key in ("ca", "sa", "a", "b", "cp", "sp")}
    out["cp"][:] = 1.0
    for j in range(n):
        i = g.alpha[j] - nu
        out["ca"][:, j], out["sa"][:, j] = pair_angle(p_dh[:, i], p_dh[:, i + 1])
        out["a"][:, j] = p_dh[:, g.a[j] - nu]
        if g.b[j] >= 0:
            out["b"][:, j] = p_dh[:, g.b[j] - nu]
        if g.phi[j] >= 0:
            i = g.phi[j] - nu
            out["cp"][:, j], out["sp"][:, j] = pair_angle(p_dh[:, i], p_dh[:, i + 1])
    return out


def rpc_parameters(kinds: str, p_dh: ArrayLike) -> Complex:
    """The system's parameters (B, k) of rows of :mod:`.general_loop_system` parameters
    (B, k_dh) of the same loop; a CapabilityError where a moving link's axes are parallel."""
    P = np.atleast_2d(np.asarray(p_dh, dtype=complex))
    lay, n, h = quadric_layout(kinds), len(kinds), _dh(kinds, P)
    if (np.abs(h["sa"][:, : n - 1]) < PARALLEL).any():
        raise CapabilityError("two consecutive free joint axes of the loop are parallel (a link "
                              "of zero twist); the R/P/C axes formulation needs k = a / sin α")
    out = np.zeros((len(P), lay.n_parameters), dtype=complex)
    out[:, lay.z0 + 2] = 1.0
    zl = np.stack([np.zeros(len(P)), h["sa"][:, -1], h["ca"][:, -1]], axis=1)  # Rx(−α) e_z
    out[:, lay.zl: lay.zl + 3] = zl
    for j in range(n - 1):
        out[:, lay.cos_a[j]] = h["ca"][:, j]
        out[:, lay.k[j]] = h["a"][:, j] / h["sa"][:, j]
        if lay.b[j] >= 0:
            out[:, lay.b[j]] = h["b"][:, j]
    for j in range(n):
        if lay.c[j] >= 0:
            out[:, lay.c[j]] = h["ca"][:, j - 1] * h["ca"][:, j] - h["sa"][:, j - 1] * \
                h["sa"][:, j] * h["cp"][:, j]
            out[:, lay.v[j]] = h["sa"][:, j - 1] * h["sa"][:, j] * h["sp"][:, j]
    g = h["a"][:, -1, None] * np.array([1.0, 0.0, 0.0])
    if kinds[0] == "R":
        g = g + h["b"][:, 0, None] * np.array([0.0, 0.0, 1.0])
    if kinds[-1] == "R":
        g = g + h["b"][:, -1, None] * zl
    out[:, lay.g: lay.g + 3] = g
    return out


def rpc_axes(kinds: str, x: ArrayLike, p: ArrayLike) -> Complex:
    """Every axis (N, n, 3) of solutions x (N, n_unknowns) at parameters p (N, k) or (k,)."""
    lay, n = quadric_layout(kinds), len(kinds)
    X = np.atleast_2d(np.asarray(x, dtype=complex))
    P = np.broadcast_to(np.asarray(p, dtype=complex), (len(X), lay.n_parameters))
    moving = X[:, : 3 * (n - 2)].reshape(len(X), n - 2, 3)
    return np.concatenate([P[:, None, lay.z0: lay.z0 + 3], moving,
                           P[:, None, lay.zl: lay.zl + 3]], axis=1)


def mirrored(kinds: str, x: ArrayLike, p: ArrayLike) -> NDArray[np.bool_]:
    """Whether each solution (N,) is a mirror's, not the loop's: at some P joint j,
    det(z_{j−1}, z_j, z_{j+1}) is nearer −v_j than v_j (module docstring)."""
    lay, n = quadric_layout(kinds), len(kinds)
    z = rpc_axes(kinds, x, p)
    P = np.broadcast_to(np.asarray(p, dtype=complex), (len(z), lay.n_parameters))
    out = np.zeros(len(z), dtype=bool)
    for j in range(n):
        if lay.v[j] >= 0:
            det = np.einsum("ni,ni->n", z[:, j - 1], np.cross(z[:, j], z[:, (j + 1) % n]))
            v = P[:, lay.v[j]]
            out |= np.abs(det + v) < np.abs(det - v)
    return out


def general_unknowns(kinds: str, x: ArrayLike, p: ArrayLike, p_dh: ArrayLike) -> Complex:
    """The :mod:`.general_loop_system` unknowns (N, n_dh) of solutions x (N, n_unknowns) at
    parameters p and the loop's DH parameters p_dh ((N, ·) or one row): θ_j of a turning joint
    from x_{j−1} to x_j about z_j (x_j = z_j × z_{j+1} / sin α_j, x_{n−1} = e_x), slides as
    they are."""
    lay, g, n = quadric_layout(kinds), loop_layout(kinds), len(kinds)
    X = np.atleast_2d(np.asarray(x, dtype=complex))
    z = rpc_axes(kinds, X, p)
    P = np.atleast_2d(np.asarray(p_dh, dtype=complex))
    sa = np.broadcast_to(_dh(kinds, P)["sa"], (len(X), n))
    nx = np.cross(z[:, :-1], z[:, 1:]) / sa[:, : n - 1, None]
    nx = np.concatenate([nx, np.broadcast_to(np.array([1.0, 0.0, 0.0]), (len(X), 1, 3))], 1)
    out = np.zeros((len(X), g.n_unknowns), dtype=complex)
    for j in range(n):
        if g.cs[j] >= 0:
            prev, here = nx[:, j - 1], nx[:, j]
            out[:, g.cs[j]] = np.einsum("ni,ni->n", prev, here)
            out[:, g.cs[j] + 1] = np.einsum("ni,ni->n", np.cross(prev, here), z[:, j])
        if g.d[j] >= 0:
            out[:, g.d[j]] = X[:, lay.slide[j]]
    return out


def random_rpc(kinds: str, rng: np.random.Generator, count: int = 1
               ) -> tuple[Complex, Complex]:
    """``count`` random complex instances (count, k) with one known solution each
    (count, n_unknowns): random complex axes with z·z = 1, lengths, slides and P targets v,
    then cos α, the P targets c and g from them."""
    lay, n = quadric_layout(kinds), len(kinds)

    def draw(*shape: int) -> Complex:
        return (rng.normal(size=shape) + 1j * rng.normal(size=shape)).astype(complex)

    z = draw(count, n, 3)
    z = z / np.sqrt(np.sum(z * z, -1))[..., None]
    p = np.zeros((count, lay.n_parameters), dtype=complex)
    x = np.zeros((count, lay.n_unknowns), dtype=complex)
    p[:, lay.z0: lay.z0 + 3], p[:, lay.zl: lay.zl + 3] = z[:, 0], z[:, -1]
    x[:, : 3 * (n - 2)] = z[:, 1:-1].reshape(count, -1)
    k = draw(count, n - 1)
    g = -np.einsum("nj,nji->ni", k, np.cross(z[:, :-1], z[:, 1:]))
    for j in range(n - 1):
        p[:, lay.cos_a[j]] = np.sum(z[:, j] * z[:, j + 1], -1)
        p[:, lay.k[j]] = k[:, j]
    for j in range(n):
        for col, source in ((lay.b[j], p), (lay.slide[j], x)):
            if col >= 0:
                source[:, col] = draw(count)
                g -= source[:, col, None] * z[:, j]
        if lay.c[j] >= 0:
            p[:, lay.c[j]] = np.sum(z[:, j - 1] * z[:, (j + 1) % n], -1)
            p[:, lay.v[j]] = draw(count)
    p[:, lay.g: lay.g + 3] = g
    return p, x


def rpc_unknowns(kinds: str, x_dh: ArrayLike, p_dh: ArrayLike) -> Complex:
    """The system's unknowns (n_unknowns,) at one :mod:`.general_loop_system` solution x_dh
    with parameters p_dh (one row each): the axes read off the chain of joint frames
    F_{j+1} = F_j Z_j K_j (:func:`~.general_loop_system.loop_transforms`), the slides as they
    are: the way in, independent of :func:`general_unknowns`."""
    lay, g, n = quadric_layout(kinds), loop_layout(kinds), len(kinds)
    xd, pd = np.asarray(x_dh, dtype=complex), np.asarray(p_dh, dtype=complex)
    F, out = np.eye(4, dtype=complex), np.zeros(lay.n_unknowns, dtype=complex)
    for j, T in enumerate(loop_transforms(kinds, xd, pd)):
        if lay.axis[j] >= 0:
            out[lay.axis[j]: lay.axis[j] + 3] = F[:3, 2]
        if lay.slide[j] >= 0:
            out[lay.slide[j]] = xd[g.d[j]]
        F = F @ T
    return out


__all__ = ["PARALLEL", "QuadricLayout", "general_unknowns", "mirrored", "quadric_layout",
           "random_rpc", "rpc_axes", "rpc_parameters", "rpc_system", "rpc_unknowns"]

"""A single loop of R, P and C joints with six free freedoms as quadrics in its joint axes
(issue 27): the axes formulation of :mod:`.loop6r` with slides and non-turning joints.

The free joints j = 0..n−1 are taken round the loop in the Denavit–Hartenberg form of
:mod:`.general_loop_system` (∏_j Z_j(q_j) Rz(φ_j) Tz(b_j) Tx(a_j) Rx(α_j) = I), in the frame of
joint 0 before its motion, labelled so that joint n−1 turns (an R or C joint). With z_j the unit
axis of joint j and x_j the unit common normal of link j (joint j → joint j+1), the loop closes
when Σ_j (s_j z_j + a_j x_j) = 0, s_j the distance along z_j between the feet of x_{j−1} and
x_j: a parameter b_j of an R joint, an unknown d_j of a P or C joint (the loop equation of
Duffy 1980, ch. 2, as in :mod:`.loop6r`). The last link is the ground: z_0, z_{n−1} and x_{n−1}
are known. The unknowns are the axes z_1..z_{n−2} and the slides. The links are of two kinds:

- between two turning joints, as in the 6R system: z_i·z_{i+1} = cos α_i and
  a_i x_i = k_i z_i × z_{i+1} (k_i = a_i / sin α_i), with z_j·z_j = 1 for each moving axis;
- in a run of P joints j..j+m−1 between turning joints a = j−1 and b = j+m: none of these joints
  turns, so the links a..b−1 keep their orientation to one another and every axis and normal
  among them is a fixed combination of z_a, z_b and z_a × z_b (z_a ∦ z_b). The run's equations
  are z_a·z_b = γ and z_i = A_i z_a + B_i z_b + C_i z_a × z_b for each P axis (3 each), and
  its links add E z_a + F z_b + G z_a × z_b to the closure. Given unit z_a, z_b at the angle γ,
  these are exactly the loop's P joints: no mirror of a P joint's angle is added (a P angle's
  cosine alone, z_{j−1}·z_{j+1} fixed, would admit θ → −θ, and would make every solution a
  double root at θ = 0 or π, the angle of a P joint in a Denavit–Hartenberg drawing);
- a run of P joints 0..m−1 at the start (after the turning ground joint n−1): its links keep the
  ground's orientation, so z_1..z_m are known (z_i = u_i, linear) and its links' normals are
  constants of the closure.

Every equation has degree ≤ 2 in the unknowns, so the dense compiled tracker runs it
(algebraic/quadrics.py). The system is square exactly when #R + #P + 2·#C = 6. Its parameters
(z_0, z_{n−1}, cos α_i, k_i, b_j, γ, A, B, C, E, F, G, u_i, g) are free: any complex values are
an instance; :func:`rpc_parameters` gives them from the DH values of a real loop and
:func:`general_unknowns` turns a solution back into :mod:`.general_loop_system`'s unknowns.
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
)

Complex = NDArray[np.complex128]
#: |sin α| of a link between two turning joints, or |z_a × z_b| of a run's end axes, below
#: this: the axes are parallel and the formulation cannot take the labelling (k = a / sin α;
#: the run's basis), see :func:`parallel_links`
PARALLEL = 1e-6


@dataclass(frozen=True)
class Run:
    """An interior run of P joints ``joints`` between the turning joints ``a`` and ``b``: the
    parameter indices of γ, of (A, B, C) per P joint and of the links' (E, F, G)."""

    a: int
    b: int
    joints: tuple[int, ...]
    gamma: int
    abc: tuple[int, ...]
    efg: int


@dataclass(frozen=True)
class QuadricLayout:
    """Where each symbol of the system is (module docstring). Unknowns: z_j at ``axis[j]``
    (3 columns; −1 for the ground axes 0 and n−1), slide d_j at ``slide[j]`` (or −1).
    Parameters: ``z0``, ``zl``, ``g`` (3 each), per link i < n−1 between two turning joints
    ``cos_a[i]``, ``k[i]`` (else −1), ``b[j]`` per R joint with an unknown, unfixed axis (else
    −1), the interior ``runs``, and the leading run's length ``lead`` = m with ``u[i−1]`` the
    parameter of z_i (i = 1..m)."""

    kinds: str
    axis: tuple[int, ...]
    slide: tuple[int, ...]
    lead: int
    u: tuple[int, ...]
    cos_a: tuple[int, ...]
    k: tuple[int, ...]
    b: tuple[int, ...]
    runs: tuple[Run, ...]
    z0: int
    zl: int
    g: int
    n_unknowns: int
    n_parameters: int


def _interior_runs(kinds: str, lead: int) -> list[tuple[int, int, tuple[int, ...]]]:
    """(a, b, P joints) of each maximal run of P joints after the leading one."""
    out, j, n = [], lead, len(kinds)
    while j < n:
        if kinds[j] != "P":
            j += 1
            continue
        start = j
        while kinds[j] == "P":
            j += 1
        out.append((start - 1, j, tuple(range(start, j))))
    return out


@lru_cache(maxsize=64)
def quadric_layout(kinds: str) -> QuadricLayout:
    """The layout of the system of free joints ``kinds`` (module docstring)."""
    if set(kinds) - set(TURNS) or freedom_count(kinds) != 6 or len(kinds) < 3:
        raise CapabilityError(f"the R/P/C loop formulation takes free R, P and C joints with "
                              f"six freedoms in all; got {kinds!r}")
    if kinds[-1] == "P" or sum(k in "RC" for k in kinds) < 3:
        raise CapabilityError(f"the R/P/C axes formulation needs at least three turning "
                              f"joints, the last of them joint n−1; got {kinds!r}")
    n = len(kinds)
    lead = next(j for j, kind in enumerate(kinds) if kind != "P")
    axis = tuple(-1 if j in (0, n - 1) else 3 * (j - 1) for j in range(n))
    col, slide = 3 * (n - 2), []
    for kind in kinds:
        slide.append(col if SLIDES[kind] else -1)
        col += 1 if SLIDES[kind] else 0
    p = 6
    u = tuple(range(p, p + 3 * lead, 3))
    p += 3 * lead
    cos_a, k = [], []
    for i in range(n - 1):
        turning = kinds[i] != "P" and kinds[i + 1] != "P"
        cos_a.append(p if turning else -1)
        k.append(p + 1 if turning else -1)
        p += 2 if turning else 0
    b = []
    for j, kind in enumerate(kinds):
        b.append(p if kind == "R" and lead < j < n - 1 else -1)
        p += 1 if b[-1] >= 0 else 0
    runs = []
    for a, end, joints in _interior_runs(kinds, lead):
        runs.append(Run(a, end, joints, p, tuple(range(p + 1, p + 1 + 3 * len(joints), 3)),
                        p + 1 + 3 * len(joints)))
        p += 4 + 3 * len(joints)
    return QuadricLayout(kinds, axis, tuple(slide), lead, u, tuple(cos_a), tuple(k), tuple(b),
                         tuple(runs), 0, 3, p, col, p + 3)


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

    def par(i: int, width: int = 1) -> list[Poly]:
        return s[nu + i: nu + i + width]

    z = [par(lay.z0, 3) if j == 0 else par(lay.zl, 3) if j == n - 1 else
         s[lay.axis[j]: lay.axis[j] + 3] for j in range(n)]
    eqs = [_dot(z[j], z[j]) - 1.0 for j in range(lay.lead + 1, n - 1) if kinds[j] != "P"]
    eqs += [_dot(z[i], z[i + 1]) - par(c)[0] for i, c in enumerate(lay.cos_a) if c >= 0]
    for i in range(1, lay.lead + 1):
        eqs += [z[i][r] - par(lay.u[i - 1] + r)[0] for r in range(3)]
    closure = par(lay.g, 3)
    for run in lay.runs:
        za, zb = z[run.a], z[run.b]
        w = _cross(za, zb)
        eqs.append(_dot(za, zb) - par(run.gamma)[0])
        for j, c in zip(run.joints, run.abc, strict=True):
            A, B, C = par(c, 3)
            eqs += [z[j][r] - A * za[r] - B * zb[r] - C * w[r] for r in range(3)]
        E, F, G = par(run.efg, 3)
        closure = [closure[r] + E * za[r] + F * zb[r] + G * w[r] for r in range(3)]
    for i, c in enumerate(lay.k):
        if c >= 0:
            w = _cross(z[i], z[i + 1])
            closure = [closure[r] + par(c)[0] * w[r] for r in range(3)]
    for j in range(n):
        if lay.b[j] >= 0:
            closure = [closure[r] + par(lay.b[j])[0] * z[j][r] for r in range(3)]
        if lay.slide[j] >= 0:
            closure = [closure[r] + s[lay.slide[j]] * z[j][r] for r in range(3)]
    eqs += closure
    return compile_system(eqs, _unknown_names(lay), _parameter_names(lay))


def _unknown_names(lay: QuadricLayout) -> list[str]:
    n = len(lay.kinds)
    return ([f"z{j}_{c}" for j in range(1, n - 1) for c in "xyz"]
            + [f"d{j}" for j in range(n) if lay.slide[j] >= 0])


def _parameter_names(lay: QuadricLayout) -> list[str]:
    names = [""] * lay.n_parameters
    n = len(lay.kinds)
    for start, label in ((lay.z0, "z0"), (lay.zl, f"z{n - 1}"), (lay.g, "g")):
        names[start: start + 3] = [f"{label}_{c}" for c in "xyz"]
    for i, c in enumerate(lay.u):
        names[c: c + 3] = [f"u{i + 1}_{x}" for x in "xyz"]
    for i, c in enumerate(lay.cos_a):
        if c >= 0:
            names[c], names[lay.k[i]] = f"cos_alpha{i}", f"k{i}"
    for j, c in enumerate(lay.b):
        if c >= 0:
            names[c] = f"b{j}"
    for run in lay.runs:
        names[run.gamma] = f"gamma{run.a}_{run.b}"
        for j, c in zip(run.joints, run.abc, strict=True):
            names[c: c + 3] = [f"{x}{j}" for x in "ABC"]
        names[run.efg: run.efg + 3] = [f"{x}{run.a}_{run.b}" for x in "EFG"]
    return names


@dataclass(frozen=True)
class Geometry:
    """A loop's orientations at every turning joint's zero, from its DH values (B rows): the
    link normals x (B, n, 3) and axes z (B, n, 3) where they do not depend on the turning
    joints (the leading run's, in the world frame), and per interior run the coefficients of
    its P axes (B, m, 3) and of each link's unit normal (B, b−a, 3) in the basis
    (z_a, z_b, z_a × z_b), with γ (B,)."""

    sa: Complex
    ca: Complex
    a: Complex
    b: Complex
    lead_z: Complex
    lead_x: Complex
    run_axes: tuple[Complex, ...]
    run_normals: tuple[Complex, ...]
    run_gamma: tuple[Complex, ...]


def pair_angle(u: Complex, v: Complex) -> tuple[Complex, Complex]:
    """(cos, sin) of the angles whose half-angle pairs are (u, v), elementwise (as
    :func:`.general_loop_system.pair_angle`)."""
    n = u * u + v * v
    return (u * u - v * v) / n, 2 * u * v / n


def _rz(c: Complex, s: Complex) -> Complex:
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)],
                    -2)


def _rx(c: Complex, s: Complex) -> Complex:
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)],
                    -2)


def geometry(kinds: str, p_dh: ArrayLike) -> Geometry:
    """The :class:`Geometry` of rows of :mod:`.general_loop_system` parameters (B, k_dh)."""
    P = np.atleast_2d(np.asarray(p_dh, dtype=complex))
    lay, gl, n, B = quadric_layout(kinds), loop_layout(kinds), len(kinds), len(P)
    nu = gl.n_unknowns
    ca, sa = (np.stack(v, 1) for v in zip(*(
        pair_angle(P[:, gl.alpha[j] - nu], P[:, gl.alpha[j] - nu + 1]) for j in range(n)),
        strict=True))
    cp, sp = np.ones((B, n), dtype=complex), np.zeros((B, n), dtype=complex)
    bb = np.zeros((B, n), dtype=complex)
    for j in range(n):
        if gl.phi[j] >= 0:
            cp[:, j], sp[:, j] = pair_angle(P[:, gl.phi[j] - nu], P[:, gl.phi[j] - nu + 1])
        if gl.b[j] >= 0:
            bb[:, j] = P[:, gl.b[j] - nu]
    a = np.stack([P[:, gl.a[j] - nu] for j in range(n)], 1)
    R = np.broadcast_to(np.eye(3, dtype=complex), (B, 3, 3))
    lead_z, lead_x = [R[..., 2]], []
    for j in range(lay.lead):
        R = R @ _rz(cp[:, j], sp[:, j])
        lead_x.append(R[..., 0])
        R = R @ _rx(ca[:, j], sa[:, j])
        lead_z.append(R[..., 2])
    run_axes, run_normals, run_gamma = [], [], []
    for run in lay.runs:
        R = np.broadcast_to(np.eye(3, dtype=complex), (B, 3, 3))
        axes, normals = [], [R[..., 0]]
        for j in range(run.a, run.b):
            R = R @ _rx(ca[:, j], sa[:, j])
            if j + 1 < run.b:
                R = R @ _rz(cp[:, j + 1], sp[:, j + 1])
                axes.append(R[..., 2])
                normals.append(R[..., 0])
        za, zb = np.broadcast_to(np.array([0, 0, 1.0 + 0j]), (B, 3)), R[..., 2]
        basis = np.stack([za, zb, np.cross(za, zb)], -1)  # columns
        # exactly parallel ends (a zero twist in a drawing): no basis; NaN, which
        # parallel_links reports through γ
        flat = np.abs(np.linalg.det(basis)) < 1e-300
        basis[flat] = np.eye(3)

        def coefficients(v: list[Complex], M: Complex = basis,
                         none: NDArray[np.bool_] = flat) -> Complex:
            out = np.linalg.solve(M[:, None], np.stack(v, 1)[..., None])[..., 0]
            out[none] = np.nan
            return np.asarray(out, dtype=complex)

        run_axes.append(coefficients(axes))
        run_normals.append(coefficients(normals))
        run_gamma.append(zb[:, 2])
    return Geometry(sa, ca, a, bb, np.stack(lead_z, 1),
                    np.stack(lead_x, 1) if lead_x else np.zeros((B, 0, 3), dtype=complex),
                    tuple(run_axes), tuple(run_normals), tuple(run_gamma))


def related_sines(kinds: str, p_dh: ArrayLike) -> NDArray[np.float64]:
    """Per row (B,): the smallest |sin| of the angle between two axes the quadrics relate
    (a link between two turning joints other than the ground, whose k = a / sin α; an
    interior run's end axes, its basis); 1 where there are none."""
    lay = quadric_layout(kinds)
    geo = geometry(kinds, p_dh) if lay.runs else None
    P = np.atleast_2d(np.asarray(p_dh, dtype=complex))
    low = np.ones(P.shape[0])
    gl, nu = loop_layout(kinds), loop_layout(kinds).n_unknowns
    for i, c in enumerate(lay.cos_a):
        if c >= 0:
            _, s = pair_angle(P[:, gl.alpha[i] - nu], P[:, gl.alpha[i] - nu + 1])
            low = np.minimum(low, np.abs(s))
    if geo is not None:
        for gamma in geo.run_gamma:
            low = np.minimum(low, np.sqrt(np.abs(1.0 - gamma * gamma)))
    return low


def parallel_links(kinds: str, p_dh: ArrayLike) -> NDArray[np.bool_]:
    """Per row (B,): whether a link between two turning joints (other than the ground) has
    parallel axes, or an interior run's end axes are parallel (:data:`PARALLEL`)."""
    return related_sines(kinds, p_dh) < PARALLEL


def rpc_parameters(kinds: str, p_dh: ArrayLike) -> Complex:
    """The system's parameters (B, k) of rows of :mod:`.general_loop_system` parameters
    (B, k_dh) of the same loop (no parallel check: :func:`parallel_links`)."""
    P = np.atleast_2d(np.asarray(p_dh, dtype=complex))
    lay, n, B, geo = quadric_layout(kinds), len(kinds), len(P), geometry(kinds, p_dh)
    out = np.zeros((B, lay.n_parameters), dtype=complex)
    out[:, lay.z0 + 2] = 1.0
    zl = np.stack([np.zeros(B), geo.sa[:, -1], geo.ca[:, -1]], axis=1)  # Rx(−α) e_z
    out[:, lay.zl: lay.zl + 3] = zl
    for i, c in enumerate(lay.u):
        out[:, c: c + 3] = geo.lead_z[:, i + 1]
    for i, c in enumerate(lay.cos_a):
        if c >= 0:
            out[:, c] = geo.ca[:, i]
            with np.errstate(all="ignore"):
                out[:, lay.k[i]] = geo.a[:, i] / geo.sa[:, i]
    for j, c in enumerate(lay.b):
        if c >= 0:
            out[:, c] = geo.b[:, j]
    for r, run in enumerate(lay.runs):
        out[:, run.gamma] = geo.run_gamma[r]
        for m, c in enumerate(run.abc):
            out[:, c: c + 3] = geo.run_axes[r][:, m]
        a = geo.a[:, run.a: run.b]
        out[:, run.efg: run.efg + 3] = np.einsum("bi,bic->bc", a, geo.run_normals[r])
    g = geo.a[:, -1, None] * np.array([1.0, 0.0, 0.0])
    for i in range(lay.lead):
        g = g + geo.a[:, i, None] * geo.lead_x[:, i]
    for j in range(n):
        if kinds[j] == "R" and lay.b[j] < 0:  # an R joint on a known axis
            g = g + geo.b[:, j, None] * (zl if j == n - 1 else geo.lead_z[:, j])
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


def general_unknowns(kinds: str, x: ArrayLike, p: ArrayLike, p_dh: ArrayLike) -> Complex:
    """The :mod:`.general_loop_system` unknowns (N, n_dh) of solutions x (N, n_unknowns) at
    parameters p and the loop's DH parameters p_dh ((N, ·) or one row): θ_j of a turning joint
    from x_{j−1} to x_j about z_j, each normal from its link's kind (module docstring), slides
    as they are."""
    lay, gl, n = quadric_layout(kinds), loop_layout(kinds), len(kinds)
    X = np.atleast_2d(np.asarray(x, dtype=complex))
    N = len(X)
    z = rpc_axes(kinds, X, p)
    P = np.atleast_2d(np.asarray(p_dh, dtype=complex))
    geo = geometry(kinds, P)
    nx = np.zeros((N, n, 3), dtype=complex)
    nx[:, n - 1, 0] = 1.0
    for i in range(lay.lead):
        nx[:, i] = geo.lead_x[:, i]
    for i, c in enumerate(lay.cos_a):
        if c >= 0:
            nx[:, i] = np.cross(z[:, i], z[:, i + 1]) / geo.sa[:, i, None]
    for r, run in enumerate(lay.runs):
        za, zb = z[:, run.a], z[:, run.b]
        basis = np.stack([za, zb, np.cross(za, zb)], -1)
        coeff = np.broadcast_to(geo.run_normals[r], (N, run.b - run.a, 3))
        nx[:, run.a: run.b] = np.einsum("nrk,nik->nir", basis, coeff)
    out = np.zeros((N, gl.n_unknowns), dtype=complex)
    for j in range(n):
        if gl.cs[j] >= 0:
            prev, here = nx[:, j - 1], nx[:, j]
            out[:, gl.cs[j]] = np.einsum("ni,ni->n", prev, here)
            out[:, gl.cs[j] + 1] = np.einsum("ni,ni->n", np.cross(prev, here), z[:, j])
        if gl.d[j] >= 0:
            out[:, gl.d[j]] = X[:, lay.slide[j]]
    return out


def rpc_unknowns(kinds: str, x_dh: ArrayLike, p_dh: ArrayLike) -> Complex:
    """The system's unknowns (n_unknowns,) at one :mod:`.general_loop_system` solution x_dh
    with parameters p_dh (one row each): the axes read off the chain of joint frames
    F_{j+1} = F_j Z_j K_j (:func:`~.general_loop_system.loop_transforms`), the slides as they
    are: the way in, independent of :func:`general_unknowns`."""
    lay, gl = quadric_layout(kinds), loop_layout(kinds)
    xd, pd = np.asarray(x_dh, dtype=complex), np.asarray(p_dh, dtype=complex)
    F, out = np.eye(4, dtype=complex), np.zeros(lay.n_unknowns, dtype=complex)
    for j, T in enumerate(loop_transforms(kinds, xd, pd)):
        if lay.axis[j] >= 0:
            out[lay.axis[j]: lay.axis[j] + 3] = F[:3, 2]
        if lay.slide[j] >= 0:
            out[lay.slide[j]] = xd[gl.d[j]]
        F = F @ T
    return out


def random_rpc(kinds: str, rng: np.random.Generator, count: int = 1
               ) -> tuple[Complex, Complex]:
    """``count`` random complex instances (count, k) with one known solution each
    (count, n_unknowns): random complex unit axes at the turning joints, random run
    coefficients (the P axes follow), lengths and slides; then cos α, γ, u and g from them."""
    lay, n = quadric_layout(kinds), len(kinds)

    def draw(*shape: int) -> Complex:
        return (rng.normal(size=shape) + 1j * rng.normal(size=shape)).astype(complex)

    z = draw(count, n, 3)
    z = z / np.sqrt(np.sum(z * z, -1))[..., None]
    p = np.zeros((count, lay.n_parameters), dtype=complex)
    x = np.zeros((count, lay.n_unknowns), dtype=complex)
    g = np.zeros((count, 3), dtype=complex)
    for run in lay.runs:
        za, zb = z[:, run.a], z[:, run.b]
        w = np.cross(za, zb)
        p[:, run.gamma] = np.sum(za * zb, -1)
        for j, c in zip(run.joints, run.abc, strict=True):
            p[:, c: c + 3] = draw(count, 3)
            z[:, j] = p[:, c, None] * za + p[:, c + 1, None] * zb + p[:, c + 2, None] * w
        p[:, run.efg: run.efg + 3] = draw(count, 3)
        g -= (p[:, run.efg, None] * za + p[:, run.efg + 1, None] * zb
              + p[:, run.efg + 2, None] * w)
    p[:, lay.z0: lay.z0 + 3], p[:, lay.zl: lay.zl + 3] = z[:, 0], z[:, -1]
    for i, c in enumerate(lay.u):
        p[:, c: c + 3] = z[:, i + 1]
    x[:, : 3 * (n - 2)] = z[:, 1:-1].reshape(count, -1)
    for i, c in enumerate(lay.cos_a):
        if c >= 0:
            p[:, c] = np.sum(z[:, i] * z[:, i + 1], -1)
            p[:, lay.k[i]] = draw(count)
            g -= p[:, lay.k[i], None] * np.cross(z[:, i], z[:, i + 1])
    for j in range(n):
        for col, source in ((lay.b[j], p), (lay.slide[j], x)):
            if col >= 0:
                source[:, col] = draw(count)
                g -= source[:, col, None] * z[:, j]
    p[:, lay.g: lay.g + 3] = g
    return p, x


__all__ = ["PARALLEL", "Geometry", "QuadricLayout", "Run", "general_unknowns", "geometry",
           "parallel_links", "quadric_layout", "random_rpc", "related_sines", "rpc_axes",
           "rpc_parameters", "rpc_system", "rpc_unknowns"]

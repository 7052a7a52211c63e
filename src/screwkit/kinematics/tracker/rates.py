"""The rate equations of a closed loop: velocities and accelerations of every freedom from the
inputs' (Bagci 1969 eqs. 3.27–3.48 differentiated; Rahman 1996 §1.4 with the true axes).

With the freedom screws S_k (ω; v) in the ground frame as the columns of the loop Jacobian,
closure holds to first and second order when

    J_p q̇_p = −J_in q̇_in,        J_p q̈_p = −J_in q̈_in − J̇q̇,   J̇q̇ = Σ_{j<k} [S_j, S_k] q̇_j q̇_k

(Lie brackets of the screws). The spin of a link between two spherical joints (an S–S rod) about
its own axis u is idle: its rule is zero absolute spin, ω·u = 0 (hence α·u = 0; Rahman 1996
§1.2), one extra row per rod. Rows are scaled by the loop's length scale L (rotation rows as
they are, translation rows / L) and translation freedoms by L, so every entry is dimensionless.

**Honest singularities.** A sample is *singular* — no rates are reported there — where the
scaled passive Jacobian J_p (with the spin rows) loses rank, σ_min < :data:`SINGULAR_RTOL`·σ_max
(the rates are not unique: a dead centre, a bifurcation or a motion left free with the input
fixed), or where the inputs' screws are not in its range (the input cannot move the loop: a
locked or rigid configuration), so that the solved rates would leave a residual
|J q̇| > :data:`RESIDUAL_TOL` (scaled). Every rate that is reported satisfies its equation to
that tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import Array, Layout, LoopFrames, constants, lie_bracket
from screwkit.model.linkage import Linkage

#: relative singular value of the scaled passive Jacobian below which a sample is singular.
#: Positions are closed to ~1e-11, so at a double root (a dead centre) the configuration is
#: known only to ~√1e-11 ≈ 3e-6 along the null direction and σ_min does not drop below that:
#: the threshold sits above it. Rates at σ_min/σ_max = 1e-5 are ~1e5 times the input rate.
SINGULAR_RTOL = 1e-5

#: largest scaled residual |J q̇| (and |J q̈ + J̇q̇|) of a reported rate, relative to the size of
#: the terms of the equation: a sample whose rates would leave more is singular (docs/kinematics.md)
RESIDUAL_TOL = 1e-9


def spin_links(linkage: Linkage) -> list[int]:
    """Moving links that lie between two spherical joints (S–S rods): their spin is idle."""
    return [i for i in range(len(linkage.joints) - 1)
            if linkage.joints[i].kind == "S" and linkage.joints[i + 1].kind == "S"]


def rod_axes(fr: LoopFrames, links: list[int]) -> Array:
    """(N, r, 3) unit axes u of the S–S rods: from the proximal ball centre to the distal one."""
    if not links:
        return np.zeros((fr.centres.shape[0], 0, 3))
    d = fr.centres[:, [i + 1 for i in links]] - fr.centres[:, links]
    return np.asarray(d / np.linalg.norm(d, axis=-1, keepdims=True))


@dataclass(frozen=True)
class RateEquations:
    """The scaled rate equations of a batch of closed configurations (module docstring)."""

    screws: Array  # (N, 6, m) unit freedom screws, ground frame
    spin: Array  # (N, r, m) zero-spin rows of the S–S rods
    spin_links: list[int]
    rod_axes: Array  # (N, r, 3)
    rows: Array  # (6,) row scaling
    cols: Array  # (m,) column scaling
    in_idx: list[int]
    p_idx: list[int]
    passive: Array  # (N, 6 + r, m_p) scaled passive Jacobian
    sigma_ratio: Array  # (N,) σ_min/σ_max of ``passive`` (0 when it has more columns than rows;
    #                     NaN where not computed: rate_equations(exact_sigma=False))
    rank_deficient: NDArray[np.bool_]  # σ ratio below SINGULAR_RTOL
    input_locked: NDArray[np.bool_]  # an input screw is not in the range of the passive one
    singular: NDArray[np.bool_]  # either: no rates here

    @cached_property
    def passive_norm(self) -> Array:
        """(N,) Frobenius norm of each sample's ``passive``."""
        return _norm2(self.passive)

    def solve(self, input_values: Array, bias: Array, spin_bias: Array,
              minimum_norm: bool = False) -> tuple[Array, Array]:
        """Passive rates (or accelerations) from the input ones and the bias terms J̇q̇ (N, 6)
        and the rods' spin bias (N, r); NaN at singular samples (or, with ``minimum_norm``,
        the minimum-norm least-squares solution there: a predictor, never a reported rate).
        Also returns each sample's scaled residual relative to the size of the equation's
        terms."""
        S, C = self.screws, self.spin
        rhs = (-np.einsum("nij,nj->ni", S[:, :, self.in_idx], input_values) - bias) * self.rows
        if C.shape[1]:
            rhs = np.concatenate(
                [rhs, -np.einsum("nij,nj->ni", C[:, :, self.in_idx], input_values) - spin_bias],
                axis=1)
        x = _least_squares(self.passive, rhs, self.singular)
        if minimum_norm and self.singular.any():
            sing = self.singular
            x[sing] = np.einsum("nij,nj->ni", np.linalg.pinv(self.passive[sing], rcond=1e-10),
                                rhs[sing])
            r = np.einsum("nij,nj->ni", self.passive, x) - rhs
            return x * self.cols[self.p_idx], np.linalg.norm(r, axis=-1)
        r = np.einsum("nij,nj->ni", self.passive, x) - rhs
        size = np.linalg.norm(rhs, axis=-1) + np.linalg.norm(x, axis=-1) * self.passive_norm
        residual = np.linalg.norm(r, axis=-1) / np.maximum(size, 1e-300)
        x[self.singular] = np.nan
        return x * self.cols[self.p_idx], residual


def _norm2(A: Array) -> Array:
    """Frobenius norm per sample (an upper bound of the 2-norm, enough for a relative size)."""
    return np.asarray(np.sqrt(np.einsum("nij,nij->n", A, A)))


def _least_squares(A: Array, b: Array, skip: NDArray[np.bool_]) -> Array:
    """x minimising |A x − b| per sample for A of full column rank (not at ``skip``): an LU
    solve when A is square, else the normal equations with one step of iterative refinement
    (the rank test has bounded the condition number by 1/SINGULAR_RTOL)."""
    N, k, m = A.shape
    ok = ~skip
    if ok.all() and k == m:
        return np.asarray(np.linalg.solve(A, b[..., None])[..., 0])
    x = np.zeros((N, m))
    if not ok.any():
        return x
    Ao, bo = A[ok], b[ok]
    if k == m:
        x[ok] = np.linalg.solve(Ao, bo[..., None])[..., 0]
        return x
    At = np.swapaxes(Ao, -1, -2)
    M = At @ Ao
    xo = np.linalg.solve(M, np.einsum("nji,nj->ni", Ao, bo)[..., None])[..., 0]
    r = bo - np.einsum("nij,nj->ni", Ao, xo)
    xo = xo + np.linalg.solve(M, np.einsum("nji,nj->ni", Ao, r)[..., None])[..., 0]
    x[ok] = xo
    return x


def _sigma_ratio(Jp: Array, exact: bool, near: tuple[Array, Array] | None = None) -> Array:
    """σ_min/σ_max of each tall or square ``Jp`` (N, k, m), from the eigenvalues of JᵀJ. With
    ``exact=False`` only the rank test's answer is kept exact: where det(JᵀJ)/u^m, a lower
    bound of (σ_min/σ_max)² (λ_min ≥ det/λ_max^(m−1) and λ_max ≤ u, the smaller of tr(JᵀJ)
    and ‖JᵀJ‖_∞), already clears
    SINGULAR_RTOL² the eigenvalues are not computed and the ratio is NaN ("well above the
    threshold"). ``near`` — a nearby sample's Jacobian (N, k, m) and its σ_min (N,) — certifies
    it without the determinant where Weyl's inequality σ_min ≥ σ_min,near − |Jp − J_near|_F
    already clears twice SINGULAR_RTOL·|Jp|_F (|Jp|_F ≥ σ_max)."""
    if exact:
        lam = np.linalg.eigvalsh(np.swapaxes(Jp, -1, -2) @ Jp)
        return np.asarray(np.sqrt(np.maximum(lam[:, 0], 0.0) / np.maximum(lam[:, -1], 1e-300)))
    if near is not None:
        fro = np.sqrt(np.einsum("nij,nij->n", Jp, Jp))
        d = Jp - near[0]
        clear = near[1] - np.sqrt(np.einsum("nij,nij->n", d, d)) > 2.0 * SINGULAR_RTOL * fro
        ratio = np.full(Jp.shape[0], np.nan)
        rest = np.nonzero(~clear)[0]
        if rest.size:
            ratio[rest] = _sigma_ratio(Jp[rest], False)
        return ratio
    # λ_max ≤ tr(JᵀJ) and λ_max ≤ ‖JᵀJ‖_∞ (any induced norm bounds the spectral radius);
    # the smaller is the bound u, and the ratio² ≥ det(JᵀJ)/u^m (the row sums are often several
    # times below the trace: with 7 columns that is the difference between an eigenvalue
    # decomposition at every sample and none)
    M = np.swapaxes(Jp, -1, -2) @ Jp
    u = np.maximum(np.minimum(np.trace(M, axis1=-2, axis2=-1),
                              np.abs(M).sum(axis=-1).max(axis=-1)), 1e-300)
    if Jp.shape[1] == Jp.shape[2]:  # square: det(JᵀJ) = det(J)²
        bound = np.linalg.det(Jp / np.sqrt(u)[:, None, None]) ** 2
    else:
        bound = np.linalg.det(M / u[:, None, None])  # det(M)/u^m, scaled against overflow
    ratio = np.full(Jp.shape[0], np.nan)
    close = ~(bound > 4.0 * SINGULAR_RTOL**2)  # a margin for the determinant's round-off
    if close.any():
        ratio[close] = _sigma_ratio(Jp[close], True)
    return ratio


def rate_equations(linkage: Linkage, lay: Layout, fr: LoopFrames,
                   mask: NDArray[np.bool_] | None = None, exact_sigma: bool = True,
                   near: tuple[Array, Array] | None = None) -> RateEquations:
    """The scaled rate equations at every sample of ``fr`` (samples outside ``mask`` are
    treated as singular and give NaN). With ``exact_sigma=False`` (a Motion's build, which
    needs only the rank test) ``sigma_ratio`` is NaN where a cheap bound shows it is well above
    :data:`SINGULAR_RTOL` (:func:`_sigma_ratio`, which ``near`` — a nearby sample's passive
    Jacobian and its smallest singular value, per sample — makes cheaper still)."""
    N, _, m = fr.screws.shape
    L = constants(linkage, lay)[2]
    names = list(lay.names)
    in_idx = [names.index(n) for n in linkage.inputs]
    p_idx = [k for k in range(m) if k not in in_idx]
    rows = np.array([1, 1, 1, 1 / L, 1 / L, 1 / L])
    cols = np.array([L if t else 1.0 for t in lay.is_translation])
    S = fr.screws
    links = spin_links(linkage)
    u = rod_axes(fr, links)
    C = np.zeros((N, len(links), m))
    for r, i in enumerate(links):
        upto = [f for f in range(m) if lay.joint_of[f] <= i]
        C[:, r, upto] = np.einsum("ni,nif->nf", u[:, r], S[:, :3, upto])
    scaled = S * (rows[:, None] * cols[None, :])
    if links:
        scaled = np.concatenate([scaled, C * cols], axis=1)
    Jp, Jin = scaled[:, :, p_idx], scaled[:, :, in_idx]
    k, mp = Jp.shape[1:]
    if mp > k or mp == 0:
        ratio = np.zeros(N)
    else:
        ratio = _sigma_ratio(Jp, exact_sigma, near)
    valid = np.ones(N, dtype=bool) if mask is None else np.asarray(mask, dtype=bool)
    deficient = valid & (ratio < SINGULAR_RTOL)
    locked = np.zeros(N, dtype=bool)
    if k > mp and mp > 0:  # a tall system: is every input screw in the range of J_p?
        for c in range(len(in_idx)):
            x = _least_squares(Jp, Jin[..., c], deficient | ~valid)
            r = np.einsum("nij,nj->ni", Jp, x) - Jin[..., c]
            size = np.linalg.norm(Jin[..., c], axis=-1) + np.linalg.norm(x, axis=-1) * _norm2(Jp)
            locked |= valid & ~deficient & (np.linalg.norm(r, axis=-1) > RESIDUAL_TOL * size)
    singular = deficient | locked | ~valid
    return RateEquations(S, C, links, u, rows, cols, in_idx, p_idx, Jp, ratio, deficient,
                         locked, singular)


def link_twists(linkage: Linkage, lay: Layout, S: Array, qd: Array) -> tuple[Array, Array]:
    """Twist (ground frame) of the frame after each joint and the bias J̇q̇ accumulated up to
    it: J̇q̇ = Σ_k [V_before(k), S_k] q̇_k, V_before(k) the motion of the loop before freedom k
    (a U joint's second axis moves with its first)."""
    N, _, m = S.shape
    n = len(linkage.joints)
    bracket = np.zeros((N, 6))
    V = np.zeros((N, 6))
    link_V = np.empty((N, n, 6))
    link_bias = np.empty((N, n, 6))
    for i, j in enumerate(linkage.joints):
        ks = [f for f in range(m) if lay.joint_of[f] == i]
        Vj = V.copy()
        for f in ks:
            if i > 0 or f != ks[0]:  # nothing moves before the first freedom
                bracket = bracket + lie_bracket(Vj, S[:, :, f]) * qd[:, f:f + 1]
            if j.kind == "U":
                Vj = Vj + S[:, :, f] * qd[:, f:f + 1]
        V = V + np.einsum("nik,nk->ni", S[:, :, ks], qd[:, ks])
        link_V[:, i] = V
        link_bias[:, i] = bracket
    return link_V, link_bias


def link_accelerations(linkage: Linkage, lay: Layout, S: Array, qdd: Array,
                       link_bias: Array) -> Array:
    """Acceleration (ground frame, the time derivative of the twist) of the frame after each
    joint: Σ_{k ≤ joint} S_k q̈_k plus the bias accumulated up to it."""
    N, _, m = S.shape
    link_A = np.empty_like(link_bias)
    acc = np.zeros((N, 6))
    for i in range(len(linkage.joints)):
        ks = [f for f in range(m) if lay.joint_of[f] == i]
        acc = acc + np.einsum("nik,nk->ni", S[:, :, ks], qdd[:, ks])
        link_A[:, i] = acc + link_bias[:, i]
    return link_A


@dataclass(frozen=True)
class Rates:
    """Freedom rates and accelerations of a batch and the twists of the frames after each
    joint; ``residual`` the larger scaled residual of the two equations."""

    qd: Array  # (N, m)
    qdd: Array  # (N, m)
    link_V: Array  # (N, n, 6)
    link_A: Array  # (N, n, 6)
    residual: Array  # (N,)


def solve_rates(linkage: Linkage, lay: Layout, eq: RateEquations, Xd: Array,
                Xdd: Array, minimum_norm: bool = False) -> Rates:
    """Velocities and accelerations of every freedom and of the frame after every joint from
    the inputs' ``Xd``, ``Xdd`` (N, n_in) (module docstring; NaN at singular samples, or the
    minimum-norm solution there with ``minimum_norm``)."""
    N, _, m = eq.screws.shape
    r = len(eq.spin_links)
    qd = np.zeros((N, m))
    qd[:, eq.in_idx] = Xd
    qd[:, eq.p_idx], res1 = eq.solve(Xd, np.zeros((N, 6)), np.zeros((N, r)), minimum_norm)
    link_V, link_bias = link_twists(linkage, lay, eq.screws, np.nan_to_num(qd))
    qdd = np.zeros((N, m))
    qdd[:, eq.in_idx] = Xdd
    spin_bias = np.einsum("nri,nri->nr", eq.rod_axes, link_bias[:, eq.spin_links, :3])
    qdd[:, eq.p_idx], res2 = eq.solve(Xdd, link_bias[:, -1], spin_bias, minimum_norm)
    link_A = link_accelerations(linkage, lay, eq.screws, np.nan_to_num(qdd), link_bias)
    return Rates(qd, qdd, link_V, link_A, np.maximum(res1, res2))


def loop_bias(linkage: Linkage, lay: Layout, S: Array, qd: Array,
              links: list[int]) -> tuple[Array, Array]:
    """The bias J̇q̇ = Σ_k [V_before(k), S_k] q̇_k of the whole loop (N, 6) and accumulated up
    to the frame after each joint in ``links`` (N, r, 6): :func:`link_twists`' sums without
    the link twists, one bracket per joint (the bracket is bilinear: a joint's freedoms all
    move with the loop before it, V_before, and a U joint's second axis also with its
    first)."""
    N = S.shape[0]
    V = np.zeros((N, 6))
    total = np.zeros((N, 6))
    upto = np.zeros((N, len(links), 6))
    for i, j in enumerate(linkage.joints):
        ks = [f for f, jj in enumerate(lay.joint_of) if jj == i]
        T = np.einsum("nik,nk->ni", S[:, :, ks], qd[:, ks]) if len(ks) > 1 \
            else S[:, :, ks[0]] * qd[:, ks[0], None]
        if i > 0:
            total += lie_bracket(V, T)
        if j.kind == "U":
            total += lie_bracket(S[:, :, ks[0]] * qd[:, ks[0], None],
                                 S[:, :, ks[1]] * qd[:, ks[1], None])
        V += T
        if i in links:
            upto[:, links.index(i)] = total
    return total, upto


@dataclass(frozen=True)
class JointRates:
    """Rates and accelerations of every freedom (N, m), NaN where ``singular`` (or outside
    the mask), and each sample's larger scaled residual of the two rate equations."""

    qd: Array
    qdd: Array
    singular: NDArray[np.bool_]
    residual: Array


def freedom_rates(linkage: Linkage, lay: Layout, eq: RateEquations, Xd: Array, Xdd: Array,
                  minimum_norm: bool = False) -> tuple[Array, Array, Array]:
    """Velocities and accelerations of every freedom (N, m) from the inputs' ``Xd``, ``Xdd``
    (N, n_in) and the larger scaled residual of the two equations (N,): :func:`solve_rates`
    without the links' twists (the bias by :func:`loop_bias`); NaN at singular samples, or
    with ``minimum_norm`` the minimum-norm solution there."""
    N, _, m = eq.screws.shape
    r = len(eq.spin_links)
    qd = np.zeros((N, m))
    qd[:, eq.in_idx] = Xd
    qd[:, eq.p_idx], res1 = eq.solve(Xd, np.zeros((N, 6)), np.zeros((N, r)), minimum_norm)
    bias, upto = loop_bias(linkage, lay, eq.screws, np.nan_to_num(qd) if not minimum_norm
                           else qd, eq.spin_links)
    qdd = np.zeros((N, m))
    qdd[:, eq.in_idx] = Xdd
    spin_bias = np.einsum("nri,nri->nr", eq.rod_axes, upto[:, :, :3]) if r \
        else np.zeros((N, 0))
    qdd[:, eq.p_idx], res2 = eq.solve(Xdd, bias, spin_bias, minimum_norm)
    return qd, qdd, np.maximum(res1, res2)


def joint_rates(linkage: Linkage, lay: Layout, eq: RateEquations, mask: NDArray[np.bool_],
                Xd: Array, Xdd: Array) -> JointRates:
    """Velocities and accelerations of every freedom from the inputs' ``Xd``, ``Xdd`` (N,
    n_in) from the rate equations ``eq`` of closed configurations where ``mask`` holds
    (module docstring; :func:`freedom_rates`). A sample is singular where the rank test or
    either residual says so (a Motion's rule); its rates are NaN, as outside the mask."""
    qd, qdd, residual = freedom_rates(linkage, lay, eq, Xd, Xdd)
    singular = mask & (eq.singular | ~(residual <= RESIDUAL_TOL))
    gone = singular | ~mask
    if gone.any():
        qd[gone] = np.nan
        qdd[gone] = np.nan
    return JointRates(qd, qdd, singular, residual)

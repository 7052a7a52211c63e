"""Taylor expansions of a loop's motion about a closed configuration, to any order, and
branch following with them.

About a closed configuration q0 at input x0 every freedom is a power series in t = x − x0,
q(x0 + t) = q0 + Σ_{k≥1} c_k t^k (a spherical joint as R0·exp([Σ c_k t^k]), its freedoms being
body increments as everywhere in :mod:`screwkit.kinematics.tracker.loop`). The loop closure
G(t) = Π J_i(q_i(t)) L_i = I holds at every order. Evaluated in truncated power-series arithmetic
("jets": Taylor-mode differentiation), the order-k coefficient of G is linear in the unknown
passive coefficients c_k with the loop's screw Jacobian as matrix (G(0) = I, ∂G/∂q_i = Ŝ_i):

    J_p c_k = −vee(G_k |_{c_k = 0})           k = 1, 2, …, K

where G_k|_{c_k=0} is built from the lower orders only (and lies in se(3) because they close the
loop). Order 1 is the rate equation J_p q̇_p = −J_in q̇_in; order 2 the acceleration equation with
its Lie-bracket bias (docs/kinematics.md). This is the loop-closure form of Bagci 1969 App. D's
exact Taylor coefficients (``rsrc_output_derivatives`` solves the RSRC's scalar loop equation
3.61 the same way); the k-th derivative is k!·c_k, exact to rounding, for any loop. Idle passive
freedoms (the spin of a rod between two balls) take the minimum-norm coefficients: a scalar
output does not depend on them.

:func:`close_loop` closes a configuration by Gauss–Newton with minimum-norm steps (inputs held);
:func:`follow` moves one along its branch to other inputs with a Taylor predictor and that
corrector.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    Layout,
    closure_twist,
    forward,
    layout,
)
from screwkit.model.linkage import Linkage

#: closure residual (rad, and length / length scale) accepted as closed
CLOSED_TOL = 1e-12


def _scales(linkage: Linkage, lay: Layout) -> tuple[Array, Array]:
    """Row scales of the closure twist (1 for rotation, 1/L for translation) and column scales
    of the freedoms (L for a translation), so the Jacobian is dimensionless."""
    L = linkage.length_scale
    rows = np.array([1.0, 1.0, 1.0, 1.0 / L, 1.0 / L, 1.0 / L])
    cols = np.array([L if t else 1.0 for t in lay.is_translation])
    return rows, cols


def _passive(linkage: Linkage, lay: Layout) -> list[int]:
    return [k for k, n in enumerate(lay.names) if n not in linkage.inputs]


def _solve_passive(J: Array, rhs: Array, rows: Array, cols: Array, pidx: list[int]) -> Array:
    """Minimum-norm passive increments δ with J[:, :, pidx] δ = rhs (scaled, batched)."""
    A = J[:, :, pidx] * rows[None, :, None] * cols[pidx][None, None, :]
    b = rhs * rows[None, :]
    y = np.einsum("nij,nj->ni", np.linalg.pinv(A, rcond=1e-12), b)
    return np.asarray(y * cols[pidx][None, :])


def _increment(conf: Configuration, delta: Array, lay: Layout) -> Configuration:
    """Scalars add; spherical joints turn by exp([δ]) about their own moving axes."""
    from scipy.spatial.transform import Rotation  # on first use: start-up stays light
    q = conf.scalars.copy()
    sph = conf.spherical.copy()
    cols = np.array(lay.scalar_col)
    scal = cols >= 0
    q[:, cols[scal]] += delta[:, np.nonzero(scal)[0]]
    for j, k in lay.spherical_of_joint.items():
        idx = [f for f, jj in enumerate(lay.joint_of) if jj == j]
        sph[:, k] = sph[:, k] @ Rotation.from_rotvec(delta[:, idx]).as_matrix()
    return Configuration(q, sph)


def closure_error(linkage: Linkage, conf: Configuration, lay: Layout | None = None) -> Array:
    """(N,) loop-closure error: max of |rotation| (rad) and |translation| / length scale."""
    lay = lay or layout(linkage)
    rows, _ = _scales(linkage, lay)
    fr = forward(linkage, conf, lay)
    return np.asarray(np.max(np.abs(closure_twist(fr.closure_R, fr.closure_p) * rows), axis=-1))


def close_loop(linkage: Linkage, conf: Configuration, lay: Layout | None = None, *,
               max_iter: int = 25) -> tuple[Configuration, NDArray[np.bool_]]:
    """Close each sample of ``conf`` by Gauss–Newton on the closure twist with minimum-norm
    passive steps (the inputs are held); returns the configurations and which ones closed to
    :data:`CLOSED_TOL`."""
    lay = lay or layout(linkage)
    rows, cols = _scales(linkage, lay)
    pidx = _passive(linkage, lay)
    m = len(lay.names)
    last = np.full(conf.size, np.inf)
    for _ in range(max_iter):
        fr = forward(linkage, conf, lay)
        xi = closure_twist(fr.closure_R, fr.closure_p)
        err = np.max(np.abs(xi * rows), axis=-1)
        # done: closed to rounding (a Newton step no longer halves the error once it is small)
        todo = np.isfinite(err) & (err > 0.1 * CLOSED_TOL) & ~((err <= CLOSED_TOL)
                                                               & (err > 0.5 * last))
        if not todo.any():
            return conf, err <= CLOSED_TOL
        last = err
        delta = np.zeros((conf.size, m))
        delta[:, pidx] = -_solve_passive(fr.screws, xi, rows, cols, pidx)
        delta[~todo] = 0.0
        conf = _increment(conf, delta, lay)
    return conf, closure_error(linkage, conf, lay) <= CLOSED_TOL


# --- truncated power series ("jets"); the order axis is axis 1 -------------------------------
def _jmul(a: Array, b: Array) -> Array:
    """Product of two matrix jets (N, K+1, p, q) @ (N, K+1, q, r), truncated at order K."""
    out = np.zeros(a.shape[:2] + (a.shape[2], b.shape[3]))
    for k in range(a.shape[1]):
        for j in range(k + 1):
            out[:, k] += a[:, j] @ b[:, k - j]
    return out


def _smul(a: Array, b: Array) -> Array:
    """Product of two scalar jets (N, K+1)."""
    out = np.zeros_like(a)
    for k in range(a.shape[1]):
        out[:, k] = np.einsum("nj,nj->n", a[:, :k + 1], b[:, k::-1])
    return out


def _cos_sin(angle: Array) -> tuple[Array, Array]:
    """cos and sin of a scalar jet: cos(a0 + t), sin(a0 + t) with t the rest of the series."""
    t = angle.copy()
    t[:, 0] = 0.0
    K1 = angle.shape[1]
    cos_t, sin_t = np.zeros_like(t), np.zeros_like(t)
    cos_t[:, 0] = 1.0
    power = np.zeros_like(t)
    power[:, 0] = 1.0
    for m in range(1, K1):
        power = _smul(power, t)
        term = power / math.factorial(m)
        if m % 2:
            sin_t += (-1) ** (m // 2) * term
        else:
            cos_t += (-1) ** (m // 2) * term
    c0, s0 = np.cos(angle[:, :1]), np.sin(angle[:, :1])
    return c0 * cos_t - s0 * sin_t, s0 * cos_t + c0 * sin_t


def _rotation_jet(c: Array, s: Array, axis: int) -> Array:
    N, K1 = c.shape
    R = np.zeros((N, K1, 3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R[:, 0, axis, axis] = 1.0
    R[:, :, i, i] = c
    R[:, :, j, j] = c
    R[:, :, i, j] = -s
    R[:, :, j, i] = s
    return R


def _exp_skew(w: Array) -> Array:
    """exp([w]) of a vector jet w (N, K+1, 3) with w_0 = 0 (the series is finite)."""
    N, K1, _ = w.shape
    W = np.zeros((N, K1, 3, 3))
    W[..., 0, 1], W[..., 0, 2], W[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    W[..., 1, 0], W[..., 2, 0], W[..., 2, 1] = w[..., 2], -w[..., 1], w[..., 0]
    out = np.zeros_like(W)
    out[:, 0] = np.eye(3)
    power = out.copy()
    for m in range(1, K1):
        power = _jmul(power, W)
        out += power / math.factorial(m)
    return out


def _transform(R: Array, p: Array) -> Array:
    """A 4×4 jet from rotation (N, K+1, 3, 3) and translation (N, K+1, 3) jets."""
    T = np.zeros(R.shape[:2] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[:, 0, 3, 3] = 1.0
    return T


def _joint_jet(linkage: Linkage, lay: Layout, i: int, q: Array, sph0: Array) -> Array:
    """The 4×4 jet of joint i's motion J_i(q_i(t)) (Rahman eq. 2.2; joint kinds as in
    :mod:`screwkit.model.joints`). ``q`` (N, m, K+1): every freedom's series."""
    joint = linkage.joints[i]
    fs = [f for f, jj in enumerate(lay.joint_of) if jj == i]
    N, _, K1 = q.shape
    p = np.zeros((N, K1, 3))
    const = np.zeros((N, K1))
    const[:, 0] = 1.0
    kind = joint.kind
    if kind in ("R", "C", "H", "U", "S"):
        p[:, 0, 2] = joint.offset
    if kind in ("R", "C", "H"):
        R = _rotation_jet(*_cos_sin(q[:, fs[0]]), 2)
        if kind == "C":
            p[:, :, 2] = q[:, fs[1]]
        elif kind == "H":
            p[:, :, 2] = joint.offset * const + joint.pitch * q[:, fs[0]]
    elif kind == "P":
        R = _rotation_jet(*_cos_sin(joint.offset * const), 2)
        p[:, :, 2] = q[:, fs[0]]
    elif kind == "U":
        R = _jmul(_rotation_jet(*_cos_sin(q[:, fs[0]]), 2),
                  _rotation_jet(*_cos_sin(q[:, fs[1]]), 1))
    else:  # S: R0·exp([w(t)]), body increments
        R0 = np.zeros((N, K1, 3, 3))
        R0[:, 0] = sph0[:, lay.spherical_of_joint[i]]
        R = _jmul(R0, _exp_skew(np.moveaxis(q[:, fs], 1, 2)))
    return _transform(R, p)


def _closure_jet(linkage: Linkage, lay: Layout, q: Array, sph0: Array) -> Array:
    N, _, K1 = q.shape
    T = np.zeros((N, K1, 4, 4))
    T[:, 0] = np.eye(4)
    for i, link in enumerate(linkage.link_transforms):
        T = _jmul(T, _joint_jet(linkage, lay, i, q, sph0))
        Lk = np.eye(4)
        Lk[:3, :3], Lk[:3, 3] = link.real, link.translation
        T = T @ Lk  # a constant: every order is multiplied by it
    return T


@dataclass(frozen=True)
class Jets:
    """Taylor coefficients of every freedom about a batch of closed configurations:
    ``coefficients`` (N, m, K+1) with column k the coefficient of tᵏ (t = the first input's
    increment; other inputs held); column 0 holds the scalar freedoms' values (0 for a spherical
    joint's increments). ``residual`` (N,) is the largest order-k closure left after the solve."""

    names: tuple[str, ...]
    coefficients: Array
    residual: Array

    def derivatives(self, name: str) -> Array:
        """(N, K) d^k q/dx^k, k = 1 … K, of freedom ``name``: k!·c_k."""
        c = self.coefficients[:, self.names.index(name), 1:]
        return np.asarray(c * np.array([math.factorial(k) for k in range(1, c.shape[1] + 1)]))

    def value_at(self, name: str, t: Array) -> Array:
        """The truncated series of freedom ``name`` at increments ``t`` (N,)."""
        c = self.coefficients[:, self.names.index(name)]
        return np.asarray(np.polynomial.polynomial.polyval(t, c.T, tensor=False))


def taylor_jets(linkage: Linkage, conf: Configuration, order: int,
                lay: Layout | None = None) -> Jets:
    """Taylor coefficients to ``order`` of every freedom along the branch through each closed
    configuration of ``conf``, w.r.t. the first input (module docstring)."""
    if not 1 <= order <= 12:
        raise InputError(f"order must be 1 … 12; got {order}")
    lay = lay or layout(linkage)
    rows, cols = _scales(linkage, lay)
    pidx = _passive(linkage, lay)
    N, m = conf.size, len(lay.names)
    q = np.zeros((N, m, order + 1))
    for f in range(m):
        if lay.scalar_col[f] >= 0:
            q[:, f, 0] = conf.scalars[:, lay.scalar_col[f]]
    q[:, lay.names.index(linkage.inputs[0]), 1] = 1.0
    screws = forward(linkage, conf, lay).screws
    residual = np.zeros(N)
    for k in range(1, order + 1):
        G = _closure_jet(linkage, lay, q[:, :, :k + 1], conf.spherical)[:, k]
        bias = np.concatenate([0.5 * np.stack([G[:, 2, 1] - G[:, 1, 2], G[:, 0, 2] - G[:, 2, 0],
                                                G[:, 1, 0] - G[:, 0, 1]], -1), G[:, :3, 3]], -1)
        q[:, pidx, k] = -_solve_passive(screws, bias, rows, cols, pidx)
        left = bias + np.einsum("nij,nj->ni", screws[:, :, pidx], q[:, pidx, k])
        residual = np.maximum(residual, np.max(np.abs(left * rows), axis=-1))
    return Jets(lay.names, q, residual)


def _predict(linkage: Linkage, lay: Layout, conf: Configuration, jets: Jets, t: Array
             ) -> Configuration:
    """The configuration the series gives at input increments ``t`` (N,)."""
    powers = t[:, None] ** np.arange(jets.coefficients.shape[2])[None, :]
    step = np.einsum("nmk,nk->nm", jets.coefficients[:, :, 1:], powers[:, 1:])
    return _increment(conf, step, lay)


def follow(linkage: Linkage, conf: Configuration, x_from: Array, x_to: Array, *,
           max_step: float | None = None, lay: Layout | None = None
           ) -> tuple[Configuration, NDArray[np.bool_]]:
    """Move closed configurations (N) along their branches from first-input values ``x_from``
    to ``x_to`` (N,), in steps no longer than ``max_step`` (default 2°, or 1/50 of the length
    scale for a translation), each a third-order Taylor prediction corrected by
    :func:`close_loop`. A sample fails (False) where a step does not close or the correction is
    not small against the step (the branch ends there, or would be left)."""
    lay = lay or layout(linkage)
    name = linkage.inputs[0]
    f_in = lay.names.index(name)
    if max_step is None:
        max_step = linkage.length_scale / 50 if lay.is_translation[f_in] else math.radians(2.0)
    x_from = np.asarray(x_from, dtype=float)
    x_to = np.asarray(x_to, dtype=float)
    n_steps = int(max(1, np.ceil(np.max(np.abs(x_to - x_from)) / max_step)))
    ok = np.ones(conf.size, dtype=bool)
    col = lay.scalar_col[f_in]
    rows, cols = _scales(linkage, lay)
    for s in range(1, n_steps + 1):
        h = (x_to - x_from) / n_steps
        jets = taylor_jets(linkage, conf, 3, lay)
        guess = _predict(linkage, lay, conf, jets, h)
        q = guess.scalars.copy()
        q[:, col] = x_from + (x_to - x_from) * (s / n_steps)
        closed, good = close_loop(linkage, Configuration(q, guess.spherical), lay)
        moved = np.abs(closed.scalars - q)  # the correction (q: the prediction at the input)
        scale = np.array([cols[f] for f in range(len(lay.names)) if lay.scalar_col[f] >= 0])
        shift = np.max(moved / scale[None, :], axis=-1) if moved.size else np.zeros(conf.size)
        good &= shift <= 1e-2 + 0.1 * np.abs(h) / (cols[f_in])
        ok &= good
        conf = closed
    return conf, ok

"""Newton's method and the rate equations on the stacked closure of a mechanism, batched.

Rows are scaled so lengths count in units of the mechanism's length scale L (a residual of 1e-12
means 1e-12 rad and 1e-12·L), and slide columns likewise, so ranks and tolerances mean the same
for a watch and a crane. Redundant constraints (a planar loop drawn in 3-D has three per loop)
make the stacked Jacobian rank-deficient by rows and idle freedoms (a rod's spin between two
balls) by columns: every solve is the minimum-norm least-squares one (the pseudo-inverse with a
relative cut-off), which is exact for the consistent closure equations and leaves idle freedoms
still.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import (
    GraphFrames,
    GraphLayout,
    body_twists,
    graph_forward,
    loop_bias,
    loop_jacobian,
)
from screwkit.kinematics.graph.small_linalg import gram_eigenvalues, qr_inverse
from screwkit.kinematics.tracker.loop import (
    Configuration,
    apply_increment,
    configuration_difference,
)
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

#: closure tolerance (scaled residual) a solved sample meets
CLOSURE_TOL = 1e-13
#: relative cut-off of the pseudo-inverse: singular values below this × the largest are rank
#: deficiency (redundant constraints, idle freedoms), not geometry
RANK_CUTOFF = 1e-9


def row_scale(lay: GraphLayout, loops: int) -> Array:
    """Per stacked row: 1 for rotations, 1/L for translations."""
    return _row_scale(lay.length, loops)


@lru_cache(maxsize=64)
def _row_scale(length: float, loops: int) -> Array:
    s = np.ones(6 * loops)
    for l in range(loops):
        s[6 * l + 3:6 * l + 6] = 1.0 / length
    s.setflags(write=False)
    return s


def column_scale(lay: GraphLayout) -> Array:
    """Per freedom: L for slides, 1 for rotations."""
    return _column_scale(lay.is_translation, lay.length)


@lru_cache(maxsize=64)
def _column_scale(is_translation: tuple[bool, ...], length: float) -> Array:
    s = np.where(np.array(is_translation, dtype=bool), length, 1.0)
    s.setflags(write=False)
    return s


def set_inputs(conf: Configuration, lay: GraphLayout, X: Array) -> Configuration:
    q = conf.scalars.copy()
    for k, f in enumerate(lay.inputs):
        q[:, lay.scalar_col[f]] = X[:, k]
    return Configuration(q, conf.spherical)


def increment(conf: Configuration, delta: Array, lay: GraphLayout) -> Configuration:
    """Move by freedom increments (scalars add; a ball turns by exp([δ]) in its own axes)."""
    return apply_increment(conf, delta, cast(Any, lay))


def difference(a: Configuration, b: Configuration, lay: GraphLayout) -> Array:
    """Freedom increments taking ``b`` to ``a`` (angles wrapped)."""
    return configuration_difference(a, b, cast(Any, lay))


@dataclass(frozen=True, eq=False)
class Linearised:
    """The scaled stacked Jacobian at a batch of configurations and its passive pseudo-inverse.

    ``J`` (N, 6L, m) scaled and ``Jp`` its passive columns; ``pinv`` (N, m_p, 6L), given (SVD,
    QR) or formed on first use from ``normal``, the regularised normal matrix JpᵀJp + μI of the
    tracker's route (whose corrector only needs :meth:`solve` with one right-hand side);
    ``sigma`` (N, k) the passive block's singular values, largest first (exact routes)."""

    frames: GraphFrames
    J: Array
    Jp: Array
    sigma: Array
    given_pinv: Array | None = None
    normal: Array | None = None

    @cached_property
    def pinv(self) -> Array:
        if self.given_pinv is not None:
            return self.given_pinv
        assert self.normal is not None
        return np.asarray(np.linalg.solve(self.normal, np.swapaxes(self.Jp, 1, 2)))

    def solve(self, rhs: Array) -> Array:
        """The passive solution (N, m_p) of J_p x = ``rhs`` (N, 6L) in the least-squares,
        minimum-norm sense of the route."""
        if self.normal is None or "pinv" in self.__dict__:
            return np.einsum("nij,nj->ni", self.pinv, rhs)
        b = np.einsum("nki,nk->ni", self.Jp, rhs)
        return np.linalg.solve(self.normal, b[..., None])[..., 0]

    def overwrite(self, index: NDArray[np.intp], part: Linearised) -> None:
        """Replace the samples ``index`` by ``part``'s, in place (this object's arrays are its
        own: Newton's work arrays of the normal-equation route)."""
        assert self.normal is not None and part.normal is not None
        self.__dict__.pop("pinv", None)
        for a, b in ((self.frames.R, part.frames.R), (self.frames.p, part.frames.p),
                     (self.frames.screws, part.frames.screws),
                     (self.frames.residual, part.frames.residual),
                     (self.frames.centres, part.frames.centres),
                     (self.frames.axes, part.frames.axes), (self.J, part.J), (self.Jp, part.Jp),
                     (self.normal, part.normal)):
            a[index] = b

    def take(self, index: slice | NDArray[np.intp]) -> Linearised:
        f = self.frames
        frames = GraphFrames(f.R[index], f.p[index], f.screws[index], f.residual[index],
                             f.centres[index], f.axes[index])
        pinv = self.pinv[index] if "pinv" in self.__dict__ or self.normal is None else None
        normal = None if self.normal is None else self.normal[index]
        return Linearised(frames, self.J[index], self.Jp[index], self.sigma[index], pinv,
                          normal)


def drawn_linearisation(mech: Mechanism, lay: GraphLayout) -> Linearised:
    """The exact linearisation (SVD route) at the drawing, every freedom 0: the ranks a
    regular sample keeps are read from it."""
    return linearise(mech, lay, Configuration(np.zeros((1, lay.n_scalar)), np.broadcast_to(
        np.eye(3), (1, lay.n_spherical, 3, 3)).copy()))


def linearise(mech: Mechanism, lay: GraphLayout, conf: Configuration,
              frames: GraphFrames | None = None, exact: bool = True,
              full_rank: bool = False) -> Linearised:
    """The scaled Jacobian and the passive block's pseudo-inverse: by the SVD (``exact``: the
    singular values too, for rank tests and singular flags) or, for the tracker's corrector and
    rates, by the normal equations with a Tikhonov term of 1e-14·tr(JᵀJ) (the minimum-norm
    solution up to that relative size; idle freedoms stay still). ``full_rank`` (a mechanism
    with no idle freedom) takes the exact route by a QR factorisation J_p = QR (the least-squares
    solution R⁻¹Qᵀ, exact for the consistent closure equations, with R's singular values, which
    are J_p's: those of J_pᵀJ_p = RᵀR, graph/small_linalg.py), and the SVD only where R is
    singular to working precision."""
    fr = frames if frames is not None else graph_forward(mech, lay, conf, exact)
    L = len(mech.topology.loops)
    J = (loop_jacobian(mech, lay, fr.screws) * row_scale(lay, L)[:, None]
         * column_scale(lay)[None, :])
    Jp = J[:, :, list(lay.passive)]
    if Jp.shape[1] == 0 or Jp.shape[2] == 0:
        N = conf.size
        return Linearised(fr, J, Jp, np.zeros((N, 0)),
                          np.zeros((N, Jp.shape[2], Jp.shape[1])))
    if not exact:
        JtJ = np.einsum("nki,nkj->nij", Jp, Jp)
        mu = 1e-14 * np.einsum("nii->n", JtJ)[:, None, None] + 1e-300
        return Linearised(fr, J, Jp, np.zeros((conf.size, 0)),
                          normal=JtJ + mu * np.eye(Jp.shape[2]))
    if full_rank and Jp.shape[1] >= Jp.shape[2]:
        s = gram_sigma(Jp)  # J_pᵀJ_p = RᵀR
        pinv = qr_inverse(Jp)[0]
        bad = ~(s[:, -1] > RANK_CUTOFF * s[:, 0])
        if bad.any():
            pinv[bad] = _svd_pinv(Jp[bad])[0]
        return Linearised(fr, J, Jp, s, pinv)
    pinv, s = _svd_pinv(Jp)
    return Linearised(fr, J, Jp, s, pinv)


#: σ_r/σ₁ below which :func:`gram_sigma` takes the SVD: above it the Gram route's relative
#: error in σ_r, ~ε·(σ₁/σ_r)², is below 1e-12
GRAM_REFINE = 1e-2


def gram_sigma(A: Array, rank: int | None = None) -> Array:
    """Singular values (N, k) of A (N, a, b), largest first, k = min(a, b): the square roots of
    the eigenvalues of the smaller Gram matrix AᵀA or AAᵀ (Golub & Van Loan, Matrix
    Computations, 4th ed., §8.6: σᵢ² = λᵢ(AᵀA); graph/small_linalg.py), several times faster
    than the SVD for these small shapes. Its error in σᵢ is ~ε·σ₁²/σᵢ, so at the samples where σ_r/σ₁ (r = ``rank``,
    default k) is below :data:`GRAM_REFINE` the SVD's values are taken instead: rank tests and
    singular flags see the SVD's values and condition numbers change at round-off level. A
    sample with a non-finite entry gets NaN."""
    if A.shape[0] == 0 or min(A.shape[1:]) == 0:
        return np.zeros((A.shape[0], min(A.shape[1:])))
    lam = gram_eigenvalues(A)  # NaN at a sample with a non-finite entry
    s = np.sqrt(np.maximum(lam, 0.0))
    ok = ~np.isnan(lam[:, 0])
    r = s.shape[1] if rank is None else rank
    redo = ok & ~(s[:, r - 1] > GRAM_REFINE * s[:, 0]) if r else np.zeros(len(s), bool)
    if redo.any():
        s[redo] = np.linalg.svd(A[redo], compute_uv=False)
    return s


def _svd_pinv(Jp: Array) -> tuple[Array, Array]:
    U, s, Vt = np.linalg.svd(Jp, full_matrices=False)
    keep = s > RANK_CUTOFF * np.maximum(s[:, :1], 1e-300)
    inv = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)
    return np.einsum("nji,nj,nkj->nik", Vt, inv, U), s


def scaled_residual(mech: Mechanism, lay: GraphLayout, fr: GraphFrames) -> Array:
    L = len(mech.topology.loops)
    return fr.residual.reshape(fr.residual.shape[0], 6 * L) * row_scale(lay, L)


def newton(mech: Mechanism, lay: GraphLayout, conf: Configuration, X: Array,
           max_iter: int = 8, tol: float = CLOSURE_TOL, exact: bool = True
           ) -> tuple[Configuration, Array, Linearised]:
    """Close every sample of ``conf`` at inputs ``X`` (N, n_in) by Newton's method on the
    passive freedoms. Returns the configurations, each sample's scaled residual norm and the
    linearisation at the result."""
    conf = set_inputs(conf, lay, X)
    cs = column_scale(lay)[list(lay.passive)]
    passive = list(lay.passive)
    lin = linearise(mech, lay, conf, exact=exact)
    err = np.linalg.norm(scaled_residual(mech, lay, lin.frames), axis=1)
    scal, sph = conf.scalars.copy(), conf.spherical.copy()
    for _ in range(max_iter):
        todo = np.nonzero(err > tol)[0]  # only the samples still open are worked on
        if not todo.size:
            break
        whole = todo.size == err.size
        sub = lin if whole else lin.take(todo)
        r = scaled_residual(mech, lay, sub.frames)
        step = np.zeros((todo.size, lay.m))
        step[:, passive] = -sub.solve(r) * cs
        moved = increment(Configuration(scal[todo], sph[todo]), step, lay)
        scal[todo], sph[todo] = moved.scalars, moved.spherical
        new = linearise(mech, lay, moved, exact=exact)
        if whole or lin.normal is None:
            lin = new if whole else _merged(lin, todo, new)
        else:
            lin.overwrite(todo, new)
        err[todo] = np.linalg.norm(scaled_residual(mech, lay, new.frames), axis=1)
    err = np.where(np.isfinite(err), err, np.inf)
    return Configuration(scal, sph), err, lin


def _merged(lin: Linearised, index: NDArray[np.intp], part: Linearised) -> Linearised:
    """``lin`` with the samples ``index`` replaced by ``part``'s (exact routes: copies)."""
    out = []
    f, g = lin.frames, part.frames
    for a, b in ((f.R, g.R), (f.p, g.p), (f.screws, g.screws), (f.residual, g.residual),
                 (f.centres, g.centres), (f.axes, g.axes), (lin.J, part.J), (lin.Jp, part.Jp),
                 (lin.sigma, part.sigma), (lin.pinv, part.pinv)):
        a = a.copy()
        a[index] = b
        out.append(a)
    return Linearised(GraphFrames(*out[:6]), out[6], out[7], out[8], out[9])


def rates(mech: Mechanism, lay: GraphLayout, lin: Linearised, Xd: Array) -> Array:
    """Every freedom's rate (N, m) for input rates ``Xd`` (N, n_in): J_p q̇_p = −J_in ẋ."""
    N = Xd.shape[0]
    cs = column_scale(lay)
    qd = np.zeros((N, lay.m))
    qd[:, list(lay.inputs)] = Xd
    rhs = -np.einsum("nij,nj->ni", lin.J[:, :, list(lay.inputs)],
                     Xd / cs[list(lay.inputs)])
    qd[:, list(lay.passive)] = lin.solve(rhs) * cs[list(lay.passive)]
    return qd


def accelerations(mech: Mechanism, lay: GraphLayout, lin: Linearised, qd: Array, Xdd: Array
                  ) -> tuple[Array, Array]:
    """Every freedom's acceleration (N, m) for input accelerations ``Xdd``: J_p q̈_p =
    −J_in ẍ − bias(q̇) (closure.loop_bias); also the joints' velocity-product terms."""
    qdd, bias, _ = accelerations_twists(mech, lay, lin, qd, Xdd)
    return qdd, bias


def accelerations_twists(mech: Mechanism, lay: GraphLayout, lin: Linearised, qd: Array,
                         Xdd: Array) -> tuple[Array, Array, Array]:
    """:func:`accelerations` and the body twists at ``qd`` it is built on (closure.body_twists'
    first result), for a caller that needs both."""
    N = Xdd.shape[0]
    L = len(mech.topology.loops)
    cs = column_scale(lay)
    V, bias = body_twists(mech, lay, lin.frames.screws, qd)
    qdd = np.zeros((N, lay.m))
    qdd[:, list(lay.inputs)] = Xdd
    rhs = -(np.einsum("nij,nj->ni", lin.J[:, :, list(lay.inputs)], Xdd / cs[list(lay.inputs)])
            + loop_bias(mech, bias) * row_scale(lay, L))
    qdd[:, list(lay.passive)] = lin.solve(rhs) * cs[list(lay.passive)]
    return qdd, bias, V

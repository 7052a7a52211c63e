"""Dense evaluation of a homotopy of quadrics: F_i(y; σ) = yᵀ Q_i(σ) y + L_i(σ)·y.

When every equation of a system has degree ≤ 2 in the unknowns (the Stewart–Gough system in
Study coordinates, the 6R loop in its axis directions, dense quadrics), its homogenisation
(:meth:`PolynomialSystem.homogenized`) is a set of homogeneous quadrics and linear forms in
y = (h, h·x). Along the parameter segment p(σ) = p_start + σ·d of a parameter homotopy
(Sommese & Wampler 2005, ch. 7) each coefficient is a polynomial in σ of degree D (the largest
total degree of a term in the parameters), so per instance

    F_i(y; σ) = Σ_{k=0..D} σ^k (yᵀ Q_ik y + L_ik·y),   Q_ik symmetric (m × m),

    ∂F_i/∂y = Σ_k σ^k (2 Q_ik y + L_ik),   ∂F_i/∂σ = Σ_k k σ^(k−1) (yᵀ Q_ik y + L_ik·y).

The σ-coefficients are exact: the coefficients at D+1 points σ_j = e^(2πij/(D+1)) on the unit
circle (:meth:`PolynomialSystem.coefficients_at`) give them by a discrete Fourier transform,
which is unitary, so no interpolation error is added. One evaluation for a set of paths is then
one matrix product y·[Q_ik] per instance (V_ik = Q_ik y for every i, k at once) and a few
contractions with the powers of σ, in place of the sparse term-by-term sums of
:mod:`.polynomial`: the same homotopy, evaluated in a different order (equal to rounding).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic.polynomial import Complex, PolynomialSystem

Index = NDArray[np.intp]


def dense_quadrics_apply(hsys: PolynomialSystem) -> bool:
    """Whether :class:`DenseQuadrics` applies to the homogenised system ``hsys``: every term of
    degree 1 or 2 in the unknowns (and so every equation, being homogeneous, a quadric or a
    linear form)."""
    unknown = hsys.sym < hsys.n
    degree = np.where(unknown, hsys.pw, 0).sum(axis=1)
    return bool(len(degree)) and bool(((degree >= 1) & (degree <= 2)).all())


@dataclass(frozen=True)
class _Plan:
    """What :meth:`DenseQuadrics.build` needs of a system apart from its parameter values:
    the σ-degree K − 1 and the K roots of unity; ``above`` (K, G) the σ^k above each
    monomial's parameter degree; the quadratic monomials ``quad`` and the sparse map
    ``cells`` (N·m·m × quad) of half of each coefficient onto its cells (j, l) and (l, j);
    the linear monomials ``lin``, their equations ``linear`` and the map ``forms``
    (N_L·m × lin)."""

    K: int
    roots: Complex
    above: NDArray[np.bool_]
    quad: Index
    cells: Any
    lin: Index
    linear: Index
    forms: Any


def _plan(hsys: PolynomialSystem) -> _Plan:
    """The :class:`_Plan` of ``hsys``, built once and kept on it."""
    plan = hsys.__dict__.get("_dense_plan")
    if plan is not None:
        return plan  # type: ignore[no-any-return]
    from scipy import sparse

    m, N = hsys.n, hsys.size
    param = hsys.sym >= hsys.n
    K = int(np.where(param, hsys.pw, 0).sum(axis=1).max(initial=0)) + 1
    eq, exps, _ = hsys.coefficients_at(np.zeros((1, hsys.k), dtype=complex))
    unknown_exps = np.zeros((len(hsys.eq), m), dtype=np.intp)
    rows = np.nonzero(~param)
    np.add.at(unknown_exps, (rows[0], hsys.sym[rows]), hsys.pw[rows])
    group = np.unique(np.column_stack([hsys.eq, unknown_exps]), axis=0,
                      return_inverse=True)[1].reshape(-1)
    top = np.zeros(len(eq), dtype=np.intp)
    np.maximum.at(top, group, np.where(param, hsys.pw, 0).sum(axis=1))
    degree = exps.sum(axis=1)
    quad = np.flatnonzero(degree == 2)
    # the two unknowns of each quadratic monomial (the same one twice for a square)
    pair = np.repeat(np.tile(np.arange(m), len(quad)), exps[quad].ravel()).reshape(-1, 2)
    where = np.concatenate([(eq[quad] * m + pair[:, 0]) * m + pair[:, 1],
                            (eq[quad] * m + pair[:, 1]) * m + pair[:, 0]])
    cells = sparse.csr_matrix((np.full(2 * len(quad), 0.5 + 0j),
                               (where, np.tile(np.arange(len(quad)), 2))),
                              shape=(N * m * m, len(quad)))
    lin = np.flatnonzero(degree == 1)
    linear = np.unique(eq[lin]).astype(np.intp)
    forms = sparse.csr_matrix((np.ones(len(lin), dtype=complex),
                               (np.searchsorted(linear, eq[lin]) * m + exps[lin].argmax(axis=1),
                                np.arange(len(lin)))), shape=(len(linear) * m, len(lin)))
    plan = _Plan(K, np.exp(2j * np.pi * np.arange(K) / K),
                 np.arange(K)[:, None] > top[None, :], quad, cells, lin, linear, forms)
    object.__setattr__(hsys, "_dense_plan", plan)
    return plan


@dataclass(frozen=True)
class DenseQuadrics:
    """The σ-coefficients of F^h(y; p_start + σ·d) for B instances (module docstring).

    ``Qt`` (B, m, C): row j, column c is Q_ik[l, j] (= Q_ik[j, l]) for (k, i, l) the c-th of
    the ``columns`` (flat indices into K·N·m) with a nonzero entry, so that y @ Qt[b] gives
    every nonzero (Q_ik y)_l at once; ``L`` (B_L, K_L, N_L, m): the linear forms of the
    equations ``linear`` (B_L = 1 when every instance has the same, K_L = 1 when they do not
    depend on σ)."""

    Qt: Complex
    columns: Index
    L: Complex
    linear: Index
    K: int
    N: int
    m: int

    @staticmethod
    def build(hsys: PolynomialSystem, p_start: Complex, direction: Complex) -> DenseQuadrics:
        """The coefficients of the instances whose segments start at the rows of ``p_start``
        (B, k) and move along the rows of ``direction`` (B, k)."""
        B, m, N = len(p_start), hsys.n, hsys.size
        plan = _plan(hsys)
        K = plan.K
        p = (p_start[:, None, :] + plan.roots[None, :, None] * direction[:, None, :])
        _, _, values = hsys.coefficients_at(p.reshape(B * K, -1))
        coef = np.fft.fft(values.reshape(B, K, -1), axis=1) / K  # (B, K, G): σ^k coefficients
        # a monomial's coefficient has σ-degree at most the largest parameter degree of its
        # terms: the higher σ^k (rounding noise of the transform) are exactly zero
        coef[:, plan.above] = 0.0
        # each quadratic monomial's coefficient split in halves over the cells (j, l), (l, j)
        cells = plan.cells @ coef[:, :, plan.quad].reshape(B * K, -1).T  # (N·m·m, B·K)
        Q = cells.T.reshape(B, K, N, m, m)
        forms = plan.forms @ coef[:, :, plan.lin].reshape(B * K, -1).T
        L = forms.T.reshape(B, K, len(plan.linear), m)
        if plan.lin.size:
            if not np.any(L[:, 1:]):
                L = L[:, :1]
            if np.all(L == L[:1]):
                L = L[:1]
        Qt = Q.transpose(0, 4, 1, 2, 3).reshape(B, m, K * N * m)
        # only the columns (k, i, l) with a nonzero entry take part in the product
        columns = np.flatnonzero(np.any(Qt != 0, axis=(0, 1))).astype(np.intp)
        return DenseQuadrics(np.ascontiguousarray(Qt[:, :, columns]), columns, L,
                             plan.linear, K, N, m)

    def matrices(self, b: int) -> Complex:
        """The symmetric Q_ik of instance b, (K, N, m, m)."""
        full = np.zeros((self.m, self.K * self.N * self.m), dtype=complex)
        full[:, self.columns] = self.Qt[b]
        return full.reshape(self.m, self.K, self.N, self.m).transpose(1, 2, 3, 0)

    def block(self, instance: Index) -> DenseBlock:
        """The layout of one set of paths (``instance`` (P,): each path's instance)."""
        if len(self.Qt) == 1:  # one instance: one product, no grouping
            zero = np.zeros(len(instance), dtype=np.intp)
            return DenseBlock(self, self.Qt, zero, zero, len(instance), self.L[:1])
        used, inverse, counts = np.unique(instance, return_inverse=True, return_counts=True)
        inverse = inverse.reshape(-1)
        order = np.argsort(inverse, kind="stable")
        slot = np.empty(len(instance), dtype=np.intp)
        starts = np.cumsum(counts) - counts
        slot[order] = np.arange(len(instance)) - np.repeat(starts, counts)
        Lp = self.L if len(self.L) == 1 else self.L[instance]
        return DenseBlock(self, self.Qt[used], inverse.astype(np.intp), slot,
                          int(counts.max(initial=0)), Lp)


@dataclass(frozen=True)
class DenseBlock:
    """:class:`DenseQuadrics` gathered for a set of paths: the matrices of the instances in
    use ``Qt`` (U, m, K·N·m), each path's index among them and slot within its instance (the
    paths of an instance are multiplied together, one matrix product per instance), and the
    linear forms ``L`` per path (or shared)."""

    dense: DenseQuadrics
    Qt: Complex
    group: Index
    slot: Index
    width: int
    L: Complex

    def evaluate(self, y: Complex, sigma: Complex, dsigma: Complex | None
                 ) -> tuple[Complex, Complex, Complex | None]:
        """F (P, N), ∂F/∂y (P, N, m) and, when ``dsigma`` is given, (∂F/∂σ)·dσ (P, N)."""
        d = self.dense
        P, K, N, m = len(y), d.K, d.N, d.m
        full = np.zeros((P, K * N * m), dtype=complex)
        if len(self.Qt) == 1:
            full[:, d.columns] = y @ self.Qt[0]
        else:
            padded = np.zeros((len(self.Qt), self.width, m), dtype=complex)
            padded[self.group, self.slot] = y
            full[:, d.columns] = np.matmul(padded, self.Qt)[self.group, self.slot]
        V = full.reshape(P, K, N, m)
        yV = np.matmul(V.reshape(P, K * N, m), y[:, :, None]).reshape(P, K, N)
        powers = np.ones((P, K), dtype=complex)
        for k in range(1, K):
            powers[:, k] = powers[:, k - 1] * sigma
        F = np.matmul(powers[:, None, :], yV)[:, 0]
        J = np.matmul(2.0 * powers[:, None, :], V.reshape(P, K, N * m)).reshape(P, N, m)
        Ft = None
        if dsigma is not None:
            slope = np.zeros((P, K), dtype=complex)
            for k in range(1, K):
                slope[:, k] = k * powers[:, k - 1] * dsigma
            Ft = np.matmul(slope[:, None, :], yV)[:, 0]
        if len(d.linear):
            KL = self.L.shape[1]
            forms = np.broadcast_to(self.L, (P, *self.L.shape[1:]))
            if KL == 1:  # the forms do not move with σ (a patch): no ∂/∂σ term
                Ls = self.L[:, 0]  # (1 or P, N_L, m)
            else:
                Ls = np.einsum("pk,pkem->pem", powers[:, :KL], forms)
            if len(Ls) == 1:  # shared by every path: one product
                Fl = y @ Ls[0].T
            else:
                Fl = np.matmul(Ls, y[:, :, None])[..., 0]
            for e, row in enumerate(d.linear):  # basic indexing: in place, no gather
                F[:, row] += Fl[:, e]
                J[:, row] += Ls[:, e]
            if Ft is not None and KL > 1:
                Lt = np.einsum("pk,pkem->pem", slope[:, :KL], forms)
                Ft[:, d.linear] += np.matmul(Lt, y[:, :, None])[..., 0]
        return F, J, Ft

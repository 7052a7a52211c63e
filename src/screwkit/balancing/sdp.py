"""The bound on what any redistribution of mass can achieve: every inertial parameter of the
chosen links is a variable, each link keeps its mass and stays physically realisable — its
pseudo-inertia matrix J(π) ⪰ 0 (Wensing, Kim & Slotine 2017) — and its mass stays inside a
given ellipsoid (tr(Q_E·J) ≥ 0). A semidefinite program with a quadratic objective, solved by
Clarabel's positive-semidefinite cone (no modelling layer needed).

Any point-mass or counterweight design that keeps the link masses and stays inside the
ellipsoids is feasible here, so the optimum is a lower bound on the objective of those designs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.balancing.balance import BalancingSetup
from screwkit.balancing.errors import BalancingError, SolverError
from screwkit.balancing.measures import MEASURES
from screwkit.balancing.problem import check_weights, consistency_constraints, quadratic_objective
from screwkit.balancing.qp import load_clarabel
from screwkit.balancing.variables import (
    DesignVariables,
    LinearConstraint,
    VariableBlock,
    moving_parts,
    part_word,
)
from screwkit.messages import given, listing
from screwkit.model.mass import N_INERTIAL_PARAMETERS, MassProperties

Array = NDArray[np.float64]


def pseudo_inertia_map() -> tuple[Array, Array]:
    """(G, order): svec(J(π)) = G·π for one link, svec the upper triangle of the 4×4 J in
    column-major order with off-diagonals × √2 (Clarabel's PSD-triangle cone)."""
    r2 = np.sqrt(2.0)
    # J = [[Σ, h], [hᵀ, m]], Σ = ½tr(I)·1 − I; π = (m, hx, hy, hz, Ixx, Iyy, Izz, Ixy, Ixz, Iyz)
    entries: list[tuple[tuple[int, int], dict[int, float]]] = [
        ((0, 0), {4: -0.5, 5: 0.5, 6: 0.5}),
        ((0, 1), {7: -1.0}), ((1, 1), {4: 0.5, 5: -0.5, 6: 0.5}),
        ((0, 2), {8: -1.0}), ((1, 2), {9: -1.0}), ((2, 2), {4: 0.5, 5: 0.5, 6: -0.5}),
        ((0, 3), {1: 1.0}), ((1, 3), {2: 1.0}), ((2, 3), {3: 1.0}), ((3, 3), {0: 1.0}),
    ]
    G = np.zeros((10, N_INERTIAL_PARAMETERS))
    for row, ((i, j), coeffs) in enumerate(entries):
        for col, c in coeffs.items():
            G[row, col] = c * (r2 if i != j else 1.0)
    return G, np.array([i * 4 + j for (i, j), _ in entries])


def ellipsoid_row(centre: ArrayLike, semi_axes: ArrayLike) -> Array:
    """a with a·π_link = tr(Q_E·J(π)) = ∫(1 − |D⁻¹(p − c)|²) dm (≥ 0 for a body inside the
    ellipsoid with centre c and semi-axes D along the link axes)."""
    c = np.asarray(centre, dtype=float)
    d = np.asarray(semi_axes, dtype=float)
    if c.shape != (3,) or d.shape != (3,) or np.any(d <= 0):
        raise BalancingError(f"ellipsoid needs a centre (3) and 3 positive semi-axes; got "
                             f"{given(centre)} and {given(semi_axes)}")
    w = 1.0 / d**2
    # ∫ 1 dm = m;  ∫ w·(p − c)² dm = Σ w_k (Σ_kk − 2 c_k h_k + c_k² m)
    a = np.zeros(N_INERTIAL_PARAMETERS)
    a[0] = 1.0 - float(w @ c**2)
    a[1:4] = 2.0 * w * c
    sigma_rows = np.array([[-0.5, 0.5, 0.5], [0.5, -0.5, 0.5], [0.5, 0.5, -0.5]])  # Σ_kk in I
    a[4:7] = -(w @ sigma_rows)
    return a


@dataclass(frozen=True)
class RedistributionBound:
    """Optimum of the SDP: the measures before/after and the new mass properties."""

    measures_before: dict[str, float]
    measures_after: dict[str, float]
    mass_properties_after: dict[str, MassProperties]
    status: str


def redistribution_bound(
    setup: BalancingSetup,
    weights: Mapping[str, float],
    ellipsoids: Mapping[str, tuple[ArrayLike, ArrayLike]],
) -> RedistributionBound:
    """Lower bound of the weighted objective over every physically consistent redistribution
    of the mass of the links in ``ellipsoids`` ({link: (centre, semi_axes)}, link frame, m)."""
    from scipy import sparse

    clarabel = load_clarabel()
    w = check_weights(weights)
    parts = moving_parts(setup.linkage)
    names = [link.name for link in parts]
    unknown = sorted(set(ellipsoids) - set(names))
    if unknown or not ellipsoids:
        raise BalancingError(f"ellipsoids must name moving {part_word(setup.linkage)}s among "
                             f"{listing(names)}; got {listing(ellipsoids)}")
    P = N_INERTIAL_PARAMETERS * len(names)
    pi0 = np.concatenate([link.mass.inertial_parameters() for link in parts
                          if link.mass is not None])
    blocks = []
    for link in ellipsoids:
        k = names.index(link)
        basis = np.zeros((P, N_INERTIAL_PARAMETERS))
        basis[k * N_INERTIAL_PARAMETERS:(k + 1) * N_INERTIAL_PARAMETERS] = np.eye(
            N_INERTIAL_PARAMETERS)
        orig = pi0[k * N_INERTIAL_PARAMETERS:(k + 1) * N_INERTIAL_PARAMETERS]
        blocks.append(VariableBlock(tuple(f"{link}.{p}" for p in range(10)), link, basis, orig,
                                    np.full(10, max(abs(orig).max(), 1e-12)), kind="full"))
    basis = np.concatenate([b.basis for b in blocks], axis=1)
    fixed = pi0 - basis @ np.concatenate([b.original for b in blocks])
    n = basis.shape[1]
    variables = DesignVariables(tuple(nm for b in blocks for nm in b.names),
                                tuple(b.link for b in blocks for _ in b.names), basis, fixed,
                                np.concatenate([b.original for b in blocks]),
                                np.concatenate([b.scale for b in blocks]), (), tuple(blocks))
    obj = quadratic_objective(setup.rows, variables, w)
    eq: list[LinearConstraint] = consistency_constraints(setup.regressor, variables)
    le: list[Array] = []
    G, _ = pseudo_inertia_map()
    psd_rows = []
    for j, (link, (centre, axes)) in enumerate(ellipsoids.items()):
        sl = slice(10 * j, 10 * (j + 1))
        a = np.zeros(n)
        a[10 * j] = 1.0
        eq.append(LinearConstraint(f"{link}: mass = original", a, "eq", float(pi0[
            names.index(link) * 10])))
        row = np.zeros(n)
        row[sl] = -ellipsoid_row(centre, axes)
        le.append(row)
        if -row[sl] @ variables.original[sl] < -1e-9 * variables.original[sl][0]:
            raise BalancingError(f"link {link!r}: the original body is not inside the ellipsoid")
        block = np.zeros((10, n))
        block[:, sl] = G
        psd_rows.append(block)
    S = variables.scale
    Q = S[:, None] * obj.Q * S[None, :]
    kappa = max(float(np.abs(Q).max()), 1e-300)
    A = np.vstack([np.array([c.coefficients for c in eq]).reshape(-1, n), np.array(le),
                   *[-r for r in psd_rows]]) * S[None, :]
    b = np.concatenate([[c.bound for c in eq], np.zeros(len(le)),
                        np.zeros(10 * len(psd_rows))])
    cones = [clarabel.ZeroConeT(len(eq)), clarabel.NonnegativeConeT(len(le))]
    cones += [clarabel.PSDTriangleConeT(4) for _ in psd_rows]
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    solver = clarabel.DefaultSolver(sparse.csc_matrix(np.triu(2 * Q / kappa)),
                                    2 * S * obj.q / kappa, sparse.csc_matrix(A), b, cones,
                                    settings)
    sol = solver.solve()
    if "Solved" not in str(sol.status):
        raise SolverError(f"the redistribution SDP stopped with status {sol.status}")
    x = np.asarray(sol.x) * S
    pi = variables.parameters(x)
    props = {}
    for link in ellipsoids:
        k = names.index(link)
        props[link] = MassProperties.from_inertial_parameters(pi[10 * k:10 * (k + 1)])
    return RedistributionBound(obj.measures(variables.original), obj.measures(x), props,
                               str(sol.status))


__all__ = ["MEASURES", "RedistributionBound", "ellipsoid_row", "pseudo_inertia_map",
           "redistribution_bound"]

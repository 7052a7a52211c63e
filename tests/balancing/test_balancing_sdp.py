"""The redistribution bound (SDP over full inertial parameters with J ⪰ 0)."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.balancing import point_mass_variables, prepare, solve_setup
from screwkit.balancing.measures import MEASURES
from screwkit.balancing.sdp import ellipsoid_row, pseudo_inertia_map, redistribution_bound
from screwkit.balancing.variables import point_parameters
from screwkit.model.mass import MassProperties

INCH = 0.0254
ELLIPSOIDS = {"crank": ([1 * INCH, 0, 0], [1.5 * INCH, 0.5 * INCH, 0.5 * INCH]),
              "rod": ([4 * INCH, 0, 0], [5 * INCH, 0.5 * INCH, 0.5 * INCH])}


def test_pseudo_inertia_map_matches_mass_properties():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(3, 3))
    mp = MassProperties.from_principal(1.7, rng.normal(size=3), [1.0, 1.5, 2.0],
                                      np.linalg.qr(A)[0] * np.sign(np.linalg.det(np.linalg.qr(A)[0])))
    G, order = pseudo_inertia_map()
    J = mp.pseudo_inertia()
    want = np.array([J[k // 4, k % 4] * (1 if k // 4 == k % 4 else np.sqrt(2)) for k in order])
    np.testing.assert_allclose(G @ mp.inertial_parameters(), want, rtol=1e-12, atol=1e-12)


def test_ellipsoid_row_of_a_point_mass():
    c, d = np.array([0.1, -0.2, 0.3]), np.array([0.5, 0.2, 0.1])
    p = np.array([0.3, -0.1, 0.32])
    want = 1.0 - np.sum(((p - c) / d) ** 2)
    assert ellipsoid_row(c, d) @ point_parameters(p) == pytest.approx(want, rel=1e-12)


def test_bound_is_below_every_mass_keeping_point_mass_design(rahman):
    spec, mode = rahman
    lk = spec.linkage
    setup = prepare(lk, mode, [point_mass_variables(lk, "crank", link_mass="equal"),
                               point_mass_variables(lk, "rod", link_mass="equal")],
                    speed=spec.speed)
    w = dict.fromkeys(MEASURES, 1.0)
    qp = solve_setup(setup, w)
    bound = redistribution_bound(setup, w, ELLIPSOIDS)
    # the seven-point designs lie inside the ellipsoids and keep the masses: feasible for the SDP
    assert bound.measures_after["G"] <= qp.measures_after["G"] * (1 + 1e-7)
    assert bound.measures_after["G"] < 0.95 * qp.measures_after["G"]
    for link, mp in bound.mass_properties_after.items():
        assert mp.mass == pytest.approx(lk.links[[x.name for x in lk.links].index(link)]
                                        .mass.mass, rel=1e-9)
        # realisable inside its ellipsoid (interior-point accuracy, hence 1e-6)
        assert ellipsoid_row(*ELLIPSOIDS[link]) @ mp.inertial_parameters() >= -1e-6 * mp.mass
    # the S-S rod stays axisymmetric about its axis (idle spin)
    rod = bound.mass_properties_after["rod"]
    assert rod.inertia[1, 1] == pytest.approx(rod.inertia[2, 2], rel=1e-6)

"""Counterweights: complete shaking-force balance of a 4R (Berkof–Lowen: counterweights on
the crank and the rocker suffice), checked by running the dynamics; bad input."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.balancing import (
    BalancingError,
    InfeasibleConstraintsError,
    balance,
    counterweight_variables,
    point_mass_variables,
    prepare,
    solve_setup,
)
from screwkit.balancing.pareto import pareto_front
from screwkit.balancing.problem import solve_balancing
from screwkit.balancing.variables import LinearConstraint
from screwkit.dynamics import inverse_dynamics
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
from screwkit.model.families import fourbar
from screwkit.model.linkage import Link
from screwkit.model.mass import MassProperties


@pytest.fixture(scope="module")
def fourbar_mode():
    lk = fourbar(0.30, 0.10, 0.28, 0.22).with_links([
        Link("crank", MassProperties(0.4, [0.05, 0.0, 0.0], np.diag([1e-5, 4e-4, 4e-4]))),
        Link("coupler", MassProperties(0.9, [0.12, 0.01, 0.0], np.diag([2e-5, 6e-3, 6e-3]))),
        Link("rocker", MassProperties(0.7, [0.10, 0.0, 0.0], np.diag([1e-5, 3e-3, 3e-3]))),
    ])
    m = motion(lk, np.radians(np.arange(0, 360, 15)), 20.0, 0.0)
    return lk, m.modes[0]


def _free_cw(lk, link):
    return counterweight_variables(lk, link, f"cw_{link}", mass_max=20.0,
                                   box=([-1.0, -1.0, -0.1], [1.0, 1.0, 0.1]))


def test_free_counterweights_make_centre_of_mass_stationary(fourbar_mode):
    lk, mode = fourbar_mode
    res = balance(lk, mode, [_free_cw(lk, "crank"), _free_cw(lk, "rocker")], {"F": 1.0},
                  speed=20.0)
    assert res.measures_before["F"] > 1e-3
    # complete balance: the optimum is (numerically) zero
    assert res.measures_after["F"] <= 1e-12 * res.measures_before["F"]
    new = lk.with_links([Link(n, mp) for n, mp in res.mass_properties_after.items()])
    dyn = inverse_dynamics(new, mode)
    peak_before = np.max(np.linalg.norm(res.dynamics_before.shaking_force, axis=-1))
    assert np.max(np.linalg.norm(dyn.shaking_force, axis=-1)) <= 1e-6 * peak_before


def test_fixed_counterweight_on_crank_balances_its_own_centre(fourbar_mode):
    """Only the crank moves in this test's loads: the crank counterweight at −c·m/μ."""
    lk, mode = fourbar_mode
    blocks = [counterweight_variables(lk, "crank", "cw", mass_max=1.0, at=[-0.04, 0.0, 0.0])]
    res = balance(lk, mode, blocks, {"F": 1.0, "T0": 0.5}, speed=20.0)
    assert res.after[0] > 0
    assert res.measures_after["F"] < res.measures_before["F"]


def test_free_counterweight_refuses_second_moment_measures(fourbar_mode):
    lk, mode = fourbar_mode
    with pytest.raises(BalancingError, match="second moments"):
        balance(lk, mode, [_free_cw(lk, "crank")], {"F": 1.0, "T": 1.0}, speed=20.0)


def test_all_zero_weights(fourbar_mode):
    lk, mode = fourbar_mode
    with pytest.raises(BalancingError, match="all weights are zero"):
        balance(lk, mode, [_free_cw(lk, "crank")], {"F": 0.0}, speed=20.0)


def test_no_variables_and_bad_link(fourbar_mode):
    lk, mode = fourbar_mode
    with pytest.raises(BalancingError, match="no design variables"):
        balance(lk, mode, [], {"F": 1.0}, speed=20.0)
    with pytest.raises(BalancingError, match="no moving link named 'crnak'"):
        point_mass_variables(lk, "crnak")
    with pytest.raises(BalancingError, match="non-empty subset"):
        point_mass_variables(lk, "crank", variables=[])


def test_infeasible_constraints_are_named(fourbar_mode):
    lk, mode = fourbar_mode
    setup = prepare(lk, mode, [point_mass_variables(lk, "crank", link_mass="equal")],
                    speed=20.0)
    v = setup.variables
    a = np.zeros(len(v.names))
    a[0] = -1.0
    clash = LinearConstraint("crank.m1 >= 2 x original", a, "le", -2 * v.original[0] * 2)
    from screwkit.balancing.problem import quadratic_objective

    obj = quadratic_objective(setup.rows, v, {"F": 1.0})
    with pytest.raises(InfeasibleConstraintsError) as exc:
        solve_balancing(obj, v, [clash])
    assert "crank.m1 >= 2 x original" in exc.value.conflicting
    assert "crank: link mass = original" in exc.value.conflicting


def test_pareto_front(fourbar_mode):
    lk, mode = fourbar_mode
    setup = prepare(lk, mode, [point_mass_variables(lk, "crank", max_increase=0.5),
                               point_mass_variables(lk, "rocker", max_increase=0.5)],
                    speed=20.0)
    front = pareto_front(setup, ("F", "T", "T0"), divisions=2)
    assert front.measures.shape == (6, 3) and front.efficient.any()
    only_f = solve_setup(setup, {"F": 1.0}).measures_after["F"]
    assert np.all(front.measures[:, 0] >= only_f * (1 - 1e-9))

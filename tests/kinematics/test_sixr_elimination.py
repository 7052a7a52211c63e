"""The 6R loop by elimination (modes/sixr_elimination.py, modes/loop6r_solve.py), checked against
the parameter homotopy (a second method), the product-of-exponentials forward kinematics of the
arm (a closure the polynomial system does not contain) and the graph tracker's loop closure.

``SCREWKIT_MODES_INSTANCES`` sets the number of random instances (default 200).
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

from modes_helpers import random_r_loop
from screwkit.algebraic.solve import Solutions, solve_all
from screwkit.errors import InputError
from screwkit.kinematics.graph.closure import graph_forward
from screwkit.kinematics.modes.arm6r import (
    Arm6RInstance,
    arm6r_instance,
    arm_forward,
    arm_inverse_kinematics,
)
from screwkit.kinematics.modes.every_mode import every_mode
from screwkit.kinematics.modes.loop6r import loop6r_start, loop6r_system, random_loop6r
from screwkit.kinematics.modes.loop6r_solve import ELIMINATION, HOMOTOPY, solve_loop6r
from screwkit.kinematics.modes.r_loop import r_loop_instance
from screwkit.kinematics.modes.sixr_elimination import OFFSETS, eliminate, fit_residual

INSTANCES = int(os.environ.get("SCREWKIT_MODES_INSTANCES", "200"))
#: solutions of the two routes agree to this, relative to 1 + the largest coordinate (the axes
#: are unit vectors in the bilinear sense; a complex solution's coordinates can be large)
MATCH = 1e-8
#: every real solution's forward kinematics gives the target back to this (unit-scale arms)
CLOSE = 1e-10


def _matched(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance from a point of either set to the nearest of the other."""
    if len(a) == 0 or len(b) == 0:
        return 0.0 if len(a) == len(b) else np.inf
    d = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2) / (
        1.0 + np.maximum(np.abs(a).max(axis=1)[:, None], np.abs(b).max(axis=1)[None, :]))
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


def _same_as_homotopy(sol: Solutions, p: np.ndarray) -> None:
    hom = solve_all(loop6r_system(), p, loop6r_start())
    assert np.array_equal(sol.found, hom.found)
    assert np.array_equal(sol.real_count, hom.real_count)
    worst = max(_matched(sol.of(b), hom.of(b)) for b in range(len(p)))
    assert worst <= MATCH, worst


def _random_arm(rng: np.random.Generator, q: np.ndarray | None = None
                ) -> tuple[tuple, Arm6RInstance, np.ndarray]:
    C, U = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    U /= np.linalg.norm(U, axis=1)[:, None]
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    home = (Q * np.sign(np.linalg.det(Q)), rng.normal(size=3))
    q = rng.uniform(-np.pi, np.pi, 6) if q is None else q
    target = arm_forward(C, U, home, q)
    return (C, U, home, target), arm6r_instance(C, U, home, target), q


def _arm_check(arms: list[tuple], insts: list[Arm6RInstance], truth: list[np.ndarray],
               sol: Solutions) -> None:
    """Every real solution's forward kinematics is the target; the generating q is among
    them."""
    worst = 0.0
    for b, inst in enumerate(insts):
        q = inst.joint_values(sol.x[(sol.instance == b) & sol.real])
        gap = np.abs(np.mod(q - truth[b] + np.pi, 2 * np.pi) - np.pi).max(axis=1)
        assert len(q) and gap.min() <= MATCH, b
        C, U, home, (Rt, pt) = arms[b]
        for row in q:
            R, p = arm_forward(C, U, home, row)
            worst = max(worst, float(np.abs(R - Rt).max() + np.abs(p - pt).max()))
    assert worst <= CLOSE, worst


@pytest.mark.parametrize("complex_values", [False, True])
def test_the_fitted_structure_holds_to_round_off(complex_values: bool) -> None:
    """The 14 quantities lie in the span of the Raghavan–Roth bases: fitted on 5 samples per
    angle (a degree-2 or -3 term would not alias), the residual is round-off."""
    p, _ = random_loop6r(np.random.default_rng(20), 50, complex_values)
    assert fit_residual(p if complex_values else p.real).max() <= 1e-12


def test_the_eigen_route_gives_the_homotopys_16_on_random_loops() -> None:
    p, x = random_loop6r(np.random.default_rng(21), INSTANCES)
    p = p.real
    sol = solve_loop6r(p)
    assert sol.route == (ELIMINATION,) * INSTANCES
    assert np.all(sol.found == 16) and sol.certified.mean() >= 0.99
    assert np.all(sol.at_infinity == 0) and np.all(sol.failed == 0)
    _same_as_homotopy(sol, p)
    for b in range(INSTANCES):  # the loop was drawn at one of them
        assert np.abs(sol.of(b) - x[b].real).max(axis=1).min() <= MATCH


def test_a_complex_instance_has_its_16_too() -> None:
    p, x = random_loop6r(np.random.default_rng(22), 20, complex_values=True)
    sol = solve_loop6r(p)
    assert sol.route == (ELIMINATION,) * 20 and np.all(sol.found == 16)
    _same_as_homotopy(sol, p)
    for b in range(20):
        assert np.abs(sol.of(b) - x[b]).max(axis=1).min() <= MATCH


def test_arm_inverse_kinematics_closes_by_the_forward_kinematics() -> None:
    rng = np.random.default_rng(23)
    arms, insts, truth = [], [], []
    for _ in range(INSTANCES):
        arm, inst, q = _random_arm(rng)
        arms.append(arm)
        insts.append(inst)
        truth.append(q)
    sol = solve_loop6r(np.array([i.params for i in insts]))
    assert sum(r == ELIMINATION for r in sol.route) >= 0.99 * INSTANCES
    assert np.all(sol.found == 16)
    _arm_check(arms, insts, truth, sol)


def test_a_batch_gives_what_each_instance_gives_alone() -> None:
    p, _ = random_loop6r(np.random.default_rng(24), 8)
    p = p.real
    batch = solve_loop6r(p)
    for b in range(len(p)):
        alone = solve_loop6r(p[b])
        assert alone.found[0] == batch.found[b] and alone.route[0] == batch.route[b]
        assert np.abs(alone.of(0) - batch.of(b)).max() <= 1e-12


def _arm_with_theta3(rng: np.random.Generator, theta3: float
                     ) -> tuple[tuple, Arm6RInstance, np.ndarray]:
    """A random arm at random joint values except that the loop's angle at joint 3 (the
    Denavit–Hartenberg θ3) is ``theta3``."""
    C, U = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    U /= np.linalg.norm(U, axis=1)[:, None]
    home = (np.eye(3), rng.normal(size=3))
    q = rng.uniform(-np.pi, np.pi, 6)
    q[2] = theta3 - arm6r_instance(C, U, home, home).home_angles[2]
    target = arm_forward(C, U, home, q)
    return (C, U, home, target), arm6r_instance(C, U, home, target), q


def test_a_solution_at_theta3_pi_is_found_by_elimination() -> None:
    """θ3 = π is x3 = ∞ of the plain half-angle tangent; the shifted tangent has it finite."""
    rng = np.random.default_rng(25)
    for _ in range(5):
        arm, inst, q = _arm_with_theta3(rng, np.pi)
        sol = solve_loop6r(inst.params)
        assert sol.route == (ELIMINATION,)
        _arm_check([arm], [inst], [q], sol)


def test_a_solution_at_the_shifted_infinity_falls_back_or_is_found() -> None:
    """θ3 = π + φ3 puts x3 at ∞ (the leading matrix singular): either the eigen route still
    certifies 16 or the homotopy runs; the answer is the homotopy's either way."""
    rng = np.random.default_rng(26)
    for _ in range(3):
        arm, inst, q = _arm_with_theta3(rng, np.pi + OFFSETS[0])
        sol = solve_loop6r(inst.params)
        _same_as_homotopy(sol, inst.params[None])
        _arm_check([arm], [inst], [q], sol)


def test_a_spherical_wrist_arm_falls_back_to_the_homotopy() -> None:
    """A PUMA-like arm (the last three axes through one point, the first three general) has
    8 solutions, not 16: elimination cannot certify 16, the homotopy runs, and every real
    solution closes."""
    rng = np.random.default_rng(27)
    C, U = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    C[3:] = C[3]  # the wrist centre
    U /= np.linalg.norm(U, axis=1)[:, None]
    home = (np.eye(3), rng.normal(size=3))
    q = rng.uniform(-np.pi, np.pi, 6)
    target = arm_forward(C, U, home, q)
    inst = arm6r_instance(C, U, home, target)
    sol = solve_loop6r(inst.params)
    assert sol.route == (HOMOTOPY,)
    assert sol.found[0] < 16
    _same_as_homotopy(sol, inst.params[None])
    _arm_check([(C, U, home, target)], [inst], [q], sol)


def test_7r_loops_go_by_elimination_and_close_in_the_graph() -> None:
    rng = np.random.default_rng(28)
    mechs = [random_r_loop(rng, 7, [int(rng.integers(7))]) for _ in range(20)]
    worst = 0.0
    for mech in mechs:
        x = [float(rng.uniform(-np.pi, np.pi))]
        inst = r_loop_instance(mech, x)
        sol = solve_loop6r(inst.params)
        assert sol.route == (ELIMINATION,) and sol.found[0] == 16
        real = sol.x[sol.real]
        if len(real):
            conf, lay = inst.configuration(real)
            worst = max(worst, float(np.abs(graph_forward(mech, lay, conf).residual).max()))
    assert worst <= CLOSE
    modes = every_mode(mechs[0], [[0.0], [0.5]])
    assert ELIMINATION in modes.how_found and np.all(modes.found == 16)


def test_bad_parameters_are_input_errors() -> None:
    with pytest.raises(InputError, match="shape"):
        solve_loop6r(np.zeros(22))
    with pytest.raises(InputError, match="finite"):
        solve_loop6r(np.full(23, np.nan))


def test_parameters_without_a_dh_chain_go_to_the_homotopy() -> None:
    """Parallel ground axes (z1 = z6) or cos α1 = 1 leave no Denavit–Hartenberg chain (a zero
    sin α): the elimination marks those instances unsettled, without an error or a warning
    for the batch, and the homotopy solves them; the others of the batch stay by elimination."""
    p, _ = random_loop6r(np.random.default_rng(29), 4)
    p = p.real.copy()
    p[1, 3:6] = p[1, 0:3]
    p[2, 6] = 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = solve_loop6r(p)
    assert sol.route == (ELIMINATION, HOMOTOPY, HOMOTOPY, ELIMINATION)
    _same_as_homotopy(sol, p)


def test_arm_inverse_kinematics_gives_the_joint_values_back() -> None:
    (C, U, home, target), _, q = _random_arm(np.random.default_rng(30))
    values, sol = arm_inverse_kinematics(C, U, home, target)
    assert sol.route == (ELIMINATION,) and sol.found[0] == 16 and len(values) == sol.real_count[0]
    assert np.abs(np.mod(values - q + np.pi, 2 * np.pi) - np.pi).max(axis=1).min() <= MATCH
    for row in values:
        R, p = arm_forward(C, U, home, row)
        assert np.abs(R - target[0]).max() + np.abs(p - target[1]).max() <= CLOSE


def _dh_arm(alpha: np.ndarray, a: np.ndarray, d: np.ndarray) -> tuple:
    """Joint lines at home (every θ = 0) and the home tool pose of the Denavit–Hartenberg arm
    A_i = Trans_z(d_i)·Trans_x(a_i)·Rot_x(α_i)."""
    T, C, U = np.eye(4), [], []
    for al, ai, di in zip(alpha, a, d, strict=True):
        C.append(T[:3, 3].copy())
        U.append(T[:3, 2].copy())
        A = np.eye(4)
        A[:3, :3] = [[1, 0, 0], [0, np.cos(al), -np.sin(al)], [0, np.sin(al), np.cos(al)]]
        A[:3, 3] = [ai, 0.0, di]
        T = T @ A
    return np.array(C), np.array(U), (T[:3, :3], T[:3, 3])


def test_arms_with_meeting_axes_go_by_elimination_relabelled() -> None:
    """Twists of ±90° and a_1 = a_4 = 0 (axes 1–2 and 4–5 meet)
    make the pencil singular in the first labelling; a cyclic relabelling settles all 16, and
    they are the homotopy's."""
    rng = np.random.default_rng(31)
    arms, insts, truth = [], [], []
    for _ in range(10):
        C, U, home = _dh_arm(rng.choice([-1.0, 1.0], 6) * np.pi / 2,
                             np.array([0.0, 0.8, 0.3, 0.0, 0.2, 0.1]), rng.uniform(-1, 1, 6))
        q = rng.uniform(-np.pi, np.pi, 6)
        target = arm_forward(C, U, home, q)
        arms.append((C, U, home, target))
        insts.append(arm6r_instance(C, U, home, target))
        truth.append(q)
    p = np.array([i.params for i in insts])
    assert np.isnan(eliminate(p, 0)[0]).any(axis=(1, 2)).all()  # the first labelling fails
    sol = solve_loop6r(p)
    assert sol.route == (ELIMINATION,) * 10 and np.all(sol.found == 16)
    _same_as_homotopy(sol, p)
    _arm_check(arms, insts, truth, sol)

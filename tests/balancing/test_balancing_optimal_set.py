"""Uniqueness and extent of a QP's optimal set (screwkit.balancing.optimal_set) on small
hand-made problems with known answers: an optimum at a vertex, on an edge and in the interior;
a set with no end; a solver failure ("could not determine", never ±inf); and one spec through
``screwkit balance`` whose every variable ends on a bound (reported non-unique with ranges
-inf … inf before)."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from screwkit.balancing.optimal_set import optimal_set
from screwkit.balancing.qp import solve_qp
from screwkit.cli.main import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
H = 1 / math.sqrt(2)


def _box(n, lo, hi):
    """Rows of lo ≤ z ≤ hi as A z ≤ b."""
    eye = np.eye(n)
    return np.vstack([eye, -eye]), np.concatenate([np.full(n, hi), np.full(n, -lo)])


def _solve(Q, q, Al, bl, z0=None):
    n = len(q)
    Ae, be = np.zeros((0, n)), np.zeros(0)
    first = solve_qp(Q, q, Ae, be, Al, bl)
    z0 = first.x if z0 is None else np.asarray(z0, float)
    return first, optimal_set(Q, q, first, Ae, be, Al, bl, z0, [f"z{i + 1}" for i in range(n)])


def test_vertex_with_a_singular_hessian_is_unique():
    # G = (z1 + z2 - 3)^2 on [0, 1]^2: Q is singular along (1, -1), but both upper bounds
    # press on the optimum (1, 1) with multiplier 2 each: the reduced Hessian has no null space
    Q = np.ones((2, 2))
    first, found = _solve(Q, np.array([-3.0, -3.0]), *_box(2, 0.0, 1.0))
    np.testing.assert_allclose(found.z, [1.0, 1.0], atol=1e-9)
    assert found.unique is True and found.directions == []


def test_vertex_with_a_linear_term_along_the_null_space_is_unique():
    # G = (z1 - 2)^2 + 2 z2 on [0, 1]^2: z2 has no curvature but its gradient pushes it to 0
    Q = np.diag([1.0, 0.0])
    first, found = _solve(Q, np.array([-2.0, 1.0]), *_box(2, 0.0, 1.0))
    np.testing.assert_allclose(found.z, [1.0, 0.0], atol=1e-9)
    assert found.unique is True and found.directions == []


def test_weakly_active_bounds_hold_a_direction_of_the_null_space():
    # G = (z1 + z2)^2 on [0, 1]^2: optimum (0, 0) with zero gradient (bounds active, multipliers
    # 0), null direction (1, -1): the bounds allow no move along it, found by the LPs
    first, found = _solve(np.ones((2, 2)), np.zeros(2), *_box(2, 0.0, 1.0))
    np.testing.assert_allclose(found.z, [0.0, 0.0], atol=1e-7)
    assert found.unique is True and found.directions == []


def test_edge_unique_and_non_unique():
    # on the edge z1 = 1 of [0, 1]^2: (z1 - 2)^2 + (z2 - 0.5)^2 has the single optimum (1, 0.5)
    first, found = _solve(np.eye(2), np.array([-2.0, -0.5]), *_box(2, 0.0, 1.0))
    np.testing.assert_allclose(found.z, [1.0, 0.5], atol=1e-9)
    assert found.unique is True
    # (z1 - 2)^2 + (z2 + z3 - 1)^2 on [0, 1]^3: z1 = 1 (strongly active) and the segment
    # z2 + z3 = 1 from (0, 1) to (1, 0); nearest to (1, 0.2, 0.2) is (1, 0.5, 0.5); along the
    # unit direction (0, 1, -1)/√2 the segment reaches ±1/√2
    Q = np.zeros((3, 3))
    Q[0, 0] = 1.0
    Q[1:, 1:] = 1.0
    first, found = _solve(Q, np.array([-2.0, -1.0, -1.0]), *_box(3, 0.0, 1.0), z0=[1, 0.2, 0.2])
    np.testing.assert_allclose(found.z, [1.0, 0.5, 0.5], atol=1e-7)
    assert found.unique is False and len(found.directions) == 1
    d = found.directions[0]
    assert d.direction == pytest.approx({"z2": H, "z3": -H}, abs=1e-12)
    assert d.low == pytest.approx(-H, abs=1e-7) and d.high == pytest.approx(H, abs=1e-7)
    assert d.extent == "bounded"


def test_interior_unique_and_non_unique():
    first, found = _solve(np.diag([1.0, 2.0]), np.array([-0.5, 1.0]), *_box(2, -5.0, 5.0))
    np.testing.assert_allclose(found.z, [0.5, -0.5], atol=1e-9)
    assert found.unique is True
    # (z1 + z2 - 1)^2 on [-5, 5]^2: the optimal line z1 + z2 = 1 meets the box from (-4, 5) to
    # (5, -4); nearest to (3, 2) is (1, 0); along (1, -1)/√2 it reaches -5√2 … +4√2
    first, found = _solve(np.ones((2, 2)), np.array([-1.0, -1.0]), *_box(2, -5.0, 5.0),
                          z0=[3.0, 2.0])
    np.testing.assert_allclose(found.z, [1.0, 0.0], atol=1e-7)
    assert found.unique is False
    (d,) = found.directions
    assert d.direction == pytest.approx({"z1": H, "z2": -H}, abs=1e-12)
    assert d.low == pytest.approx(-10 * H, abs=1e-7) and d.high == pytest.approx(8 * H, abs=1e-7)


def test_a_set_without_end_is_unbounded_not_infinite():
    n = 2
    first, found = _solve(np.ones((n, n)), np.array([-1.0, -1.0]), np.zeros((0, n)),
                          np.zeros(0), z0=[0.5, 0.5])
    (d,) = found.directions
    assert found.unique is False
    assert d.low is None and d.high is None
    assert d.extent == "unbounded below, unbounded above"


def test_a_failing_linear_program_says_could_not_determine(monkeypatch):
    import scipy.optimize

    class Failed:
        status, fun, message = 4, float("nan"), "numerical difficulties (test)"

    monkeypatch.setattr(scipy.optimize, "linprog", lambda *a, **k: Failed())
    first, found = _solve(np.ones((2, 2)), np.array([-1.0, -1.0]), *_box(2, -5.0, 5.0))
    assert found.unique is None
    (d,) = found.directions
    assert d.low is None and d.high is None
    assert d.extent == "could not determine below, could not determine above"
    assert found.failures and all("stopped" in m for m in found.failures)


def test_spec_with_every_variable_on_a_bound_is_unique_through_the_cli(tmp_path):
    # shaking moment only, both links' pair masses free: every variable ends on a bound (rod.m1
    # at +10 %, the rest at -5 %); the optimum is a vertex and unique
    text = (EXAMPLES / "rahman_cssp_balance.toml").read_text()
    text = text[:text.index("[balancing]")] + (
        '[balancing]\nweights = { T = 1 }\n'
        '[balancing.links.crank]\npair_sum = "at_most"\nlink_mass = "at_most"\n'
        '[balancing.links.rod]\npair_sum = "at_most"\nlink_mass = "at_most"\n')
    spec = tmp_path / "vertex.toml"
    spec.write_text(text)
    r = CliRunner().invoke(app, ["balance", str(spec), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    ratio = np.array(doc["variables"]["after"]) / np.array(doc["variables"]["before"])
    assert np.all(np.isclose(ratio, 0.95, atol=1e-9) | np.isclose(ratio, 1.10, atol=1e-9))
    assert doc["unique"] is True
    assert doc["non_unique_directions"] == []
    table = CliRunner().invoke(app, ["balance", str(spec)])
    assert "unique optimum: yes" in table.output and "inf" not in table.output

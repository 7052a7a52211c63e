"""Rahman's example: KKT conditions, objective from the regressor = objective recomputed by the
dynamics, the seed's constraint sets, non-uniqueness, JSON and CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from balancing_examples import EXAMPLE

from screwkit.balancing import balance, point_mass_variables
from screwkit.balancing.measures import MEASURES, load_rows
from screwkit.dynamics import inverse_dynamics, regressor
from screwkit.model.linkage import Link
from screwkit.pipeline import balance_from_spec


@pytest.fixture(scope="module")
def result(rahman):
    spec, mode = rahman
    return balance_from_spec(spec, mode_motion=mode)


def test_kkt_conditions(result):
    """Stationarity, primal feasibility, dual feasibility and complementary slackness."""
    x = result.after
    obj = result.objective
    grad = 2 * obj.Q @ x + 2 * obj.q
    cons = list(result.variables.constraints)
    A = np.array([c.coefficients for c in cons])
    viol = A @ x - np.array([c.bound for c in cons])
    kinds = [c.kind for c in cons]
    scale = result.variables.scale.max()
    # feasibility to 1e-9 of the variable size (the solver's polished tolerance)
    for v, k in zip(viol, kinds, strict=True):
        assert (abs(v) if k == "eq" else v) <= 1e-9 * scale
    # multipliers: those of the listed constraints plus the axisymmetry equality
    mu = np.array([result.multipliers.get(c.name, 0.0) for c in cons])
    for c, m, v in zip(cons, mu, viol, strict=True):
        if c.kind == "le":
            assert m >= -1e-9 * np.abs(grad).max()
            assert abs(m * v) <= 1e-9 * np.abs(grad).max() * scale
    # stationarity holds with the axisymmetry row added (its multiplier is free)
    extra = [n for n in result.multipliers if n.startswith("idle-spin")]
    assert len(extra) <= 1
    rest = grad + A.T @ mu
    spec_rows = result.dynamics_after  # noqa: F841 - keeps the fixture's dynamics alive
    # the residual of stationarity lies in the span of the axisymmetry equality (x6 = x7)
    names = list(result.names)
    tie = np.zeros(len(names))
    tie[names.index("rod.m2")], tie[names.index("rod.m3")] = 1.0, -1.0
    proj = rest - tie * (tie @ rest) / (tie @ tie)
    assert np.abs(proj).max() <= 1e-7 * np.abs(grad).max()  # lstsq on the active set


def test_objective_equals_dynamics_recomputed(rahman, result):
    """G from the quadratic form = G from inverse_dynamics run with the optimised links."""
    spec, mode = rahman
    lk = spec.linkage.with_links(
        [Link(n, mp) for n, mp in result.mass_properties_after.items()])
    dyn = inverse_dynamics(lk, mode)
    norm = result.normalisation
    F0 = norm.force
    sf = np.mean(np.sum(dyn.shaking_force**2, -1)) / F0**2
    sm = np.mean(np.sum(dyn.shaking_moment**2, -1)) / (F0 * norm.length) ** 2
    bf = np.mean(sum(np.sum(r["force"] ** 2, -1) for r in dyn.reactions.values())) / F0**2
    t0 = np.mean(dyn.efforts["crank.theta"] ** 2) / (F0 * norm.length) ** 2
    after = result.measures_after
    for got, want in ((sf, after["F"]), (sm, after["T"]), (bf, after["R"]), (t0, after["T0"])):
        assert got == pytest.approx(want, rel=1e-10)
    # the full measure set via the regressor of the new linkage, and no idle-spin residual
    rows = load_rows(lk, mode, regressor(lk, mode), norm)
    pi = np.concatenate([lk_.mass.inertial_parameters() for lk_ in lk.links])
    for k, v in rows.values(pi).items():
        assert v == pytest.approx(after[k], rel=1e-10)
    assert np.max(dyn.relative_residual) < 1e-12


def test_seed_constraints_and_nonunique_crank(result):
    ratio = dict(zip(result.names, result.after / result.before, strict=True))
    # the seed's vertex for the rod and the CoM masses (SPEC §4.4), here with correct physics
    assert ratio["rod.m1"] == pytest.approx(1.10, abs=1e-9)
    for k in ("rod.m2", "rod.m3", "rod.m4", "crank.m4"):
        assert ratio[k] == pytest.approx(0.95, abs=1e-9)
    # the crank's pair split does not matter: not unique, nearest member = original split
    assert not result.unique
    assert len(result.directions) == 2
    assert all(set(d.direction) <= {"crank.m1", "crank.m2", "crank.m3"}
               for d in result.directions)
    for k in ("crank.m1", "crank.m2", "crank.m3"):
        assert ratio[k] == pytest.approx(1.0, abs=1e-8)
    # the seed's constraints remove 1.25 % of each varied link (it claimed none)
    ch = result.link_mass_change()
    assert ch["crank"] == pytest.approx(-1.25, abs=1e-5)
    assert ch["rod"] == pytest.approx(-1.25, abs=1e-5)
    assert result.measures_after["G"] < result.measures_before["G"]


def test_text_constraint_at_most_and_link_mass_equal(rahman):
    spec, mode = rahman
    lk = spec.linkage
    w = dict.fromkeys(MEASURES, 1.0)
    at_most = balance(lk, mode, [point_mass_variables(lk, "crank", pair_sum="at_most"),
                                 point_mass_variables(lk, "rod", pair_sum="at_most")],
                      w, speed=spec.speed)
    equal = balance(lk, mode, [point_mass_variables(lk, "crank", link_mass="equal"),
                               point_mass_variables(lk, "rod", link_mass="equal")],
                    w, speed=spec.speed)
    assert at_most.measures_after["G"] <= equal.measures_after["G"] * (1 + 1e-9)
    for name, m in equal.link_mass_after.items():
        assert m == pytest.approx(equal.link_mass_before[name], rel=1e-9)
    # at fixed link mass and fixed CoM no redistribution changes the shaking force (SPEC §7)
    assert equal.measures_after["F"] == pytest.approx(equal.measures_before["F"], rel=1e-9)


def test_json_document(result):
    doc = json.loads(json.dumps(result.as_dict()))
    assert set(doc["measures"]["before"]) == {"F", "T", "R", "M", "T0", "G"}
    assert len(doc["variables"]["names"]) == len(doc["variables"]["after"]) == 8
    assert doc["unique"] is False
    assert set(doc["link_mass"]["after"]) == {"crank", "rod", "slider"}
    assert len(doc["per_sample"]["input"]) == 36


def test_cli_balance_json(tmp_path):
    from typer.testing import CliRunner

    from screwkit.cli.balance_cmd import register
    from screwkit.cli.main import app

    if "balance" not in {c.name or c.callback.__name__ for c in app.registered_commands}:
        register(app)
    r = CliRunner().invoke(app, ["balance", str(EXAMPLE), "--json", "--tables", str(tmp_path)])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)  # the document alone on stdout; "wrote …" lines on stderr
    assert doc["measures"]["after"]["G"] < doc["measures"]["before"]["G"]
    assert (tmp_path / "balance_shaking_force.csv").is_file()


def test_mass_properties_in_the_spec_units(rahman, result):
    """Rahman's Table 5.1 shape in the spec's units (in, lbf·s²·in), SI by default; the values
    are the SI ones divided by one unit (1 in = 0.0254 m, 1 lbf·s²·in = 0.11298482933 kg·m²)."""
    spec, _ = rahman
    si = result.mass_properties_table()
    shown = result.mass_properties_table(spec.display_units())
    lbf_s2_in = 0.45359237 * 9.80665 * 0.0254
    assert [r[1] for r in si[:5]] == ["mass (kg)", "com x (m)", "com y (m)", "com z (m)",
                                      "Ixx about CoM (kg*m^2)"]
    assert [r[1] for r in shown[:5]] == ["mass (kg)", "com x (in)", "com y (in)", "com z (in)",
                                         "Ixx about CoM (lbf*s^2*in)"]
    for a, b in zip(si, shown, strict=True):
        scale = 0.0254 if "(in)" in b[1] else lbf_s2_in if "lbf" in b[1] else 1.0
        assert np.allclose(np.array(b[2:]) * scale, a[2:], rtol=1e-12, atol=0)
    # the crank's centre of mass as the spec gives it: 1 in along x
    assert shown[1][2] == pytest.approx(1.0, rel=1e-12)

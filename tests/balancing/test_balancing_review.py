"""Regressions of the balancing review: gravity direction, a non-axisymmetric S–S rod, the
indeterminate-reaction note, a sweep that does not assemble, --tables on a file, round-off
percentages, a canonical basis of the non-unique directions."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import EXAMPLE
from screwkit.balancing import BalancingError
from screwkit.io.balance_tables import write_balance_tables
from screwkit.io.spec import load_spec
from screwkit.pipeline import balance_from_spec

FOURBAR = Path(__file__).resolve().parents[2] / "examples" / "fourbar_dynamics.toml"
RAHMAN = EXAMPLE.read_text()


def _fourbar(tmp_path: Path, balancing: str, direction: str = "[0, -1, 0]") -> Path:
    text = FOURBAR.read_text().replace("gravity_direction = [0, -1, 0]",
                                       f"gravity_direction = {direction}")
    assert f"gravity_direction = {direction}" in text
    p = tmp_path / f"fb_{len(list(tmp_path.glob('fb_*.toml')))}.toml"
    p.write_text(text + "\n" + balancing)
    return p


def _cli():
    from typer.testing import CliRunner

    from screwkit.cli.balance_cmd import register
    from screwkit.cli.main import app

    if "balance" not in {c.name or c.callback.__name__ for c in app.registered_commands}:
        register(app)
    return CliRunner(), app


def test_gravity_follows_gravity_direction(tmp_path):
    table = "[balancing]\nweights = {F = 1}\ngravity = true\n[balancing.links.crank]\n"
    in_plane = balance_from_spec(load_spec(_fourbar(tmp_path, table, "[0, -1, 0]")))
    normal = balance_from_spec(load_spec(_fourbar(tmp_path, table, "[0, 0, -1]")))
    # the 4R moves in the x-y plane: in-plane gravity loads no bearing moment (round-off,
    # ~1e-27 against measures of order 1), gravity normal to the plane does (0.23)
    assert in_plane.measures_before["M"] < 1e-12 * in_plane.measures_before["R"]
    assert normal.measures_before["M"] > 0.1


def test_round_off_measure_has_no_percentage(tmp_path):
    table = "[balancing]\nweights = {F = 1}\ngravity = true\n[balancing.links.crank]\n"
    res = balance_from_spec(load_spec(_fourbar(tmp_path, table)))
    ch = res.changes()
    assert ch["M"] is None and ch["F"] is not None and ch["F"] < 0
    row = next(r for r in res.summary_table() if r[0].endswith("(M)"))
    assert row[3] == "n/a (round-off)"
    assert json.loads(json.dumps(res.as_dict()))["measures"]["change_percent"]["M"] is None


def test_indeterminate_reactions_are_noted(tmp_path):
    bearing = balance_from_spec(load_spec(_fourbar(
        tmp_path, "[balancing]\nweights = {R = 1, M = 1}\n[balancing.links.crank]\n")))
    assert any("statically indeterminate" in n and "minimum-norm" in n for n in bearing.notes)
    assert any("statically indeterminate" in n for n in bearing.as_dict()["notes"])
    shaking = balance_from_spec(load_spec(_fourbar(
        tmp_path, "[balancing]\nweights = {F = 1, T = 1}\n[balancing.links.crank]\n")))
    assert not any("statically indeterminate" in n for n in shaking.notes)


def test_non_axisymmetric_rod_is_named(tmp_path):
    text = RAHMAN.replace("inertia = [8.195304e-4, 0.105310, 0.105310]",
                          "inertia = [0.02, 0.105310, 0.095]")
    assert text != RAHMAN
    p = tmp_path / "rod_asym.toml"
    p.write_text(text)
    with pytest.raises(BalancingError) as exc:
        balance_from_spec(load_spec(p))
    msg = str(exc.value)
    assert "link 'rod'" in msg and "transverse moments" in msg and "axisymmetric" in msg
    assert "cannot all hold" not in msg


def test_sweep_that_does_not_assemble_is_named_in_spec_units(tmp_path):
    text = RAHMAN.replace("a2 = 8.0", "a2 = 1.5")
    assert text != RAHMAN
    p = tmp_path / "noasm.toml"
    p.write_text(text)
    with pytest.raises(BalancingError) as exc:
        balance_from_spec(load_spec(p))
    msg = str(exc.value)
    assert "16 of 36 inputs (0, 10, 20" in msg and "deg" in msg
    assert "[motion] start/stop/step" in msg
    assert "allow_partial" not in msg and "nan" not in msg.lower()


def test_tables_on_an_existing_file(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("keep me")
    spec = _fourbar(tmp_path, "[balancing]\nweights = {F = 1}\n[balancing.links.crank]\n")
    runner, app = _cli()
    r = runner.invoke(app, ["balance", str(spec), "--tables", str(afile)])
    assert r.exit_code == 2
    assert "--tables needs a folder" in r.output
    assert afile.read_text() == "keep me"
    res = balance_from_spec(load_spec(spec))
    with pytest.raises(BalancingError, match="needs a folder"):
        write_balance_tables(res, str(afile))
    paths = write_balance_tables(res, str(tmp_path / "new" / "tables"))
    assert len(paths) == 7 and all(Path(p).is_file() for p in paths)
    assert not list((tmp_path / "new" / "tables").glob(".*"))  # no temporary files left


def test_canonical_basis_depends_only_on_the_space():
    from screwkit.balancing.problem import canonical_basis

    rng = np.random.default_rng(3)
    space = np.linalg.qr(rng.normal(size=(6, 3)))[0]
    first = canonical_basis(space)
    for _ in range(5):
        rot = np.linalg.qr(rng.normal(size=(3, 3)))[0]  # another orthonormal basis, any signs
        # the basis is rebuilt by elimination: agreement to round-off of a 6x3 elimination
        np.testing.assert_allclose(canonical_basis(space @ rot), first, atol=1e-12)
    # same space, unit columns, leading entries positive
    np.testing.assert_allclose(np.linalg.norm(first, axis=0), 1.0, atol=1e-12)
    proj = space @ space.T
    np.testing.assert_allclose(proj @ first, first, atol=1e-12)
    lead = [col[np.flatnonzero(np.abs(col) > 1e-12)[0]] for col in first.T]
    assert all(v > 0 for v in lead)


def test_rahman_directions_are_canonical(rahman):
    spec, mode = rahman
    res = balance_from_spec(spec, mode_motion=mode)
    h = np.sqrt(0.5)
    got = [{k: round(v, 12) for k, v in d.direction.items()} for d in res.directions]
    assert got == [{"crank.m1": round(h, 12), "crank.m3": round(-h, 12)},
                   {"crank.m2": round(h, 12), "crank.m3": round(-h, 12)}]

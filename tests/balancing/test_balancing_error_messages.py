"""Bad balancing input is named in the user's words: a non-axisymmetric S–S rod, a sweep that
does not assemble (in the spec's units), --tables pointing at a file."""

from __future__ import annotations

from pathlib import Path

import pytest
from balancing_examples import EXAMPLE, fourbar_spec

from screwkit.balancing import BalancingError
from screwkit.io.balance_tables import write_balance_tables
from screwkit.io.spec import load_spec
from screwkit.pipeline import balance_from_spec

RAHMAN = EXAMPLE.read_text()


def _cli():
    from typer.testing import CliRunner

    from screwkit.cli.balance_cmd import register
    from screwkit.cli.main import app

    if "balance" not in {c.name or c.callback.__name__ for c in app.registered_commands}:
        register(app)
    return CliRunner(), app


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
    spec = fourbar_spec(tmp_path, "[balancing]\nweights = {F = 1}\n[balancing.links.crank]\n")
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

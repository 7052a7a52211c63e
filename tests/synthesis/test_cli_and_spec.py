"""`screwkit synthesize`: JSON keys in SI, tables, atomic output, user errors as exit 2; the
[synthesis] table's validation."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from screwkit.cli.synthesize_cmd import register
from screwkit.io.spec import load_spec
from screwkit.io.synthesis_table import SynthesisConfigError, problem_from_spec
from screwkit.synthesis.overlay import overlay_fit

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
app = typer.Typer()
register(app)


@app.command()
def _placeholder() -> None:  # a second command keeps typer's subcommand form
    """(unused)"""


runner = CliRunner()


def test_json_document(tmp_path: Path) -> None:
    out = tmp_path / "ex4.json"
    r = runner.invoke(app, ["synthesize", str(EXAMPLES / "bagci_example4_synthesis.toml"),
                            "--json", "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert r.stdout.startswith(f"wrote {out} (JSON")  # -o: the file and one line
    doc = json.loads(out.read_text())
    for key in ("dimensions", "mode", "E_phi", "E_S", "rmse", "rmse_phi", "rmse_S",
                "iterations", "rows"):
        assert key in doc
    assert set(doc["rows"][0]) >= {"theta0", "phi_g", "S", "psi_d0", "S_d"}
    assert doc["mode"] == 2  # Table V's "negative signed radical"
    assert doc["dimensions"]["d1"] == pytest.approx(0.0254)  # SI: 1 in
    assert doc["dimensions"]["theta01"] == pytest.approx(math.radians(25.0))
    assert doc["rows"][0]["S_d"] is None  # translation not prescribed
    assert doc["range_check"]["ok"] is True


def test_tables_and_plot(tmp_path: Path) -> None:
    png = tmp_path / "ex3.png"
    r = runner.invoke(app, ["synthesize", str(EXAMPLES / "bagci_example3_synthesis.toml"),
                            "--plot", str(png)])
    assert r.exit_code == 0, r.output
    assert "optimised dimensions" in r.output and "desired vs generated" in r.output
    assert png.stat().st_size > 1000


def test_user_errors_exit_2(tmp_path: Path) -> None:
    r = runner.invoke(app, ["synthesize", str(EXAMPLES / "bagci_fig7_rsrc.toml")])
    assert r.exit_code == 2
    assert "no [synthesis] table" in r.output
    bad = tmp_path / "bad.toml"
    text = (EXAMPLES / "bagci_example1_synthesis.toml").read_text()
    bad.write_text(text.replace('function = "parabola_dip"',
                                'expression = "__import__(\'os\')"'))
    r = runner.invoke(app, ["synthesize", str(bad)])
    assert r.exit_code == 2
    assert "only the functions" in r.output


def test_spec_validation_messages(tmp_path: Path) -> None:
    base = (EXAMPLES / "bagci_example1_synthesis.toml").read_text()
    cases = {
        'unknowns = ["e", "d1", "d2", "d3", "a", "b", "delta0", "theta01"]':
            ('unknowns = ["e", "d9"]', "cannot be solved for"),
        "inversion = 2 ": ("inversion = 7 ", "inversion must be 1, 2, 3, 4"),
        "max_iterations = 2000": ("max_iterations = 2000\ncolour = 1", "unknown key"),
        'length_scale = "1 in"': ('length_scale = "1 kg"', "length_scale"),
    }
    for old, (new, message) in cases.items():
        path = tmp_path / "case.toml"
        path.write_text(base.replace(old, new))
        with pytest.raises(SynthesisConfigError, match=None) as info:
            problem_from_spec(load_spec(path))
        assert message in str(info.value), str(info.value)


def test_overlay_recovers_an_exact_mechanism() -> None:
    # a delta0 = 0 mechanism generates psi at 7 points; the overlay with its own d1, d2, theta01
    # must find its output crank again (the circles then meet exactly)
    from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_positions

    d = math.radians
    dims = RSRCDimensions(2.0, 3.0, 2.5, 3.2, 1.1, 0.0, 0.0, d(60))
    theta01 = d(100)
    theta = np.radians(np.arange(0.0, 91.0, 15.0))
    phi = rsrc_positions(dims, theta01 + theta).phi0[:, 0]
    psi = np.unwrap(phi - phi[0])
    fit = overlay_fit(d1=2.0, d2=3.0, lambda0=d(60), theta01=theta01, theta=theta, psi=psi)
    assert np.max(np.abs(fit.circle_residual)) < 1e-9
    assert fit.dimensions.d3 == pytest.approx(2.5, abs=1e-8)
    assert fit.dimensions.a == pytest.approx(3.2, abs=1e-8)
    assert fit.dimensions.b == pytest.approx(1.1, abs=1e-8)
    assert fit.rmse_phi < 1e-9


def test_start_that_does_not_assemble_exits_2(tmp_path: Path) -> None:
    base = (EXAMPLES / "bagci_example1_synthesis.toml").read_text()
    bad = tmp_path / "short_coupler.toml"
    bad.write_text(base.replace("d2 = 3.0", "d2 = 0.2"))  # the loop cannot close
    r = runner.invoke(app, ["synthesize", str(bad)])
    assert r.exit_code == 2
    assert "cannot start" in r.output and "does not assemble" in r.output

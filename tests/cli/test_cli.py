"""The command line: readable tables, JSON documents in SI, atomic output, user errors as exit
status 2 with a one-paragraph message (no traceback)."""

import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.io.spec import SpecError, load_spec

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()


def test_every_bundled_example_validates():
    files = sorted(EXAMPLES.glob("*.toml"))
    assert len(files) >= 12
    r = runner.invoke(app, ["validate", *map(str, files)])
    assert r.exit_code == 0, r.output
    assert r.output.count("ok ") == len(files)


def test_analyze_json_shape_and_units(tmp_path):
    out = tmp_path / "fig7.json"
    r = runner.invoke(
        app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "--json", "-o", str(out)]
    )
    assert r.exit_code == 0, r.output
    # -o writes the file and prints one line; --json alone prints the same document
    assert r.stdout.strip().splitlines() == [r.stdout.strip()]
    assert r.stdout.startswith(f"wrote {out} (JSON")
    doc = json.loads(out.read_text())
    printed = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "--json"])
    assert json.loads(printed.stdout) == doc
    n = len(doc["input"])
    assert n == 36 and abs(doc["input"][1] - np.radians(10)) < 1e-12  # SI: radians
    assert len(doc["modes"]) == 2
    for mode in doc["modes"]:
        assert len(mode["assembles"]) == n
        for key in ("phi0", "S", "chi0"):
            assert len(mode["variables"][key]) == n
            assert len(mode["velocities"][key]) == n
            assert len(mode["accelerations"][key]) == n
        assert set(mode["coupler_point"]) == {"x", "y", "z"}


def test_analyze_table_output():
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_example3_4r.toml")])
    assert r.exit_code == 0, r.output
    assert "assembly mode 0" in r.output and "phi0" in r.output


def test_cssp_names_in_json():
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "rahman_cssp.toml"), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    for key in ("s4", "theta2", "eta2"):
        assert key in doc["modes"][0]["variables"]
    # 3000 rpm in SI
    assert abs(doc["input_speed"] - 3000 * 2 * np.pi / 60) < 1e-9


def test_non_assembling_range_is_reported_not_hidden():
    # Bagci's Example 7 mechanism (d3 rebuilt) does not assemble for θ0 ≈ 299°…318°
    r = runner.invoke(
        app, ["analyze", str(EXAMPLES / "bagci_example7_double_crank.toml"), "--json"]
    )
    doc = json.loads(r.stdout)
    any_mode = np.any([m["assembles"] for m in doc["modes"]], axis=0)
    assert not any_mode[6]  # θ0 = 305.35°
    assert any("stops assembling" in e for m in doc["modes"] for e in m["events"])
    assert all(m["variables"]["phi0"][6] is None for m in doc["modes"])


def _bad(tmp_path, text):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize(
    "text, fragment",
    [
        ('[mechanism]\nfamily = "RSRC"\n[dimensions]\nd1 = "2 in"\n', "missing"),
        ('[mechanism]\nfamily = "XYZ"\n', "unknown family"),
        (
            '[mechanism]\nfamily = "4R"\n[dimensions]\na = "3 kg"\nd1 = 1\nd2 = 3\nd3 = 2.5\n',
            "is not a length",
        ),
        (
            '[mechanism]\nfamily = "4R"\n[dimensions]\na = -3\nd1 = 1\nd2 = 3\nd3 = 2.5\n',
            "positive length",
        ),
        (
            '[mechanism]\nfamily = "4R"\n[dimensions]\na = 3\nd1 = 1\nd2 = 3\nd3 = 2.5\n[motion]\nstep = 0\n',
            "step must be positive",
        ),
        (
            '[mechanism]\nfamily = "4R"\n[dimensions]\na = 3\nd1 = 1\nd2 = 3\nd3 = 2.5\nd4 = 1\n',
            "unknown key",
        ),
        ('[mechanism]\nfamily = "4R"\ncolour = "red"\n', "unknown key"),
        ("[mechanism\n", "not valid TOML"),
        (
            '[mechanism]\nfamily = "4R"\n[dimensions]\na = 30\nd1 = 1\nd2 = 3\nd3 = 2.5\n',
            "does not close",
        ),
        (
            '[mechanism]\nfamily = "CSSP"\n[dimensions]\na1=2\na2=8\na4=1\nalpha4=4\n[links.crank]\nmass = 1\ninertia=[1, 1, 5]\n',
            "links.crank",
        ),
    ],
)
def test_user_errors_exit_2_with_a_message(tmp_path, text, fragment):
    p = _bad(tmp_path, text)
    r = runner.invoke(app, ["analyze", str(p)])
    assert r.exit_code == 2
    assert "Traceback" not in r.output
    assert fragment in r.output.replace("\n", " ")
    assert str(p.name) in r.output or "does not close" in r.output


def test_failed_run_leaves_no_output_file(tmp_path):
    p = _bad(
        tmp_path, '[mechanism]\nfamily = "4R"\n[dimensions]\na = 30\nd1 = 1\nd2 = 3\nd3 = 2.5\n'
    )
    out = tmp_path / "result.json"
    r = runner.invoke(app, ["analyze", str(p), "--json", "-o", str(out)])
    assert r.exit_code == 2 and not out.exists()
    assert not [f for f in os.listdir(tmp_path) if f.startswith(".result")]


def test_units_defaults_and_explicit_units_agree(tmp_path):
    a = load_spec(
        _bad(
            tmp_path,
            '[mechanism]\nfamily = "4R"\n[units]\nlength = "in"\n[dimensions]\na = 3\nd1 = 1\nd2 = 3\nd3 = 2.5\n',
        )
    )
    b = load_spec(
        _bad(
            tmp_path,
            '[mechanism]\nfamily = "4R"\n[dimensions]\na = "3 in"\nd1 = "25.4 mm"\nd2 = "3 in"\nd3 = "2.5 in"\n',
        )
    )
    assert a.dimensions == pytest.approx(b.dimensions, rel=1e-12)
    assert a.dimensions["a"] == pytest.approx(3 * 0.0254)


def test_weights_become_masses_with_the_spec_gravity():
    s = load_spec(EXAMPLES / "rahman_cssp.toml")
    crank = s.linkage.links[0].mass
    # 1.9 lbf / 386.4 in/s² in kg
    assert crank.mass == pytest.approx(1.9 * 4.4482216152605 / (386.4 * 0.0254), rel=1e-12)


def test_spec_error_is_a_value_error():
    with pytest.raises(SpecError, match="no such spec file"):
        load_spec("does-not-exist.toml")


def test_demo_runs_every_example(tmp_path):
    # (the HTML reports are tested in tests/report on a few examples: --no-reports here)
    r = runner.invoke(app, ["demo", str(EXAMPLES), "--output-dir", str(tmp_path), "--no-plots",
                            "--no-reports"])
    assert r.exit_code == 0, r.output
    written = sorted(tmp_path.glob("*.analysis.json"))
    graphs = list(EXAMPLES.glob("mechanisms/*.toml"))
    assert len(written) == len(list(EXAMPLES.glob("*.toml"))) + len(graphs) and graphs
    # the graph examples too: their topology, and loads where every body has masses
    assert json.loads((tmp_path / "jansen_leg.mobility.json").read_text())["mobility"] == 1
    assert (tmp_path / "watt_sixbar.dynamics.json").exists()
    # the main job reproduces both seed systems: synthesis of Bagci's examples, dynamics and
    # balancing of Rahman's
    assert len(list(tmp_path.glob("bagci_example*_synthesis.synthesis.json"))) >= 7
    assert (tmp_path / "rahman_cssp.dynamics.json").exists()
    assert (tmp_path / "rahman_cssp_balance.balance.json").exists()
    # and an HTML index people can open
    page = (tmp_path / "index.html").read_text()
    assert page.startswith("<!doctype html>") and "rahman_cssp_balance" in page
    assert "balancing objective G" in page and "shaking force RMS" in page
    assert "stewart_platform" in page and "redundant constraints, idle freedoms" in page


def test_dynamics_json_has_the_documented_keys():
    r = runner.invoke(app, ["dynamics", str(EXAMPLES / "rahman_cssp.toml"), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    for key in ("shaking_force", "shaking_moment", "moment_point", "reactions", "efforts"):
        assert key in doc
    assert len(doc["shaking_force"]) == 36 and len(doc["shaking_force"][0]) == 3
    assert set(doc["reactions"]) == {"crank", "pin", "ball", "slider"}
    assert "crank.theta" in doc["efforts"]


def test_dynamics_without_masses_says_which_link():
    r = runner.invoke(app, ["dynamics", str(EXAMPLES / "bagci_fig7_rsrc.toml")])
    assert r.exit_code == 2 and "links.crank" in r.output.replace("\n", "")


def test_limits_reproduce_bagci_fig9_and_fig10_dwells():
    r = runner.invoke(app, ["limits", str(EXAMPLES / "bagci_fig9_dwell.toml"), "--dwell-tol", "1e-4", "--at", "270", "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    # Fig. 9: third-order instantaneous dwell at θ0 = 270° on the negative-radical inversion
    # (reference spec §3.6; the printed dimensions hold it to ~1e-4)
    orders = {d["inversion_label"]: d["dwell_order"] for d in doc["dwells_at"]}
    assert orders[2] == 3 and orders[1] == 0
    kinds = {lim["kind"] for lim in doc["limits"]}
    assert kinds == {"rotation", "translation"}
    # translation limits of a δ0 = 0 RSRC are at θ0 = ±90° (eq. 3.60a)
    tl = sorted(np.degrees(lim["theta0"]) % 360 for lim in doc["limits"] if lim["kind"] == "translation")
    assert np.allclose(tl, [90, 90, 270, 270], atol=1e-6)
    r = runner.invoke(app, ["limits", str(EXAMPLES / "bagci_fig10_double_crank.toml"), "--dwell-tol", "1e-2", "--at", "220.33", "--json"])
    doc = json.loads(r.stdout)
    assert {d["inversion_label"]: d["dwell_order"] for d in doc["dwells_at"]}[2] == 2


def test_limits_of_a_loop_without_a_closed_form_take_the_generic_route():
    r = runner.invoke(app, ["limits", str(EXAMPLES / "rssr_spatial.toml"), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert doc["method"] == "generic" and doc["outputs"] == ["phi0"]
    assert len(doc["limits"]) == 4 and all(lim["dwell_order"] == 1 for lim in doc["limits"])
    r = runner.invoke(app, ["limits", str(EXAMPLES / "rssr_spatial.toml"), "--method", "closed"])
    assert r.exit_code == 2 and "no closed-form limits" in r.output


def test_limits_of_the_cssp_slider_are_the_stroke_ends():
    r = runner.invoke(app, ["limits", str(EXAMPLES / "rahman_cssp.toml"), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert doc["method"] == "generic" and {lim["kind"] for lim in doc["limits"]} == {"translation"}
    import screwkit as sk
    from screwkit.io.spec import load_spec

    s = load_spec(EXAMPLES / "rahman_cssp.toml")
    for lim in doc["limits"]:  # the closed form just around each limit: s4 is extreme there
        x = lim["input"] + np.radians(np.linspace(-0.5, 0.5, 1001))
        md = sk.solve_motion(s.linkage, x, method="closed").modes[lim["mode"]]
        s4 = md.variables["s4"]
        k = int(np.argmax(s4) if lim["second_derivative"] < 0 else np.argmin(s4))
        assert abs(x[k] - lim["input"]) < np.radians(1e-3)
        assert abs(s4[k] - lim["value"]) < 1e-12


def test_analyze_plot_writes_a_png(tmp_path):
    png = tmp_path / "fig7.png"
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "--plot", str(png)])
    assert r.exit_code == 0, r.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


@pytest.mark.parametrize("name", ["rsrc_fig7_dynamics", "fourbar_dynamics", "rssr_spatial", "rccc_loop"])
def test_dynamics_runs_on_every_family_from_the_cli(name):
    r = runner.invoke(app, ["dynamics", str(EXAMPLES / f"{name}.toml"), "--json", "--gravity"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert max(doc["residual"]) < 1e-10 * doc["residual_scale"]
    if name == "fourbar_dynamics":
        assert "3 reaction component(s) statically indeterminate" in doc["indeterminacy"]


def test_gravity_direction_is_validated(tmp_path):
    p = _bad(tmp_path, 'gravity_direction = [0, 0, 0]\n[mechanism]\nfamily = "4R"\n[dimensions]\na = 3\nd1 = 1\nd2 = 3\nd3 = 2.5\n')
    r = runner.invoke(app, ["analyze", str(p)])
    assert r.exit_code == 2 and "gravity_direction" in r.output


def test_dynamics_of_a_partly_assembling_mode_reports_where(tmp_path):
    text = (EXAMPLES / "fourbar_dynamics.toml").read_text()
    text = text.replace("a = 300\nd1 = 100\nd2 = 300\nd3 = 250", "a = 200\nd1 = 180\nd2 = 220\nd3 = 150")
    p = tmp_path / "triple_rocker.toml"
    p.write_text(text)
    r = runner.invoke(app, ["dynamics", str(p), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert "does not assemble" in doc["note"]
    assert any(v is None for v in doc["shaking_force"]) and any(v is not None for v in doc["shaking_force"])

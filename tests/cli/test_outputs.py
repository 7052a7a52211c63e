"""Output an engineer can use (issue 17): a spec in mm and degrees gives tables, CSV, Parquet,
NPZ and plots in mm and degrees and JSON in SI, with equal values after conversion — command by
command; -o by extension with a one-line summary; long tables summarised; the balancing
measures as RMS loads (checked against the per-sample loads)."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()
MM, DEG = 1e-3, math.pi / 180

RSRC_MM = """
[mechanism]
family = "RSRC"
name = "RSRC in mm"
[units]
length = "mm"
angle = "deg"
[dimensions]
d1 = 50.8
d2 = 114.3
d3 = 76.2
a = 76.2
b = 76.2
e = 25.4
delta0 = 18.0
lambda0 = 60.0
[motion]
step = 10
speed = "120 rpm"
[coupler_point]
f = 10.0
g = 20.0
h = 5.0
[links.crank]
mass = "0.4 kg"
com = [25.4, 0.0, 0.0]
inertia = ["1e-5 kg*m^2", "1.5e-4 kg*m^2", "1.5e-4 kg*m^2"]
[links.coupler]
mass = "0.9 kg"
com = [0.0, 57.15, 0.0]
inertia = ["1.0e-3 kg*m^2", "3e-5 kg*m^2", "1.0e-3 kg*m^2"]
[links.output]
mass = "0.7 kg"
com = [-38.1, 0.0, -12.7]
inertia = ["4e-4 kg*m^2", "6e-4 kg*m^2", "5e-4 kg*m^2"]
"""


def _spec(tmp_path: Path, text: str = RSRC_MM, name: str = "rsrc_mm.toml") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def _run(*args: str) -> str:
    r = runner.invoke(app, [str(a) for a in args])
    assert r.exit_code == 0, r.output
    return r.stdout


def _read_csv(path: Path) -> dict[str, np.ndarray]:
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    head, body = rows[0], rows[1:]
    out = {}
    for k, h in enumerate(head):
        cells = [r[k] for r in body]
        if all(c in ("true", "false") for c in cells):
            out[h] = np.array([c == "true" for c in cells])
        else:
            try:
                out[h] = np.array([float(c) if c else np.nan for c in cells])
            except ValueError:
                out[h] = np.array(cells)
    return out


def _same(csv_values: np.ndarray, json_values: object, scale: float = 1.0) -> None:
    """CSV values equal the JSON's (SI, null where missing) divided by ``scale``."""
    j = np.array([np.nan if v is None else v for v in json_values], dtype=float)  # type: ignore[union-attr]
    np.testing.assert_array_equal(np.isnan(csv_values), np.isnan(j))
    np.testing.assert_allclose(csv_values, j / scale, rtol=1e-13, atol=0, equal_nan=True)


def test_analyze_csv_parquet_npz_and_json_agree_after_conversion(tmp_path):
    spec = _spec(tmp_path)
    doc = json.loads(_run("analyze", spec, "--json"))
    assert doc["units"]["length"] == "m" and doc["units"]["angle"] == "rad"  # JSON stays SI
    _run("analyze", spec, "--csv", tmp_path / "a.csv")
    t = _read_csv(tmp_path / "a.csv")
    n = len(doc["input"])
    assert len(t["mode"]) == n * len(doc["modes"])  # one row per sample and mode
    for mode in doc["modes"]:
        rows = t["mode"] == mode["mode"]
        _same(t["input [deg]"][rows], doc["input"], DEG)
        _same(t["phi0 [deg]"][rows], mode["variables"]["phi0"], DEG)
        _same(t["phi0_dot [deg/s]"][rows], mode["velocities"]["phi0"], DEG)  # rates follow
        _same(t["phi0_ddot [deg/s^2]"][rows], mode["accelerations"]["phi0"], DEG)
        _same(t["S [mm]"][rows], mode["variables"]["S"], MM)
        _same(t["S_dot [mm/s]"][rows], mode["velocities"]["S"], MM)
        _same(t["coupler_y [mm]"][rows], mode["coupler_point"]["y"], MM)
        assert list(t["assembles"][rows]) == mode["assembles"]
    # the machine formats hold the same table
    import pandas as pd

    _run("analyze", spec, "-o", tmp_path / "a.parquet")
    pq = pd.read_parquet(tmp_path / "a.parquet")
    np.testing.assert_array_equal(pq["S [mm]"].to_numpy(), t["S [mm]"])
    _run("analyze", spec, "-o", tmp_path / "a.npz")
    with np.load(tmp_path / "a.npz") as z:
        np.testing.assert_array_equal(z["phi0"], t["phi0 [deg]"])
        units = dict(z["units"].tolist())
    assert units["phi0_dot"] == "deg/s" and units["S"] == "mm"
    # --units si and a per-kind override
    _run("analyze", spec, "--units", "si", "--unit", "angle=rev", "--csv", tmp_path / "b.csv")
    b = _read_csv(tmp_path / "b.csv")
    _same(b["S [m]"][b["mode"] == 0], doc["modes"][0]["variables"]["S"])
    _same(b["phi0 [rev]"][b["mode"] == 0], doc["modes"][0]["variables"]["phi0"], 2 * math.pi)


def test_analyze_tables_and_plot_in_the_spec_units(tmp_path, monkeypatch):
    spec = _spec(tmp_path)
    out = _run("analyze", spec)
    assert "[deg/s]" in out and "[mm]" in out and "[rad" not in out
    assert "d1=50.8 mm" in out and "delta0=18 deg" in out
    pytest.importorskip("matplotlib")
    import screwkit.report.plots as plots

    figures = []
    monkeypatch.setattr(plots, "save_figure", lambda fig, path, *a, **k: figures.append(fig))
    _run("analyze", spec, "--plot", tmp_path / "a.png")
    titles = [ax.get_title() for ax in figures[0].axes]
    assert "phi0' (deg/s)" in titles and "phi0'' (deg/s²)" in titles and "S (mm)" in titles
    doc = json.loads(_run("analyze", spec, "--json"))
    ax = next(a for a in figures[0].axes if a.get_title() == "S (mm)")
    y = ax.get_lines()[0].get_ydata()
    _same(np.asarray(y, dtype=float), doc["modes"][0]["variables"]["S"], MM)


def test_dynamics_csv_reports_every_load_and_its_point_of_application(tmp_path):
    spec = _spec(tmp_path)
    doc = json.loads(_run("dynamics", spec, "--json", "--gravity"))
    assert doc["gravity_on"] is True
    _run("dynamics", spec, "--gravity", "--csv", tmp_path / "d.csv")
    t = _read_csv(tmp_path / "d.csv")
    f = np.array(doc["shaking_force"], dtype=float)
    _same(t["shaking_force_x [N]"], f[:, 0])
    _same(t["shaking_moment_z [N*m]"], np.array(doc["shaking_moment"], dtype=float)[:, 2])
    for joint, r in doc["reactions"].items():
        point = np.array(r["point"], dtype=float)
        _same(t[f"{joint}.point_z [mm]"], point[:, 2], MM)
        _same(t[f"{joint}.force_y [N]"], np.array(r["force"], dtype=float)[:, 1])
    name = next(iter(doc["efforts"]))
    _same(t[f"{name}.effort [N*m]"], doc["efforts"][name])
    out = _run("dynamics", spec, "--gravity")
    assert "gravity on: 9.80665 m/s^2 along (0, 0, -1)" in out
    assert "gravity off" in _run("dynamics", spec)
    # the table in the terminal: RMS of the shaking force in N equals the JSON summary
    assert f"{doc['summary']['shaking_force']['rms']:.6g}" in out


def test_dynamics_table_does_not_build_the_json_document(tmp_path, monkeypatch):
    import screwkit.io.documents as documents

    def refuse(*a, **k):
        raise AssertionError("the JSON document was built for a table")

    monkeypatch.setattr(documents, "dynamics_document", refuse)
    assert "loads over the cycle" in _run("dynamics", _spec(tmp_path))


def test_analyze_to_a_binary_file_builds_no_document_and_one_transmission(tmp_path,
                                                                           monkeypatch):
    """Issue 30: `analyze -o out.npz` cost 9x the solve, building the JSON document it does not
    write and computing the transmission twice (once for the document, once for the table)."""
    import screwkit.io.documents as documents
    import screwkit.pipeline as pipeline

    def refuse(*a, **k):
        raise AssertionError("the JSON document was built for a binary output")

    calls = []

    def counted(motion):
        calls.append(1)
        return transmission(motion)

    transmission = pipeline.transmission
    spec = str(EXAMPLES / "bagci_fig7_rsrc.toml")
    with monkeypatch.context() as m:
        m.setattr(documents, "analysis_document", refuse)
        m.setattr(pipeline, "transmission", counted)
        r = runner.invoke(app, ["analyze", spec, "-o", str(tmp_path / "a.npz")])
        assert r.exit_code == 0, r.output
    assert calls == [1]
    monkeypatch.setattr(pipeline, "transmission", counted)
    r = runner.invoke(app, ["analyze", spec, "--json", "--csv", str(tmp_path / "a.csv")])
    assert r.exit_code == 0 and calls == [1, 1]  # the document and the CSV table share one


def test_limits_csv_in_spec_units(tmp_path):
    spec = _spec(tmp_path)
    doc = json.loads(_run("limits", spec, "--json"))
    _run("limits", spec, "--csv", tmp_path / "l.csv")
    t = _read_csv(tmp_path / "l.csv")
    _same(t["theta0 [deg]"], [x["theta0"] for x in doc["limits"]], DEG)
    _same(t["S [mm]"], [x["S"] for x in doc["limits"]], MM)
    assert list(t["kind"]) == [x["kind"] for x in doc["limits"]]
    # d²y/dx² per rad²: a translation's in the display length, a rotation's a plain number
    rows = doc["limits"]
    _same(t["second_derivative_length_per_rad2 [mm]"],
          [x["second_derivative"] if x["kind"] == "translation" else None for x in rows], MM)
    _same(t["second_derivative"],
          [x["second_derivative"] if x["kind"] == "rotation" else None for x in rows])


BALANCE_MM = (EXAMPLES / "rahman_cssp_balance.toml").read_text(encoding="utf-8")
for key, inch in (("a1", 2.0), ("a2", 8.0), ("a4", 1.0), ("s1", 0.4)):
    BALANCE_MM = BALANCE_MM.replace(f"{key} = {inch}", f"{key} = {inch * 25.4}")
BALANCE_MM = (BALANCE_MM.replace('length = "in"', 'length = "mm"')
              .replace("length = 2.0 ", "length = 50.8 ").replace("= 0.4    #", "= 10.16    #")
              .replace("com = [1.0,", "com = [25.4,").replace("com = [4.0,", "com = [101.6,"))


def test_balance_in_spec_units_rms_loads_and_bounds(tmp_path):
    spec = _spec(tmp_path, BALANCE_MM, "balance_mm.toml")
    assert 'a1 = 50.8' in BALANCE_MM and "bearing_length = 10.16" in BALANCE_MM
    doc = json.loads(_run("balance", spec, "--json"))
    _run("balance", spec, "--csv", tmp_path / "b.csv")
    t = _read_csv(tmp_path / "b.csv")
    ps = doc["per_sample"]
    _same(t["input [deg]"], ps["input"], DEG)
    _same(t["shaking_force_after [N]"], ps["shaking_force"]["after"])
    _same(t["input_torque_before [N*m]"], ps["input_torque"]["before"])
    # the RMS loads in N and N·m are the measures undone; check them against the per-sample loads
    rms = doc["measures_rms"]
    for key, load in (("F", "shaking_force"), ("T", "shaking_moment"), ("T0", "input_torque"),
                      ("R", "bearing_force"), ("M", "bearing_moment")):
        for when in ("before", "after"):
            direct = float(np.sqrt(np.mean(np.square(ps[load][when]))))
            assert rms[when][key] == pytest.approx(direct, rel=1e-9), (key, when)
    assert rms["units"] == {"F": "N", "T": "N*m", "R": "N", "M": "N*m", "T0": "N*m"}
    assert {b["variable"] for b in doc["active_bounds"]} >= {"crank.m4", "rod.m2"}
    out = _run("balance", spec)
    assert "RMS loads over the cycle" in out and "at lower" in out
    assert f"{rms['before']['F']:.6g}" in out
    assert "a1=50.8 mm" in out


def test_synthesize_csv_with_a_length_override(tmp_path):
    spec = EXAMPLES / "bagci_example1_synthesis.toml"
    doc = json.loads(_run("synthesize", spec, "--json"))
    _run("synthesize", spec, "--unit", "length=mm", "--csv", tmp_path / "s.csv")
    t = _read_csv(tmp_path / "s.csv")
    rows = sorted(doc["rows"], key=lambda r: r["theta"])
    _same(t["theta0 [deg]"], [r["theta0"] for r in rows], DEG)
    _same(t["S [mm]"], [r["S"] for r in rows], MM)
    out = _run("synthesize", spec, "--unit", "length=mm")
    assert "[mm]" in out and "[in]" not in out


def test_validate_and_demo_speak_the_spec_units(tmp_path):
    spec = _spec(tmp_path)
    assert "d1=50.8 mm" in _run("validate", spec)
    folder = tmp_path / "ex"
    folder.mkdir()
    (folder / "rsrc_mm.toml").write_text(RSRC_MM, encoding="utf-8")
    _run("demo", folder, "--output-dir", tmp_path / "out", "--no-plots", "--no-reports")
    doc = json.loads((tmp_path / "out" / "rsrc_mm.analysis.json").read_text())
    t = _read_csv(tmp_path / "out" / "rsrc_mm.analysis.csv")
    _same(t["S [mm]"][t["mode"] == 1], doc["modes"][1]["variables"]["S"], MM)


def test_o_prints_one_line_and_json_alone_prints_the_document(tmp_path):
    spec = _spec(tmp_path)
    for cmd in (["analyze"], ["dynamics"], ["limits"], ["mobility"]):
        out = tmp_path / f"{cmd[0]}.json"
        text = _run(*cmd, spec, "--json", "-o", out)
        assert text.count("\n") == 1 and text.startswith(f"wrote {out} (JSON, SI units")
        assert json.loads(out.read_text()) == json.loads(_run(*cmd, spec, "--json"))
    text = _run("analyze", spec, "-o", tmp_path / "a.csv", "--csv", tmp_path / "b.csv")
    assert text.count("\n") == 1 and "72 rows" in text and "wrote" in text


def test_long_tables_are_summarised_unless_full(tmp_path):
    spec = _spec(tmp_path, RSRC_MM.replace("step = 10", "step = 0.5"))
    short = _run("analyze", spec)
    assert "more" in short and "extrema over all 720 rows" in short
    assert len(short.splitlines()) < 200
    full = _run("analyze", spec, "--full")
    assert len(full.splitlines()) > 2 * 720


def test_result_types_have_tables_and_dataframes(tmp_path):
    pytest.importorskip("pandas")
    import screwkit as sk

    spec = sk.load_spec(_spec(tmp_path))
    m = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
    df = m.to_dataframe(spec.display_units())
    np.testing.assert_allclose(df["phi0 [deg]"].to_numpy()[: len(spec.inputs)],
                               np.degrees(m.variable("phi0", mode=0)), rtol=1e-13)
    assert df.attrs["units"]["S_dot"] == "mm/s"
    dyn = sk.inverse_dynamics(m, 0)
    buf = io.StringIO()
    dyn.to_csv(buf)
    assert buf.getvalue().startswith("input.theta [rad],valid,shaking_force_x [N]")
    assert "input.point_z [m]" in dyn.to_dataframe().columns
    res = sk.Pipeline(sk.load_spec(EXAMPLES / "rahman_cssp_balance.toml")).balance()
    t = res.table()
    assert t.rows == 36 and "bearing_moment_after" in t.names
    path = tmp_path / "bal.csv"
    res.to_csv(path)
    assert path.read_text().startswith("input [rad],G_before,G_after,shaking_force_before [N]")


def test_progress_bar_counts_on_a_terminal_and_is_silent_otherwise(monkeypatch):
    from rich.console import Console

    import screwkit.cli.common as common
    from screwkit.cli.progress import progress_bar

    quiet = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(file=quiet, force_terminal=False))
    with progress_bar("starts", total=3) as advance:
        for k in range(3):
            advance(k + 1, 3)
    assert quiet.getvalue() == ""
    loud = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(file=loud, force_terminal=True, width=100))
    with progress_bar("starts", total=3) as advance:
        for k in range(3):
            advance(k + 1, 3)
    assert "3/3" in loud.getvalue() and "starts" in loud.getvalue()


def test_long_calls_report_progress():
    import screwkit as sk
    from screwkit.balancing.balance import prepare
    from screwkit.balancing.pareto import pareto_front
    from screwkit.balancing.variables import point_mass_variables

    spec = sk.load_spec(EXAMPLES / "bagci_example1_synthesis.toml")
    calls: list[tuple[int, int]] = []
    sk.synthesize(spec.synthesis, starts=3, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(1, 3), (2, 3), (3, 3)]
    bal = sk.load_spec(EXAMPLES / "rahman_cssp_balance.toml")
    mode = sk.Pipeline(bal).mode()
    setup = prepare(bal.linkage, mode, [point_mass_variables(bal.linkage, "rod")],
                    speed=bal.speed)
    calls.clear()
    front = pareto_front(setup, ("F", "T"), divisions=2, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(1, 3), (2, 3), (3, 3)] and front.measures.shape == (3, 2)


def test_simulate_csv_in_spec_units(tmp_path):
    spec = EXAMPLES / "rahman_cssp_drive.toml"
    doc = json.loads(_run("simulate", spec, "--cycles", "2", "--json"))
    _run("simulate", spec, "--cycles", "2", "--unit", "angular_velocity=rpm",
         "--csv", tmp_path / "s.csv")
    t = _read_csv(tmp_path / "s.csv")
    s = doc["samples"]
    _same(t["time [s]"], s["time"])
    _same(t["angle [deg]"], s["angle"], DEG)
    _same(t["speed [rpm]"], s["speed"], 2 * math.pi / 60)
    _same(t["motor_torque [N*m]"], s["motor_torque"])
    assert "crank.point_z [in]" in t and "kinetic_energy [J]" in t


def test_unit_option_takes_the_spec_kind_names():
    """--unit accepts what [units] accepts for a moment: torque is the same kind."""
    from screwkit.io.display_units import parse_unit_overrides

    assert parse_unit_overrides(["torque=lbf*in"]) == {"moment": "lbf*in"}
    assert parse_unit_overrides(["moment=N*m"]) == {"moment": "N*m"}

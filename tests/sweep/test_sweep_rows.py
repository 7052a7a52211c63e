"""Every row of a sweep equals the single-spec command's result for that design: the design is
written as its own spec file and the command's JSON document is compared with the row, number
for number (the sweep runs in this process here; tests/sweep/test_sweep_engine.py shows the Dask
runs give the same table)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from sweep_helpers import EXAMPLES, command_json, design_spec, runner

from screwkit.cli.main import app
from screwkit.sweep import EngineConfig, JobOptions, define_sweep, run_sweep
from screwkit.sweep.table import read_table

IN_PROCESS = EngineConfig(workers=0)


def sweep_rows(tmp_path: Path, spec: str, vary: list[str], job: str, **options: object
               ) -> tuple[list[dict], object]:
    definition = define_sweep(EXAMPLES / spec, vary, job, options=JobOptions(**options))  # type: ignore[arg-type]
    out = tmp_path / f"{job}.parquet"
    run_sweep(definition, out, IN_PROCESS)
    return read_table(out), definition


def designs_as_files(tmp_path: Path, spec: str, definition, rows: list[dict]) -> list[Path]:
    files = []
    for row in rows:
        i = row["design"]
        overrides = {k.text: v for k, v in zip(definition.designs.keys,
                                                 [v for _, v in definition.designs.overrides(i)],
                                                 strict=True)}
        files.append(design_spec(EXAMPLES / spec, overrides, tmp_path, f"design{i}"))
    return files


def test_dynamics_rows_equal_the_dynamics_command(tmp_path):
    spec = "rsrc_fig7_dynamics.toml"
    rows, d = sweep_rows(tmp_path, spec, ["d2=4.2:4.8:2", "links.coupler.mass=0.5 kg:1.5 kg:2"],
                         "dynamics")
    assert [r["design"] for r in rows] == [0, 1, 2, 3]
    assert [r["dimensions.d2 [in]"] for r in rows] == [4.2, 4.2, 4.8, 4.8]
    assert [r["links.coupler.mass [kg]"] for r in rows] == [0.5, 1.5, 0.5, 1.5]
    for row, f in zip(rows, designs_as_files(tmp_path, spec, d, rows), strict=True):
        doc = command_json("dynamics", str(f))
        assert row["status"] == "ok" and row["assembles"]
        for name, stats in doc["summary"].items():
            if isinstance(stats, dict) and "rms" in stats:
                col = name.replace("effort ", "effort.")
                assert row[f"{col}.rms"] == stats["rms"], name
                assert row[f"{col}.peak"] == stats["peak"], name
    # the coupler's mass changes the loads (the override reached the model)
    assert rows[0]["shaking_force.rms"] != rows[1]["shaking_force.rms"]


def test_analyze_and_limits_rows_equal_the_commands(tmp_path):
    spec = "bagci_fig7_rsrc.toml"
    rows, d = sweep_rows(tmp_path, spec, ["d3=2.8:3.2:2", "lambda0=55deg:65deg:2"], "analyze")
    lim_rows, _ = sweep_rows(tmp_path, spec, ["d3=2.8:3.2:2", "lambda0=55deg:65deg:2"], "limits")
    for row, lrow, f in zip(rows, lim_rows, designs_as_files(tmp_path, spec, d, rows), strict=True):
        doc = command_json("analyze", str(f))
        assert row["modes"] == len(doc["modes"])
        for mode in doc["modes"]:
            k = mode["mode"]
            for name in ("phi0", "S", "chi0"):
                values = np.array([np.nan if v is None else v for v in mode["variables"][name]])
                assert row[f"mode{k}.{name}.min"] == np.nanmin(values)
                assert row[f"mode{k}.{name}.max"] == np.nanmax(values)
            chi = np.array([np.nan if v is None else v for v in mode["variables"]["chi0"]])
            assert row[f"mode{k}.min_abs_sin_chi0"] == np.nanmin(np.abs(np.sin(chi)))
        limits = command_json("limits", str(f))
        kinds = [x["kind"] for x in limits["limits"]]
        assert row["limits.rotation"] == kinds.count("rotation")
        assert row["limits.translation"] == kinds.count("translation")
        assert lrow["limits"] == len(limits["limits"])
        for j, lim in enumerate(limits["limits"]):
            for field in ("kind", "branch", "theta0", "phi0", "second_derivative"):
                assert lrow[f"limit{j}.{field}"] == lim[field]
            assert lrow[f"limit{j}.dwell_order"] == lim.get("dwell_order")
    # λ0 given in degrees went into the spec as degrees
    assert [r["dimensions.lambda0 [deg]"] for r in rows] == [55.0, 65.0, 55.0, 65.0]


def test_mobility_and_balance_rows_equal_the_commands(tmp_path):
    rows, d = sweep_rows(tmp_path, "rahman_cssp_balance.toml", ["a2=7.5,8.5"], "balance")
    mob, dm = sweep_rows(tmp_path, "rccc_loop.toml", ["joints[1].length=0.9:1.1:2"], "mobility")
    for row, f in zip(rows, designs_as_files(tmp_path, "rahman_cssp_balance.toml", d, rows),
                      strict=True):
        doc = command_json("balance", str(f))
        for name, value in doc["measures"]["before"].items():
            assert row[f"{name}.before"] == value
            assert row[f"{name}.after"] == doc["measures"]["after"][name]
        assert row["mass.after"] == sum(doc["link_mass"]["after"].values())
    assert rows[0]["G.before"] != rows[1]["G.before"]
    for row, f in zip(mob, designs_as_files(tmp_path, "rccc_loop.toml", dm, mob), strict=True):
        doc = command_json("mobility", str(f))
        assert row["formula.mobility"] == doc["formula"]["mobility"]
        assert row["numeric.mobility"] == doc["numeric"]["mobility"]
        assert row["numeric.rank"] == doc["numeric"]["rank"]


def test_synthesize_rows_equal_the_command(tmp_path):
    spec = "bagci_example1_synthesis.toml"
    rows, d = sweep_rows(tmp_path, spec, ["d2=2.9,3.1"], "synthesize")
    for row, f in zip(rows, designs_as_files(tmp_path, spec, d, rows), strict=True):
        doc = command_json("synthesize", str(f))
        assert row["E"] == doc["objective"]
        assert row["rmse"] == doc["rmse"] and row["rmse_S"] == doc["rmse_S"]
        for name, value in doc["dimensions"].items():
            assert row[f"result.{name}"] == value


def test_a_bad_design_is_a_row_with_the_commands_reason(tmp_path):
    spec = "rsrc_fig7_dynamics.toml"
    rows, d = sweep_rows(tmp_path, spec, ["d1=0,2", "links.crank.mass=-1 kg,0.4 kg"], "dynamics")
    assert [r["status"] for r in rows] == ["failed", "failed", "failed", "ok"]
    files = designs_as_files(tmp_path, spec, d, rows)
    for row, f in zip(rows[:3], files[:3], strict=True):
        r = runner.invoke(app, ["dynamics", str(f)])
        assert r.exit_code == 2
        # the command names its own file; the row names the swept spec
        expected = " ".join(r.stderr.split()).removeprefix("error: ")
        assert " ".join(row["reason"].split()) == expected.replace(str(f), str(EXAMPLES / spec))
        assert row.get("shaking_force.rms") is None
    assert "d1" in rows[0]["reason"] and "mass" in rows[2]["reason"]


def test_a_design_that_assembles_only_in_part_says_where(tmp_path):
    spec = "rsrc_fig7_dynamics.toml"
    rows, d = sweep_rows(tmp_path, spec, ["d2=0.5,4.5"], "dynamics")
    part, whole = rows
    assert part["status"] == "ok" and part["assembles"] is False
    assert 0 < part["assembling_samples"] < 36
    assert part["where"].endswith("deg") and whole["where"] == "everywhere"
    f = designs_as_files(tmp_path, spec, d, rows)[0]
    doc = command_json("dynamics", str(f))
    assert f"at {36 - part['assembling_samples']} of 36 inputs" in doc["note"]
    assert part["shaking_force.rms"] == doc["summary"]["shaking_force"]["rms"]


@pytest.mark.parametrize("text", ["d9=1:2:3", "links.nothing.mass=1:2:2", "d2=1 kg:2 kg:3",
                                  "motion.mode=0.5:1:2", "d2", "d2=1:2:x"])
def test_bad_vary_options_are_refused_before_any_work(tmp_path, text):
    from screwkit.sweep.designs import DesignError

    with pytest.raises((DesignError, ValueError)):
        define_sweep(EXAMPLES / "rsrc_fig7_dynamics.toml", [text], "dynamics")

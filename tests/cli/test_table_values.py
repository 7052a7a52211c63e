"""What the terminal tables print (issue 30): round-off zeros as 0 below a noise floor
relative to the quantity's scale, the input at each dynamics peak, the limits' second
derivative with its true unit, no stray separator in a joint list's description, and a split
table balanced rather than ending with a lone column."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.formatting import (
    NOISE_RTOL,
    TextColumn,
    _groups,
    extrema_columns,
    noise_floor,
    number,
    print_columns,
    table_columns,
)
from screwkit.cli.main import app
from screwkit.tables import Column, ResultTable

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_values_below_the_noise_floor_print_as_zero():
    assert noise_floor([1.6, -0.866, np.nan]) == pytest.approx(1.6 * NOISE_RTOL)
    assert number(9.61481e-17, floor=noise_floor([1.6])) == "0"
    assert number(-0.0) == "0"
    assert number(2.3e-29) == "2.3e-29"  # no floor given: a small value is a value
    assert number(0.866025, floor=noise_floor([1.6])) == "0.866025"


def test_a_column_is_floored_by_its_quantity_over_the_whole_table():
    table = ResultTable((Column("x", "length", np.array([1.6, 0.5])),
                         Column("z", "length", np.array([1.7e-18, -2.3e-29])),
                         Column("residual", "ratio", np.array([3e-16, 1e-15]))))
    cols, _ = table_columns(table, ["x", "z", "residual"])
    assert list(cols[1].cells) == ["0", "0"]  # a length next to lengths of order 1
    assert list(cols[2].cells) == ["3e-16", "1e-15"]  # a ratio is its own scale
    ext = extrema_columns(["z"], [np.array([1.7e-18, -2.3e-29])], np.array([0.0, 1.0]), "deg",
                          [cols[1].floor])
    assert list(ext[1].cells) == ["0"] and list(ext[3].cells) == ["0"]


def test_analyze_prints_round_off_as_zero():
    r = CliRunner().invoke(app, ["analyze", str(EXAMPLES / "bagci_example1_synthesis.toml")])
    assert r.exit_code == 0, r.output
    assert "e-16" not in r.output and "e-17" not in r.output


def test_dynamics_gives_each_peak_with_its_input():
    spec = sk.load_spec(EXAMPLES / "fourbar_dynamics.toml")
    pipe = sk.Pipeline(spec)
    dyn = pipe.dynamics()
    summary = dyn.summary()
    force = np.linalg.norm(dyn.shaking_force, axis=-1)
    k = int(np.argmax(force))
    assert summary["shaking_force"]["peak_at"] == dyn.inputs[k, 0]
    r = CliRunner().invoke(app, ["dynamics", str(EXAMPLES / "fourbar_dynamics.toml")])
    assert r.exit_code == 0, r.output
    assert "peak at" in r.output and "input [deg]" in r.output
    row = next(line for line in r.output.splitlines() if "shaking_force " in line)
    assert f"{np.degrees(dyn.inputs[k, 0]):g}" in row
    moment = next(line for line in r.output.splitlines() if "crank_pin.moment" in line)
    assert "e-1" not in moment and " 0 " in moment  # a planar pin carries no moment


def test_limits_second_derivative_has_its_unit():
    r = CliRunner().invoke(app, ["limits", str(EXAMPLES / "bagci_fig9_dwell.toml")])
    assert r.exit_code == 0, r.output
    assert "per rad²" not in r.output
    assert "rad/rad²" in r.output and "in/rad²" in r.output


def test_joint_list_description_has_no_stray_separator():
    r = CliRunner().invoke(app, ["validate", str(EXAMPLES / "rrsrr_loop.toml")])
    assert r.exit_code == 0, r.output
    flat = " ".join(line.strip() for line in r.output.splitlines())  # prose is wrapped
    assert " ;" not in flat and "LOOP (RRSRR); 36 input samples" in flat


def test_a_split_table_is_balanced():
    key = TextColumn("output", ["phi0"])
    cols = [key] + [TextColumn(f"c{i}", ["x" * 8]) for i in range(7)]
    groups = _groups(cols, 1, 80)  # 7 columns of 11 next to a key of 10: six fit, then one
    assert [len(g) for g in groups] == [4, 3]
    out = io.StringIO()
    print_columns(Console(file=out, width=80, color_system=None), "t", cols, width=80)
    assert "columns 6–8 of 8" in out.getvalue()
    assert all(len(line) <= 80 for line in out.getvalue().splitlines())

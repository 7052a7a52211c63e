"""A synthesis that ends on a bound says so (issue 30: Bagci's Example 1 ends with
a = 30.00000 in on its |a| <= 30 in bound): in the result (``at_bounds``), its message, the
JSON document and the terminal table."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.synthesis.solve import bounds_reached

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
INCH = 0.0254


def test_bounds_reached_names_the_side_and_the_bound():
    x = np.array([0.762, 0.1, -1.0, 0.5 - 1e-12])
    got = bounds_reached(["a", "b", "c", "d"], x, [-0.762, 0.0, -1.0, -np.inf],
                         [0.762, 1.0, 1.0, 0.5], [INCH, INCH, 1.0, 1.0])
    assert got == {"a": ("upper", 0.762), "c": ("lower", -1.0), "d": ("upper", 0.5)}
    assert bounds_reached(["a"], np.array([0.76]), [-0.762], [0.762], [INCH]) == {}


def test_bagci_example_1_ends_on_its_a_bound():
    spec = sk.load_spec(EXAMPLES / "bagci_example1_synthesis.toml")
    best = sk.Pipeline(spec).synthesize().results[0]
    assert best.dimensions["a"] == pytest.approx(30 * INCH, abs=1e-9)  # independent of the flag
    assert best.at_bounds == {"a": ("upper", pytest.approx(30 * INCH))}
    assert "a ended on its upper bound (30 in)" in best.message


def test_the_bound_reaches_the_json_and_the_table(tmp_path):
    spec = str(EXAMPLES / "bagci_example1_synthesis.toml")
    r = CliRunner().invoke(app, ["synthesize", spec, "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    best = doc["results"][0] if "results" in doc else doc
    assert best["at_bounds"] == {"a": {"side": "upper", "bound": pytest.approx(30 * INCH)}}
    r = CliRunner().invoke(app, ["synthesize", spec])
    assert r.exit_code == 0, r.output
    row = next(line for line in r.output.splitlines() if line.startswith("│ a "))
    assert "on upper" in row
    assert "ended on its upper bound" in " ".join(line.strip() for line in r.output.splitlines())


def test_an_interior_optimum_has_no_bound_note():
    spec = sk.load_spec(EXAMPLES / "bagci_example5_synthesis.toml")
    best = sk.Pipeline(spec).synthesize().results[0]
    assert best.at_bounds == {} and "bound" not in best.message


def test_the_loop_route_reports_a_bound_too(tmp_path):
    # the RSSR example's free optimum has d3 = 135.4 mm; a bound at 120 mm holds it there
    text = (EXAMPLES / "rssr_synthesis.toml").read_text(encoding="utf-8")
    assert "d3 = [20, 200]" in text
    path = tmp_path / "rssr_bound.toml"
    path.write_text(text.replace("d3 = [20, 200]", "d3 = [20, 120]"), encoding="utf-8")
    spec = sk.load_spec(path)
    assert spec.synthesis.route == "generic"
    best = sk.Pipeline(spec).synthesize().results[0]
    assert best.dimensions["d3"] == pytest.approx(0.120, abs=1e-9)
    assert best.at_bounds == {"d3": ("upper", pytest.approx(0.120))}
    assert "d3 ended on its upper bound (120 mm)" in best.message

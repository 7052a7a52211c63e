"""Numbers in notes and messages are formatted for people, in the spec's units (issue 30: a
note read ``stops assembling after input [np.float64(4.363323129985823)]`` — a numpy repr in
radians for a spec in degrees)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.io.display_units import display_units
from screwkit.messages import message_units, shown, shown_range
from screwkit.model.families import fourbar

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
REPR = re.compile(r"np\.float|\[\d+\.\d{7,}")  # a numpy repr or a long raw float in brackets


def _crank_rocker_that_locks() -> sk.Linkage:
    """Bagci's Example 3 4R with a longer crank: it assembles only over two input ranges."""
    inch = 0.0254
    return fourbar(a=9.204072 * inch, d1=3.0 * inch, d2=8.099989 * inch, d3=1.181742 * inch)


def test_shown_formats_si_values_in_the_units_asked_for():
    assert shown(np.float64(math.radians(250.0)), "angle") == "250 deg"
    assert shown(0.0127, "length") == "0.0127 m"
    mm = display_units({"length": "mm", "angle": "rad"})
    assert shown(0.0127, "length", mm) == "12.7 mm"
    assert shown(math.pi, "angle", mm) == "3.14159 rad"
    assert shown(-0.0, "length", mm) == "0 mm"
    assert shown_range(0.0, math.pi / 2, "angle") == "[0, 90] deg"
    with message_units(mm):
        assert shown(0.0254, "length") == "25.4 mm"
    assert shown(0.0254, "length") == "0.0254 m"  # the context ends with the block


def test_assembly_events_quote_the_input_in_degrees_not_a_repr():
    lk = _crank_rocker_that_locks()
    motion = sk.solve_motion(lk, np.radians(np.arange(0.0, 360.0, 5.0)))
    events = [e for md in motion.modes for e in md.events]
    assert events and all("deg" in e and not REPR.search(e) for e in events), events
    generic = sk.solve_motion(lk, np.radians(np.arange(0.0, 360.0, 5.0)), method="generic")
    events = [e for md in generic.modes for e in md.events] + list(generic.notes)
    assert events and all(not REPR.search(e) for e in events), events


def test_the_pipeline_formats_messages_in_the_spec_units(tmp_path):
    text = (EXAMPLES / "bagci_example3_4r.toml").read_text(encoding="utf-8")
    text = (text.replace("d1 = 1.0", "d1 = 3.0").replace("start = -82.625311", "start = 0")
            .replace("stop = 7.374689", "stop = 360").replace("step = 10", "step = 5"))
    spec_file = tmp_path / "locks.toml"
    spec_file.write_text(text, encoding="utf-8")
    spec = sk.load_spec(spec_file)
    events = [e for md in sk.Pipeline(spec).motion.modes for e in md.events]
    assert any("input.theta = 33.8705 deg" in e for e in events), events
    radians = sk.Pipeline(spec, units=spec.display_units(overrides={"angle": "rad"}))
    events = [e for md in radians.motion.modes for e in md.events]
    assert any("input.theta = 0.591152 rad" in e for e in events), events
    result = CliRunner().invoke(app, ["analyze", str(spec_file), "--unit", "angle=rad"])
    assert result.exit_code == 0, result.output
    flat = " ".join(line.strip() for line in result.output.splitlines())  # prose is wrapped
    assert "input.theta = 0.591152 rad" in flat and not REPR.search(flat)


def test_spec_load_messages_quote_the_spec_length_unit(tmp_path):
    spec_file = tmp_path / "rssr.toml"
    spec_file.write_text((EXAMPLES / "rssr_spatial.toml").read_text(encoding="utf-8")
                         + '\n[coupler_point]\nlink = "coupler"\nf = 50.0\ng = 10.0\nh = 0.0\n',
                         encoding="utf-8")
    with pytest.raises(sk.SpecError) as info:
        sk.load_spec(spec_file)
    assert "this point is 10 mm off it" in str(info.value) and "50 mm along" in str(info.value)

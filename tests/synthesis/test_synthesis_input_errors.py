"""Bad synthesis input gets the real reason in the user's words: starts outside their bounds and
d3_range in the spec's units, the reason instead of "no start assembled", targets checked up
front (finite, span > 0, data range), the equality-constrained route named for a construction
with delta0, and ``--plot`` file names and folders checked before the solve."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from screwkit.cli.synthesize_cmd import register
from screwkit.io.spec import load_spec
from screwkit.io.synthesis_table import SynthesisConfigError, synthesis_from_spec
from screwkit.synthesis.problem import (
    ConstraintConstruction,
    ConstraintPoint,
    RSRCSynthesisProblem,
)
from screwkit.synthesis.solve import SynthesisError, synthesize, synthesize_multistart
from screwkit.synthesis.targets import ScrewTarget, data_function, library_function

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
EX1 = (EXAMPLES / "bagci_example1_synthesis.toml").read_text()
HEAD = EX1.split("[synthesis]")[0]
UNKNOWNS = 'unknowns = ["e", "d1", "d2", "d3", "a", "b", "delta0", "theta01"]\n'

app = typer.Typer()
register(app)


@app.command()
def _placeholder() -> None:  # a second command keeps typer's subcommand form
    """(unused)"""


def _spec(tmp_path: Path, synthesis: str, name: str = "s.toml") -> Path:
    p = tmp_path / name
    p.write_text(HEAD + synthesis)
    return p


def _problem(tmp_path: Path, synthesis: str):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy RuntimeWarning on the way to the error
        return synthesis_from_spec(load_spec(_spec(tmp_path, synthesis)))


ROT = '[synthesis.rotation]\nfunction = "zero"\ndesign_points = { start = 0, stop = 80, step = 10 }\n'


def test_start_outside_bounds_in_spec_units(tmp_path):
    text = f"[synthesis]\n{UNKNOWNS}start = {{theta01 = 200}}\nbounds = {{a = [10, 30]}}\n{ROT}"
    with pytest.raises(SynthesisConfigError) as exc:
        _problem(tmp_path, text)
    msg = str(exc.value)
    assert "[synthesis.bounds.a]" in msg and "2.5 in (0.0635 m)" in msg
    assert "[10 in (0.254 m), 30 in (0.762 m)]" in msg and "np.float64" not in msg


def _ex1_problem(**changes) -> RSRCSynthesisProblem:
    d = math.radians
    target = ScrewTarget(library_function("zero"), np.radians(np.arange(0, 81, 10.0)))
    start = {"e": 0.0, "d1": 0.0254, "d2": 0.0762, "d3": 0.0508, "a": 0.0635, "b": 0.0381,
             "delta0": 0.0, "lambda0": d(60), "theta01": d(200)}
    start.update(changes.pop("start", {}))
    return RSRCSynthesisProblem(target, start, ("e", "d1", "d2", "d3", "a", "b", "delta0",
                                                "theta01"), **changes)


def test_solver_bounds_message_plain_numbers():
    problem = _ex1_problem(bounds={"a": (0.254, 0.762)})
    for run in (lambda: synthesize(problem), lambda: synthesize_multistart(problem, n_starts=3)):
        with pytest.raises(SynthesisError) as exc:
            run()
        msg = str(exc.value)
        assert "a = 0.0635 m is outside its bounds [0.254 m, 0.762 m]" in msg
        assert "np.float64" not in msg and "no start" not in msg


def test_multistart_names_the_reason():
    problem = _ex1_problem(start={"d2": 0.000254})  # coupler far too short: assembles nowhere
    with pytest.raises(SynthesisError) as exc:
        synthesize_multistart(problem, n_starts=1)
    msg = str(exc.value)
    assert "does not assemble" in msg and "widen the spread" not in msg
    with pytest.raises(SynthesisError) as exc:
        synthesize_multistart(problem, n_starts=3, spread=0.1)
    msg = str(exc.value)
    assert "3 start(s) tried" in msg and "does not assemble" in msg and "spread" in msg


def test_non_finite_expression_is_named(tmp_path):
    text = (f"[synthesis]\n{UNKNOWNS}start = {{theta01 = 200}}\n[synthesis.rotation]\n"
            'expression = "1/(theta-10)"\ndesign_points = { start = 0, stop = 80, step = 10 }\n')
    with pytest.raises(SynthesisConfigError, match=r"not finite at theta = 10"):
        _problem(tmp_path, text)


def test_power_span_zero(tmp_path):
    text = (f"[synthesis]\n{UNKNOWNS}start = {{theta01 = 200}}\n[synthesis.rotation]\n"
            'function = "power"\nparameters = {amplitude = 10, span = 0, power = 2}\n'
            "design_points = { start = 0, stop = 80, step = 10 }\n")
    with pytest.raises(SynthesisConfigError, match=r"span must be > 0"):
        _problem(tmp_path, text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match="not finite at theta = 0 deg"):
            ScrewTarget(lambda t: 1.0 / t, np.radians([10.0, 20.0]))


def test_data_outside_its_range(tmp_path):
    text = (f"[synthesis]\n{UNKNOWNS}start = {{theta01 = 200}}\n[synthesis.rotation]\n"
            "data = {theta = [0, 40, 80], value = [0, 1, 2]}\ndesign_points = [0, 100]\n")
    with pytest.raises(SynthesisConfigError, match=r"theta = 100 deg lie outside the data's "
                                                   r"range \[0, 80\] deg"):
        _problem(tmp_path, text)
    fn = data_function([0.0, 1.0], [0.0, 2.0])
    np.testing.assert_allclose(fn(np.array([0.0, 0.5, 1.0])), [0.0, 1.0, 2.0], rtol=0, atol=0)


def test_overlay_d3_range_in_spec_units(tmp_path):
    text = (EXAMPLES / "bagci_example8_overlay.toml").read_text() + "d3_range = [2, 1]\n"
    p = tmp_path / "ov.toml"
    p.write_text(text)
    with pytest.raises(SynthesisConfigError) as exc:
        synthesis_from_spec(load_spec(p))
    msg = str(exc.value)
    assert "[synthesis.overlay.d3_range]" in msg and "2 in (0.0508 m)" in msg
    assert "np.float64" not in msg


def test_construction_with_delta0_names_the_python_route():
    target = ScrewTarget(library_function("power", amplitude=math.radians(40),
                                          span=math.radians(47.5)), np.radians([10.0, 30.0]))
    start = {"e": 0.0, "d1": 0.0254, "d2": 0.0762, "delta0": 0.1, "lambda0": math.radians(60),
             "theta01": math.radians(25)}
    cons = ConstraintConstruction(ConstraintPoint(0.0), ConstraintPoint(math.radians(47.5)))
    with pytest.raises(ValueError, match="synthesize_equality_constrained"):
        RSRCSynthesisProblem(target, start, ("d1", "d2", "theta01"), construction=cons)


def test_plot_name_gets_png_and_folder_checked_first(tmp_path):
    spec = EXAMPLES / "bagci_example4_synthesis.toml"
    out = tmp_path / "out"
    r = CliRunner().invoke(app, ["synthesize", str(spec), "--plot", str(out)])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "out.png").is_file() and not out.exists()
    assert f"wrote {out}.png" in r.output
    missing = tmp_path / "nowhere" / "p.png"
    bad = _spec(tmp_path, "[synthesis]\nunknowns = [\"nonsense\"]\n" + ROT, "bad.toml")
    r = CliRunner().invoke(app, ["synthesize", str(bad), "--plot", str(missing)])
    assert r.exit_code == 2
    assert "does not exist" in r.output  # the plot folder is checked before the spec is solved

"""`validate` checks every table of a spec against what its family offers: a table a job would
refuse is reported at validate, with the file, the key and the reason; a good spec lists its
jobs."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()


def _spec(tmp_path: Path, base: str, extra: str = "", old: str = "", new: str = "") -> Path:
    text = (EXAMPLES / base).read_text(encoding="utf-8")
    if old:
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "case.toml"
    path.write_text(text + "\n" + extra, encoding="utf-8")
    return path


@pytest.mark.parametrize(("base", "extra", "old", "new", "key", "why"), [
    ("rssr_synthesis.toml", "", "[synthesis.rotation]", "[synthesis.translation]",
     "[synthesis.translation]", "generates no translation"),
    ("rssr_spatial.toml", '[limits]\noutput = "chi0"\n', "", "", "[limits]",
     "no output variable 'chi0'"),
    ("rssr_spatial.toml", '[limits]\nmethod = "closed"\n', "", "", "[limits]",
     "no closed-form limits"),
    ("rssr_spatial.toml", "[coupler_point]\nf = 40\ng = 3\n", "", "", "[coupler_point]",
     "only points on that line"),
    ("rccc_loop.toml", "", 'link = "link2"', 'link = "link9"', "[coupler_points[0].link]",
     "no moving link called 'link9'"),
    ("bagci_example3_4r_synthesis.toml", "", '"d2", "q2"', '"d2", "lambda0", "q2"',
     "[synthesis.unknowns]", "lambda0 cannot be solved for"),
])
def test_validate_reports_what_a_job_would_refuse(tmp_path, base, extra, old, new, key, why):
    r = runner.invoke(app, ["validate", str(_spec(tmp_path, base, extra, old, new))])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert key in text and why in text, text
    assert "Traceback" not in r.output


def test_validate_lists_the_jobs_of_a_spec():
    r = runner.invoke(app, ["validate", str(EXAMPLES / "rrsrr_loop.toml"),
                            str(EXAMPLES / "rssr_synthesis.toml"),
                            str(EXAMPLES / "bagci_fig9_dwell.toml")])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "jobs: analyze (2 coupler point(s)), mobility, limits (generic route)" in text
    assert "synthesize (generic route)" in text


def test_a_joint_list_with_a_middle_input_names_why_it_has_no_output(tmp_path):
    text = (EXAMPLES / "rccc_loop.toml").read_text(encoding="utf-8")
    text = text.replace("input = true\n", "", 1).replace('name = "C2"\nkind = "C"',
                                                           'name = "C2"\nkind = "C"\ninput = true')
    text = text.replace('output = "C4.s"\n', "")  # the loop's outputs, which it has none of
    path = tmp_path / "mid.toml"
    path.write_text(text, encoding="utf-8")
    r = runner.invoke(app, ["validate", str(path)])
    out = " ".join(r.output.split())
    assert r.exit_code == 2 and "[limits]" in out and "not one of the two joints on the ground" in out

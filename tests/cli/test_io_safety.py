"""Unit tests of the input/output guards (docs/reliability.md): the quantity grammar, the
magnitude limits, safe spec reading, safe outputs and strict JSON. The command-line behaviour is
covered by the corpus in tests/bad_inputs."""

import json
import math
import os
import re
import stat
import time
from pathlib import Path

import numpy as np
import pytest

from screwkit.io.outputs import OutputPathError, atomic_path, check_output_path, check_outputs
from screwkit.io.quantity import QuantitySyntaxError, parse_quantity, parse_unit
from screwkit.io.results import NonFiniteResultError, dumps, jsonable, write_atomic
from screwkit.io.toml_file import MAX_NESTING, SpecFileError, read_toml
from screwkit.io.units import MAGNITUDE_LIMITS, UnitError, check_unit, to_si

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("text, magnitude, units", [
    ("2.0 in", 2.0, (("in", 1),)),
    ("  -1.5e-3   mm ", -1.5e-3, (("mm", 1),)),
    (".5 deg", 0.5, (("deg", 1),)),
    ("3000 rpm", 3000.0, (("rpm", 1),)),
    ("386.4 in/s^2", 386.4, (("in", 1), ("s", -2))),
    ("2.05e-4 lbf*s^2*in", 2.05e-4, (("lbf", 1), ("s", 2), ("in", 1))),
    ("1 kg·m²", 1.0, (("kg", 1), ("m", 2))),
    ("1 kg*m**2", 1.0, (("kg", 1), ("m", 2))),
    ("1 m / s / s", 1.0, (("m", 1), ("s", -1), ("s", -1))),
    ("1 kg/m^3*s", 1.0, (("kg", 1), ("m", -3), ("s", 1))),   # left to right, as pint
    ("1 m^-2", 1.0, (("m", -2),)),
    ("1 µm", 1.0, (("µm", 1),)),
    ("42", 42.0, ()),
])
def test_the_grammar_reads_every_documented_spelling(text, magnitude, units):
    q = parse_quantity(text)
    assert q.magnitude == magnitude and q.units == units


@pytest.mark.parametrize("text", [
    "10**10**10 in", "9^9^9 in", "10**400 in", "2*3 in", "2 (in)", "sqrt(4) in", "in",
    "1 m^5", "1 m^0", "1 m^2^2", "1 m**2**2", "1 kg m", "1 m/", "1 m*", "1e400 in", "",
    "nan m", "inf m", "1 m^99999999999", "1 m¹", "1 " + "a" * 41, "x" * 201, "1 in; import os",
])
def test_the_grammar_refuses_everything_else(text):
    with pytest.raises(QuantitySyntaxError):
        parse_quantity(text)


def test_parsing_is_linear_in_the_length():
    started = time.perf_counter()
    for text in ("1" * 199 + " ", "1 " + "m*" * 98 + "m", "1 " + "m/" * 98 + "m"):
        try:
            parse_quantity(text)
        except QuantitySyntaxError:
            pass
    assert time.perf_counter() - started < 0.5


def test_every_quantity_string_in_the_examples_and_docs_is_read():
    seen = 0
    pattern = re.compile(r'"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?\s*[A-Za-z][^"]*)"')
    for path in [*ROOT.glob("examples/*.toml"), ROOT / "docs" / "spec-format.md"]:
        for text in pattern.findall(path.read_text()):
            if any(w in text for w in ("theta", "seed", "Table", "Example", "Fig")):
                continue  # expressions and prose, not quantities
            parse_quantity(text)
            seen += 1
    assert seen > 40
    for unit in ("kg*mm^2", "lbf*s^2*in", "in", "deg", "rad/s", "in/s^2", "kg*m^2"):
        parse_unit(unit)


@pytest.mark.parametrize("text, kind, default, expected", [
    ("2.0 in", "length", None, 0.0508),
    ("60 rpm", "angular_velocity", None, 2 * math.pi),
    ("50 rev/s", "angular_velocity", None, 100 * math.pi),
    ("1 lbf*in*s^2", "inertia", None, 0.45359237 * 9.80665 * 0.0254),
    ("2", "inertia", "kg*mm^2", 2e-6),
    (3, "length", "in", 0.0762),
    ("0", "mass", None, 0.0),
])
def test_conversions(text, kind, default, expected):
    assert to_si(text, kind, default) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("kind", sorted(MAGNITUDE_LIMITS))
def test_magnitude_limits_per_kind(kind):
    high, low = MAGNITUDE_LIMITS[kind]
    assert to_si(high, kind) == high and to_si(-high, kind) == -high and to_si(0, kind) == 0
    with pytest.raises(UnitError, match="outside the range"):
        to_si(high * 1.01, kind)
    if low > 1e-300:
        assert to_si(low, kind) == low
        with pytest.raises(UnitError, match="outside the range"):
            to_si(low * 0.99, kind)


def test_unit_names_are_looked_up_one_by_one():
    with pytest.raises(UnitError, match="unknown unit"):
        check_unit("furlongz", "length")
    with pytest.raises(UnitError, match="cannot read the unit"):
        check_unit("2**1000*in", "length")
    with pytest.raises(UnitError, match="not a unit of angle"):
        check_unit("m", "angle")


# --- spec files ------------------------------------------------------------------------------

def _write(tmp_path, data: bytes, name="s.toml"):
    p = tmp_path / name
    p.write_bytes(data)
    return p


def test_brackets_in_strings_and_comments_do_not_count_as_nesting(tmp_path):
    deep = "[" * (3 * MAX_NESTING)
    text = (f'# {deep}\n[mechanism]\nfamily = "4R"\nname = "{deep}"\n'
            f"description = '{deep}'\nsource = \"\"\"\n{deep}\n\"\"\"\n")
    doc = read_toml(_write(tmp_path, text.encode()))
    assert doc["mechanism"]["name"] == deep


def test_nesting_at_the_limit_is_read_and_beyond_is_refused(tmp_path):
    ok = "x = " + "[" * MAX_NESTING + "]" * MAX_NESTING + "\n"
    assert read_toml(_write(tmp_path, ok.encode()))["x"]
    deep = "x = " + "[" * (MAX_NESTING + 1) + "]" * (MAX_NESTING + 1) + "\n"
    with pytest.raises(SpecFileError, match="nested more than"):
        read_toml(_write(tmp_path, deep.encode()))


def test_a_utf8_byte_order_mark_is_dropped(tmp_path):
    p = _write(tmp_path, b"\xef\xbb\xbf[mechanism]\nfamily = \"4R\"\n")
    assert read_toml(p) == {"mechanism": {"family": "4R"}}


@pytest.mark.parametrize("data, fragment", [
    (b"", "the file is empty"),
    (b"\n \t\n", "the file is empty"),
    (b"\xff\xfe[\x00m\x00", "UTF-16 byte-order mark"),
    (b"a = 1\x00", "NUL byte at offset 5"),
    (b"a = '\xe9'", "not UTF-8 text (byte 0xe9 at offset 5)"),
    (b"a = [1, 2", "not valid TOML"),
])
def test_unreadable_files_are_named(tmp_path, data, fragment):
    with pytest.raises(SpecFileError, match=re.escape(fragment)):
        read_toml(_write(tmp_path, data))


def test_folders_fifos_and_missing_files_are_refused_without_reading(tmp_path):
    os.mkfifo(tmp_path / "pipe.toml")
    (tmp_path / "dir.toml").mkdir()
    for name, fragment in (("pipe.toml", "FIFO"), ("dir.toml", "folder"),
                           ("none.toml", "no such spec file")):
        with pytest.raises(SpecFileError, match=fragment):
            read_toml(tmp_path / name)


# --- outputs ---------------------------------------------------------------------------------

def test_write_atomic_refuses_inputs_links_and_special_files(tmp_path):
    spec = tmp_path / "x.toml"
    spec.write_text("keep")
    (tmp_path / "link").symlink_to(spec)
    os.link(spec, tmp_path / "hard")
    os.mkfifo(tmp_path / "fifo")
    for target, fragment in ((spec, "input of the command"), (tmp_path / "link", "input"),
                             (tmp_path / "hard", "input"), (tmp_path / "fifo", "FIFO"),
                             (tmp_path, "folder"), (tmp_path / "no" / "r.json", "does not exist")):
        with pytest.raises(OutputPathError, match=fragment):
            write_atomic(target, "{}", [spec])
    (tmp_path / "elsewhere").symlink_to(tmp_path / "other.json")
    with pytest.raises(OutputPathError, match="symbolic link"):
        write_atomic(tmp_path / "elsewhere", "{}")
    assert spec.read_text() == "keep"
    assert not (tmp_path / "other.json").exists()
    with pytest.raises(OutputPathError, match="name the same file"):
        check_outputs([spec], {"-o": tmp_path / "a.json", "--plot": tmp_path / "a.json"})


def test_an_error_while_writing_leaves_no_file(tmp_path):
    target = tmp_path / "r.json"
    with pytest.raises(KeyboardInterrupt), atomic_path(target) as tmp:
        Path(tmp).write_text("half")
        raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        Path(tmp).write_text("half")
        raise RuntimeError("disk full")
    assert target.read_text() == "old" and sorted(tmp_path.iterdir()) == [target]


def test_results_are_ordinary_files_and_replace_regular_files(tmp_path):
    target = tmp_path / "r.json"
    target.write_text("old")
    write_atomic(target, "{}\n")
    mask = os.umask(0)
    os.umask(mask)
    assert target.read_text() == "{}\n"
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~mask
    assert check_output_path(tmp_path / "new.json") == tmp_path / "new.json"


def test_json_is_strict():
    doc = {"a": np.array([1.0, np.nan]), "b": np.float64(2.0), "c": [np.bool_(True)]}
    assert json.loads(dumps(doc)) == {"a": [1.0, None], "b": 2.0, "c": [True]}
    with pytest.raises(NonFiniteResultError, match=r"modes\[0\]\.x\[1\]"):
        jsonable({"modes": [{"x": np.array([0.0, np.inf])}]})
    with pytest.raises(NonFiniteResultError, match="low"):
        dumps({"low": float("-inf")})


def test_floating_point_errors_in_a_command_exit_2_instead_of_warning(capsys):
    import typer

    from screwkit.cli.common import guard

    for bad in (lambda: np.array([1e308]) * 10, lambda: np.array([1.0]) / 0.0,
                lambda: np.sqrt(np.array([-1.0]))):
        with pytest.raises(typer.Exit) as exc:
            guard(bad)
        assert exc.value.exit_code == 2
        assert "failed numerically" in capsys.readouterr().err


    def expects_nan() -> float:
        with np.errstate(invalid="ignore"):  # code that expects NaN says so and is left alone
            return float(np.sqrt(np.array([-1.0]))[0])

    assert np.isnan(guard(expects_nan))

"""CSV formula injection (issue 30): a name that starts as a spreadsheet formula (``=``, ``+``,
``-``, ``@``) is refused in a spec file, naming the key, and neutralised (a leading apostrophe)
in every CSV and Parquet header and text cell written for a name given through the Python API."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.sweep.table import csv_text, read_table, write_table
from screwkit.tables import FORMULA_STARTS, Column, ResultTable, safe_cell

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
BAD = "=HYPERLINK(1)"


def _loop_with(name: str) -> sk.Linkage:
    joints = [sk.Joint("a", "R"), sk.Joint(name, "R"), sk.Joint("c", "R"), sk.Joint("d", "R")]
    return sk.Linkage.from_hartenberg_denavit("L", joints, [1.0, 3.0, 2.5, 3.0], [0, 0, 0, 0],
                                              ["a.theta"])


def _formula_cells(cells: list[str]) -> list[str]:
    return [c for c in cells if c.startswith(FORMULA_STARTS)]


def test_safe_cell_prefixes_only_formula_starts():
    assert [safe_cell(t) for t in ("=1+2", "+a", "-x", "@f", "\tx", "ok", "a=b")] == [
        "'=1+2", "'+a", "'-x", "'@f", "'\tx", "ok", "a=b"]


@pytest.mark.parametrize("samples", [37, 5000])  # the csv module's rows, and pyarrow's
def test_motion_csv_headers_are_neutralised(samples):
    lk = _loop_with(BAD)
    motion = sk.solve_motion(lk, np.linspace(0.0, 2 * np.pi, samples, endpoint=False))
    text = motion.table().csv_text()
    header = next(csv.reader(io.StringIO(text)))
    assert not _formula_cells(header), header
    assert f"'{BAD}.theta [rad]" in header
    rows = list(csv.reader(io.StringIO(text)))[1:]
    assert len(rows) > 0 and all(len(r) == len(header) for r in rows)
    assert any(cell.startswith("-") for r in rows for cell in r)  # numbers keep their sign


def test_parquet_headers_are_neutralised(tmp_path):
    import pyarrow.parquet as pq  # the dev extra has pyarrow
    table = ResultTable((Column(f"{BAD}.theta", "angle", np.array([0.1, -0.2])),
                         Column("ok", "length", np.array([1.0, 2.0]))))
    table.to_parquet(tmp_path / "t.parquet")
    names = pq.read_table(tmp_path / "t.parquet").column_names
    assert names == [f"'{BAD}.theta [rad]", "ok [m]"]


def test_text_cells_are_quoted_and_neutralised():
    table = ResultTable((Column("name", "text", np.array(["@SUM(A1)", "a, b"])),
                         Column("x", "length", np.array([-1.0, 2.0]))))
    rows = list(csv.reader(io.StringIO(table.csv_text())))
    assert rows[1:] == [["'@SUM(A1)", "-1.0"], ["a, b", "2.0"]]


def test_sweep_tables_neutralise_headers_and_text(tmp_path):
    rows = [{f"{BAD}.d1": 1.0, "error": "-bad design", "n": -3}]
    header, first = list(csv.reader(io.StringIO(csv_text(rows))))
    assert header == [f"'{BAD}.d1", "error", "n"] and first == ["1.0", "'-bad design", "-3"]
    write_table(tmp_path / "s.parquet", rows, {})
    assert list(read_table(tmp_path / "s.parquet")[0]) == [f"'{BAD}.d1", "error", "n"]


@pytest.mark.parametrize(("example", "old", "new", "key"), [
    ("rrsrr_loop.toml", 'name = "ball"', f'name = "{BAD}"', "[joints.2.name]"),
    ("rrsrr_loop.toml", 'name = "elbow link tip"', 'name = "-1+2"', "[coupler_points.0.name]"),
    ("rrsrr_loop.toml", 'link = "link2"', 'link = "@link2"', "[coupler_points.0.link]"),
    ("fourbar_dynamics.toml", "[links.crank]", '[links."+crank"]', "[links.+crank]"),
])
def test_spec_refuses_formula_names_naming_the_key(tmp_path, example, old, new, key):
    text = (EXAMPLES / example).read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / example
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    with pytest.raises(sk.SpecError) as info:
        sk.load_spec(path)
    assert key in str(info.value) and "reads as a formula" in str(info.value)

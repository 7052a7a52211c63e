"""Parquet and CSV columns go into pyarrow through their buffers (``screwkit.tables.
arrow_array``): the same arrays as ``pa.array(v, from_pandas=True)`` (NaN as null), and an
``analyze -o .parquet`` no longer imports pandas (0.4 s of a 100,000-sample run, issue 30)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

from screwkit.tables import arrow_array

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("v", [
    np.array([1.0, np.nan, np.inf, -0.0, -np.inf]),
    np.array([1.5, 2.5], dtype=np.float32),
    np.full(9, np.nan),
    np.arange(20.0)[::3],  # not contiguous
    np.array([True, False, True] * 7),
    np.arange(11, dtype=np.int64),
    np.arange(3, dtype=np.uint8),
    np.array(["a", "b"]),
    np.array([], dtype=float),
])
def test_same_array_as_from_pandas(v):
    got = arrow_array(v)
    got.validate(full=True)
    assert got.equals(pa.array(v, from_pandas=True))
    nans = int(np.count_nonzero(np.isnan(v))) if v.dtype.kind == "f" else 0
    assert got.null_count == nans


def test_parquet_output_does_not_import_pandas(tmp_path):
    code = ("import sys\nfrom screwkit.cli.main import app\n"
            "try:\n    app(['analyze', sys.argv[1], '-o', sys.argv[2]])\n"
            "except SystemExit as e:\n    assert not e.code, e.code\n"
            "print('pandas' in sys.modules)\n")
    out = tmp_path / "a.parquet"
    r = subprocess.run([sys.executable, "-c", code, str(ROOT / "examples" /
                        "bagci_fig7_rsrc.toml"), str(out)], capture_output=True, text=True,
                       check=True)
    assert r.stdout.strip().splitlines()[-1] == "False"
    import pyarrow.parquet as pq

    table = pq.read_table(out)
    assert table.num_rows == 72 and table.num_columns == 44

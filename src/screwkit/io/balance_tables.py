"""Per-sample CSV tables of a balancing result (before/after), each written atomically."""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

from screwkit.balancing.errors import BalancingError
from screwkit.balancing.result import SAMPLE_LOADS, BalanceResult
from screwkit.io.results import write_atomic


def write_balance_tables(result: BalanceResult, folder: str | Path) -> list[str]:
        """CSV files: one per per-sample load and the mass properties, each written atomically;
        returns the paths. ``folder`` is created if missing; an existing file is refused."""
        from pathlib import Path


        out = Path(folder)
        if out.exists() and not out.is_dir():
            raise BalancingError(f"--tables needs a folder: {out} is an existing file; give a "
                                 "folder name (it is created if missing)")
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise BalancingError(f"cannot create the tables folder {out}: {exc.strerror}") from exc

        def csv_text(header: list[list[str]], rows: list[list[Any]]) -> str:
            buf = io.StringIO()
            w = csv.writer(buf)
            w.writerows(header)
            w.writerows(rows)
            return buf.getvalue()

        paths = []
        for key, title, unit in SAMPLE_LOADS:
            p = out / f"balance_{key}.csv"
            write_atomic(p, csv_text([[f"# {title} ({unit}); input in rad"],
                                      ["input", "before", "after"]], result.per_sample_table(key)))
            paths.append(str(p))
        p = out / "balance_mass_properties.csv"
        write_atomic(p, csv_text([["link", "quantity", "before", "after"]],
                                 result.mass_properties_table()))
        paths.append(str(p))
        return paths

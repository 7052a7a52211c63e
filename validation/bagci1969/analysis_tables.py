"""Reproduce the displacement columns of Bagci's Tables I-XII with screwkit's RSRC closed form.

For every row of every table, phi_g, chi0 and S are recomputed at the row's theta0 with
`screwkit.kinematics.closed_forms.rsrc.rsrc_positions`, for the inversion the table used (its program label),
with the dimensions tables/REPRODUCTION.md prescribes: as printed (I, II, III, VIII) or with
d3, a, b rebuilt from the parameters of constraint q1, q2 (eqs. 5.13-5.21, `rebuild_dimensions`)
where the text prints them rounded or not at all (IV-VII, IX-XII).

Conventions (REPRODUCTION.md, "Conventions pinned down"): phi_g is compared modulo 360 deg (some
tables print (-180, 180], others (0, 360)); tables with delta0 = 0 print |chi0|, so |chi0| is
compared there; S is compared as printed (Tables XI, XII print it in the "S1 + S_g" column).

Rows that cannot be compared are listed with the reason, never dropped silently.

Usage::

    python validation/bagci1969/analysis_tables.py           # print the table of deviations
    python validation/bagci1969/analysis_tables.py --write   # also write analysis_tables.md
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
DATA = HERE.parents[1] / "tests" / "data" / "bagci1969"
sys.path.insert(0, str(HERE))

from rebuild_dimensions import rebuild_from_table_json  # noqa: E402

from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_positions, rsrc_rates  # noqa: E402

TABLES = ("I", "II", "III", "IV", "V", "VI", "VII", "VIII", "IX", "X", "XI", "XII")
REBUILT = frozenset({"IV", "V", "VI", "VII", "IX", "X", "XI", "XII"})

#: Documented corrections of a printed input cell: (table, row) -> (column, value, reason)
CORRECTIONS: dict[tuple[str, int], tuple[str, float, str]] = {
    ("IX", 18): ("theta0_deg", 255.0,
                 "theta0 printed 225 (OCR); the 15-deg step and S(18) = S(255 deg) give 255"),
}

#: Documented exclusions of single printed cells: (table, row, quantity) -> reason
EXCLUSIONS: dict[tuple[str, int, str], str] = {
    ("IX", 1, "phi_g"): "printed 142.3735395 has an extra digit (OCR); 142.375395 is implied by "
                        "phi_g - psi_g0 = 112.040613 in every other row",
    ("XI", 2, "phi_g"): "printed 145.20401 is not reproducible (3.08 deg off) while the same row's "
                        "chi0 and S are; the three related printed values are mutually "
                        "consistent, so the error is in the hand-typed original",
}


@dataclass
class TableComparison:
    """Deviations (computed - printed) of one table, per quantity, and what was left out."""

    name: str
    label: int
    dims: RSRCDimensions
    dims_source: str
    rows: int
    deviations: dict[str, list[tuple[int, float]]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def max_abs(self, quantity: str) -> float:
        values = [abs(v) for _, v in self.deviations.get(quantity, [])]
        return max(values) if values else 0.0


def load_table(name: str) -> tuple[dict[str, Any], list[dict[str, str]]]:
    """The JSON metadata and CSV rows of table ``name``."""
    meta = json.loads((DATA / f"table_{name}.json").read_text())
    with (DATA / f"table_{name}.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    return meta, rows


def table_dimensions(name: str, meta: dict[str, Any]) -> tuple[RSRCDimensions, str]:
    """Dimensions (inches, radians) used to reproduce table ``name`` and where they come from."""
    mech = meta["mechanism_stated"]
    d1, d2 = float(mech["d1"]), float(mech["d2"])
    d3, a, b = mech["d3"], mech["a"], mech["b"]
    source = "printed"
    if name in REBUILT:
        rebuilt = rebuild_from_table_json(meta)
        d2 = float(meta["q_reconstruction"].get("d2_used", d2))
        d3, a, b = rebuilt.d3, rebuilt.a, rebuilt.b
        source = (f"d3, a, b rebuilt from q1 = {rebuilt.q1_deg:.6f}, q2 = {rebuilt.q2_deg:.6f} deg "
                  "(eqs. 5.13-5.21)")
        if "d2_used" in meta["q_reconstruction"]:
            source += f"; d2 = {d2} (not the printed {mech['d2']})"
    dims = RSRCDimensions(
        d1=d1, d2=d2, d3=float(d3), a=float(a), b=float(b), e=float(mech["e"]),
        delta0=math.radians(float(mech["delta0_deg"])),
        lambda0=math.radians(float(mech["lambda0_deg"])),
    )
    return dims, source


def _s_column(row: dict[str, str]) -> str:
    return "S_in" if "S_in" in row else "S1_plus_S_g_in"


def compare_table(name: str) -> TableComparison:
    """Recompute phi_g, chi0 and S of every row of table ``name``."""
    meta, rows = load_table(name)
    dims, source = table_dimensions(name, meta)
    label = int(meta["inversion"]["program_label"])
    cmp = TableComparison(name, label, dims, source, len(rows))
    theta_deg = []
    for row in rows:
        i = int(row["i"])
        value = float(row["theta0_deg"])
        if (name, i) in CORRECTIONS:
            column, value, reason = CORRECTIONS[(name, i)]
            cmp.notes.append(f"row {i}: {column} taken as {value:g}: {reason}")
        theta_deg.append(value)
    pos = rsrc_positions(dims, np.radians(theta_deg))
    phi, chi, s, ok = pos.inversion(label)
    delta_zero = dims.delta0 == 0.0
    for k, row in enumerate(rows):
        i = int(row["i"])
        if not ok[k]:
            cmp.notes.append(f"row {i}: inversion {label} does not assemble at theta0 = "
                             f"{theta_deg[k]} deg")
            continue
        chi_deg = math.degrees(chi[k])
        computed = {
            "phi_g": math.degrees(phi[k]),
            "chi0": abs(chi_deg) if delta_zero else chi_deg,
            "S": float(s[k]),
        }
        printed = {
            "phi_g": float(row["phi_g_deg"]),
            "chi0": float(row["chi0_deg"]),
            "S": float(row[_s_column(row)]),
        }
        for quantity in ("phi_g", "chi0", "S"):
            if (name, i, quantity) in EXCLUSIONS:
                cmp.notes.append(f"row {i}: {quantity} excluded: "
                                 f"{EXCLUSIONS[(name, i, quantity)]}")
                continue
            dev = computed[quantity] - printed[quantity]
            if quantity == "phi_g":
                dev = math.remainder(dev, 360.0)
            cmp.deviations.setdefault(quantity, []).append((i, dev))
    return cmp


def example7_rate_ratios() -> list[tuple[float, float, float, float, float]]:
    """Example 7 (Table XII mechanism): printed vs computed phi0'/theta0' and phi0''/theta0'^2.

    Returns (theta_deg, printed velocity ratio, computed, printed acceleration ratio, computed) at
    theta = 345, 350, 355, 0, 5, 10, 15 deg (text line 2200).
    """
    meta, _ = load_table("XII")
    dims, _ = table_dimensions("XII", meta)
    thetas = [345.0, 350.0, 355.0, 0.0, 5.0, 10.0, 15.0]
    theta0 = np.radians(float(meta["mechanism_stated"]["theta01_deg"]) + np.array(thetas))
    pos = rsrc_positions(dims, theta0)
    rates = rsrc_rates(dims, pos, 1.0, 0.0)
    label = int(meta["inversion"]["program_label"]) - 1
    vel = meta["other_stated"]["velocity_ratio_at_theta_345_350_355_0_5_10_15"]
    acc = meta["other_stated"]["accel_ratio_at_theta_345_350_355_0_5_10_15"]
    return [
        (t, float(v), float(rates.phi0_dot[k, label]), float(a), float(rates.phi0_ddot[k, label]))
        for k, (t, v, a) in enumerate(zip(thetas, vel, acc, strict=True))
    ]


def report(comparisons: list[TableComparison]) -> str:
    """The Markdown report."""
    lines = [
        "# Bagci 1969 Tables I-XII reproduced by `screwkit.kinematics.closed_forms.rsrc`",
        "",
        "Generated by `validation/bagci1969/analysis_tables.py --write`. Each row's phi_g, chi0 "
        "and S are recomputed at the row's theta0 with `rsrc_positions` for the table's "
        "inversion label. Max |computed - printed| over the rows:",
        "",
        "| table | label | rows | dims | max d(phi_g) deg | max d(chi0) deg | max d(S) in |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in comparisons:
        dims = "printed" if c.dims_source == "printed" else "rebuilt"
        lines.append(
            f"| {c.name} | {c.label} | {c.rows} | {dims} | {c.max_abs('phi_g'):.2e} | "
            f"{c.max_abs('chi0'):.2e} | {c.max_abs('S'):.2e} |"
        )
    lines += ["", "## Dimensions", ""]
    for c in comparisons:
        d = c.dims
        lines.append(
            f"- **{c.name}**: d1={d.d1:.6f}, d2={d.d2:.6f}, d3={d.d3:.6f}, a={d.a:.6f}, "
            f"b={d.b:.6f}, e={d.e:g}, delta0={math.degrees(d.delta0):.5f} deg, "
            f"lambda0={math.degrees(d.lambda0):g} deg; {c.dims_source}."
        )
    lines += ["", "## Rows and cells not compared, or corrected, and why", ""]
    for c in comparisons:
        for note in c.notes:
            lines.append(f"- Table {c.name}, {note}")
    lines += [
        "",
        "## Example 7 rate ratios (text line 2200, Table XII mechanism, label 2)",
        "",
        "| theta deg | printed phi'/th' | computed | printed phi''/th'^2 | computed |",
        "|---|---|---|---|---|",
    ]
    for t, v, vc, a, ac in example7_rate_ratios():
        lines.append(f"| {t:g} | {v:.5f} | {vc:.6f} | {a:.5f} | {ac:.6f} |")
    lines += [
        "",
        "The printed 0.03443 at theta = 355 deg differs from the computed 0.034482 by 5e-5: a "
        "probable OCR/typing error for 0.03448 (table_XII.json flags); all other printed ratios "
        "agree to 1e-5.",
        "",
        "Deviations at the level of 1e-6 deg / 1e-6 in are the print precision; the larger ones "
        "of Tables IV (2.5e-4 deg: d2 = 28.7 in amplifies the IBM 7040's single precision), XI "
        "and XII (typed with 5 decimals, theta0 accumulated in single precision) match "
        "tables/REPRODUCTION.md.",
        "",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="write analysis_tables.md")
    args = parser.parse_args(argv)
    comparisons = [compare_table(name) for name in TABLES]
    print(f"{'table':>5} {'label':>5} {'rows':>4} {'dims':>8} {'max dphi deg':>13} "
          f"{'max dchi deg':>13} {'max dS in':>10}")
    for c in comparisons:
        dims = "printed" if c.dims_source == "printed" else "rebuilt"
        print(f"{c.name:>5} {c.label:>5} {c.rows:>4} {dims:>8} {c.max_abs('phi_g'):13.2e} "
              f"{c.max_abs('chi0'):13.2e} {c.max_abs('S'):10.2e}")
    print("\nnot compared / corrected:")
    for c in comparisons:
        for note in c.notes:
            print(f"  Table {c.name}, {note}")
    if args.write:
        out = HERE / "analysis_tables.md"
        out.write_text(report(comparisons))
        print(f"\nwrote {out}")
    # fail when a table is reproduced worse than its printed precision allows
    # (tables/REPRODUCTION.md: 1e-5 deg for I-II; up to ~3e-4 deg for the rebuilt IV, XII and
    # 1e-3 deg for XI, typed with 5 decimals; S to its 6 printed decimals)
    limit_deg = {"I": 1e-5, "II": 1e-5, "XI": 2e-3, "IV": 5e-4, "XII": 5e-4}
    failed = [c.name for c in comparisons
              if max(c.max_abs("phi_g"), c.max_abs("chi0")) > limit_deg.get(c.name, 1e-4)
              or c.max_abs("S") > 2e-5]
    if failed:
        print(f"\nFAILED: tables {failed} are not reproduced to print precision")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Start-up (issue 17): ``screwkit --help`` and ``screwkit validate`` load no heavy module they
do not use — scipy.spatial, pint's registry, matplotlib, pandas, pyarrow — so each starts in
about the time of ``import numpy, pint`` (timed side by side in benchmarks/bench_startup.py)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

SPEC = Path(__file__).resolve().parents[2] / "examples" / "bagci_fig7_rsrc.toml"
PROBE = """
import contextlib, io, json, sys
from screwkit.cli.main import app
with contextlib.redirect_stdout(io.StringIO()):
    try:
        app(sys.argv[1:])
    except SystemExit:
        pass
print(json.dumps(sorted(sys.modules)))
"""


def _modules(*args: str) -> set[str]:
    r = subprocess.run([sys.executable, "-c", PROBE, *args], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    return set(json.loads(r.stdout.strip().splitlines()[-1]))


def test_validate_and_help_load_nothing_heavy():
    for args in (("validate", str(SPEC)), ("--help",)):
        loaded = _modules(*args)
        heavy = sorted(m for m in loaded if m.split(".")[0] in ("pint", "matplotlib",
                                                                  "pandas", "pyarrow")
                       or m.startswith(("scipy.spatial", "scipy.optimize")))
        assert not heavy, f"screwkit {' '.join(args)} loaded {heavy}"
    assert "numpy" not in _modules("--help")


def test_common_units_need_no_pint_registry():
    """A spec in in/mm/deg/rpm/lbf is read without pint; the table agrees with pint."""
    from screwkit.io.units import COMMON_UNITS, registry

    ureg = registry()
    for name, (factor, dims) in COMMON_UNITS.items():
        q = ureg.Quantity(1.0, ureg.Unit({"rev": "revolution", "revs": "revolution"}.get(
            name, name))).to_base_units()
        d = q.dimensionality
        assert (d.get("[length]", 0), d.get("[mass]", 0), d.get("[time]", 0)) == dims, name
        assert set(d) <= {"[length]", "[mass]", "[time]"}, name
        assert q.magnitude == factor, name  # the same double: results do not move by an ulp
    from screwkit.io.quantity import parse_unit
    from screwkit.io.units import _factor, common_unit_factor

    for unit, kind in (("lbf*s^2*in", "inertia"), ("kg*mm^2", "inertia"), ("in/s^2",
                       "acceleration"), ("lbf*in", "moment"), ("rev/min", "angular_velocity")):
        names = parse_unit(unit)
        assert common_unit_factor(names, kind) == _factor(names, kind), unit

"""The 6-SPS platform: examples/mechanisms/stewart_platform.toml with each leg's U joint on the
base replaced by a ball (S) joint at the same centre. Each leg (cylinder, piston, slid along
the line between its two balls) then spins idly about that line; the platform's poses, which
the six leg lengths alone decide, are the 6-UPS's."""

from __future__ import annotations

import re
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "mechanisms" / "stewart_platform.toml"
#: a U joint's kind and axes, kept: its name, bodies and centre
_U = re.compile(r'kind = "U"\n(between = \[[^\]]*\]\nat = \[[^\]]*\]\n)axis = \[[^\]]*\]\n'
                r'axis2 = \[[^\]]*\]\n')


def six_sps_text() -> str:
    """The 6-SPS spec's text (TOML)."""
    text, n = _U.subn(r'kind = "S"\n\1', EXAMPLE.read_text())
    assert n == 6, "the Stewart example's six U joints were not found"
    return text.replace('name = "Stewart-Gough platform"', 'name = "6-SPS platform"')


def six_sps_spec(folder: Path) -> Path:
    """The 6-SPS spec written into ``folder``."""
    path = folder / "six_sps.toml"
    path.write_text(six_sps_text())
    return path

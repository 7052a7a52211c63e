"""The balancing tests' examples: Rahman's CSSP and the planar 4R dynamics example with a
[balancing] table of the test's choice (imported by name, not from conftest)."""

from __future__ import annotations

from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "rahman_cssp_balance.toml"
FOURBAR = Path(__file__).resolve().parents[2] / "examples" / "fourbar_dynamics.toml"


def fourbar_spec(tmp_path: Path, balancing: str, direction: str = "[0, -1, 0]") -> Path:
    """The 4R example with gravity along ``direction`` and the ``balancing`` table appended."""
    text = FOURBAR.read_text().replace("gravity_direction = [0, -1, 0]",
                                       f"gravity_direction = {direction}")
    assert f"gravity_direction = {direction}" in text
    p = tmp_path / f"fb_{len(list(tmp_path.glob('fb_*.toml')))}.toml"
    p.write_text(text + "\n" + balancing)
    return p

"""Every ```python block of the README and docs/ runs as written (the blocks of one file share
a namespace, in order), from a scratch folder that sees the bundled examples: a doc example
that goes stale fails here, not in a user's hands."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FENCE = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
WITH_CODE = [p for p in DOCS if FENCE.search(p.read_text(encoding="utf-8"))]


def blocks(path: Path) -> list[str]:
    return FENCE.findall(path.read_text(encoding="utf-8"))


def test_the_docs_have_python_examples() -> None:
    names = {p.name for p in WITH_CODE}
    assert {"README.md", "dynamics.md", "balancing.md", "synthesis.md", "mobility.md",
            "report.md", "architecture.md"} <= names


@pytest.mark.parametrize("path", WITH_CODE, ids=[p.name for p in WITH_CODE])
def test_doc_python_blocks_run(path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                               ) -> None:
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict[str, object] = {"__name__": f"doc_{path.stem}"}
    for i, code in enumerate(blocks(path)):
        try:
            exec(compile(code, f"{path.name}[python block {i}]", "exec"), namespace)
        except Exception as exc:  # pragma: no cover - the failure message is the point
            pytest.fail(f"{path.relative_to(ROOT)}, python block {i}: "
                        f"{type(exc).__name__}: {exc}")

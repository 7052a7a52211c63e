"""Checkpoints of a sweep: the rows of every finished batch, kept in a hidden folder next to
the output (``.<output name>.sweep/``) until the table is written (docs/sweeps.md, "Resume").

The folder holds ``sweep.json`` with the sweep's fingerprint (a hash of the spec's tables, the
designs, the job and its options, and the screwkit version) and one ``batch-<first>-<last>.json``
per finished batch, each written through a temporary file and a rename, so an interruption
leaves only whole batches. ``--resume`` reads them back and computes only the designs not yet
done; a checkpoint of a different sweep is refused rather than mixed in. A checkpoint holding
finished designs is never discarded silently: a run without ``--resume`` refuses it unless
``--fresh`` says to discard it.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path
from typing import Any

from screwkit import __version__
from screwkit.errors import InputError
from screwkit.io.outputs import write_text_atomic

Row = dict[str, Any]


class CheckpointError(InputError):
    """A checkpoint that cannot be used for this sweep (the message says what to do)."""


def fingerprint(data: dict[str, Any], designs: str, job: str, options: dict[str, Any]) -> str:
    """The key of a sweep's checkpoint: what decides every row's values."""
    text = json.dumps({"spec": data, "designs": designs, "job": job, "options": options,
                       "version": __version__}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def check_resume_flags(resume: bool, fresh: bool) -> None:
    """``--resume`` and ``--fresh`` exclude each other."""
    if resume and fresh:
        raise CheckpointError("--resume continues the checkpoint and --fresh discards it: pass "
                              "one of them")


def checkpoint_folder(output: Path) -> Path:
    return output.parent / f".{output.name}.sweep"


class Checkpoint:
    """The checkpoint folder of one sweep (module docstring)."""

    def __init__(self, output: Path, key: str) -> None:
        self.folder = checkpoint_folder(output)
        self.key = key

    def exists(self) -> bool:
        return self.folder.is_dir()

    def _stored_key(self) -> str | None:
        try:
            return str(json.loads((self.folder / "sweep.json").read_text())["fingerprint"])
        except (OSError, ValueError, KeyError, TypeError):
            return None

    def resume(self) -> dict[int, Row]:
        """The rows finished by an earlier run of this sweep, by design number."""
        if not self.exists():
            return {}
        if self._stored_key() != self.key:
            raise CheckpointError(
                f"--resume: the checkpoint {self.folder} belongs to another sweep (the spec, "
                "the designs, the job or its options differ); pass --fresh instead of "
                "--resume to discard it and start this sweep afresh")
        return self._rows()

    def _rows(self) -> dict[int, Row]:
        rows: dict[int, Row] = {}
        for f in sorted(self.folder.glob("batch-*.json")):
            try:
                batch = json.loads(f.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                continue  # an unreadable batch is computed again
            for row in batch:
                rows[int(row["design"])] = row
        return rows

    def start(self, resume: bool, fresh: bool = False) -> int:
        """Create the folder for this sweep and return how many finished designs of an earlier
        run were discarded. ``resume`` keeps this sweep's checkpoint; ``fresh`` discards any;
        without either, a checkpoint holding finished designs is refused (one that holds none
        loses nothing and is replaced)."""
        check_resume_flags(resume, fresh)
        discarded = 0
        same = self._stored_key() == self.key
        if self.exists() and not (resume and same):
            discarded = len(self._rows())
            if discarded and not fresh:
                whose = ("an interrupted run of this sweep" if same
                         else "another sweep writing the same output")
                resume_hint = "pass --resume to continue it, or " if same else "pass "
                raise CheckpointError(
                    f"{self.folder} holds {discarded} finished design(s) of {whose}; "
                    f"{resume_hint}--fresh to discard them and start again")
            self.discard()
        self.folder.mkdir(exist_ok=True)
        write_text_atomic(self.folder / "sweep.json",
                          json.dumps({"fingerprint": self.key, "version": __version__}))
        return discarded

    def save(self, rows: list[Row]) -> None:
        """Keep a finished batch (whole or not at all)."""
        if not rows:
            return
        first, last = rows[0]["design"], rows[-1]["design"]
        name = f"batch-{first:09d}-{last:09d}.json"
        write_text_atomic(self.folder / name, json.dumps(rows, allow_nan=True))

    def discard(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)

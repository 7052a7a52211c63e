"""Where an export samples the motion: the spec's ``[motion]`` sweep (the curves, the animation)
and the inputs the user asked the skeleton at (``--at``), solved together in one sweep so the
skeleton sits exactly at the asked inputs and the curves stay the sweep's own samples."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError

Array = NDArray[np.float64]


class ExportError(InputError):
    """An export cannot be made as asked (a format, an input value, a mode)."""


@dataclass(frozen=True)
class ExportSamples:
    """``inputs`` (M,) to solve (rad or m): the sweep with the ``at`` values merged in, in the
    sweep's order; ``sweep`` (N,) the indices of the sweep's own samples in ``inputs``; ``at``
    the index in ``inputs`` of each asked value, in the order asked."""

    inputs: Array
    sweep: NDArray[np.intp]
    at: NDArray[np.intp]


def export_samples(sweep: Sequence[float] | Array, at: Sequence[float] = (),
                   shown: Sequence[str] = (), span: str = "") -> ExportSamples:
    """Merge the ``at`` values (SI) into the sweep (SI, monotonic). A value within round-off
    (1e-12 of the sweep's span) of a sample is that sample, so the motion is unchanged; a value
    outside the sweep's range is refused (mode numbering is fixed by the sweep's first sample,
    docs/conventions.md "Assembly modes"), naming it as the user wrote it (``shown``) and the
    sweep's range (``span``, as the user reads it)."""
    x = np.asarray(sweep, dtype=float).reshape(-1)
    ascending = np.sort(x)
    lo, hi = float(ascending[0]), float(ascending[-1])
    tol = 1e-12 * max(hi - lo, 1.0)

    def nearest(values: Array, v: float) -> float:  # distance to the nearest of sorted values
        i = int(np.searchsorted(values, v))
        return min(abs(values[j] - v) for j in (i - 1, i) if 0 <= j < len(values))

    extra: list[float] = []
    for k, v in enumerate(at):
        if not np.isfinite(v) or v < lo - tol or v > hi + tol:
            name = shown[k] if k < len(shown) else repr(v)
            raise ExportError(f"--at {name} lies outside the spec's [motion] sweep{span}; give "
                              "inputs between its start and stop, or widen the sweep")
        if nearest(ascending, v) > tol and all(abs(v - e) > tol for e in extra):
            extra.append(float(v))
    every = np.concatenate([x, np.asarray(extra, dtype=float)])
    descending = len(x) > 1 and x[-1] < x[0]
    order = np.argsort(-every if descending else every, kind="stable")
    inputs = every[order]
    place = np.empty(len(every), dtype=np.intp)
    place[order] = np.arange(len(every))
    merged_ascending = np.sort(inputs)

    def index(v: float) -> int:  # the merged sample nearest v
        j = int(np.searchsorted(merged_ascending, v))
        i = min((k for k in (j - 1, j) if 0 <= k < len(inputs)),
                key=lambda k: abs(merged_ascending[k] - v))
        return len(inputs) - 1 - i if descending else i

    return ExportSamples(inputs, place[:len(x)],
                         np.array([index(v) for v in at], dtype=np.intp))


def assembled_runs(ok: NDArray[np.bool_] | Array) -> list[tuple[int, int]]:
    """(start, stop) of each run of consecutive True values of ``ok``."""
    flags = np.concatenate([[False], np.asarray(ok, dtype=bool), [False]])
    edges = np.flatnonzero(np.diff(flags.astype(np.int8)))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]

"""What the continuation keeps and computes per branch (:mod:`screwkit.kinematics.tracker.continuation`):
a :class:`Track` (one branch over the sweep, with the rates found on the way), a
:class:`Front` (a branch end moving along the sweep), and the branch's Taylor series from the
rate equations — the predictor's q(X + d) ≈ q + q_X d + ½ q_XX(d, d), whose directional jets a
closure system gives (tracker/system.py)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import Array, Configuration, Layout, closure_error, forward
from screwkit.kinematics.tracker.solve import newton
from screwkit.model.linkage import Linkage


@dataclass
class Track:
    """One branch over the sweep: its configurations where ``mask`` holds, the sample it was
    seeded at, and where it ends: ``stops`` after sample k (forwards), ``starts`` at sample k
    (backwards), each with the input position reached before the end."""

    scalars: Array
    spherical: Array
    mask: NDArray[np.bool_]
    seed: int
    stops: list[tuple[int, float]] = field(default_factory=list)
    starts: list[tuple[int, float]] = field(default_factory=list)
    #: the rates found on the way (a tracker asked for them): at samples where ``rates.known``
    rates: TrackRates | None = None

    def configuration(self) -> Configuration:
        return Configuration(np.where(self.mask[:, None], self.scalars, 0.0), self.spherical)

    def set_sample(self, k: int, scalars: Array, spherical: Array) -> None:
        """Hold this configuration at sample ``k`` (rates found there before are forgotten)."""
        self.scalars[k], self.spherical[k], self.mask[k] = scalars, spherical, True
        if self.rates is not None:
            self.rates.known[k] = False


@dataclass
class TrackRates:
    """Rates and accelerations of a track's freedoms (N, m) where ``known``, from the rate
    equations at the very configurations the tracker accepted (:func:`joint_rates`), and
    whether the sample is singular."""

    qd: Array
    qdd: Array
    singular: NDArray[np.bool_]
    known: NDArray[np.bool_]


@dataclass
class Front:
    track: int
    direction: int
    t: float
    conf: Configuration  # one row
    prev: Configuration | None = None
    prev_t: float = 0.0
    chunk: int = 4
    substep: float = 0.0  # 0: chunk mode; else the sub-step (a fraction of the spacing)
    sigma: tuple[float, float] = (np.inf, np.nan)  # σ ratio of J_p at the front, and where
    sigma_before: tuple[float, float] = (np.inf, np.nan)
    jump: bool = False  # this wave steps over a singular sample to the one after it
    jumped: bool = False  # a jump was tried since the front last advanced normally
    derivatives: tuple[Array, Array, Array] | None = None  # jets q', q'' along u, and u (this wave)
    passive: Array | None = None  # the scaled passive Jacobian there
    plain: bool = False  # an interpolated sample failed: correct the next chunk sample by sample
    fill: bool = True  # interpolate between corrected samples (off: most fills needed Newton)


def input_at(X: Array, t: Array) -> Array:
    """Inputs (T, n_in) at positions ``t`` (T,) along the sweep (straight between samples)."""
    i0 = np.clip(np.floor(t).astype(int), 0, X.shape[0] - 1)
    i1 = np.minimum(i0 + 1, X.shape[0] - 1)
    frac = (t - i0)[:, None]
    return np.asarray(X[i0] + frac * (X[i1] - X[i0]))


def closure_residual(linkage: Linkage, R: Array, p: Array) -> Array:
    """The corrector's closure residual max|ξ| (scaled rows) of closure displacements (R, p)."""
    rows = np.array([1.0, 1.0, 1.0, *([1.0 / linkage.length_scale] * 3)])
    return np.asarray(np.max(np.abs(closure_error(R, p) * rows), axis=-1))


def polished(linkage: Linkage, lay: Layout, conf: Configuration) -> Configuration:
    """Roots of a root search (closed to 1e-11) polished by Newton to round-off, as every
    corrected sample is; kept as they were where that does not lower the residual."""
    fr = forward(linkage, conf, lay, frames=False)
    before = closure_residual(linkage, fr.closure_R, fr.closure_p)
    res = newton(linkage, conf, max_iter=3, tol=1e-15, lay=lay)
    better = res.residual <= before
    return Configuration(np.where(better[:, None], res.conf.scalars, conf.scalars),
                         np.where(better[:, None, None, None], res.conf.spherical,
                                  conf.spherical))


def sample_writer(idx: NDArray[np.intp], rows: NDArray[np.intp]) -> Callable[[Array, Array], None]:
    """A writer of ``values[rows]`` into ``array[idx]``: by slices where both are runs of
    consecutive indices (a chunk of samples, either direction; several times faster than
    fancy indexing for the large arrays of long sweeps)."""
    n = len(idx)
    if n > 1 and abs(int(idx[-1]) - int(idx[0])) == n - 1 and rows[-1] - rows[0] == n - 1 \
            and np.all(np.abs(np.diff(idx)) == 1):
        lo, hi = int(min(idx[0], idx[-1])), int(max(idx[0], idx[-1])) + 1
        src = slice(int(rows[0]), int(rows[-1]) + 1)
        rev = idx[-1] < idx[0]

        def by_slice(array: Array, values: Array) -> None:
            array[lo:hi] = values[src][::-1] if rev else values[src]

        return by_slice

    def by_index(array: Array, values: Array) -> None:
        array[idx] = values[rows]

    return by_index


def coarse_targets(n: int, stride: int) -> NDArray[np.intp]:
    """Indices of every ``stride``-th of ``n`` targets, and always the last."""
    idx = np.arange(stride - 1, n, stride)
    return idx if idx.size and idx[-1] == n - 1 else np.append(idx, n - 1)


__all__ = ["Front", "Track", "TrackRates", "closure_residual", "coarse_targets", "input_at",
           "polished", "sample_writer"]

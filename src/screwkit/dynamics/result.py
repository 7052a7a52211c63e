"""The result of an inverse-dynamics analysis: loads over the motion cycle (frozen, batch-first).

Conventions (../shared/DESIGN.md, docs/dynamics.md): every vector is in the world frame, SI
units. A joint reaction is the force and moment exerted on the distal link by the proximal link
(on the moving link by the ground for the two ground joints), moment about the joint centre. The
shaking force and moment are what the moving links exert on the ground, moment about
``moment_point``. Samples where ``valid`` is False (no assembly, or a singular configuration)
hold NaN in the arrays and ``None`` in :meth:`Dynamics.as_dict`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import UnknownNameError

if TYPE_CHECKING:
    from screwkit.tables import ResultTable, UnitChoice

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Reaction:
    """The load one joint transmits over the cycle: ``force`` and ``moment`` (N, 3) exerted on
    the distal link by the proximal link (on the moving link by the ground for the two ground
    joints), world frame, moment about the joint centre ``point`` (N, 3), the point of
    application. ``reaction["force"]`` reads a field by name."""

    force: Array
    moment: Array
    point: Array

    def __getitem__(self, key: str) -> Array:
        if key not in ("force", "moment", "point"):
            raise UnknownNameError(f"a reaction has 'force', 'moment' and 'point'; got {key!r}")
        return getattr(self, key)  # type: ignore[no-any-return]


@dataclass(frozen=True)
class Indeterminacy:
    """What the rigid-body joint model leaves undetermined, generic over the mode.

    ``count``: number of statically indeterminate wrench components (6 − rank of the passive
    statics); the returned reactions are the minimum-norm ones (docs/dynamics.md).
    ``directions`` (count, 6): unit self-stress wrenches (f; m about the world origin) that can
    be added to every joint reaction alike without changing any link's balance.
    ``idle_freedoms``: passive motions the joints cannot load (an S–S rod spinning about its
    axis); link loads along them show up in :attr:`Dynamics.residual`.
    """

    count: int
    directions: Array
    idle_freedoms: int

    def describe(self) -> str:
        parts = []
        if self.count:
            parts.append(
                f"{self.count} reaction component(s) statically indeterminate (overconstrained "
                "loop); the minimum-norm reactions are given"
            )
        if self.idle_freedoms:
            parts.append(
                f"{self.idle_freedoms} idle passive freedom(s) (e.g. a rod spinning about its own "
                "axis) that the joints cannot load; any load along them is reported as residual"
            )
        return "; ".join(parts) if parts else "statically determinate"


def _as_list(a: Array, valid: NDArray[np.bool_]) -> list[Any]:
    out: list[Any] = np.asarray(a).tolist()  # one C call; then None at the invalid samples
    for i in np.flatnonzero(~np.asarray(valid, dtype=bool)).tolist():
        out[i] = None
    return out


def _as_array(a: Array, valid: NDArray[np.bool_]) -> Array | list[Any]:
    """The array itself where every sample is valid; else the list with ``None`` rows (a
    vector sample that is not valid is one ``null``, as docs/cli.md says)."""
    if np.all(valid):
        return np.asarray(a, dtype=float)
    return _as_list(a, valid)


def _stats(values: Array, valid: NDArray[np.bool_], inputs: Array) -> dict[str, float]:
    """RMS and peak of a load over the valid samples (vector loads by their magnitude), and
    ``peak_at``: the (first) input where the peak is reached (rad or m)."""
    v = values[valid]
    mag = np.abs(v) if v.ndim == 1 else np.linalg.norm(v, axis=-1)
    if mag.size == 0:
        return {"rms": float("nan"), "peak": float("nan"), "peak_at": float("nan")}
    k = int(np.argmax(mag))
    return {"rms": float(np.sqrt(np.mean(mag**2))), "peak": float(mag[k]),
            "peak_at": float(np.asarray(inputs).reshape(len(valid), -1)[valid][k, 0])}


@dataclass(frozen=True, eq=False)
class Dynamics:
    """Loads of one assembly mode over the motion cycle (N samples).

    Attributes
    ----------
    inputs:
        (N, n_in) input values per sample (NaN where unknown), names in ``input_names``.
    shaking_force, shaking_moment:
        (N, 3) what the moving links exert on the ground; moment about ``moment_point``.
    reactions:
        ``{joint: Reaction}``: force and moment (N, 3), moment about the joint centre
        ``Reaction.point`` (N, 3).
    efforts:
        ``{driven freedom: (N,)}``: torque (N·m) of a driven rotation, force (N) of a driven
        translation, exerted by the proximal link on the distal link along the freedom — the
        actuator's. With viscous friction in the driven joint (a simulation's
        ``[drive.friction]``) the joint's reaction along the freedom is the actuator's effort
        plus the friction's (docs/simulation.md).
    residual:
        (N,) unbalanced generalised force along idle passive freedoms (N, moments divided by the
        length scale), zero when the joint model can carry every link load.
    residual_scale:
        largest joint load over the cycle in the same units (to read ``residual`` relatively).
    """

    input_names: tuple[str, ...]
    inputs: Array
    valid: NDArray[np.bool_]
    shaking_force: Array
    shaking_moment: Array
    moment_point: Array
    reactions: Mapping[str, Reaction]
    joint_centres: Array
    efforts: Mapping[str, Array]
    indeterminacy: Indeterminacy
    residual: Array
    residual_scale: float
    gravity: Array

    @property
    def relative_residual(self) -> Array:
        """``residual / residual_scale`` per sample."""
        return self.residual / max(self.residual_scale, np.finfo(float).tiny)

    def summary(self) -> dict[str, dict[str, float]]:
        """RMS and peak over the valid samples of every load (vectors by magnitude), with the
        input where the peak is reached (``peak_at``, rad or m: the first input)."""
        out = {
            "shaking_force": _stats(self.shaking_force, self.valid, self.inputs),
            "shaking_moment": _stats(self.shaking_moment, self.valid, self.inputs),
        }
        for name, r in self.reactions.items():
            out[f"{name}.force"] = _stats(r.force, self.valid, self.inputs)
            out[f"{name}.moment"] = _stats(r.moment, self.valid, self.inputs)
        for name, e in self.efforts.items():
            out[f"effort {name}"] = _stats(e, self.valid, self.inputs)
        out["relative_residual"] = _stats(self.relative_residual, self.valid, self.inputs)
        return out

    @property
    def gravity_on(self) -> bool:
        """Whether the loads include gravity (a non-zero ``gravity`` vector)."""
        return bool(np.any(self.gravity != 0))

    def table(self, mode: int | None = None) -> ResultTable:
        """One row per sample: input, shaking force and moment, every reaction with its point
        of application, efforts (SI; :mod:`screwkit.dynamics.result_table`)."""
        from screwkit.dynamics.result_table import dynamics_table

        return dynamics_table(self, mode)

    def to_dataframe(self, units: UnitChoice | None = None) -> Any:
        """:meth:`table` as a pandas DataFrame, headers with units (needs pandas)."""
        return self.table().to_dataframe(units)

    def to_csv(self, path: Any, units: UnitChoice | None = None) -> None:
        """:meth:`table` as CSV (``shaking_force_x [N]`` …; empty cells where not valid)."""
        self.table().to_csv(path, units)

    def as_dict(self, arrays: bool = False) -> dict[str, Any]:
        """JSON-able dictionary (SI units, lists, ``None`` where a sample is not valid).

        With ``arrays`` the per-sample values of a mode valid at every sample stay float arrays
        (what the io layer's orjson writer takes directly, column by column, instead of a
        Python float per value); the JSON written is the same."""
        v = self.valid
        _listify: Callable[[Array, NDArray[np.bool_]], Any] = _as_array if arrays else _as_list
        return {
            "units": {"force": "N", "moment": "N*m", "effort": "N*m or N", "length": "m"},
            "input_names": list(self.input_names),
            "inputs": _listify(self.inputs, v),
            "valid": np.asarray(v, dtype=bool) if arrays else v.tolist(),
            "moment_point": self.moment_point.tolist(),
            "gravity": self.gravity.tolist(),
            "shaking_force": _listify(self.shaking_force, v),
            "shaking_moment": _listify(self.shaking_moment, v),
            "reactions": {
                name: {"force": _listify(r.force, v), "moment": _listify(r.moment, v),
                       "point": _listify(r.point, v)}
                for name, r in self.reactions.items()
            },
            "efforts": {name: _listify(e, v) for name, e in self.efforts.items()},
            "indeterminacy": {
                "count": self.indeterminacy.count,
                "idle_freedoms": self.indeterminacy.idle_freedoms,
                "directions": self.indeterminacy.directions.tolist(),
                "description": self.indeterminacy.describe(),
            },
            "residual": _listify(self.residual, v),
            "residual_scale": self.residual_scale,
            "summary": self.summary(),
        }

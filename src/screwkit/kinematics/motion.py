"""The result of solving a loop's motion: :class:`Motion`, one :class:`ModeMotion` per assembly
mode. Every solver — a family's closed form or the generic loop solver — returns this type, with
the same fields, units and mode numbering (docs/conventions.md, "Assembly modes").

Arrays are batch-first over the N input samples, SI units and radians. Entries where a mode does
not assemble (``assembles`` False) are NaN; rates and accelerations are also NaN where the mode
is ``singular`` (the rate equation has no unique solution there). Read every array through its
mask.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError, InputTypeError, UnknownNameError
from screwkit.kinematics.tracker.loop import Array, Configuration
from screwkit.messages import listing, shown, shown_values
from screwkit.model.linkage import Linkage

if TYPE_CHECKING:
    from screwkit.tables import ResultTable, UnitChoice


class AssemblyError(InputError):
    """The mechanism does not assemble where it was asked to."""


@dataclass(frozen=True, eq=False)
class ModeMotion:
    """One assembly mode over the input sweep.

    ``variables``/``velocities``/``accelerations`` map a variable name to an (N,) array: every
    joint freedom as ``"<joint>.<freedom>"`` (``theta`` rad, ``s`` m; a spherical joint's
    orientation as the rotation vector ``<joint>.rx|ry|rz`` and its rates as ``<joint>.wx|wy|wz``,
    the relative angular velocity in the child frame) and, for a family, the seed's names
    (RSRC θ0 ``theta0``, φ0 ``phi0``, S ``S``, χ0 ``chi0``; CSSP ``theta1``, ``s4``, ``theta2``,
    ``eta2`` …; docs/conventions.md).

    Link ``k`` (``linkage.links[k]``) lies between joints k and k+1; its body frame is joint k's
    frame after the joint motion, in the world: ``link_rotation`` (N, L, 3, 3), ``link_origin``
    (N, L, 3); its angular velocity and acceleration and the velocity and acceleration of its
    frame origin are world vectors. ``joint_centres``/``joint_axes`` (N, n, 3) are in the world.
    ``closure_residual`` (N,) is the loop-closure error (rad, and length / length scale).
    """

    assembles: NDArray[np.bool_]
    singular: NDArray[np.bool_]
    conf: Configuration
    variables: dict[str, Array]
    velocities: dict[str, Array]
    accelerations: dict[str, Array]
    link_rotation: Array
    link_origin: Array
    link_angular_velocity: Array
    link_origin_velocity: Array
    link_angular_acceleration: Array
    link_origin_acceleration: Array
    joint_centres: Array
    joint_axes: Array
    closure_residual: Array
    events: list[str] = field(default_factory=list)
    index: int = 0
    label: str = ""

    @property
    def samples(self) -> int:
        return int(self.assembles.shape[0])


@dataclass(frozen=True, eq=False)
class Motion:
    """Positions, velocities and accelerations of a loop over an input sweep, every assembly mode.

    ``modes[k]`` is assembly mode k (docs/conventions.md: mode 0 is the seed's branch for the
    seed families; the same numbering in the spec's ``[motion] mode``, the CLI and JSON).
    ``method`` is ``"closed"`` (a family's closed form) or ``"generic"`` (the loop solver);
    ``solver`` names the equations used.
    """

    linkage: Linkage
    inputs: Array  # (N, n_in)
    input_rates: Array
    input_accelerations: Array
    modes: tuple[ModeMotion, ...]
    method: str = "generic"
    solver: str = ""
    notes: tuple[str, ...] = ()

    @property
    def input_names(self) -> tuple[str, ...]:
        return self.linkage.inputs

    @property
    def samples(self) -> int:
        return int(self.inputs.shape[0])

    @property
    def input_values(self) -> Array:
        """The first input's values (N,): the sweep variable of a one-input loop."""
        return np.asarray(self.inputs[:, 0])

    def mode(self, index: int) -> ModeMotion:
        """Assembly mode ``index`` (0 … len(modes) − 1), with a message naming the modes."""
        n = len(self.modes)
        if isinstance(index, bool) or not isinstance(index, int | np.integer):
            raise InputTypeError(f"mode must be an integer index 0…{n - 1}; got {index!r}")
        if not 0 <= index < n:
            raise AssemblyError(
                f"{self.linkage.name}: assembly mode {index} asked for, but the mechanism has "
                f"{n} assembly mode(s) over these inputs (0…{n - 1})")
        return self.modes[index]

    def variable(self, name: str, mode: int = 0, *, derivative: int = 0) -> Array:
        """One variable of one mode over the sweep: ``derivative`` 0 the value, 1 its rate,
        2 its acceleration (e.g. ``motion.variable("phi0", mode=0)``)."""
        md = self.mode(mode)
        tables = (md.variables, md.velocities, md.accelerations)
        if derivative not in (0, 1, 2):
            raise InputError(f"derivative must be 0, 1 or 2; got {derivative!r}")
        table = tables[derivative]
        if name not in table:
            raise UnknownNameError(f"{self.linkage.name}: no variable {name!r} in mode {mode}; "
                                   f"the variables are {listing(sorted(table))}")
        return table[name]

    def table(self, coupler_point: Any = None, coupler_link: int = 1, *,
              coupler_points: Any = (), transmission: Any = None) -> ResultTable:
        """One row per input sample and mode, one column per variable, rate and acceleration
        (SI; :mod:`screwkit.kinematics.motion_table`), with the coupler points' paths and the
        transmission quality when given."""
        from screwkit.kinematics.motion_table import motion_table

        return motion_table(self, coupler_point, coupler_link, coupler_points=coupler_points,
                            transmission=transmission)

    def to_dataframe(self, units: UnitChoice | None = None) -> Any:
        """:meth:`table` as a pandas DataFrame, headers with units (``phi0 [rad]``; pass
        ``units=spec.display_units()`` for the spec's units). Needs pandas."""
        return self.table().to_dataframe(units)

    def to_csv(self, path: Any, units: UnitChoice | None = None) -> None:
        """:meth:`table` as CSV (header ``phi0 [rad]``; empty cells where a mode does not
        assemble)."""
        self.table().to_csv(path, units)


def as_input_array(linkage: Linkage, values: ArrayLike, name: str) -> Array:
    """``values`` as an (N, n_in) array of finite numbers, one column per input of the loop."""
    if not isinstance(linkage, Linkage):
        raise InputTypeError(f"linkage must be a screwkit Linkage (e.g. sk.rsrc(...) or "
                             f"load_spec(...).linkage); got {type(linkage).__name__}")
    not_numbers = InputTypeError(f"{name}: give numbers (one per sample and input); got "
                                 f"{type(values).__name__}")
    if values is None or isinstance(values, str | bytes):  # np.asarray makes NaN of None
        raise not_numbers
    try:
        a = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise not_numbers from None
    n_in = len(linkage.inputs)
    if a.ndim == 0:
        a = a[None, None]
    if a.ndim == 1:
        a = a[:, None] if n_in == 1 else a[None, :]
    if a.ndim != 2 or a.shape[-1] != n_in:
        raise InputError(f"{name}: expected {n_in} value(s) per sample for inputs "
                         f"({listing(linkage.inputs)}); got shape {shown_values(np.shape(values))}")
    if a.shape[0] == 0:
        raise InputError(f"{name}: give at least one sample")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name}: values must be finite")
    return a


def per_sample(linkage: Linkage, values: ArrayLike, name: str, X: Array) -> Array:
    """The inputs' rates or accelerations ``values`` as an (N, n_in) array for the N samples of
    ``X``: one value for every sample, or one per sample (:func:`as_input_array`)."""
    if np.ndim(values) == 0 and not isinstance(values, str):  # one value for every input
        values = np.full(len(linkage.inputs), values, dtype=float) if np.isreal(values) \
            else values
    a = as_input_array(linkage, values, name)
    if a.shape[0] not in (1, X.shape[0]):
        raise InputError(f"{name}: give one value for every sample or one per sample "
                         f"({X.shape[0]} samples); got {a.shape[0]}")
    if a.shape[0] == 1 and not np.any(a) and not np.any(np.signbit(a)):
        return np.zeros(X.shape)  # untouched zero pages until written (issue 30)
    return np.array(np.broadcast_to(a, X.shape))


def format_inputs(linkage: Any, x: ArrayLike) -> str:
    """Input values for a message, ``input.theta = 250 deg``, in the units of
    :func:`screwkit.messages.message_units` (the spec's, through a Pipeline; else degrees and
    metres). ``linkage`` is a Linkage or a Mechanism (whose rows hold its joint inputs, then its
    driven body freedoms: ``driven_names``)."""
    values = np.atleast_1d(np.asarray(x, dtype=float))
    names = tuple(getattr(linkage, "driven_names", linkage.inputs))
    if hasattr(linkage, "driven_is_translation"):
        slides = list(linkage.driven_is_translation())
    else:
        slides = [name.endswith(".s") for name in names]
    if len(names) != values.size:  # not one row of this mechanism's inputs
        return shown_values(values)
    return ", ".join(f"{name} = {shown(v, 'length' if slide else 'angle')}"
                     for name, v, slide in zip(names, values, slides, strict=True))

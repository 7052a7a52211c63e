"""A :class:`~screwkit.kinematics.motion.Motion` as a column table: one row per input sample
and assembly mode, one column per quantity (``Motion.table()``; written by ``to_csv``,
``to_dataframe`` and ``screwkit analyze --csv``).

Columns: ``mode``, ``input`` (the sweep value), ``assembles``, ``singular``; then every
variable with its rate and acceleration — ``phi0``, ``phi0_dot``, ``phi0_ddot`` — the seed's
names first, then every joint freedom (``B.theta``, ``B.theta_dot`` …; a spherical joint's
rotation vector ``B.rx`` and its angular velocity ``B.wx`` with ``B.wx_dot``); then
``closure_residual`` and, when asked, the world path of each coupler point (``coupler_x|y|z``
for one called "coupler point", ``<name>_x|y|z`` for others) and the transmission quality
(``transmission_index_<output>``, ``transmission_angle``, ``cone_angle_<ball joint>``). Values are
SI and radians, NaN where the mode does not assemble (rates and accelerations also where it is
singular), as in the JSON document.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from screwkit.errors import InputTypeError
from screwkit.tables import Column, ResultTable, stack_tables

if TYPE_CHECKING:
    from screwkit.kinematics.analysis.coupler_curves import CouplerPoint
    from screwkit.kinematics.analysis.transmission import Transmission
    from screwkit.kinematics.motion import ModeMotion, Motion

_TRANSLATION_SEED = re.compile(r"[sS]\d*")


def variable_kind(name: str) -> str:
    """``"length"`` for a translation, ``"angle"`` for a rotation: a joint freedom by its name
    (``<joint>.s`` is a slide; ``.theta``, ``.rx``, ``.wx`` … are rotations), a seed variable by
    the seeds' convention (Bagci's S and Rahman's s_i are slides, θ, φ, χ, η angles)."""
    if "." in name:
        return "length" if name.rsplit(".", 1)[1] == "s" else "angle"
    return "length" if _TRANSLATION_SEED.fullmatch(name) else "angle"


RATE_KIND = {"length": "velocity", "angle": "angular_velocity"}
ACCELERATION_KIND = {"length": "acceleration", "angle": "angular_acceleration"}


def _ordered(names: Sequence[str]) -> list[str]:
    """The seed's names (no dot) first, then the joint freedoms, each in their own order."""
    return [n for n in names if "." not in n] + [n for n in names if "." in n]


def mode_columns(md: ModeMotion, inputs: np.ndarray, input_kind: str) -> list[Column]:
    """The columns of one mode (module docstring), without the coupler point."""
    n = md.samples
    cols = [Column("mode", "index", np.full(n, md.index, dtype=np.int64)),
            Column("input", input_kind, np.asarray(inputs, dtype=float)),
            Column("assembles", "flag", np.asarray(md.assembles, dtype=bool)),
            Column("singular", "flag", np.asarray(md.singular, dtype=bool))]
    for name in _ordered(list(md.variables)):
        kind = variable_kind(name)
        cols.append(Column(name, kind, md.variables[name]))
        if name in md.velocities:
            cols.append(Column(f"{name}_dot", RATE_KIND[kind], md.velocities[name]))
        if name in md.accelerations:
            cols.append(Column(f"{name}_ddot", ACCELERATION_KIND[kind], md.accelerations[name]))
    for name in _ordered([v for v in md.velocities if v not in md.variables]):
        # angular velocities of spherical joints (B.wx): a rate with no position of its own
        kind = variable_kind(name)
        cols.append(Column(name, RATE_KIND[kind], md.velocities[name]))
        if name in md.accelerations:
            cols.append(Column(f"{name}_dot", ACCELERATION_KIND[kind], md.accelerations[name]))
    cols.append(Column("closure_residual", "ratio", md.closure_residual))
    return cols


def column_prefix(point_name: str) -> str:
    """The column prefix of a coupler point's path: ``coupler`` for the one called "coupler
    point" (the ``[coupler_point]`` table), else its name with other characters as ``_``."""
    return "coupler" if point_name == "coupler point" else re.sub(r"\W", "_", point_name)


def motion_table(motion: Motion, coupler_point: Sequence[float] | None = None,
                 coupler_link: int = 1, *, coupler_points: Sequence[CouplerPoint] = (),
                 transmission: Transmission | None = None) -> ResultTable:
    """Every mode of ``motion`` one under the other (module docstring); ``coupler_point``
    (f, g, h) in the body frame of moving link ``coupler_link`` adds its world path, as does
    each of ``coupler_points``; ``transmission`` adds the transmission quality."""
    from screwkit.kinematics.analysis.coupler_curves import CouplerPoint, coupler_point_path

    input_kind = variable_kind(motion.input_names[0])
    x = motion.input_values
    points = [("coupler", coupler_link, coupler_point)] if coupler_point is not None else []
    if isinstance(coupler_points, str) or not all(isinstance(cp, CouplerPoint)
                                                  for cp in coupler_points):
        raise InputTypeError("coupler_points must be CouplerPoint objects (spec.coupler_points "
                             f"or coupler_point(linkage, (f, g, h), link)); got "
                             f"{coupler_points!r:.60}")
    points += [(column_prefix(cp.name), cp.link, cp.point) for cp in coupler_points]
    tables = []
    for k, md in enumerate(motion.modes):
        cols = mode_columns(md, x, input_kind)
        for prefix, link, point in points:
            p = coupler_point_path(md, point, link)
            cols += [Column(f"{prefix}_{a}", "length", p[:, j]) for j, a in enumerate("xyz")]
        if transmission is not None:
            mt = transmission.modes[k]
            cols += [Column(f"transmission_index_{n}", "ratio", v) for n, v in mt.index.items()]
            if mt.angle is not None:
                cols.append(Column("transmission_angle", "angle", mt.angle))
            cols += [Column(f"cone_angle_{j}", "angle", v) for j, v in mt.cone_angle.items()]
        tables.append(ResultTable(tuple(cols)))
    title = f"{motion.linkage.name}: {motion.method} analysis, one row per input and mode"
    return stack_tables(tables, title)

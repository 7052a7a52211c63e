"""What every export format draws, in one form for a single loop and for a mechanism graph
(docs/exchange.md): per assembly mode, the frame of every body (the moving links or bodies,
then the ground), the polyline that pictures each body at every sample (what the report
draws), the world path of every named point and of every joint's centre.

:func:`loop_geometry` reads it from a loop's :class:`~screwkit.kinematics.motion.Motion`
(coupler points, :func:`screwkit.report.scene.link_polylines`), :func:`graph_geometry` from a
:class:`~screwkit.kinematics.graph.motion.MechanismMotion` (the ``[[points]]`` paths,
:func:`screwkit.report.graph_scene.body_polylines`). The DXF and glTF writers
(:mod:`screwkit.exchange.dxf`, :mod:`screwkit.exchange.gltf`) read only this.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.exchange.samples import Array


@dataclass(frozen=True, eq=False)
class ModeGeometry:
    """One assembly mode over N samples: ``index`` its number; ``assembles`` (N,);
    ``rotations`` (N, B + 1, 3, 3) and ``origins`` (N, B + 1, 3) the frame of each body named
    in ``bodies`` (the ground last, the identity); ``skeleton`` (N, B + 1, P, 3) the world
    polyline of each body (a short one padded by repeating its last vertex); ``points`` the
    world path (N, 3) of each named point; ``joints`` the world path (N, 3) of each joint's
    centre. NaN where the mode does not assemble."""

    index: int
    assembles: NDArray[np.bool_]
    bodies: tuple[str, ...]
    rotations: Array
    origins: Array
    skeleton: Array
    points: dict[str, Array]
    joints: dict[str, Array]

    def scale(self, frames: NDArray[np.intp] | None = None) -> float:
        """The largest joint-centre coordinate (m) over ``frames`` (default every sample)."""
        c = np.stack(list(self.joints.values()), axis=1)
        c = c if frames is None else c[frames]
        return float(np.nanmax(np.abs(c))) if np.isfinite(c).any() else 1.0


@dataclass(frozen=True, eq=False)
class ExportGeometry:
    """The modes to export of a solved motion, with the first input's name and values (N,)."""

    input_name: str
    inputs: Array
    modes: tuple[ModeGeometry, ...]


def _with_ground(R: Array, o: Array) -> tuple[Array, Array]:
    N = R.shape[0]
    R_all = np.concatenate([R, np.broadcast_to(np.eye(3), (N, 1, 3, 3))], axis=1)
    o_all = np.concatenate([o, np.zeros((N, 1, 3))], axis=1)
    return R_all, o_all


def loop_geometry(motion: Any, modes: Sequence[int], points: Sequence[Any]) -> ExportGeometry:
    """The geometry of the ``modes`` (indices of ``motion.mode``) of a single loop's ``motion``
    with its coupler ``points`` (:class:`~screwkit.kinematics.analysis.coupler_curves.
    CouplerPoint`)."""
    from screwkit.kinematics.analysis.coupler_curves import coupler_point_path
    from screwkit.report.scene import link_polylines

    lk = motion.linkage
    out = []
    for k in modes:
        md = motion.mode(k)
        R, o = _with_ground(np.asarray(md.link_rotation, dtype=float),
                            np.asarray(md.link_origin, dtype=float))
        centres = np.asarray(md.joint_centres, dtype=float)
        out.append(ModeGeometry(
            index=int(md.index), assembles=np.asarray(md.assembles, dtype=bool),
            bodies=(*(link.name for link in lk.links), "ground"), rotations=R, origins=o,
            skeleton=link_polylines(lk, md),
            points={cp.name: coupler_point_path(md, cp.point, cp.link) for cp in points},
            joints={j.name: centres[:, i] for i, j in enumerate(lk.joints)}))
    return ExportGeometry(str(lk.inputs[0]), np.asarray(motion.input_values, dtype=float),
                          tuple(out))


def graph_geometry(motion: Any, modes: Sequence[int]) -> ExportGeometry:
    """The geometry of the ``modes`` (indices of ``motion.mode``) of a mechanism graph's
    ``motion`` (``solve_mechanism``): its bodies as the report draws them, its ``[[points]]``."""
    from screwkit.report.graph_scene import body_polylines

    mech = motion.mechanism
    out = []
    for k in modes:
        md = motion.mode(k)
        R, o = _with_ground(np.asarray(md.link_rotation, dtype=float),
                            np.asarray(md.link_origin, dtype=float))
        centres = np.asarray(md.joint_centres, dtype=float)
        out.append(ModeGeometry(
            index=int(md.index), assembles=np.asarray(md.assembles, dtype=bool),
            bodies=(*mech.body_names, "ground"), rotations=R, origins=o,
            skeleton=body_polylines(mech, md),
            points={name: np.asarray(path, dtype=float) for name, path in md.points.items()},
            joints={j.name: centres[:, i] for i, j in enumerate(mech.joints)}))
    return ExportGeometry(str(mech.driven_names[0]),
                          np.asarray(motion.inputs, dtype=float)[:, 0], tuple(out))

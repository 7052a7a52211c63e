"""The loads in the report of a mechanism graph (docs/report.md, "Mechanism graphs"): the
inverse dynamics of its drawn mode (:func:`~screwkit.dynamics.graph_inverse.graph_inverse_dynamics`)
as arrows on the 3-D view — the reaction force at every joint centre (by the joint's first body on
its second), the applied inertia (+ weight) force of every body at its centre of mass, the
shaking force at the world origin — and as the dynamics plots single loops have, with one plot of
every input's effort; and the before/after plots of the spec's ``[balancing]`` run."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.dynamics.graph_inverse import GraphDynamics, body_masses
from screwkit.dynamics.inertia import inertia_wrenches
from screwkit.kinematics.graph.motion import MechanismMotion
from screwkit.report.scene_plots import dynamics_arrows

Array = NDArray[np.float64]


def graph_dynamics_document(dyn: GraphDynamics) -> dict[str, Any]:
    """:meth:`GraphDynamics.as_dict` with what the report's plots read of a loop's document:
    the moment point (the world origin) and a sentence on the indeterminate components."""
    doc = dyn.as_dict()
    doc["moment_point"] = np.zeros(3)
    if dyn.indeterminate:
        doc["indeterminacy"] = {"description": (
            f"{dyn.indeterminate} reaction component(s) statically indeterminate (carried by "
            f"{', '.join(dyn.indeterminate_joints)}); the least-norm reactions are shown "
            "(docs/dynamics.md)")}
    return doc


def graph_load_arrows(motion: MechanismMotion, mode: int, doc: dict[str, Any]
                      ) -> dict[str, Any]:
    """Arrows of one mode (module docstring); points and vectors SI, NaN where the mode is not
    regular."""
    mech = motion.mechanism
    md = motion.mode(mode)
    centres = np.asarray(md.joint_centres, dtype=float)
    arrows = dynamics_arrows(doc, centres, mech)
    masses = body_masses(motion)
    ok = np.asarray(md.assembles & ~md.singular)
    with np.errstate(invalid="ignore"):
        loads = inertia_wrenches(masses, md, np.asarray(doc["gravity"], dtype=float),
                                 np.zeros(3))
        com = np.stack([mp.com for mp in masses])
        at = np.einsum("nbij,bj->nbi", md.link_rotation, com) + md.link_origin
    word = "inertia and weight" if np.any(np.asarray(doc["gravity"]) != 0) else "inertia"
    for b, body in enumerate(mech.bodies):
        force = np.where(ok[:, None], loads[:, b, :3], np.nan)
        arrows[f"{word} force on {body.name}"] = {"kind": "force", "unit": "N",
                                                  "vectors": force, "points": at[:, b]}
    return arrows

"""Mobility of a :class:`~screwkit.model.Linkage`: the structural count (Malytcheff/Kutzbach,
Bagci 1969 App. B) next to the rank of its loop-closure screw Jacobian at an assembled sample,
and why they differ (e.g. a planar 4R seen as a spatial loop: 3 redundant constraints)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from screwkit.errors import CapabilityError, expect_instance
from screwkit.kinematics.motion import AssemblyError, as_input_array
from screwkit.kinematics.registry import output_joint
from screwkit.kinematics.tracker.loop import Array, forward, layout
from screwkit.kinematics.tracker.solve import find_assemblies
from screwkit.mobility import (
    FormulaMobility,
    MobilityComparison,
    NumericMobility,
    compare_mobility,
    formula_mobility,
    mobility_from_jacobian,
)
from screwkit.model.linkage import Linkage


@dataclass(frozen=True)
class LinkageMobility:
    """Formula and Jacobian mobility of one loop, and their comparison."""

    mechanism: str
    pairs: str
    sample_input: Array
    formula: FormulaMobility
    numeric: NumericMobility
    comparison: MobilityComparison

    @property
    def summary(self) -> list[str]:
        return [self.formula.describe(), self.numeric.describe(), self.comparison.describe()]

    def as_dict(self) -> dict[str, Any]:
        """The JSON document of ``screwkit mobility`` (docs/cli.md)."""
        return {
            "mechanism": self.mechanism,
            "pairs": self.pairs,
            "sample_input": self.sample_input,
            "formula": self.formula.as_dict(),
            "numeric": self.numeric.as_dict(),
            "comparison": self.comparison.as_dict(),
            "summary": self.summary,
        }


def mobility(linkage: Linkage, inputs: ArrayLike | None = None) -> LinkageMobility:
    """Formula mobility (Malytcheff, Kutzbach, Kolchin with every term; Bagci 1969 App. B) and
    the numerical mobility from the rank of the loop's screw Jacobian at the first input value
    where the loop assembles (the first assembly found there), searching ``inputs`` a few at a
    time (default: the input at 0). Redundant constraints and passive motions are named by
    joint."""
    expect_instance(linkage, Linkage, "mobility: linkage",
                    "a screwkit Linkage (e.g. sk.rsrc(...) or load_spec(...).linkage)")
    lay = layout(linkage)
    values = (np.zeros((1, len(linkage.inputs))) if inputs is None
              else as_input_array(linkage, inputs, "mobility: inputs"))
    X = np.atleast_2d(values.reshape(len(values), -1))
    asm = None
    i = -1
    X_i = X[0]
    for start in range(0, len(X), 8):
        block = find_assemblies(linkage, X[start:start + 8], starts=24)
        rows = np.nonzero(block.found.any(axis=1))[0]
        if rows.size:
            asm, i = block, int(rows[0])
            X_i = X[start + i]
            break
    if asm is None:
        raise AssemblyError(
            f"{linkage.name}: the loop does not close at any of the given inputs, so its "
            "mobility at a configuration cannot be computed; check the dimensions"
        )
    slot = int(np.argmax(asm.found[i]))
    K = asm.found.shape[1]
    fr = forward(linkage, asm.conf.take(np.array([i * K + slot])), lay)
    kinds = "".join(j.kind for j in linkage.joints)
    formula = formula_mobility(len(linkage.joints), kinds, name=linkage.name)
    numeric = mobility_from_jacobian(fr.screws[0], list(lay.names), inputs=list(linkage.inputs),
                                     outputs=_output_freedoms(linkage),
                                     length_scale=linkage.length_scale)
    return LinkageMobility(linkage.name, kinds, X_i, formula, numeric,
                           compare_mobility(formula, numeric, name=linkage.name))


def _output_freedoms(linkage: Linkage) -> list[str] | None:
    """The freedoms of the loop's output joint (the ground joint that is not driven), so that
    motions that leave it still — an S–S rod's spin — count as redundant freedoms; None when
    the input is not on the ground."""
    try:
        joint = linkage.joints[output_joint(linkage)]
    except CapabilityError:
        return None
    return list(joint.freedom_names())


def linkage_mobility(linkage: Linkage, input_values: ArrayLike) -> dict[str, Any]:
    """The ``screwkit mobility`` document of :func:`mobility` (kept for scripts)."""
    return mobility(linkage, input_values).as_dict()

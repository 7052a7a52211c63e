"""Mobility of a :class:`~screwkit.model.Linkage`: the structural count (Malytcheff/Kutzbach,
Bagci 1969 App. B) next to the rank of its loop-closure screw Jacobian at an assembled sample,
and why they differ (e.g. a planar 4R seen as a spatial loop: 3 redundant constraints)."""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.kinematics.loop import forward, layout
from screwkit.kinematics.solve import find_assemblies
from screwkit.mobility import compare_mobility, formula_mobility, mobility_from_jacobian
from screwkit.model.linkage import Linkage


def linkage_mobility(linkage: Linkage, input_values: np.ndarray) -> dict[str, Any]:
    """Formula and numerical mobility of ``linkage`` at the first input value where it
    assembles (the first assembly found there), searching the inputs a few at a time."""
    lay = layout(linkage)
    X = np.atleast_2d(np.asarray(input_values, dtype=float).reshape(len(input_values), -1))
    asm = None
    i = -1
    for start in range(0, len(X), 8):
        block = find_assemblies(linkage, X[start:start + 8], starts=24)
        rows = np.nonzero(block.found.any(axis=1))[0]
        if rows.size:
            asm, i = block, int(rows[0])
            X_i = X[start + i]
            break
    if asm is None:
        raise ValueError(
            f"{linkage.name}: the loop does not close at any of the given inputs, so its "
            "mobility at a configuration cannot be computed; check the dimensions"
        )
    slot = int(np.argmax(asm.found[i]))
    K = asm.found.shape[1]
    fr = forward(linkage, asm.conf.take(np.array([i * K + slot])), lay)
    J = fr.screws[0]
    kinds = "".join(j.kind for j in linkage.joints)
    formula = formula_mobility(len(linkage.joints), kinds, name=linkage.name)
    numeric = mobility_from_jacobian(J, list(lay.names), inputs=list(linkage.inputs),
                                     length_scale=linkage.length_scale)
    comparison = compare_mobility(formula, numeric, name=linkage.name)
    return {
        "mechanism": linkage.name,
        "pairs": kinds,
        "sample_input": X_i,
        "formula": formula.as_dict(),
        "numeric": numeric.as_dict(),
        "comparison": comparison.as_dict(),
        "summary": [formula.describe(), numeric.describe(), comparison.describe()],
    }

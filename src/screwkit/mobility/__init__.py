"""Mobility of mechanisms: structural formulas and the rank of the loop screw Jacobian.

``screwkit.mobility(linkage, inputs=None)`` — this package is callable — gives a linkage's
formula mobility (Malytcheff, Kutzbach, Kolchin; Bagci 1969 App. B) next to the rank of its
loop-closure screw Jacobian at the first input where it assembles, and names the redundant
constraints and passive motions by joint (a
:class:`~screwkit.kinematics.analysis.loop_mobility.LinkageMobility`; SI units, radians).

* :mod:`~screwkit.mobility.pairs` — pair catalogue (class, freedoms, names).
* :mod:`~screwkit.mobility.general_constraints` — Bagci's m(M_R1 M_R2 M_R3, M_T1 M_T2 M_T3).
* :mod:`~screwkit.mobility.formula` — Malytcheff, Kutzbach, Kolchin (Bagci 1969, App. B).
* :mod:`~screwkit.mobility.numeric` — instantaneous mobility from a (6k, m) screw Jacobian.
* :mod:`~screwkit.mobility.compare` — why a formula and the Jacobian disagree.

The modules are pure counting and linear algebra: none of them imports the linkage model.
"""

import sys
import types
from typing import Any

from screwkit.mobility.compare import MobilityComparison, compare_mobility
from screwkit.mobility.errors import MobilityInputError
from screwkit.mobility.formula import (
    BASIC,
    OVERCLOSED,
    OVERCLOSED_WITH_PASSIVE_FREEDOMS,
    WITH_PASSIVE_FREEDOMS,
    FormulaMobility,
    formula_mobility,
    kutzbach_mobility,
    loop_count,
    malytcheff_mobility,
    planar_mobility,
    spherical_mobility,
)
from screwkit.mobility.general_constraints import (
    GeneralConstraints,
    general_constraint_types,
    general_constraints,
)
from screwkit.mobility.numeric import (
    DEFAULT_RTOL,
    LoopConstraints,
    NumericMobility,
    characteristic_length,
    jacobian_rank,
    mobility_from_jacobian,
)
from screwkit.mobility.pairs import (
    PAIR_KINDS,
    PairKind,
    freedom_names,
    pair_kind,
    pair_kind_names,
    parse_pairs,
)

__all__ = [
    "BASIC",
    "DEFAULT_RTOL",
    "OVERCLOSED",
    "OVERCLOSED_WITH_PASSIVE_FREEDOMS",
    "PAIR_KINDS",
    "WITH_PASSIVE_FREEDOMS",
    "FormulaMobility",
    "GeneralConstraints",
    "LoopConstraints",
    "MobilityComparison",
    "MobilityInputError",
    "NumericMobility",
    "PairKind",
    "characteristic_length",
    "compare_mobility",
    "formula_mobility",
    "freedom_names",
    "general_constraint_types",
    "general_constraints",
    "jacobian_rank",
    "kutzbach_mobility",
    "loop_count",
    "malytcheff_mobility",
    "mobility_from_jacobian",
    "pair_kind",
    "pair_kind_names",
    "parse_pairs",
    "planar_mobility",
    "spherical_mobility",
]


class _CallableMobility(types.ModuleType):
    """``screwkit.mobility`` is both this package and the front-door verb
    ``screwkit.mobility(linkage)``: whichever way it is reached (``sk.mobility``,
    ``import screwkit.mobility``), it is the same object, and calling it runs
    :func:`screwkit.kinematics.analysis.loop_mobility.mobility`."""

    def __call__(self, linkage: Any, inputs: Any = None) -> Any:
        from screwkit.kinematics.analysis.loop_mobility import mobility

        return mobility(linkage, inputs)


sys.modules[__name__].__class__ = _CallableMobility

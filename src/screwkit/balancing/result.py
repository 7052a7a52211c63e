"""The result of a balancing run: the design before and after, the load measures, per-sample
loads (like Rahman's Tables 5.2–5.7), new mass properties (like Table 5.1), and how unique the
optimum is. JSON via :meth:`BalanceResult.as_dict`; plots via :mod:`screwkit.report.balance_plots`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from screwkit.balancing.measures import MEASURE_TITLES, MEASURES, Normalisation
from screwkit.balancing.problem import NonUniqueDirection, QuadraticObjective
from screwkit.balancing.variables import DesignVariables
from screwkit.dynamics import Dynamics
from screwkit.dynamics.graph_inverse import GraphDynamics
from screwkit.model.mass import MassProperties

if TYPE_CHECKING:  # the SDP bound and the Pareto sweep are built on top of BalanceResult
    from screwkit.balancing.pareto import ParetoFront
    from screwkit.balancing.sdp import RedistributionBound
    from screwkit.tables import ResultTable, UnitChoice

Array = NDArray[np.float64]

#: per-sample physical loads reported (key, title, unit)
SAMPLE_LOADS = (
    ("G", "objective G per sample", "1"),
    ("shaking_force", "|shaking force|", "N"),
    ("shaking_moment", "|shaking moment|", "N*m"),
    ("bearing_force", "sqrt(sum of |joint force|^2)", "N"),
    ("bearing_moment", "sqrt(sum of |joint moment|^2), input torque removed", "N*m"),
    ("input_torque", "input torque (signed)", "N*m"),
)


#: a measure below this fraction of the largest measure (before or after) is round-off: its
#: percentage change is reported as None / "n/a"
NEGLIGIBLE_MEASURE = 1e-12


def percent_change(before: float, after: float) -> float:
    """100·(after − before)/before (NaN when before is 0)."""
    return float(100.0 * (after - before) / before) if before != 0 else float("nan")


@dataclass(frozen=True, eq=False)
class BalanceResult:
    """Everything a balancing run found (SI units; measures are non-dimensional)."""

    variables: DesignVariables
    before: Array
    after: Array
    objective: QuadraticObjective
    measures_before: dict[str, float]
    measures_after: dict[str, float]
    per_sample_before: dict[str, Array]
    per_sample_after: dict[str, Array]
    inputs: Array  # (N,) the first input (crank angle, rad)
    link_mass_before: dict[str, float]
    link_mass_after: dict[str, float]
    mass_properties_before: dict[str, MassProperties]
    mass_properties_after: dict[str, MassProperties]
    unique: bool | None  # None: could not be determined (see notes)
    directions: list[NonUniqueDirection]
    active_constraints: list[str]
    multipliers: dict[str, float]
    normalisation: Normalisation
    dynamics_before: Dynamics | GraphDynamics  # GraphDynamics for a mechanism graph
    dynamics_after: Dynamics | GraphDynamics
    notes: list[str]
    #: the bound over every physically consistent redistribution (SDP), when asked for
    redistribution_bound: RedistributionBound | None = None
    #: the Pareto sweep over some measures' weights, when asked for
    pareto: ParetoFront | None = None

    @property
    def names(self) -> tuple[str, ...]:
        return self.variables.names

    def changes(self) -> dict[str, float | None]:
        """Percentage change of each measure's mean (and of G); ``None`` for a measure that is
        round-off before and after (below ``NEGLIGIBLE_MEASURE`` of the largest measure), whose
        percentage would be noise."""
        keys = (*MEASURES, "G")
        top = max((abs(d[k]) for d in (self.measures_before, self.measures_after) for k in keys),
                  default=0.0)
        floor = NEGLIGIBLE_MEASURE * top
        return {k: None if max(abs(self.measures_before[k]), abs(self.measures_after[k])) <= floor
                else percent_change(self.measures_before[k], self.measures_after[k])
                for k in keys}

    def mean_of_sample_changes(self) -> dict[str, float]:
        """Mean over the samples of the per-sample % change of each load magnitude — the
        statistic of Rahman's §5.3 text (SPEC §5.1), for comparison only."""
        out = {}
        for key, _, _ in SAMPLE_LOADS:
            b, a = self.per_sample_before[key], self.per_sample_after[key]
            with np.errstate(divide="ignore", invalid="ignore"):
                out[key] = float(np.nanmean(100.0 * (np.abs(a) - np.abs(b)) / np.abs(b)))
        return out

    def link_mass_change(self) -> dict[str, float]:
        """Percentage change of each link's total mass (the seed claimed none; SPEC §7)."""
        return {k: percent_change(self.link_mass_before[k], self.link_mass_after[k])
                for k in self.link_mass_before}

    def summary_table(self) -> list[list[str]]:
        """Rows (quantity, before, after, change %) for the CLI."""
        ch = self.changes()
        rows = [[f"{MEASURE_TITLES.get(k, 'objective G')} ({k})", f"{self.measures_before[k]:.6g}",
                 f"{self.measures_after[k]:.6g}",
                 "n/a (round-off)" if ch[k] is None else f"{ch[k]:+.3f}"]
                for k in (*MEASURES, "G")]
        for link, m0 in self.link_mass_before.items():
            m1 = self.link_mass_after[link]
            rows.append([f"mass of {link} (kg)", f"{m0:.6g}", f"{m1:.6g}",
                         f"{percent_change(m0, m1):+.3f}"])
        for name, b, a in zip(self.names, self.before, self.after, strict=True):
            rows.append([f"variable {name} (kg or kg*m)", f"{b:.6g}", f"{a:.6g}",
                         f"{percent_change(b, a):+.3f}" if b else "new"])
        return rows

    def per_sample_table(self, key: str) -> list[list[float]]:
        """Rows (input, before, after) of one of ``SAMPLE_LOADS`` (input in the library's unit,
        rad for a crank)."""
        b, a = self.per_sample_before[key], self.per_sample_after[key]
        return [[float(t), float(x), float(y)] for t, x, y in zip(self.inputs, b, a, strict=True)]

    def mass_properties_table(self, units: UnitChoice | None = None) -> list[list[Any]]:
        """Rows (link, quantity, before, after) like Rahman's Table 5.1: mass, centre of mass
        and inertia about it, in ``units`` (e.g. ``spec.display_units()``; default SI)."""
        from screwkit.tables import SIUnits

        u = units if units is not None else SIUnits()
        (ml, mf), (ll, lf), (il, jf) = (u.unit_of(k) for k in ("mass", "length", "inertia"))
        rows: list[list[Any]] = []
        for link, mp0 in self.mass_properties_before.items():
            mp1 = self.mass_properties_after[link]
            rows.append([link, f"mass ({ml})", mp0.mass / mf, mp1.mass / mf])
            for k, axis in enumerate("xyz"):
                rows.append([link, f"com {axis} ({ll})", float(mp0.com[k]) / lf,
                             float(mp1.com[k]) / lf])
            for i, j, lab in ((0, 0, "Ixx"), (1, 1, "Iyy"), (2, 2, "Izz"), (0, 1, "Ixy"),
                              (0, 2, "Ixz"), (1, 2, "Iyz")):
                rows.append([link, f"{lab} about CoM ({il})", float(mp0.inertia[i, j]) / jf,
                             float(mp1.inertia[i, j]) / jf])
        return rows

    def table(self) -> ResultTable:
        """One row per input sample: every per-sample load before and after (SI;
        :mod:`screwkit.balancing.result_table`)."""
        from screwkit.balancing.result_table import balance_table

        return balance_table(self)

    def to_dataframe(self, units: UnitChoice | None = None) -> Any:
        """:meth:`table` as a pandas DataFrame, headers with units (needs pandas)."""
        return self.table().to_dataframe(units)

    def to_csv(self, path: Any, units: UnitChoice | None = None) -> None:
        """:meth:`table` as CSV (``shaking_force_before [N]`` …)."""
        self.table().to_csv(path, units)

    def as_dict(self) -> dict[str, Any]:
        """JSON-able (docs/balancing.md documents every key)."""
        return {
            "variables": {"names": list(self.names), "links": list(self.variables.links),
                          "before": self.before.tolist(), "after": self.after.tolist()},
            "measures": {"before": dict(self.measures_before), "after": dict(self.measures_after),
                         "change_percent": self.changes(),
                         "mean_of_sample_changes_percent": self.mean_of_sample_changes()},
            "weights": dict(self.objective.weights),
            "normalisation": self.normalisation.as_dict(),
            "link_mass": {"before": dict(self.link_mass_before),
                          "after": dict(self.link_mass_after),
                          "change_percent": self.link_mass_change()},
            "unique": self.unique,
            "non_unique_directions": [
                {"direction": d.direction, "low": d.low, "high": d.high, "extent": d.extent}
                for d in self.directions
            ],
            "active_constraints": list(self.active_constraints),
            "multipliers": dict(self.multipliers),
            "mass_properties": [
                {"link": r[0], "quantity": r[1], "before": r[2], "after": r[3]}
                for r in self.mass_properties_table()
            ],
            "per_sample": {
                "input": self.inputs.tolist(),
                **{k: {"before": self.per_sample_before[k].tolist(),
                       "after": self.per_sample_after[k].tolist()} for k, _, _ in SAMPLE_LOADS},
            },
            "notes": list(self.notes),
            **self._extra_documents(),
        }

    def _extra_documents(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        b = self.redistribution_bound
        if b is not None:
            out["redistribution_bound"] = {
                "measures_before": b.measures_before, "measures_after": b.measures_after,
                "mass_properties": {k: {"mass": v.mass, "com": v.com.tolist(),
                                        "inertia": v.inertia.tolist()}
                                    for k, v in b.mass_properties_after.items()}}
        f = self.pareto
        if f is not None:
            out["pareto"] = {"measures": list(f.names), "weights": f.weights.tolist(),
                             "values": f.measures.tolist(), "efficient": f.efficient.tolist()}
        return out

"""The result of :func:`~screwkit.kinematics.analysis.limit_positions.limit_positions`: limit positions
of output variables (d output / d input = 0) with the order of the instantaneous dwell at each,
from either route (Bagci 1969 App. D's closed form, or the generic route on any loop)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class LimitPosition:
    """A limit of ``output`` (d output/d input = 0) on one branch.

    ``kind`` is ``"rotation"`` or ``"translation"`` (what the output is); ``input`` and
    ``value`` the input and the output there (rad or m); ``second_derivative`` d²output/d input²;
    ``dwell_order`` the number of vanishing consecutive derivatives dᵏoutput/d inputᵏ,
    k = 1 … max_order (1: a plain limit, 2 or more: an instantaneous dwell), with
    ``derivatives`` k = 1 … max_order + 1 (None where the route gives none: the closed form's
    translation limits). ``mode``: the motion's assembly mode (generic route); ``branch``: the
    closed form's branch column (closed route). ``variables``: every variable there (the seed's
    names and the scalar joint freedoms)."""

    output: str
    kind: str
    input: float
    value: float
    second_derivative: float
    dwell_order: int | None
    derivatives: list[float] | None
    mode: int | None = None
    branch: int | None = None
    variables: dict[str, float | None] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"output": self.output, "kind": self.kind}
        d.update({"mode": self.mode} if self.mode is not None else {"branch": self.branch})
        d.update(input=self.input, value=self.value, second_derivative=self.second_derivative,
                 dwell_order=self.dwell_order, derivatives=self.derivatives)
        d.update({k: v for k, v in self.variables.items() if "." not in k})  # the seed's names
        d["variables"] = dict(self.variables)
        return d


@dataclass(frozen=True)
class DwellAt:
    """The dwell order of ``output`` at a given input, on one mode (generic route: ``mode``)
    or inversion (closed route: ``inversion_label``, Bagci's root label 1 … 4)."""

    output: str
    input: float
    value: float
    dwell_order: int
    derivatives: list[float]
    mode: int | None = None
    inversion_label: int | None = None

    def as_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"output": self.output, "input": self.input, "value": self.value}
        if self.mode is not None:
            d["mode"] = self.mode
        else:
            d.update(inversion_label=self.inversion_label, theta0=self.input, phi0=self.value)
        d.update(dwell_order=self.dwell_order, derivatives=self.derivatives)
        return d


@dataclass(frozen=True)
class LimitPositions:
    """Limit positions and dwell orders of a loop's outputs (SI units, radians).

    ``method``: ``"closed"`` (Bagci 1969 App. D: the RSRC and planar 4R over a full input turn)
    or ``"generic"`` (any loop, over the motion's input sweep; docs/kinematics.md);
    ``derivatives`` says how the derivatives were computed."""

    mechanism: str
    family: str
    method: str
    input_name: str
    outputs: tuple[str, ...]
    dwell_tolerance: float
    max_order: int
    limits: list[LimitPosition]
    dwells_at: list[DwellAt] = field(default_factory=list)
    derivatives: str = ""
    notes: tuple[str, ...] = ()
    #: what the input is when its name does not say: ``"length"``, ``"angle"`` or ``"ratio"``
    #: (a position along a path of input rows, counted in rows)
    input_kind: str | None = None

    def as_dict(self) -> dict[str, Any]:
        """The JSON document of ``screwkit limits`` (docs/cli.md)."""
        extra = {} if self.input_kind is None else {"input_kind": self.input_kind}
        return {**extra, "mechanism": self.mechanism, "family": self.family, "method": self.method,
                "input_name": self.input_name, "outputs": list(self.outputs),
                "dwell_tolerance": self.dwell_tolerance, "max_order": self.max_order,
                "derivatives": self.derivatives, "notes": list(self.notes),
                "units": {"angle": "rad", "length": "m",
                          "derivatives": "output unit / input unit^k"},
                "limits": [x.as_dict() for x in self.limits],
                "dwells_at": [d.as_dict() for d in self.dwells_at]}

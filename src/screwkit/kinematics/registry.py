"""The family registry: the one place that knows what each mechanism family is.

A :class:`Family` maps a family name to its dimensions (with their quantity kinds), its
constructor (:mod:`screwkit.model.families`), its closed-form solver if it has one
(:mod:`screwkit.kinematics.closed_form_motion`), the seed's variable names read off any mode
(:mod:`screwkit.kinematics.seed_names`), a parameter sketch and the capabilities screwkit offers
for it. Nothing else in the package compares family strings: code asks the registry
(``family_of(linkage).closed_form``, ``require(linkage, "limits")``).

To add a family: write its constructor in :mod:`screwkit.model.families`, optionally a closed
form returning a :class:`~screwkit.kinematics.motion.Motion`, and one :class:`Family` entry below
(docs/architecture.md).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics import seed_names
from screwkit.kinematics.loop import Array
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.model import families as constructors
from screwkit.model.linkage import Linkage

Named = dict[str, Array]
ClosedForm = Callable[[Linkage, Array, Array, Array], Motion]
SeedNames = Callable[[Linkage, ModeMotion], tuple[Named, Named, Named]]

#: capabilities a family can have, as (what, where it comes from); `require` names a missing
#: one in a sentence: "<what> are computed for <families> (<source>); this is a <family>"
CAPABILITIES = {
    "analyze": ("positions, velocities and accelerations", "docs/kinematics.md"),
    "mobility": ("mobilities by formula and from the loop Jacobian", "Bagci App. B"),
    "dynamics": ("inverse dynamics", "docs/dynamics.md"),
    "balance": ("optimum balances", "Rahman ch. 4"),
    "limits": ("limit positions and dwells", "Bagci App. D"),
    "coupler_point": ("coupler points", "Bagci App. C"),
    "synthesize": ("dimensional syntheses", "Bagci ch. IV-V"),
}
_EVERY_LOOP = frozenset({"analyze", "mobility", "dynamics", "balance"})


@dataclass(frozen=True)
class Family:
    """One mechanism family (see the module docstring)."""

    name: str
    title: str  # how a sentence names it: "the RSRC", "the planar 4R"
    description: str
    dimensions: Mapping[str, str]  # name -> quantity kind ("length", "angle")
    optional: Mapping[str, float] = field(default_factory=dict)  # name -> default (SI)
    build: Callable[..., Linkage] | None = None  # keyword dimensions (SI) -> Linkage
    closed_form: ClosedForm | None = None
    #: whether the closed form solves a given loop of the family (None: every loop)
    closed_form_applies: Callable[[Linkage], bool] | None = None
    seed_names: SeedNames | None = None
    capabilities: frozenset[str] = _EVERY_LOOP
    aliases: tuple[str, ...] = ()
    sketch: str = ""
    why_not: Mapping[str, str] = field(default_factory=dict)  # capability -> reason it is missing

    def closed_form_for(self, linkage: Linkage) -> ClosedForm | None:
        """The closed form that solves ``linkage``, or None (then the generic solver does)."""
        if self.closed_form is None:
            return None
        if self.closed_form_applies is not None and not self.closed_form_applies(linkage):
            return None
        return self.closed_form

    def linkage(self, **dimensions: float) -> Linkage:
        """The family's loop from its dimensions (SI units, radians)."""
        if self.build is None:
            raise CapabilityError(f"a {self.name} is built from its joint list, not from "
                                  "dimensions")
        return self.build(**{**self.optional, **dimensions})


def _rsrc_closed(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    from screwkit.kinematics.closed_form_motion import rsrc_closed_motion

    return rsrc_closed_motion(linkage, X, Xd, Xdd)


def _cssp_closed(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    from screwkit.kinematics.closed_form_motion import cssp_closed_motion

    return cssp_closed_motion(linkage, X, Xd, Xdd)


def _rssr_closed(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    from screwkit.kinematics.closed_form_motion import rssr_closed_motion

    return rssr_closed_motion(linkage, X, Xd, Xdd)


def _rccc_closed(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    from screwkit.kinematics.closed_form_motion import rccc_closed_motion

    return rccc_closed_motion(linkage, X, Xd, Xdd)


def _is_rccc(linkage: Linkage) -> bool:
    from screwkit.kinematics.rccc import rccc_applies

    return rccc_applies(linkage)


def _cssp(a1: float, a2: float, a4: float, alpha4: float, s1: float = 0.0) -> Linkage:
    return constructors.cssp(a1, a2, a4, alpha4, s1)


def _rccc(a1: float, a2: float, a3: float, a4: float, alpha1: float, alpha2: float,
          alpha3: float, alpha4: float, input_offset: float = 0.0) -> Linkage:
    return constructors.rccc((a1, a2, a3, a4), (alpha1, alpha2, alpha3, alpha4), input_offset)


_LENGTH, _ANGLE = "length", "angle"

FAMILIES: dict[str, Family] = {
    f.name: f for f in (
        Family(
            "RSRC", "the RSRC", "Bagci's RSRC space mechanism (input R, S, coupler R, output C)",
            {"d1": _LENGTH, "d2": _LENGTH, "d3": _LENGTH, "a": _LENGTH, "b": _LENGTH,
             "e": _LENGTH, "delta0": _ANGLE, "lambda0": _ANGLE},
            build=constructors.rsrc, closed_form=_rsrc_closed, seed_names=seed_names.rsrc_names,
            capabilities=_EVERY_LOOP | {"limits", "coupler_point", "synthesize"},
            aliases=("rsrc",), sketch=constructors.RSRC_SKETCH),
        Family(
            "4R", "the planar 4R", "planar four-bar (Bagci's special case of the RSRC)",
            {"a": _LENGTH, "d1": _LENGTH, "d2": _LENGTH, "d3": _LENGTH},
            build=constructors.fourbar, closed_form=_rsrc_closed,
            seed_names=seed_names.fourbar_names, capabilities=_EVERY_LOOP | {"limits"},
            aliases=("4r", "fourbar"), sketch=constructors.FOURBAR_SKETCH,
            why_not={"synthesize": "restate the 4R as an RSRC with delta0 = lambda0 = b = e = 0 "
                                   "(Bagci's plane case), as the bundled Example 3 does",
                     "coupler_point": "coupler points are defined with Bagci's RSRC frames "
                                      "(App. C)"}),
        Family(
            "CSSP", "the CSSP", "Rahman's generalised slider-crank (C-S-S-P)",
            {"a1": _LENGTH, "a2": _LENGTH, "a4": _LENGTH, "alpha4": _ANGLE, "s1": _LENGTH},
            optional={"s1": 0.0}, build=_cssp, closed_form=_cssp_closed,
            seed_names=seed_names.cssp_names, aliases=("cssp",), sketch=constructors.CSSP_SKETCH,
            why_not={"limits": "the CSSP's output is a slider; its limits are where the quadratic's "
                               "discriminant vanishes (reported as branch events by analyze)"}),
        Family(
            "RSSR", "the RSSR", "spatial R-S-S-R crank-rocker (closed form A cos φ0 + B sin φ0 = K)",
            {"d1": _LENGTH, "d2": _LENGTH, "d3": _LENGTH, "a": _LENGTH, "b": _LENGTH,
             "lambda0": _ANGLE, "output_offset": _LENGTH},
            optional={"output_offset": 0.0}, build=constructors.rssr, closed_form=_rssr_closed,
            seed_names=seed_names.rssr_names, aliases=("rssr",),
            sketch=constructors.RSSR_SKETCH),
        Family(
            "RCCC", "the RCCC", "R-C-C-C loop in Hartenberg-Denavit form (closed form: the dual "
            "input-output equation)",
            {"a1": _LENGTH, "a2": _LENGTH, "a3": _LENGTH, "a4": _LENGTH, "alpha1": _ANGLE,
             "alpha2": _ANGLE, "alpha3": _ANGLE, "alpha4": _ANGLE, "input_offset": _LENGTH},
            optional={"input_offset": 0.0}, build=_rccc, closed_form=_rccc_closed,
            closed_form_applies=_is_rccc, aliases=("rccc",),
            sketch=constructors.RCCC_SKETCH),
        Family(
            "LOOP", "a joint-list loop", "any single loop given as a joint list (generic solver; "
            "the RCCC closed form for an R C C C list driven at its R joint)", {},
            closed_form=_rccc_closed, closed_form_applies=_is_rccc, aliases=("loop",),
            sketch="[[joints]]: name, kind (R P C H U S), length, twist, offset, pitch, input "
                   "(Hartenberg-Denavit, Rahman eq. 2.2)"),
    )
}
_ALIASES = {alias: f.name for f in FAMILIES.values() for alias in (f.name.lower(), *f.aliases)}


def family(name: str) -> Family:
    """The family called ``name`` (case-insensitive; ``fourbar`` is the 4R)."""
    key = _ALIASES.get(str(name).lower())
    if key is None:
        raise InputError(f"unknown family {name!r}; use one of {', '.join(FAMILIES)}")
    return FAMILIES[key]


def family_of(linkage: Linkage) -> Family:
    """The family a linkage was built as (``LOOP`` for a joint list)."""
    return FAMILIES.get(linkage.family or "LOOP", FAMILIES["LOOP"])


def require(linkage_or_family: Linkage | Family, capability: str) -> Family:
    """The family, or a ValueError saying in one sentence why ``capability`` is not offered."""
    fam = (linkage_or_family if isinstance(linkage_or_family, Family)
           else family_of(linkage_or_family))
    if capability not in fam.capabilities:
        what, source = CAPABILITIES[capability]
        offered = [f.title for f in FAMILIES.values() if capability in f.capabilities]
        listed = (" and ".join(offered) if len(offered) < 3
                  else ", ".join(offered[:-1]) + " and " + offered[-1])
        why = fam.why_not.get(capability)
        raise CapabilityError(f"{what} are computed for {listed or 'no family yet'} ({source}); this "
                         f"is a {fam.name}" + (f": {why}" if why else ""))
    return fam


def seed_variables(linkage: Linkage, mode: ModeMotion) -> tuple[Named, Named, Named]:
    """The seed's variables of a mode (empty for a family without seed names)."""
    fam = family_of(linkage)
    if fam.seed_names is None:
        return {}, {}, {}
    return fam.seed_names(linkage, mode)

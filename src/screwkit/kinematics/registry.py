"""The family registry: the one place that knows what each mechanism family is.

A :class:`Family` maps a family name to its dimensions (with their quantity kinds), its
constructor (:mod:`screwkit.model.families`), its closed-form solver if it has one
(:mod:`screwkit.kinematics.closed_forms.closed_form_motion`), the seed's variable names read off any mode
(:mod:`screwkit.kinematics.closed_forms.seed_names`), a parameter sketch and the capabilities screwkit offers
for it. Nothing else in the package compares family strings: code asks the registry
(``family_of(linkage).closed_form``, ``require(linkage, "limits")``).

To add a family: write its constructor in :mod:`screwkit.model.families`, optionally a closed
form returning a :class:`~screwkit.kinematics.motion.Motion`, and one :class:`Family` entry below
(docs/architecture.md).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from screwkit.errors import CapabilityError, InputError, UnknownNameError
from screwkit.kinematics.closed_forms import seed_names
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.kinematics.tracker.loop import Array
from screwkit.model import families as constructors
from screwkit.model import geometry as geometries
from screwkit.model.geometry import LoopGeometry
from screwkit.model.linkage import Linkage

if TYPE_CHECKING:
    from screwkit.kinematics.closed_forms.closed_form_motion import ClosedBranches

Named = dict[str, Array]
ClosedForm = Callable[[Linkage, Array, Array, Array], Motion]
#: a closed form's modes before they are built (closed_form_motion.ClosedBranches)
ClosedFormBranches = Callable[[Linkage, Array, Array, Array], "ClosedBranches"]
SeedNames = Callable[[Linkage, ModeMotion], tuple[Named, Named, Named]]
ClosedLimits = Callable[..., Any]  # (linkage, dwell_tolerance, max_order, at) -> LimitPositions

#: capabilities a family can have, as (what, where it comes from); `require` names a missing
#: one in a sentence: "<what> are computed for <families> (<source>); this is a <family>"
CAPABILITIES = {
    "analyze": ("positions, velocities and accelerations", "docs/kinematics.md"),
    "mobility": ("mobilities by formula and from the loop Jacobian", "Bagci App. B"),
    "dynamics": ("inverse dynamics", "docs/dynamics.md"),
    "balance": ("optimum balances", "Rahman ch. 4"),
    "limits": ("limit positions and dwells", "Bagci App. D; docs/kinematics.md"),
    "coupler_point": ("coupler points", "Bagci App. C; docs/kinematics.md"),
    "transmission": ("transmission angles and indices", "docs/kinematics.md"),
    "synthesize": ("dimensional syntheses", "Bagci ch. IV-V; docs/synthesis.md"),
    "closed_synthesis": ("closed-form syntheses (Programs B and C, the overlay)",
                         "Bagci ch. V"),
    "overlay": ("overlay syntheses", "Bagci §5.4"),
}
_NOT_CLOSED = ("it has no closed-form synthesis; it is synthesised by the generic route "
               "(solver = \"generic\" or \"auto\", docs/synthesis.md)")
_NOT_OVERLAY = ("the overlay draws Bagci's RSRC coupler circles about its input-crank ellipse, "
                "which this loop does not have; use method = \"least_squares\"")
_EVERY_LOOP = frozenset({"analyze", "mobility", "dynamics", "balance", "limits",
                         "coupler_point", "transmission", "synthesize"})


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
    #: the closed form's modes as branches before they are built (the same configurations and
    #: numbering; None: only the whole Motion is offered)
    closed_branches: ClosedFormBranches | None = None
    seed_names: SeedNames | None = None
    capabilities: frozenset[str] = _EVERY_LOOP
    aliases: tuple[str, ...] = ()
    sketch: str = ""
    why_not: Mapping[str, str] = field(default_factory=dict)  # capability -> reason it is missing
    #: the seed's names that are a joint freedom times a sign (their derivatives are the
    #: freedom's): name -> (freedom, sign), e.g. the RSRC's phi0 = -output_C.theta
    seed_freedoms: Mapping[str, tuple[str, float]] = field(default_factory=dict)
    #: the output variables (limits, transmission and synthesis default to them); empty for a
    #: joint list, whose output is the freedoms of the ground joint that is not the input
    outputs: tuple[str, ...] = ()
    #: the moving link a coupler point is on by default (its body frame: docs/kinematics.md)
    coupler_link: str | None = None
    #: Bagci's App. D closed form of the limits of ``outputs`` (None: the generic route)
    closed_limits: ClosedLimits | None = None
    #: the loop's constant geometry from its dimensions, complex-safe (model/geometry.py): the
    #: generic synthesis route differentiates the loop closure through it
    geometry: Callable[..., LoopGeometry] | None = None
    #: Bagci's closed-form synthesis (Programs B/C, the overlay) as the RSRC with these
    #: dimensions held (the 4R: b = e = δ0 = λ0 = 0); None: the generic route only
    closed_synthesis: Mapping[str, float] | None = None
    #: the most assembly modes a loop of the family has at one input (the degree of its
    #: input-output equation: the RSRC quartic 3.63 gives 4, a quadratic 2); None: not known
    #: here (a joint list), and memory estimates assume ``MODES_ESTIMATE``
    max_modes: int | None = None

    def closed_form_for(self, linkage: Linkage) -> ClosedForm | None:
        """The closed form that solves ``linkage``, or None (then the generic solver does)."""
        if self.closed_form is None:
            return None
        if self.closed_form_applies is not None and not self.closed_form_applies(linkage):
            return None
        return self.closed_form

    def closed_branches_for(self, linkage: Linkage) -> ClosedFormBranches | None:
        """The closed form's branches for ``linkage`` (where :meth:`closed_form_for` applies
        and the family offers them), or None."""
        if self.closed_branches is None or self.closed_form_for(linkage) is None:
            return None
        return self.closed_branches

    def linkage(self, **dimensions: float) -> Linkage:
        """The family's loop from its dimensions (SI units, radians)."""
        if self.build is None:
            raise CapabilityError(f"a {self.name} is built from its joint list, not from "
                                  "dimensions")
        return self.build(**{**self.optional, **dimensions})


def _rsrc_closed(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    from screwkit.kinematics.closed_forms.closed_form_motion import rsrc_closed_motion

    return rsrc_closed_motion(linkage, X, Xd, Xdd)


def _cssp_closed(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    from screwkit.kinematics.closed_forms.closed_form_motion import cssp_closed_motion

    return cssp_closed_motion(linkage, X, Xd, Xdd)


def _rssr_closed(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    from screwkit.kinematics.closed_forms.closed_form_motion import rssr_closed_motion

    return rssr_closed_motion(linkage, X, Xd, Xdd)


def _rccc_closed(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> Motion:
    from screwkit.kinematics.closed_forms.closed_form_motion import rccc_closed_motion

    return rccc_closed_motion(linkage, X, Xd, Xdd)


def _rsrc_branches(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> ClosedBranches:
    from screwkit.kinematics.closed_forms.closed_form_motion import rsrc_branches

    return rsrc_branches(linkage, X, Xd, Xdd)


def _rssr_branches(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> ClosedBranches:
    from screwkit.kinematics.closed_forms.closed_form_motion import rssr_branches

    return rssr_branches(linkage, X, Xd, Xdd)


def _rccc_branches(linkage: Linkage, X: Array, Xd: Array, Xdd: Array) -> ClosedBranches:
    from screwkit.kinematics.closed_forms.closed_form_motion import rccc_branches

    return rccc_branches(linkage, X, Xd, Xdd)


def _is_rccc(linkage: Linkage) -> bool:
    from screwkit.kinematics.closed_forms.rccc import rccc_applies

    return rccc_applies(linkage)


def _rsrc_limits(linkage: Linkage, dwell_tolerance: float, max_order: int,
                 at: list[float] | None) -> Any:
    from screwkit.kinematics.closed_forms.closed_limits import rsrc_limit_positions

    return rsrc_limit_positions(linkage, dwell_tolerance, max_order, at)


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
            build=constructors.rsrc, closed_form=_rsrc_closed, closed_branches=_rsrc_branches,
            seed_names=seed_names.rsrc_names,
            aliases=("rsrc",), sketch=constructors.RSRC_SKETCH,
            capabilities=_EVERY_LOOP | {"closed_synthesis", "overlay"},
            seed_freedoms={"theta0": ("input.theta", 1.0), "phi0": ("output_C.theta", -1.0),
                           "S": ("output_C.s", 1.0), "chi0": ("coupler_R.theta", 1.0)},
            outputs=("phi0", "S"), coupler_link="coupler", closed_limits=_rsrc_limits,
            geometry=geometries.rsrc_geometry, closed_synthesis={}, max_modes=4),
        Family(
            "4R", "the planar 4R", "planar four-bar (Bagci's special case of the RSRC)",
            {"a": _LENGTH, "d1": _LENGTH, "d2": _LENGTH, "d3": _LENGTH},
            build=constructors.fourbar, closed_form=_rsrc_closed, closed_branches=_rsrc_branches,
            seed_names=seed_names.fourbar_names,
            aliases=("4r", "fourbar"), sketch=constructors.FOURBAR_SKETCH,
            capabilities=_EVERY_LOOP | {"closed_synthesis"},
            why_not={"overlay": "it turns the plane mechanism to put the output pivot on the "
                                "line of centres (Program C L6248-L6262), which the 4R's own "
                                "parameters do not carry; state it as an RSRC with lambda0 = "
                                "delta0 = b = e = 0, or use method = \"least_squares\""},
            seed_freedoms={"theta0": ("input.theta", 1.0), "phi0": ("output.theta", -1.0),
                           "chi0": ("rocker_pin.theta", 1.0)},
            outputs=("phi0",), coupler_link="coupler", closed_limits=_rsrc_limits,
            geometry=geometries.fourbar_geometry,
            closed_synthesis={"b": 0.0, "e": 0.0, "delta0": 0.0, "lambda0": 0.0}, max_modes=2),
        Family(
            "CSSP", "the CSSP", "Rahman's generalised slider-crank (C-S-S-P)",
            {"a1": _LENGTH, "a2": _LENGTH, "a4": _LENGTH, "alpha4": _ANGLE, "s1": _LENGTH},
            optional={"s1": 0.0}, build=_cssp, closed_form=_cssp_closed,
            seed_names=seed_names.cssp_names, aliases=("cssp",), sketch=constructors.CSSP_SKETCH,
            why_not={"closed_synthesis": _NOT_CLOSED, "overlay": _NOT_OVERLAY},
            seed_freedoms={"theta1": ("crank.theta", 1.0), "s4": ("slider.s", 1.0)},
            outputs=("s4",), coupler_link="rod", geometry=geometries.cssp_geometry, max_modes=2),
        Family(
            "RSSR", "the RSSR", "spatial R-S-S-R crank-rocker (closed form A cos φ0 + B sin φ0 = K)",
            {"d1": _LENGTH, "d2": _LENGTH, "d3": _LENGTH, "a": _LENGTH, "b": _LENGTH,
             "lambda0": _ANGLE, "output_offset": _LENGTH},
            optional={"output_offset": 0.0}, build=constructors.rssr, closed_form=_rssr_closed,
            closed_branches=_rssr_branches,
            seed_names=seed_names.rssr_names, aliases=("rssr",),
            why_not={"closed_synthesis": _NOT_CLOSED, "overlay": _NOT_OVERLAY},
            sketch=constructors.RSSR_SKETCH,
            seed_freedoms={"theta0": ("input.theta", 1.0), "phi0": ("output.theta", -1.0)},
            outputs=("phi0",), coupler_link="coupler", geometry=geometries.rssr_geometry,
            max_modes=2),
        Family(
            "RCCC", "the RCCC", "R-C-C-C loop in Hartenberg-Denavit form (closed form: the dual "
            "input-output equation)",
            {"a1": _LENGTH, "a2": _LENGTH, "a3": _LENGTH, "a4": _LENGTH, "alpha1": _ANGLE,
             "alpha2": _ANGLE, "alpha3": _ANGLE, "alpha4": _ANGLE, "input_offset": _LENGTH},
            optional={"input_offset": 0.0}, build=_rccc, closed_form=_rccc_closed,
            closed_branches=_rccc_branches, closed_form_applies=_is_rccc, aliases=("rccc",),
            why_not={"closed_synthesis": _NOT_CLOSED, "overlay": _NOT_OVERLAY},
            sketch=constructors.RCCC_SKETCH, outputs=("C4.theta", "C4.s"), coupler_link="link2",
            geometry=geometries.rccc_geometry, max_modes=2),
        Family(
            "LOOP", "a joint-list loop", "any single loop given as a joint list (generic solver; "
            "the RCCC closed form for an R C C C list driven at its R joint)", {},
            closed_form=_rccc_closed, closed_branches=_rccc_branches,
            closed_form_applies=_is_rccc, aliases=("loop",),
            why_not={"closed_synthesis": _NOT_CLOSED, "overlay": _NOT_OVERLAY},
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


def has_rsrc_quartic(linkage: Linkage) -> bool:
    """Whether the loop's positions are the real roots of the RSRC quartic (Bagci 1969
    eq. 3.63): the RSRC and the planar 4R, its δ0 = λ0 = b = e = 0 case."""
    return linkage.family in ("RSRC", "4R")


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


def output_joint(linkage: Linkage) -> int:
    """The index of the loop's output joint: the joint on the ground (the last or the first
    joint; the ground link closes the loop between them) that is not the input joint. A
    CapabilityError says why when the input is not on the ground (then no joint is the output)."""
    n = len(linkage.joints)
    driven = {name.split(".")[0] for name in linkage.inputs}
    first, last = linkage.joints[0].name, linkage.joints[n - 1].name
    if first in driven and last not in driven:
        return n - 1
    if last in driven and first not in driven:
        return 0
    raise CapabilityError(
        f"{linkage.name}: the input joint ({', '.join(sorted(driven))}) is not one of the two "
        f"joints on the ground ({first}, {last}), so the loop has no output joint to take limits, "
        "transmission or synthesis of; name the output variable (e.g. --output <joint>.theta)")


def default_outputs(linkage: Linkage) -> tuple[str, ...]:
    """The output variables of a loop: the family's (RSRC φ0 and S, 4R and RSSR φ0, CSSP s4,
    RCCC C4.theta and C4.s) or, for a joint list, the scalar freedoms of its output joint."""
    fam = family_of(linkage)
    if fam.outputs:
        return fam.outputs
    joint = linkage.joints[output_joint(linkage)]
    if joint.kind == "S":
        raise CapabilityError(f"{linkage.name}: the output joint {joint.name!r} is a ball joint, whose "
                         "rotation has no scalar variable; name the output variable")
    return tuple(joint.freedom_names())


def output_freedom(linkage: Linkage, name: str) -> tuple[str, float]:
    """The joint freedom and sign of an output variable ``name``: a scalar freedom
    ``"<joint>.<freedom>"`` is itself (sign +1); a seed name of the family is its freedom times
    a sign (RSRC ``phi0`` = −``output_C.theta``). An UnknownNameError lists the names that work."""
    fam = family_of(linkage)
    scalar = [f for j in linkage.joints if j.kind != "S" for f in j.freedom_names()]
    if name in scalar:
        return name, 1.0
    if name in fam.seed_freedoms:
        return fam.seed_freedoms[name]
    raise UnknownNameError(f"{linkage.name}: no output variable {name!r}; use a joint freedom "
                     f"({', '.join(scalar)})"
                     + (f" or one of the seed's names {', '.join(fam.seed_freedoms)}"
                        if fam.seed_freedoms else ""))


def coupler_link_index(linkage: Linkage, name: str | None = None) -> int:
    """The moving link a coupler point is on: the link called ``name``, else the family's
    coupler (RSRC, 4R, RSSR ``coupler``; CSSP ``rod``; RCCC ``link2``), else the only moving
    link of a joint list that touches no ground joint."""
    names = [link.name for link in linkage.links]
    if name is not None:
        if name not in names:
            raise UnknownNameError(f"{linkage.name}: no moving link called {name!r}; the links are "
                             f"{', '.join(names)}")
        return names.index(name)
    fam = family_of(linkage)
    if fam.coupler_link is not None and fam.coupler_link in names:
        return names.index(fam.coupler_link)
    floating = list(range(1, len(names) - 1))
    if len(floating) == 1:
        return floating[0]
    raise InputError(f"{linkage.name}: a joint list of {len(linkage.joints)} joints has "
                     f"{len(floating) or 'no'} moving link(s) off the ground, so it has no one "
                     f"coupler; name the link (link = \"...\", one of {', '.join(names)})")

"""Mechanism spec files: TOML with units, validated with pydantic.

Every error names the file, the key, what is wrong and what would be right
(``docs/spec-format.md`` documents every key).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    StrictFloat,
    StrictInt,
    StrictStr,
    ValidationError,
    field_validator,
)

from screwkit.constants import STANDARD_GRAVITY
from screwkit.errors import InputTypeError, ScrewkitError, did_you_mean
from screwkit.io.errors import SpecError
from screwkit.io.toml_file import SpecFileError, read_toml
from screwkit.io.units import KIND_UNITS, UnitError, check_unit, to_si
from screwkit.io.validation import Name, refuse_formula, validation_lines
from screwkit.kinematics.registry import family, require
from screwkit.messages import listing, message_units
from screwkit.model.linkage import Link, Linkage, LinkageError

if TYPE_CHECKING:
    from screwkit.balancing.config import BalancingConfig
    from screwkit.io.display_units import DisplayUnits
    from screwkit.io.drive_table import DriveConfig
    from screwkit.kinematics.analysis.coupler_curves import CouplerPoint
    from screwkit.kinematics.analysis.limit_positions import LimitsConfig
    from screwkit.synthesis.config import SynthesisConfig

Value = StrictFloat | StrictInt | StrictStr  # strict: a TOML true is not the number 1
Number = StrictFloat | StrictInt


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class MechanismTable(_Strict):
    family: str
    name: str | None = None
    source: str | None = Field(None, description="where the example comes from (seed, section)")
    description: str | None = None

    @field_validator("family")
    @classmethod
    def _family(cls, v: str) -> str:
        return family(v).name


class MotionTable(_Strict):
    start: Value = 0.0
    stop: Value = 360.0
    step: Value = 10.0
    speed: Value = Field(1.0, description="input speed (angular velocity for a crank)")
    acceleration: Value = 0.0
    periodic: StrictBool | None = Field(None, description="drop the stop sample when it repeats the start")
    mode: StrictInt = Field(0, ge=0, le=10_000, description="assembly mode used by dynamics and balancing")


class JointTable(_Strict):
    name: Name
    kind: Literal["R", "P", "C", "H", "U", "S"]
    length: Value = 0.0
    twist: Value = 0.0
    offset: Value = 0.0
    pitch: Value = 0.0
    input: StrictBool = False


class LinkMassTable(_Strict):
    mass: Value | None = None
    weight: Value | None = None
    com: list[Value] = Field(default_factory=lambda: [0.0, 0.0, 0.0])  # type: ignore[arg-type]
    inertia: list[Value] | list[list[Value]] | None = None
    principal_axes: list[list[Number]] | None = None


class CouplerPointTable(_Strict):
    name: Annotated[StrictStr, AfterValidator(refuse_formula)] | None = Field(None, max_length=80)
    link: Annotated[StrictStr, AfterValidator(refuse_formula)] | None = Field(
        None, description="moving link (default: the family's coupler)")
    f: Value = 0.0
    g: Value = 0.0
    h: Value = 0.0


class LimitsTable(_Strict):
    output: StrictStr | None = None
    dwell_tolerance: Number = 1e-6
    max_order: StrictInt = Field(5, ge=1, le=10)
    at: list[Value] = Field(default_factory=list, max_length=1000)
    method: Literal["auto", "closed", "generic"] = "auto"


class SpecFile(_Strict):
    mechanism: MechanismTable
    units: dict[str, str] = Field(default_factory=dict)
    dimensions: dict[str, Value] = Field(default_factory=dict)
    joints: list[JointTable] = Field(default_factory=list)
    motion: MotionTable = Field(default_factory=MotionTable)  # type: ignore[arg-type]
    links: dict[Name, LinkMassTable] = Field(default_factory=dict)
    coupler_point: CouplerPointTable | None = None
    coupler_points: list[CouplerPointTable] = Field(default_factory=list, max_length=100)
    limits: LimitsTable | None = None
    gravity: Value | None = None
    gravity_direction: list[Number] = Field(default_factory=lambda: [0.0, 0.0, -1.0])
    balancing: dict[str, Any] | None = None
    synthesis: dict[str, Any] | None = None
    drive: dict[str, Any] | None = None
    tolerances: dict[str, StrictStr] | None = None  # read by `screwkit tolerance`


class Spec:
    """A validated spec file, converted to SI units (docs/spec-format.md).

    Attributes: ``path``, ``name``, ``family``, ``source``, ``units`` (the ``[units]`` table),
    ``dimensions`` (SI), ``inputs`` (N,) input samples (rad or m), ``speed`` and
    ``acceleration`` of the input, ``mode`` (the assembly mode dynamics and balancing use),
    ``gravity_magnitude``, ``gravity_direction``, ``coupler_points`` (every
    :class:`~screwkit.kinematics.analysis.coupler_curves.CouplerPoint` of ``[coupler_point]`` and
    ``[[coupler_points]]``), ``coupler_point`` (the ``[coupler_point]`` table's (f, g, h), m);
    the property ``linkage`` is the mechanism model (a :class:`~screwkit.model.Linkage`, built
    once at load); ``balancing``, ``synthesis`` and ``limits`` are the ``[balancing]``,
    ``[synthesis]`` and ``[limits]`` tables as typed configs
    (:class:`~screwkit.balancing.config.BalancingConfig`,
    :class:`~screwkit.synthesis.config.SynthesisConfig`,
    :class:`~screwkit.kinematics.analysis.limit_positions.LimitsConfig`), or ``None``; ``drive`` the
    ``[drive]`` table of ``screwkit simulate`` (:class:`~screwkit.io.drive_table.DriveConfig`),
    or ``None``.
    """

    def __init__(self, raw: SpecFile, path: str) -> None:
        self.raw = raw
        self.path = path
        self.family = raw.mechanism.family
        self.name = raw.mechanism.name or Path(path).stem
        self.source = raw.mechanism.source
        self.units = dict(raw.units)
        for kind, unit in self.units.items():
            if kind not in KIND_UNITS or kind == "dimensionless":
                kinds = ", ".join(k for k in KIND_UNITS if k != "dimensionless")
                hint = did_you_mean(kind, [k for k in KIND_UNITS if k != "dimensionless"])
                self._fail(f"units.{kind}", f"unknown kind {kind!r}; {hint}the kinds are {kinds}")
            try:
                check_unit(unit, kind)
            except UnitError as exc:
                self._fail(f"units.{kind}", str(exc))
        self.dimensions = self._dimensions()
        self.inputs = self._input_samples()
        self.speed = self.quantity(raw.motion.speed, self._rate_kind(), "motion.speed")
        self.acceleration = self.quantity(raw.motion.acceleration, self._rate_kind(2), "motion.acceleration")
        self.mode = raw.motion.mode
        self.gravity_magnitude = (
            None if raw.gravity is None else self.quantity(raw.gravity, "acceleration", "gravity")
        )
        if self.gravity_magnitude is not None and not self.gravity_magnitude > 0:
            self._fail("gravity", f"gravity must be a positive acceleration (it turns weights into "
                                  f"masses and sets the weight loads); got {raw.gravity!r}")
        gd = np.asarray(raw.gravity_direction, dtype=float)
        if gd.shape != (3,) or not np.all(np.isfinite(gd)) or np.linalg.norm(gd) == 0:
            self._fail("gravity_direction", f"give a non-zero world vector [x, y, z]; got {raw.gravity_direction}")
        self.gravity_direction = gd / np.linalg.norm(gd)
        self._linkage = self._build()
        self.coupler_point: tuple[float, float, float] | None = None
        self.coupler_points = self._coupler_points()
        if raw.coupler_point is not None:
            self.coupler_point = self.coupler_points[0].point
        self.limits = self._limits()
        self.balancing: BalancingConfig | None = None
        self.synthesis: SynthesisConfig | None = None
        if raw.balancing is not None:
            from screwkit.io.balancing_table import balancing_config

            self.balancing = balancing_config(self)
        if raw.synthesis is not None:
            from screwkit.io.synthesis_table import synthesis_config

            self.synthesis = synthesis_config(self)
        self.drive: DriveConfig | None = None
        if raw.drive is not None:
            from screwkit.io.drive_table import drive_config

            self.drive = drive_config(self)

    # --- helpers ---------------------------------------------------------------------------
    def _coupler_points(self) -> list[CouplerPoint]:
        """``[coupler_point]`` and ``[[coupler_points]]`` as coupler points of the linkage."""
        from screwkit.kinematics.analysis.coupler_curves import coupler_point
        from screwkit.kinematics.registry import coupler_link_index

        tables = [("coupler_point", self.raw.coupler_point, "coupler point")] if (
            self.raw.coupler_point is not None) else []
        tables += [(f"coupler_points[{k}]", t, f"point {k + 1}")
                   for k, t in enumerate(self.raw.coupler_points)]
        out: list[CouplerPoint] = []
        for key, t, default in tables:
            assert t is not None
            try:
                require(family(self.family), "coupler_point")
            except ValueError as exc:
                self._fail(key, str(exc))
            xyz = [self.quantity(getattr(t, c), "length", f"{key}.{c}") for c in "fgh"]
            name = t.name or default
            if any(p.name == name for p in out):
                self._fail(f"{key}.name", f"the name {name!r} is used twice; give each point "
                                          "its own name")
            try:
                coupler_link_index(self._linkage, t.link)
            except ScrewkitError as exc:
                self._fail(f"{key}.link", str(exc))
            try:
                out.append(coupler_point(self._linkage, xyz, t.link, name))
            except ValueError as exc:
                self._fail(key, str(exc))
        return out

    def _limits(self) -> LimitsConfig | None:
        """``[limits]`` as a :class:`LimitsConfig`, checked against the loop (the output names
        a variable it has; the closed form is there when asked for)."""
        t = self.raw.limits
        if t is None:
            return None
        from screwkit.kinematics.analysis.limit_positions import LimitsConfig, check_limits_config

        kind = "angle" if self.input_is_angle else "length"
        at = tuple(self.quantity(v, kind, "limits.at") for v in t.at)
        config = LimitsConfig(t.output, float(t.dwell_tolerance), t.max_order, at, t.method)
        try:
            check_limits_config(self._linkage, config)
        except ScrewkitError as exc:
            self._fail("limits", str(exc))
        return config

    def _fail(self, key: str, message: str) -> None:
        raise SpecError(f"{self.path}: [{key}] {message}")

    def _default_unit(self, kind: str) -> str | None:
        return self.units.get(kind)

    def quantity(self, value: Any, kind: str, key: str) -> float:
        """``value`` (a number in the spec's ``[units]`` for ``kind``, or a string with its
        unit) in SI units; a :class:`SpecError` naming ``key`` if it cannot be."""
        try:
            return to_si(value, kind, self._default_unit(kind))
        except UnitError as exc:
            self._fail(key, str(exc))
        raise AssertionError  # unreachable

    def _rate_kind(self, order: int = 1) -> str:
        base = ("angle" if family(self.family).build is not None or self._loop_input_is_angle()
                else "length")
        if base == "angle":
            return "angular_velocity" if order == 1 else "angular_acceleration"
        return "velocity" if order == 1 else "acceleration"

    def _loop_input_is_angle(self) -> bool:
        ins = [j for j in self.raw.joints if j.input]
        return not ins or ins[0].kind != "P"

    def _dimensions(self) -> dict[str, float]:
        if family(self.family).build is None:  # a joint list (LOOP)
            if self.raw.dimensions:
                self._fail("dimensions", "a LOOP family takes its geometry from [[joints]]; remove [dimensions]")
            return {}
        fam = family(self.family)
        wanted = fam.dimensions
        unknown = sorted(set(self.raw.dimensions) - set(wanted))
        if unknown:
            self._fail("dimensions", f"unknown key(s) {listing(unknown)} for a {self.family}; "
                                     f"expected {listing(sorted(wanted))}")
        missing = sorted(set(wanted) - set(self.raw.dimensions) - set(fam.optional))
        if missing:
            self._fail("dimensions", f"missing {listing(missing)} for a {self.family} "
                                     "(e.g. d1 = \"2.0 in\")")
        return {k: self.quantity(v, wanted[k], f"dimensions.{k}") for k, v in self.raw.dimensions.items()}

    def _input_samples(self) -> np.ndarray:
        m = self.raw.motion
        kind = "angle" if self._rate_kind() == "angular_velocity" else "length"
        if kind == "length":
            missing = [k for k in ("start", "stop", "step") if k not in m.model_fields_set]
            if missing:
                self._fail("motion", f"the input is a translation: give {listing(missing)} as lengths "
                                     f"(e.g. start = \"0 mm\", stop = \"50 mm\", step = \"1 mm\")")
        start = self.quantity(m.start, kind, "motion.start")
        stop = self.quantity(m.stop, kind, "motion.stop")
        step = self.quantity(m.step, kind, "motion.step")
        if step <= 0:
            self._fail("motion.step", f"the step must be positive; got {m.step!r}")
        if stop < start:
            self._fail("motion.stop", f"stop ({m.stop!r}) must not be below start ({m.start!r})")
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        if n > 10_000_000:
            self._fail("motion.step", f"{n} samples is too many; use a larger step")
        x = start + step * np.arange(n)
        periodic = m.periodic
        if periodic is None:
            periodic = kind == "angle" and abs((stop - start) - 2 * math.pi) < 1e-9
        if periodic and n > 1 and abs(x[-1] - (start + 2 * math.pi)) < 1e-9:
            x = x[:-1]  # 0° and 360° are the same sample: count it once
        return x

    def _masses(self, link_names: list[str]) -> list[Link]:
        from screwkit.model.mass import MassProperties

        unknown = sorted(set(self.raw.links) - set(link_names))
        if unknown:
            self._fail("links", f"no link named {listing(unknown, 'or')} in a {self.family}; "
                                f"the links are {listing(link_names)}")
        g = self.gravity_magnitude if self.gravity_magnitude is not None else STANDARD_GRAVITY
        # (gravity > 0 is checked at load)
        out = []
        for name in link_names:
            t = self.raw.links.get(name)
            if t is None:
                out.append(Link(name))
                continue
            key = f"links.{name}"
            if (t.mass is None) == (t.weight is None):
                self._fail(key, "give exactly one of mass (e.g. \"0.86 kg\") or weight (e.g. \"1.9 lbf\")")
            mass = (self.quantity(t.mass, "mass", key + ".mass") if t.mass is not None
                    else self.quantity(t.weight, "force", key + ".weight") / g)
            if len(t.com) != 3:
                self._fail(key + ".com", f"give 3 coordinates; got {len(t.com)}")
            com = [self.quantity(v, "length", f"{key}.com") for v in t.com]
            if t.inertia is None:
                self._fail(key + ".inertia", "give the principal moments [Ixx, Iyy, Izz] or a 3×3 tensor about the CoM")
            inertia = t.inertia
            try:
                if inertia and isinstance(inertia[0], list):
                    if len(inertia) != 3 or any(not isinstance(r, list) or len(r) != 3 for r in inertia):
                        self._fail(key + ".inertia", "a full inertia tensor is 3 rows of 3 numbers "
                                   "(about the CoM, link axes); or give the 3 principal moments")
                    I = np.array([[self.quantity(v, "inertia", f"{key}.inertia") for v in row] for row in inertia])  # type: ignore[union-attr]
                    props = MassProperties(mass, np.array(com), I)
                else:
                    moments = [self.quantity(v, "inertia", f"{key}.inertia") for v in inertia]  # type: ignore[union-attr]
                    if len(moments) != 3:
                        self._fail(key + ".inertia", f"give 3 principal moments; got {len(moments)}")
                    props = MassProperties.from_principal(mass, np.array(com), np.array(moments), t.principal_axes)
            except SpecError:
                raise
            except ValueError as exc:
                self._fail(key, str(exc))
            out.append(Link(name, props))
        return out

    def _build(self) -> Linkage:
        fam = family(self.family)
        try:
            lk = fam.linkage(**self.dimensions) if fam.build is not None else self._loop()
        except LinkageError as exc:
            self._fail("dimensions" if fam.build is not None else "joints", str(exc))
        if self.raw.links:
            lk = lk.with_links(self._masses([link.name for link in lk.links]))
        return lk

    def _loop(self) -> Linkage:
        from screwkit.model.joints import Joint

        if len(self.raw.joints) < 2:
            self._fail("joints", "a LOOP needs a [[joints]] list of at least 2 joints")
        joints, lengths, twists, inputs = [], [], [], []
        for k, j in enumerate(self.raw.joints):
            key = f"joints[{k}]"
            off_kind = "angle" if j.kind == "P" else "length"
            if j.kind == "C" and j.offset not in (0, 0.0, "0"):
                self._fail(f"{key}.offset", "a C joint has no constant offset (both its rotation "
                                           "and its translation are variables); remove offset")
            try:
                joints.append(Joint(j.name, j.kind, self.quantity(j.offset, off_kind, key + ".offset"),
                                    self.quantity(j.pitch, "length", key + ".pitch")))
            except ValueError as exc:
                self._fail(key, str(exc))
            lengths.append(self.quantity(j.length, "length", key + ".length"))
            twists.append(self.quantity(j.twist, "angle", key + ".twist"))
            if j.input:
                inputs.append(f"{j.name}.{joints[-1].freedoms[0]}")
        if len(inputs) != 1:
            self._fail("joints", f"mark exactly one joint with input = true; {len(inputs)} marked")
        return Linkage.from_hartenberg_denavit(self.name, joints, lengths, twists, inputs, family=None)

    # --- public ------------------------------------------------------------------------------
    @property
    def linkage(self) -> Linkage:
        """The mechanism model (read only; built once when the spec is loaded)."""
        return self._linkage

    def display_units(self, system: str = "spec", overrides: dict[str, str] | None = None
                      ) -> DisplayUnits:
        """The units tables, CSV and plots show this spec's results in: its ``[units]``
        (``system="spec"``) or SI (``"si"``), with per-kind ``overrides``
        (:func:`screwkit.io.display_units.display_units`)."""
        from screwkit.io.display_units import display_units

        return display_units(self.units, system=system, overrides=overrides)

    def describe(self, units: DisplayUnits | None = None) -> str:
        """One line: name, family, dimensions and input span in ``units`` (default: the
        spec's own [units])."""
        du = units if units is not None else self.display_units()
        lk = self._linkage
        kinds = family(self.family).dimensions
        dims = ", ".join(f"{k}={du.show(kinds[k], v):.6g} {du.label(kinds[k])}"
                         for k, v in self.dimensions.items())
        n = len(self.inputs)
        joints = "".join(j.kind for j in lk.joints)
        src = f" — source: {self.source}" if self.source else ""
        kind = "angle" if self.input_is_angle else "length"
        span = (f"{du.show(kind, self.inputs[0]):.6g}…{du.show(kind, self.inputs[-1]):.6g} "
                f"{du.label(kind)}")
        head = f"{self.name}: {self.family} ({joints})" + (f" {dims}" if dims else "")
        return f"{head}; {n} input samples {span}{src}"

    def jobs(self) -> list[str]:
        """The jobs this spec asks for, each checked at load against what its family offers
        (the registry's capabilities): what ``screwkit demo`` runs on it."""
        from screwkit.kinematics.analysis.limit_positions import uses_closed_form

        out = ["analyze" + (f" ({len(self.coupler_points)} coupler point(s))"
                            if self.coupler_points else ""), "mobility"]
        if all(link.mass is not None for link in self._linkage.links):
            out.append("dynamics")
        if self.balancing is not None:
            out.append("balance")
        if self.synthesis is not None:
            out.append(f"synthesize ({self.synthesis.route} route)")
        if self.limits is not None:
            closed = uses_closed_form(self._linkage, self.limits.output, self.limits.method)
            out.append(f"limits ({'closed' if closed else 'generic'} route)")
        if self.drive is not None:
            out.append("simulate")
        return out

    @property
    def input_is_angle(self) -> bool:
        """Whether the driven freedom is a rotation (else a translation, in metres)."""
        return self._rate_kind() == "angular_velocity"


def _format_validation(path: str, exc: ValidationError) -> str:
    return "\n".join([f"{path}: the spec file is not valid:", *validation_lines(exc)])


MechanismSpec = Spec  # the name used before the front door


def load_spec(path: str | Path) -> Spec:
    """Read and validate a spec file (TOML with units; docs/spec-format.md) into a :class:`Spec`
    in SI units, with its mechanism model and its ``[balancing]``/``[synthesis]`` tables parsed;
    raises :class:`SpecError` naming the file, the key and a fix."""
    if not isinstance(path, str | os.PathLike) or not isinstance(os.fspath(path), str):
        raise InputTypeError(f"load_spec: path must be a file name (a str or pathlib.Path); "
                             f"got {type(path).__name__}")
    p = Path(path)
    try:
        data = read_toml(p)  # size, encoding, nesting and string-length checks
    except SpecFileError as exc:
        raise SpecError(str(exc)) from None
    from screwkit.io.spec_kind import is_graph_spec

    if is_graph_spec(data):  # the graph model is imported for graph specs only
        from screwkit.io.mechanism_spec import graph_spec_from_data

        return graph_spec_from_data(data, p)  # type: ignore[return-value]
    return spec_from_data(data, p)


def spec_from_data(data: dict[str, Any], path: str | Path) -> Spec:
    """A :class:`Spec` from the parsed TOML tables of a spec file (what :func:`load_spec` reads
    from ``path``), validated exactly as :func:`load_spec` does; ``path`` names the file in
    messages. Design sweeps use it to load a spec whose values were replaced."""
    try:
        raw = SpecFile.model_validate(data)
    except ValidationError as exc:
        raise SpecError(_format_validation(str(path), exc)) from exc
    with message_units(_units_of(raw)):  # messages about the model in the spec's units
        return Spec(raw, str(path))


def _units_of(raw: SpecFile) -> DisplayUnits | None:
    """The display units of a validated spec's ``[units]`` for its messages; None where the
    table is wrong (then the spec's own check reports it)."""
    from screwkit.io.display_units import display_units

    try:
        return display_units(raw.units)
    except ScrewkitError:
        return None

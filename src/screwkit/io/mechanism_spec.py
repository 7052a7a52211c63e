"""Graph spec files: any mechanism, placed by world coordinates in one drawn configuration.

A spec is a graph spec when it has ``[[bodies]]`` or joints with ``between`` (docs/mechanisms.md);
``[mechanism]`` then holds no ``family``. Every length is in ``[units] length`` (or a string with
its unit), every angle in ``[units] angle``; inputs are measured from the drawing. The file
becomes a :class:`GraphSpec` in SI with its :class:`~screwkit.model.mechanism.Mechanism`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    StrictFloat,
    StrictInt,
    StrictStr,
    ValidationError,
)

from screwkit.errors import ScrewkitError
from screwkit.io.display_units import DisplayUnits, display_units
from screwkit.io.errors import SpecError
from screwkit.io.spec_kind import is_graph_spec as is_graph_spec  # re-exported (sweep, studio)
from screwkit.io.units import KIND_UNITS, UnitError, check_unit, to_si
from screwkit.io.validation import validation_lines
from screwkit.messages import listing
from screwkit.model.mass import MassProperties
from screwkit.model.mechanism import (
    MAX_BODIES,
    MAX_JOINTS,
    Body,
    BodyPoint,
    Mechanism,
    MechanismJoint,
)
from screwkit.model.mechanism_drives import DRIVE_FREEDOMS, BodyDrive
from screwkit.model.mechanism_outputs import BodyAngle, Output, PointTravel

if TYPE_CHECKING:
    from screwkit.balancing.config import BalancingConfig
    from screwkit.synthesis.graph_route import GraphSynthesisProblem

Value = StrictFloat | StrictInt | StrictStr
MAX_ROWS = 10_000_000


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class GraphMechanismTable(_Strict):
    name: StrictStr | None = Field(None, max_length=200)
    source: StrictStr | None = None
    description: StrictStr | None = None


class BodyTable(_Strict):
    name: StrictStr = Field(max_length=80)
    mass: Value | None = None
    com: list[Value] | None = Field(None, min_length=3, max_length=3)
    inertia: list[list[Value]] | None = None


class GraphJointTable(_Strict):
    name: StrictStr = Field(max_length=80)
    kind: Literal["R", "P", "C", "H", "U", "S"]
    between: list[StrictStr] = Field(min_length=2, max_length=2)
    at: list[Value] = Field(min_length=3, max_length=3)
    axis: list[Value] | None = Field(None, min_length=3, max_length=3)
    axis2: list[Value] | None = Field(None, min_length=3, max_length=3)
    pitch: Value = 0.0
    input: StrictBool | StrictStr = False
    actuated: StrictBool | StrictStr = False


class PointTable(_Strict):
    name: StrictStr = Field(max_length=80)
    body: StrictStr
    at: list[Value] = Field(min_length=3, max_length=3)


class OutputTable(_Strict):
    name: StrictStr = Field(max_length=80)
    body: StrictStr | None = None
    vector: list[StrictFloat | StrictInt] | None = Field(None, min_length=3, max_length=3)
    about: list[StrictFloat | StrictInt] | None = Field(None, min_length=3, max_length=3)
    point: StrictStr | None = None
    along: list[StrictFloat | StrictInt] | None = Field(None, min_length=3, max_length=3)


class DriveTable(_Strict):
    body: StrictStr | None = None
    freedom: Literal["x", "y", "z", "roll", "pitch", "yaw"]
    at: list[Value] | None = Field(None, min_length=3, max_length=3)
    point: StrictStr | None = None


class GraphMotionTable(_Strict):
    start: Value = 0.0
    stop: Value | None = None
    step: Value | None = None
    rows: list[list[Value]] | None = Field(None, max_length=100_000)
    speed: Value | list[Value] = 1.0
    acceleration: Value | list[Value] = 0.0


class GraphSpecFile(_Strict):
    mechanism: GraphMechanismTable = Field(default_factory=GraphMechanismTable)  # type: ignore[arg-type]
    units: dict[str, str] = Field(default_factory=dict)
    bodies: list[BodyTable] = Field(default_factory=list, max_length=MAX_BODIES + 1)
    joints: list[GraphJointTable] = Field(max_length=MAX_JOINTS + 1)
    points: list[PointTable] = Field(default_factory=list, max_length=1000)
    outputs: list[OutputTable] = Field(default_factory=list, max_length=100)
    drives: list[DriveTable] = Field(default_factory=list, max_length=100)
    motion: GraphMotionTable = Field(default_factory=GraphMotionTable)  # type: ignore[arg-type]
    gravity: Value | None = None
    gravity_direction: list[StrictFloat | StrictInt] = Field(
        default_factory=lambda: [0.0, 0.0, -1.0])
    tolerances: dict[str, StrictStr] | None = None  # read by `screwkit tolerance`
    balancing: dict[str, Any] | None = None
    drive: dict[str, Any] | None = None  # checked by io/graph_drive.py when simulating
    synthesis: dict[str, Any] | None = None  # io/graph_synthesis_table.py


class GraphSpec:
    """A validated graph spec in SI: ``mechanism``, ``inputs`` (N, n_in) measured from the
    drawing, ``speed`` and ``acceleration`` of the inputs, ``units``, ``gravity_vector``."""

    family = "graph"

    def __init__(self, raw: GraphSpecFile, path: str) -> None:
        self.raw = raw
        self.path = path
        self.name = raw.mechanism.name or Path(path).stem
        self.source = raw.mechanism.source
        self.units = dict(raw.units)
        for kind, unit in self.units.items():
            if kind not in KIND_UNITS or kind == "dimensionless":
                self._fail(f"units.{kind}", f"unknown kind {kind!r}; the kinds are "
                           + ", ".join(k for k in KIND_UNITS if k != "dimensionless"))
            try:
                check_unit(unit, kind)
            except UnitError as exc:
                self._fail(f"units.{kind}", str(exc))
        self.mode = 0
        self.mechanism = self._mechanism()
        self.inputs = self._inputs()
        kinds = [self._input_kind(k) for k in range(len(self.mechanism.driven_names))]
        rate = {"angle": "angular_velocity", "length": "velocity"}
        accel = {"angle": "angular_acceleration", "length": "acceleration"}
        self.speed = np.array([self.quantity(v, rate[k], f"motion.speed{at}") for k, v, at
                               in self._per_input(raw.motion.speed, kinds, "speed")])
        self.acceleration = np.array([self.quantity(v, accel[k], f"motion.acceleration{at}")
                                      for k, v, at in self._per_input(
                                          raw.motion.acceleration, kinds, "acceleration")])
        g = 9.80665 if raw.gravity is None else self.quantity(raw.gravity, "acceleration",
                                                              "gravity")
        d = np.asarray(raw.gravity_direction, dtype=float)
        if d.shape != (3,) or not np.linalg.norm(d) > 0:
            self._fail("gravity_direction", f"give a non-zero vector [x, y, z]; got {d.tolist()}")
        self.gravity_vector = g * d / np.linalg.norm(d)
        from screwkit.kinematics.graph.topology import mechanism_topology

        self.topology = mechanism_topology(self.mechanism)
        if self.mechanism.drives and not self.topology.as_dict()["drives"]:
            self._fail("drives", self.topology.verdict)
        if self.topology.free or "conflict" in self.topology.verdict:
            self._fail("joints", f"{self.topology.verdict} (mark input = true on as many "
                                 "joints as the mechanism has freedoms)")
        self.balancing: BalancingConfig | None = None
        if raw.balancing is not None:  # the form single loops use, bodies for links
            from screwkit.io.balancing_table import balancing_config

            self.balancing = balancing_config(self)

        from screwkit.io.graph_drive import GraphDriveConfig, graph_drive_config

        #: the ``[drive]`` table of ``screwkit simulate`` (io/graph_drive.py), checked here so
        #: that ``validate`` reports what ``simulate`` would refuse
        self.drive: GraphDriveConfig | None = (graph_drive_config(self) if raw.drive is not None
                                               else None)
        from screwkit.io.graph_synthesis_table import graph_synthesis_problem

        #: the ``[synthesis]`` table (docs/synthesis.md, "Graphs"), checked at load
        self.synthesis: GraphSynthesisProblem | None = (
            graph_synthesis_problem(self, raw.synthesis) if raw.synthesis is not None else None)

    def _per_input(self, value: Any, kinds: list[str], key: str) -> list[tuple[str, Any, str]]:
        """A rate for every input: one value for all, or a list of one per input."""
        if not isinstance(value, list):
            return [(k, value, "") for k in kinds]
        if len(value) != len(kinds):
            self._fail(f"motion.{key}", f"give one {key} for every driven freedom "
                       f"({len(kinds)}: {', '.join(self.mechanism.driven_names)}) or one for "
                       f"all; got {len(value)}")
        return [(k, v, f"[{i}]") for i, (k, v) in enumerate(zip(kinds, value, strict=True))]

    def describe(self, units: DisplayUnits | None = None) -> str:
        """One line: what the spec describes."""
        t = self.topology
        n = self.inputs.shape[0]
        return (f"{self.path}: {self.name}: {t.bodies} bodies, {t.joints} joints, "
                f"{len(t.loops)} loop(s); input {', '.join(self.mechanism.driven_names)}, "
                f"{n} samples")

    def jobs(self) -> list[str]:
        out = ["analyze", "mobility"]
        if all(b.mass is not None for b in self.mechanism.bodies):
            out.append("dynamics")
        if self.balancing is not None:
            out.append("balance")
        if self.synthesis is not None:
            out.append("synthesize")
        return out

    # --- helpers ---------------------------------------------------------------------------
    def _fail(self, key: str, message: str) -> None:
        raise SpecError(f"{self.path}: [{key}] {message}")

    def quantity(self, value: Any, kind: str, key: str) -> float:
        try:
            return to_si(value, kind, self.units.get(kind))
        except UnitError as exc:
            self._fail(key, str(exc))
        raise AssertionError  # unreachable

    def coordinate(self, value: Any, kind: str, key: str) -> float:
        """A coordinate, an inertia entry or an input measured from the drawing, in SI: like
        :meth:`quantity`, but a plain number whose size is below the smallest accepted (CAD's
        round-off, such as 1e-15 mm or a 1e-35 product of inertia) is 0, since such a value may
        be nought."""
        if isinstance(value, int | float) and not isinstance(value, bool):
            from screwkit.io.units import MAGNITUDE_LIMITS, unit_factor

            unit = self.units.get(kind)
            factor = unit_factor(unit, kind) if unit else 1.0
            if abs(value * factor) < MAGNITUDE_LIMITS[kind][1]:
                return 0.0
        return self.quantity(value, kind, key)

    def _vector(self, values: list[Any], kind: str, key: str) -> np.ndarray:
        return np.array([self.coordinate(v, kind, f"{key}[{k}]") for k, v in enumerate(values)])

    def _direction(self, values: list[Any], key: str) -> np.ndarray:
        try:
            v = np.array([float(x) for x in values])
        except (TypeError, ValueError):
            self._fail(key, f"an axis is three plain numbers (a direction has no unit); "
                            f"got {values!r}")
        if not np.all(np.isfinite(v)) or float(np.linalg.norm(v)) == 0.0:
            self._fail(key, f"the axis {values!r} has zero length; give a direction such as "
                            "[0, 0, 1]")
        return v / np.linalg.norm(v)

    def _mechanism(self) -> Mechanism:
        raw = self.raw
        if len(raw.bodies) > MAX_BODIES or len(raw.joints) > MAX_JOINTS:
            self._fail("bodies", f"{len(raw.bodies)} bodies and {len(raw.joints)} joints: at "
                                 f"most {MAX_BODIES} bodies and {MAX_JOINTS} joints")
        bodies = [Body(b.name, self._mass(b, k)) for k, b in enumerate(raw.bodies)]
        joints = []
        inputs = []
        for k, j in enumerate(raw.joints):
            key = f"joints.{k}"
            if j.kind == "S" and j.axis is not None:
                self._fail(f"{key}.axis", f"joint {j.name!r} is spherical: it has no axis; "
                                          "remove 'axis'")
            if j.kind != "S" and j.axis is None:
                self._fail(f"{key}.axis", f"joint {j.name!r} ({j.kind}) needs an axis, e.g. "
                                          "axis = [0, 0, 1]")
            if (j.axis2 is not None) != (j.kind == "U"):
                self._fail(f"{key}.axis2", f"joint {j.name!r}: 'axis2' is for U joints only, "
                                           "and a U joint needs it")
            axis = self._direction(j.axis, f"{key}.axis") if j.axis else np.array([0, 0, 1.0])
            axis2 = self._direction(j.axis2, f"{key}.axis2") if j.axis2 else None
            pitch = (self.quantity(j.pitch, "length", f"{key}.pitch") if j.kind == "H" else 0.0)
            at = self._vector(j.at, "length", f"{key}.at")
            joints.append(MechanismJoint(j.name, j.kind, (j.between[0], j.between[1]), at,
                                         axis, axis2, pitch))
            inputs.extend(self._joint_inputs(j, key))
        points = [BodyPoint(p.name, p.body, self._vector(p.at, "length", f"points.{k}.at"))
                  for k, p in enumerate(raw.points)]
        drives = [self._drive(d, k, points) for k, d in enumerate(raw.drives)]
        if not inputs and not drives:
            self._fail("joints", "nothing is driven: mark the driven joint with input = true, "
                                 "or drive a body's pose with [[drives]]")
        actuated = [f for k, j in enumerate(raw.joints)
                    for f in self._joint_inputs(j, f"joints.{k}", "actuated")]
        if drives and len(actuated) not in (0, len(drives)):
            self._fail("joints", f"{len(actuated)} actuated freedom(s) "
                       f"({', '.join(actuated)}) for {len(drives)} driven body freedom(s) in "
                       "[[drives]]: mark actuated = true on one joint freedom per driven body "
                       "freedom (the motors whose efforts the loads report)")
        if actuated and not drives:
            self._fail("joints", "actuated = true is for mechanisms driven by body freedoms "
                                 "([[drives]]); a joint input is actuated already")
        outputs = tuple(self._output(o, k) for k, o in enumerate(raw.outputs))
        try:
            return Mechanism(self.name, tuple(bodies), tuple(joints), tuple(inputs),
                             tuple(points), outputs=outputs, drives=tuple(drives),
                             actuated=tuple(actuated))
        except ScrewkitError as exc:
            raise SpecError(f"{self.path}: {exc}") from None

    def _output(self, o: OutputTable, k: int) -> Output:
        key = f"outputs.{k}"
        if o.body is not None:
            if o.vector is None or o.about is None or o.point or o.along:
                self._fail(key, f"output {o.name!r}: a body angle takes 'body', 'vector' (fixed "
                                "in the body, as drawn) and 'about' (a world axis)")
            return BodyAngle(o.name, o.body, self._direction(list(o.vector or []),
                                                              f"{key}.vector"),
                             self._direction(list(o.about or []), f"{key}.about"))
        if o.point is None or o.along is None or o.vector or o.about:
            self._fail(key, f"output {o.name!r}: give either body, vector and about (an angle) "
                            "or point and along (a travel)")
        assert o.point is not None and o.along is not None
        return PointTravel(o.name, o.point, self._direction(list(o.along), f"{key}.along"))

    def _drive(self, d: DriveTable, k: int, points: list[BodyPoint]) -> BodyDrive:
        key = f"drives.{k}"
        at = None if d.at is None else self._vector(d.at, "length", f"{key}.at")
        body = d.body
        if d.point is not None:
            found = [p for p in points if p.name == d.point]
            if not found:
                self._fail(f"{key}.point", f"no point {d.point!r}; the points are "
                           f"{[p.name for p in points]}")
            if at is not None or (body is not None and body != found[0].body):
                self._fail(key, f"point {d.point!r} is on {found[0].body!r}: give the point "
                                "alone (its body is known), or body and at")
            body, at = found[0].body, found[0].at
        if body is None:
            self._fail(f"{key}.body", "say which body's freedom is driven: body = \"<name>\"")
        assert body is not None
        if at is None and DRIVE_FREEDOMS[d.freedom]:
            self._fail(key, f"the travel {d.freedom!r} of {body!r} is measured at a point: "
                            "give at = [x, y, z] (where it is drawn) or point = \"<name>\"")
        return BodyDrive(f"{body}.{d.freedom}", body, d.freedom,
                         np.zeros(3) if at is None else at)

    def _joint_inputs(self, j: GraphJointTable, key: str, what: str = "input") -> list[str]:
        from screwkit.model.joints import JOINT_FREEDOMS

        value = j.input if what == "input" else j.actuated
        if value is False:
            return []
        freedoms = JOINT_FREEDOMS[j.kind]
        verb = "driven" if what == "input" else "actuated"
        if j.kind == "S":
            self._fail(f"{key}.{what}", f"joint {j.name!r} is spherical: its freedoms cannot be "
                                        f"{verb}; use an R, P, C, H or U joint")
        if value is True:
            if len(freedoms) > 1:
                self._fail(f"{key}.{what}", f"joint {j.name!r} ({j.kind}) has freedoms "
                                            f"{listing(freedoms)}: say which is {verb}, e.g. "
                                            f"{what} = {freedoms[0]!r}")
            return [f"{j.name}.{freedoms[0]}"]
        names = [x.strip() for x in str(value).split(",")]
        for n in names:
            if n not in freedoms:
                self._fail(f"{key}.{what}", f"joint {j.name!r} ({j.kind}) has no freedom "
                                            f"{n!r}; its freedoms are {listing(freedoms)}")
        return [f"{j.name}.{n}" for n in names]

    def _mass(self, b: BodyTable, k: int) -> MassProperties | None:
        key = f"bodies.{k}"
        if b.mass is None:
            if b.com is not None or b.inertia is not None:
                self._fail(f"{key}.mass", f"body {b.name!r} has 'com' or 'inertia' but no mass")
            return None
        mass = self.quantity(b.mass, "mass", f"{key}.mass")
        if b.com is None:  # the drawing's origin is no default for a body's centre of mass
            self._fail(f"{key}.com", f"body {b.name!r} has a mass: give its centre of mass in "
                                     "the drawing, com = [x, y, z]")
        com = self._vector(b.com or [], "length", f"{key}.com")
        if b.inertia is None:
            inertia = np.zeros((3, 3))
        else:
            if len(b.inertia) != 3 or any(len(r) != 3 for r in b.inertia):
                self._fail(f"{key}.inertia", "the inertia about the centre of mass is a 3×3 "
                                             "matrix [[Ixx, Ixy, Ixz], [..], [..]]")
            inertia = np.array([[self.coordinate(v, "inertia", f"{key}.inertia")
                                 for v in row] for row in b.inertia])
        try:
            return MassProperties(mass, com, inertia)
        except ScrewkitError as exc:
            self._fail(key, f"body {b.name!r}: {exc}")
        raise AssertionError  # unreachable

    def _input_kind(self, k: int) -> str:
        return "length" if self.mechanism.driven_is_translation()[k] else "angle"

    def _inputs(self) -> np.ndarray:
        m = self.raw.motion
        names = self.mechanism.driven_names
        n_in = len(names)
        kinds = [self._input_kind(k) for k in range(n_in)]
        if m.rows is not None:
            if m.stop is not None or m.step is not None:
                self._fail("motion", "give either rows or start/stop/step, not both")
            rows = []
            for r, row in enumerate(m.rows):
                if len(row) != n_in:
                    self._fail(f"motion.rows.{r}", f"each row gives one value per input "
                               f"({n_in}: {', '.join(names)}); got {len(row)}")
                rows.append([self.coordinate(v, kinds[c], f"motion.rows.{r}")
                             for c, v in enumerate(row)])
            if not rows:
                self._fail("motion.rows", "give at least one row")
            return np.array(rows, dtype=float)
        if n_in != 1:
            self._fail("motion", f"the mechanism has {n_in} inputs "
                                 f"({', '.join(names)}): give their values as "
                                 "rows = [[...], ...], one value per input")
        if m.stop is None or m.step is None:
            self._fail("motion", "give start, stop and step (measured from the drawing)")
        start = self.coordinate(m.start, kinds[0], "motion.start")
        stop = self.quantity(m.stop, kinds[0], "motion.stop")
        step = self.quantity(m.step, kinds[0], "motion.step")
        if not step > 0:
            self._fail("motion.step", f"the step must be positive; got {m.step!r}")
        if stop < start:
            self._fail("motion.stop", f"stop ({m.stop!r}) must not be below start ({m.start!r})")
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        if n > MAX_ROWS:
            self._fail("motion.step", f"{n} samples is too many; use a larger step")
        return (start + step * np.arange(n))[:, None]

    def display_units(self, system: str = "spec", overrides: dict[str, str] | None = None
                      ) -> DisplayUnits:
        return display_units(self.units, system=system, overrides=overrides)

    @property
    def input_is_angle(self) -> bool:
        return self._input_kind(0) == "angle"


def graph_spec_from_data(data: dict[str, Any], path: str | Path) -> GraphSpec:
    try:
        raw = GraphSpecFile.model_validate(data)
    except ValidationError as exc:
        raise SpecError("\n".join([f"{path}: the spec file is not valid:",
                                   *validation_lines(exc)])) from exc
    return GraphSpec(raw, str(path))

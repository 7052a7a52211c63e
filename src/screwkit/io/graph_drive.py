"""The ``[drive]`` table of a mechanism-graph spec: what ``screwkit simulate`` needs to run any
mechanism (docs/simulation.md, "Graphs"), validated with pydantic and turned, once, into a typed
:class:`GraphDriveConfig` in SI units.

    [drive]
    duration = "2 s"              # simulated time (required)
    samples = 201                 # reported samples at equal times
    initial_speed = "0 deg/s"     # every input's rate at the start, or { "OA.theta" = … }
    flywheel = 0                  # on every input, or { "OA.theta" = "0.01 kg*m^2" }
    gravity = true
    rtol = 1e-10
    [drive.motors."OA.theta"]     # one motor per driven input, the [drive.motor] of a loop
    kind = "constant"
    torque = "0.05 N*m"
    [drive.motors."leg1.s"]       # a linear (force) motor on a slide input: N and m/s
    kind = "linear"
    stall_force = "200 N"
    no_load_speed = "0.5 m/s"
    [drive.load]                  # a load on any joint freedom (the loop's [drive.load])
    freedom = "slider.s"
    force = "40 N"
    damping = "2 N*s/m"
    [drive.point_force]           # a constant force (world axes) at a named body point
    point = "P"
    force = ["0 N", "-20 N", "0 N"]
    [drive.friction]              # joint -> viscous coefficient, or { rotation, translation }
    OB = "1e-4 N*m*s/rad"

The run starts at the first ``[motion]`` row (measured from the drawing)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

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

from screwkit.io.drive_table import (
    DriveConfigError,
    FrictionTable,
    JointFriction,
    LoadConfig,
    LoadTable,
    MotorConfig,
    MotorTable,
    Value,
    load_config,
    motor_config,
    split_friction,
)
from screwkit.io.validation import validation_lines
from screwkit.messages import listing


class PointForceTable(BaseModel):
    model_config = ConfigDict(extra="forbid")
    point: StrictStr
    force: list[Value] = Field(min_length=3, max_length=3)


class GraphDriveTable(BaseModel):
    model_config = ConfigDict(extra="forbid")
    duration: Value
    samples: StrictInt = Field(201, ge=2, le=100_000)
    initial_speed: Value | dict[StrictStr, Value] = 0.0
    flywheel: Value | dict[StrictStr, Value] = 0.0
    motors: dict[StrictStr, MotorTable] = Field(default_factory=dict)
    load: LoadTable | None = None
    point_force: PointForceTable | None = None
    friction: dict[StrictStr, Value | FrictionTable] | None = None
    gravity: StrictBool = False
    rtol: StrictFloat = Field(1e-10, gt=0.0, lt=1e-2)
    atol: StrictFloat | None = Field(None, gt=0.0)


@dataclass(frozen=True)
class GraphDriveConfig:
    """The graph ``[drive]`` table in SI (module docstring): one motor, flywheel and initial
    rate per input, in input order."""

    duration: float
    samples: int
    initial_rates: tuple[float, ...]
    flywheel: tuple[float, ...]
    motors: tuple[MotorConfig, ...]
    friction: tuple[JointFriction, ...]
    gravity: bool
    rtol: float
    atol: float | None
    load: LoadConfig | None = None
    point_force: tuple[str, tuple[float, float, float]] | None = None


def _fail(spec: Any, key: str, message: str) -> None:
    raise DriveConfigError(f"{spec.path}: [drive.{key}] {message}")


def _per_input(spec: Any, value: Any, kind: Callable[[str], str], key: str
               ) -> tuple[float, ...]:
    """One SI value per input from a single value or an ``{input = value}`` table;
    ``kind(input)`` is the quantity kind of that input's value."""
    inputs = list(spec.mechanism.inputs)
    if not isinstance(value, dict):
        return tuple(spec.quantity(value, kind(name), f"drive.{key}") for name in inputs)
    unknown = sorted(set(value) - set(inputs))
    if unknown:
        _fail(spec, key, f"{listing(unknown)} are not inputs of {spec.name!r}; the inputs are "
                         f"{listing(inputs)}")
    return tuple(spec.quantity(value.get(name, 0.0), kind(name), f"drive.{key}.{name}")
                 for name in inputs)


def _friction(spec: Any, table: dict[str, Any] | None) -> tuple[JointFriction, ...]:
    joints = {j.name: j for j in spec.mechanism.joints}
    out = []
    for name, value in (table or {}).items():
        key = f"friction.{name}"
        if name not in joints:
            _fail(spec, key, f"no joint {name!r}; the joints are {listing(joints)}")
        rotation, translation = split_friction(spec, key, name, joints[name].kind, value)
        c_r = 0.0 if rotation is None else spec.quantity(rotation, "rotational_damping",
                                                         f"drive.{key}")
        c_t = 0.0 if translation is None else spec.quantity(translation,
                                                            "translational_damping",
                                                            f"drive.{key}")
        if c_r < 0 or c_t < 0:
            _fail(spec, key, "a viscous friction coefficient is >= 0")
        out.append(JointFriction(name, c_r, c_t))
    return tuple(out)


def graph_drive_config(spec: Any) -> GraphDriveConfig:
    """The ``[drive]`` table of a loaded graph spec as a typed, SI :class:`GraphDriveConfig`;
    a :class:`~screwkit.io.drive_table.DriveConfigError` naming the file and key otherwise."""
    raw = spec.raw.drive
    if getattr(spec, "drive", None) is not None:
        return spec.drive  # type: ignore[no-any-return]
    if raw is None:
        raise DriveConfigError(f"{spec.path}: no [drive] table; add one to simulate (duration, "
                               "motors, flywheel, friction; docs/simulation.md, \"Graphs\")")
    try:
        t = GraphDriveTable.model_validate(raw)
    except ValidationError as exc:
        lines = [f"{spec.path}: the [drive] table is not valid:"]
        lines += validation_lines(exc, "drive.", "docs/simulation.md")
        raise DriveConfigError("\n".join(lines)) from None
    inputs = list(spec.mechanism.inputs)
    motors = []
    for name in inputs:
        table = t.motors.get(name)
        motors.append(MotorConfig() if table is None else
                      motor_config(spec, table, f'motors."{name}"', slide=name.endswith(".s")))
    freedoms = [f for j in spec.mechanism.joints for f in j.freedom_names()]
    missing = sorted(set(t.motors) - set(freedoms))
    if missing:
        _fail(spec, "motors", f"a motor on {listing(missing)}: no such freedom in {spec.name!r}; "
                              f"motors drive its inputs {listing(inputs)}")
    unknown = sorted(set(t.motors) - set(inputs))
    if unknown:
        _fail(spec, "motors", f"a motor on {listing(unknown)}, which {'is' if len(unknown) == 1 else 'are'}"
                              f" not an input of {spec.name!r}: motors drive inputs, and the "
                              f"inputs are {listing(inputs)} (mark input = true on the joint to drive)")
    duration = spec.quantity(t.duration, "time", "drive.duration")
    if not duration > 0:
        _fail(spec, "duration", f"the simulated time must be positive; got {t.duration!r}")

    def rate(name: str) -> str:
        return "velocity" if name.endswith(".s") else "angular_velocity"

    def inertia(name: str) -> str:
        return "mass" if name.endswith(".s") else "inertia"

    flywheel = _per_input(spec, t.flywheel, inertia, "flywheel")
    if min(flywheel) < 0:
        _fail(spec, "flywheel", f"an inertia is >= 0; got {t.flywheel!r}")
    return GraphDriveConfig(duration, t.samples,
                            _per_input(spec, t.initial_speed, rate, "initial_speed"), flywheel,
                            tuple(motors), _friction(spec, t.friction), t.gravity, t.rtol,
                            t.atol, _load(spec, t.load), _point_force(spec, t.point_force))


def _point_force(spec: Any, t: PointForceTable | None
                 ) -> tuple[str, tuple[float, float, float]] | None:
    """``[drive.point_force]``: a named point of a moving body and a constant force (world
    axes, the spec's force unit)."""
    if t is None:
        return None
    points = {p.name: p for p in spec.mechanism.points}
    if t.point not in points:
        have = f"the points are {listing(sorted(points))}" if points else "it has no points"
        _fail(spec, "point_force.point", f"no point {t.point!r}; {have} (add a [[points]] "
                                         "entry on the body it is fixed to)")
    if points[t.point].body == "ground":
        _fail(spec, "point_force.point", f"{t.point!r} is on the ground, which does not move")
    x, y, z = (spec.quantity(v, "force", f"drive.point_force.force[{i}]")
               for i, v in enumerate(t.force))
    return t.point, (x, y, z)


def _load(spec: Any, t: LoadTable | None) -> LoadConfig | None:
    """The ``[drive.load]`` on a named freedom of any joint but a ball (whose three rotations
    are not freedoms one load can act on)."""
    if t is None:
        return None
    joints = {j.name: j for j in spec.mechanism.joints}
    freedoms = [f for j in spec.mechanism.joints if j.kind != "S" for f in j.freedom_names()]
    if t.freedom is None:
        _fail(spec, "load.freedom", f"name the freedom the load acts on, one of "
                                    f"{listing(freedoms, 'or')}")
    assert t.freedom is not None
    if t.freedom not in freedoms:
        joint = joints.get(t.freedom.split(".")[0])
        why = (f"{joint.name!r} is a ball joint, whose rotations take no single load"
               if joint is not None and joint.kind == "S" else "no such freedom")
        _fail(spec, "load.freedom", f"{t.freedom!r}: {why}; the loaded freedom is one of "
                                    f"{listing(freedoms, 'or')}")
    return load_config(spec, t, t.freedom)

"""The ``[drive]`` table of a spec file: the motor, the flywheel, the load on the output and the
integration settings of ``screwkit simulate`` (docs/simulation.md), validated with pydantic and
turned, once, into a typed :class:`DriveConfig` in SI units.

Quantities take the spec's ``[units]`` or explicit unit strings (``"5 N*m"``, ``"3000 rpm"``).
Every error names the file and the key (:class:`DriveConfigError`, a SpecError)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

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

from screwkit.io.errors import SpecError
from screwkit.io.validation import validation_lines
from screwkit.kinematics.tracker.rates import spin_links
from screwkit.messages import listing

Value = StrictFloat | StrictInt | StrictStr
MOTOR_KINDS = ("none", "constant", "linear", "table")


class DriveConfigError(SpecError):
    """A ``[drive]`` table that cannot be used; the message names the file and the key."""


@dataclass(frozen=True)
class MotorConfig:
    """The motor on the input shaft (SI): ``kind`` ``"none"`` (no torque), ``"constant"``
    (``torque``), ``"linear"`` (τ = ``stall_torque``·(1 − ω/``no_load_speed``), the DC-motor
    line) or ``"table"`` (τ(ω) linear between the points ``speeds``/``torques``, held at the
    end values outside them)."""

    kind: str = "none"
    torque: float = 0.0
    stall_torque: float = 0.0
    no_load_speed: float = 0.0
    speeds: tuple[float, ...] = ()
    torques: tuple[float, ...] = ()


@dataclass(frozen=True)
class LoadConfig:
    """The load on one freedom of the output (SI): a torque (N·m) on a rotation or a force (N)
    on a translation, ``constant`` + ``damping``·q̇ in magnitude. With ``against_motion`` the
    constant part always opposes the output's motion (a resisting, Coulomb-like load);
    otherwise it acts in the freedom's negative direction whatever the motion. The damping part
    always opposes the motion."""

    freedom: str
    constant: float = 0.0
    damping: float = 0.0
    against_motion: bool = True


@dataclass(frozen=True)
class JointFriction:
    """Viscous friction in one joint (SI): ``rotation`` (N·m·s/rad) resists the relative angular
    velocity of the two links the joint joins (R, C, H, U, S joints: the moment −c ω_rel),
    ``translation`` (N·s/m) their relative sliding along the axis (P and C joints: the force
    −c ṡ u)."""

    joint: str
    rotation: float = 0.0
    translation: float = 0.0


@dataclass(frozen=True)
class DriveConfig:
    """The ``[drive]`` table in SI units (module docstring; docs/simulation.md)."""

    motor: MotorConfig
    load: LoadConfig | None
    flywheel: float  # kg·m² on the input shaft
    initial_speed: float  # rad/s
    cycles: int
    samples_per_cycle: int
    rtol: float
    atol: float | None  # rad and rad/s; None: rtol·(2π, initial speed)
    gravity: bool
    max_time: float | None  # s
    friction: tuple[JointFriction, ...] = ()  # viscous friction per joint


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class MotorTable(_Strict):
    kind: Literal["none", "constant", "linear", "table"] = "none"
    torque: Value | None = None
    stall_torque: Value | None = None
    no_load_speed: Value | None = None
    speeds: list[Value] | None = None
    torques: list[Value] | None = None
    # a linear (force) motor on a slide input of a mechanism graph (io/graph_drive.py)
    force: Value | None = None
    stall_force: Value | None = None
    forces: list[Value] | None = None


class LoadTable(_Strict):
    freedom: StrictStr | None = None
    torque: Value | None = None
    force: Value | None = None
    damping: Value | None = None
    against_motion: StrictBool = True


class FrictionTable(_Strict):
    rotation: Value | None = None
    translation: Value | None = None


class DriveTable(_Strict):
    motor: MotorTable = Field(default_factory=MotorTable)  # type: ignore[arg-type]
    load: LoadTable | None = None
    flywheel: Value = 0.0
    initial_speed: Value | None = None
    cycles: StrictInt = Field(10, ge=1, le=100_000)
    samples_per_cycle: StrictInt = Field(72, ge=8, le=4096)
    rtol: StrictFloat = Field(1e-9, gt=0.0, lt=1e-2)
    atol: StrictFloat | None = Field(None, gt=0.0)
    gravity: StrictBool = False
    max_time: Value | None = None
    friction: dict[StrictStr, Value | FrictionTable] | None = None


def _table(spec: Any) -> DriveTable:
    try:
        return DriveTable.model_validate(spec.raw.drive)
    except ValidationError as exc:
        lines = [f"{spec.path}: the [drive] table is not valid:"]
        lines += validation_lines(exc, "drive.", "docs/simulation.md")
        raise DriveConfigError("\n".join(lines)) from None


def _si(spec: Any, value: Any, kind: str, key: str) -> float:
    return float(spec.quantity(value, kind, f"drive.{key}"))


def _fail(spec: Any, key: str, message: str) -> None:
    raise DriveConfigError(f"{spec.path}: [drive.{key}] {message}")


#: the motor keys of a rotating input and of a slide (a force motor: N, m/s)
ROTARY_KEYS = {"torque": "torque", "stall_torque": "stall_torque", "torques": "torques"}
SLIDE_KEYS = {"torque": "force", "stall_torque": "stall_force", "torques": "forces"}


def motor_config(spec: Any, t: MotorTable, key: str = "motor", slide: bool = False
                 ) -> MotorConfig:
    """The motor of table ``t`` (at ``[drive.<key>]``) in SI. On a rotating input it reads
    torques (N·m) and speeds (rad/s); on a ``slide`` (a linear motor on a P joint's input of a
    mechanism graph) forces (N: ``force``, ``stall_force``, ``forces``) and speeds (m/s); the
    :class:`MotorConfig` fields keep their names (``torque`` is then the force)."""
    names = SLIDE_KEYS if slide else ROTARY_KEYS
    other = ROTARY_KEYS if slide else SLIDE_KEYS
    wrong = sorted(other[k] for k in other if getattr(t, other[k]) is not None
                   and other[k] != names[k])
    if wrong:
        what, right = (("a slide", "force, stall_force, forces") if slide
                       else ("a rotating input", "torque, stall_torque, torques"))
        _fail(spec, f"{key}.{wrong[0]}", f"the motor drives {what}: give {right}")
    torque, stall, torques = (getattr(t, names[k]) for k in ("torque", "stall_torque",
                                                               "torques"))
    need = {"constant": (names["torque"],), "linear": (names["stall_torque"], "no_load_speed"),
            "table": ("speeds", names["torques"]), "none": ()}[t.kind]
    given = {k for k in (*names.values(), "no_load_speed", "speeds") if getattr(t, k) is not None}
    for k in need:
        if k not in given:
            _fail(spec, f"{key}.{k}", f"a {t.kind} motor needs {' and '.join(need)}")
    extra = sorted(given - set(need))
    if extra:
        _fail(spec, key, f"{listing(extra)} do not apply to a {t.kind!r} motor (it reads "
                         f"{listing(need) if need else 'nothing'}); remove them or change kind")
    effort = "force" if slide else "torque"
    speed = "velocity" if slide else "angular_velocity"
    if t.kind == "constant":
        return MotorConfig("constant", torque=_si(spec, torque, effort,
                                                  f"{key}.{names['torque']}"))
    if t.kind == "linear":
        stall_si = _si(spec, stall, effort, f"{key}.{names['stall_torque']}")
        free = _si(spec, t.no_load_speed, speed, f"{key}.no_load_speed")
        if not free > 0:
            _fail(spec, f"{key}.no_load_speed", f"must be a positive speed; got "
                                               f"{t.no_load_speed!r}")
        return MotorConfig("linear", stall_torque=stall_si, no_load_speed=free)
    if t.kind == "table":
        speeds = [_si(spec, v, speed, f"{key}.speeds") for v in t.speeds or []]
        efforts = [_si(spec, v, effort, f"{key}.{names['torques']}") for v in torques or []]
        if len(speeds) != len(efforts) or len(speeds) < 2:
            _fail(spec, key, f"speeds and {names['torques']} need the same number of points, "
                             f"at least 2; got {len(speeds)} and {len(efforts)}")
        if any(b <= a for a, b in zip(speeds, speeds[1:], strict=False)):
            _fail(spec, f"{key}.speeds", "the speeds must increase strictly")
        return MotorConfig("table", speeds=tuple(speeds), torques=tuple(efforts))
    return MotorConfig("none")


def _load(spec: Any, t: LoadTable | None) -> LoadConfig | None:
    if t is None:
        return None
    lk = spec.linkage
    freedom = t.freedom or lk.joints[-1].freedom_names()[0]
    if freedom not in lk.freedom_names:
        _fail(spec, "load.freedom", f"no freedom {freedom!r}; the freedoms are "
                                    f"{listing(lk.freedom_names)}")
    if freedom not in lk.joints[-1].freedom_names():
        _fail(spec, "load.freedom", f"the load acts on the output, a freedom of the last joint "
                                    f"(the one to the ground): {lk.joints[-1].freedom_names()}")
    return load_config(spec, t, freedom)


def load_config(spec: Any, t: LoadTable, freedom: str, key: str = "load") -> LoadConfig:
    """The load of table ``t`` on ``freedom`` (a checked freedom name) in SI: a force on a
    translation (``….s``), a torque on a rotation."""
    translation = freedom.endswith(".s")
    wrong = "torque" if translation else "force"
    if getattr(t, wrong) is not None:
        what, right = ("a translation", "force") if translation else ("a rotation", "torque")
        _fail(spec, f"{key}.{wrong}", f"{freedom!r} is {what}: give {right}")
    if (t.force if translation else t.torque) is None and t.damping is None:
        _fail(spec, key, f"give {'force' if translation else 'torque'} and/or damping")
    constant = 0.0
    if translation and t.force is not None:
        constant = _si(spec, t.force, "force", f"{key}.force")
    if not translation and t.torque is not None:
        constant = _si(spec, t.torque, "torque", f"{key}.torque")
    damping = 0.0
    if t.damping is not None:
        kind = "translational_damping" if translation else "rotational_damping"
        damping = _si(spec, t.damping, kind, f"{key}.damping")
    if constant < 0 or damping < 0:
        _fail(spec, key, "give the load's size (>= 0): it acts against the motion, or in "
                            "the freedom's negative direction with against_motion = false")
    return LoadConfig(freedom, constant, damping, t.against_motion)


_ROTATING = frozenset("RCHUS")
_SLIDING = frozenset("PC")


def friction_problem(linkage: Any, joint: str, rotation: bool, translation: bool
                     ) -> tuple[str, str] | None:
    """Why friction with a rotational (``rotation``) and/or translational part cannot be put
    in ``joint`` of ``linkage``, as (which part: ``""``, ``"rotation"``, ``"translation"``,
    the reason); None when it can. One rule for spec files and the Python API."""
    joints = {j.name: j for j in linkage.joints}
    if joint not in joints:
        return "", f"no joint {joint!r}; the joints are {listing(joints)}"
    kind = joints[joint].kind
    rods = {linkage.joints[k].name: linkage.links[i].name
            for i in spin_links(linkage) for k in (i, i + 1)}
    if rotation and joint in rods:
        return "", (f"{joint!r} is a ball joint of the rod {rods[joint]!r}, which lies between "
                    "two ball joints: its spin about its own axis is free and screwkit holds it "
                    "at zero (docs/kinematics.md), so friction there, which would drive that "
                    "spin, is not modelled; put friction on the other joints")
    if rotation and kind not in _ROTATING:
        return "rotation", f"{joint!r} is a {kind} joint: it does not turn"
    if translation and kind not in _SLIDING:
        return "translation", (f"{joint!r} is a {kind} joint: it does not slide (a helical "
                               "joint's friction is on its rotation)")
    return None


def checked_friction(linkage: Any, friction: Any) -> tuple[JointFriction, ...]:
    """``friction`` (JointFriction items) checked against ``linkage`` — finite, >= 0, each
    part in a joint that has it (:func:`friction_problem`) — and merged by joint (the
    coefficients of repeated entries add), in joint order. Raises :class:`DriveConfigError`."""
    merged: dict[str, list[float]] = {}
    for f in friction:
        c = [float(f.rotation), float(f.translation)]
        if not all(np.isfinite(c)) or min(c) < 0:
            raise DriveConfigError(f"friction in joint {f.joint!r}: a viscous friction "
                                   f"coefficient is finite and >= 0; got {c}")
        problem = friction_problem(linkage, f.joint, c[0] > 0, c[1] > 0)
        if problem is not None:
            raise DriveConfigError(f"friction in joint {f.joint!r}: {problem[1]}")
        total = merged.setdefault(f.joint, [0.0, 0.0])
        total[0] += c[0]
        total[1] += c[1]
    order = [j.name for j in linkage.joints]
    return tuple(JointFriction(name, *merged[name]) for name in order if name in merged)


def split_friction(spec: Any, key: str, name: str, kind: str, value: Any
                   ) -> tuple[Any, Any]:
    """One ``[drive.friction]`` entry as its (rotation, translation) coefficients as written
    (None where absent): a ``{ rotation = …, translation = … }`` table, or one value, which is
    translational for a P joint and rotational otherwise; a C joint (both) needs the table.
    Shared by single loops and mechanism graphs (io/graph_drive.py)."""
    if isinstance(value, FrictionTable):
        if value.rotation is None and value.translation is None:
            _fail(spec, key, "give rotation and/or translation")
        return value.rotation, value.translation
    if kind == "C":
        _fail(spec, key, f"{name!r} is a C joint, which turns and slides: give "
                         "{ rotation = …, translation = … } (N·m·s/rad and N·s/m)")
    return (None, value) if kind == "P" else (value, None)


def _friction(spec: Any, table: dict[str, Any] | None) -> tuple[JointFriction, ...]:
    """``[drive.friction]``: joint name -> a viscous coefficient (rotational for R, H, U, S;
    translational for P) or ``{ rotation = …, translation = … }`` (a C joint has both)."""
    if not table:
        return ()
    joints = {j.name: j for j in spec.linkage.joints}
    out = []
    for name, value in table.items():
        key = f"friction.{name}"
        kind = joints[name].kind if name in joints else ""
        rotation, translation = split_friction(spec, key, name, kind, value)
        problem = friction_problem(spec.linkage, name, rotation is not None,
                                   translation is not None)
        if problem is not None:
            _fail(spec, f"{key}.{problem[0]}" if problem[0] else key, problem[1])
        c_r = 0.0 if rotation is None else _si(spec, rotation, "rotational_damping", key)
        c_t = 0.0 if translation is None else _si(spec, translation, "translational_damping",
                                                  key)
        if c_r < 0 or c_t < 0:
            _fail(spec, key, "a viscous friction coefficient is >= 0")
        out.append(JointFriction(name, c_r, c_t))
    return tuple(out)


def drive_config(spec: Any) -> DriveConfig:
    """The ``[drive]`` table of a loaded spec as a typed, SI :class:`DriveConfig`."""
    t = _table(spec)
    if not spec.input_is_angle or len(spec.linkage.inputs) != 1:
        _fail(spec, "", "simulation needs one rotating input (a crank)")
    speed = (spec.speed if t.initial_speed is None
             else _si(spec, t.initial_speed, "angular_velocity", "initial_speed"))
    if not speed > 0:
        _fail(spec, "initial_speed", f"the crank must start turning forward (> 0); got {speed} "
                                     "rad/s")
    flywheel = _si(spec, t.flywheel, "inertia", "flywheel")
    if flywheel < 0:
        _fail(spec, "flywheel", f"an inertia is >= 0; got {t.flywheel!r}")
    max_time = None if t.max_time is None else _si(spec, t.max_time, "time", "max_time")
    if max_time is not None and not max_time > 0:
        _fail(spec, "max_time", f"must be positive; got {t.max_time!r}")
    return DriveConfig(motor=motor_config(spec, t.motor), load=_load(spec, t.load), flywheel=flywheel,
                       initial_speed=speed, cycles=t.cycles,
                       samples_per_cycle=t.samples_per_cycle, rtol=t.rtol, atol=t.atol,
                       gravity=t.gravity, max_time=max_time,
                       friction=_friction(spec, t.friction))

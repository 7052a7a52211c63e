"""Driven body freedoms as constraint rows of the closure (model/mechanism_drives.py).

A body's driven pose coordinates are the freedoms of a virtual serial chain from the ground to
the body: slides along world x, y, z, then turns about world z, y, x through the body's drive
point a. By the product of exponentials (model/mechanism.py) the chain's end pose is

    T = Trans(x, y, z) · Rot_a(Rz(yaw) · Ry(pitch) · Rx(roll)),

so the chain's freedoms are exactly the drive coordinates of model/mechanism_drives.py (the point
a travels by (x, y, z); the rotation is the Tait–Bryan one). The chain closes one more loop:
its six closure rows, with the chain's undriven freedoms passive, say "the body's driven
coordinates equal the chain's driven freedoms" — the constraint rows "pose coordinate − driven
value" of the task, eliminated of the chain's other freedoms. The undriven freedoms carry no
constraint (a free six-freedom chain), so the mechanism's mobility is unchanged and each drive
fixes one freedom. The augmented mechanism is solved by the continuation on the stacked closure (graph/follow.py) with
the chain's driven freedoms as its inputs; rates and accelerations come from its stacked
Jacobian (graph/newton.py) with the driven rates given; the chain (massless, carrying no load)
is then removed from the result.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Body, Mechanism, MechanismJoint

#: the virtual chain: joint kind, axis and which drive freedom each joint is
_CHAIN = (("P", (1.0, 0.0, 0.0), "x"), ("P", (0.0, 1.0, 0.0), "y"),
          ("P", (0.0, 0.0, 1.0), "z"), ("R", (0.0, 0.0, 1.0), "yaw"),
          ("R", (0.0, 1.0, 0.0), "pitch"), ("R", (1.0, 0.0, 0.0), "roll"))
PREFIX = "_drive_"


def drive_point(mech: Mechanism, body: str) -> np.ndarray:
    """The point of ``body`` its chain turns about: its translation drives' point, else the
    mean of its joint centres (any point gives the same rotation)."""
    for d in mech.drives:
        if d.body == body and d.is_translation:
            return np.asarray(d.at, dtype=float)
    return np.mean([j.at for j in mech.joints if body in j.bodies], axis=0)


def augmented(mech: Mechanism) -> Mechanism:
    """``mech`` with one virtual chain per driven body (module docstring), its inputs the joint
    inputs then the drives in order; the virtual bodies and joints follow the real ones."""
    bodies = list(mech.bodies)
    joints = list(mech.joints)
    input_of: dict[str, str] = {}
    for body in dict.fromkeys(d.body for d in mech.drives):
        a = drive_point(mech, body)
        prev = GROUND
        for k, (kind, axis, freedom) in enumerate(_CHAIN):
            nxt = body if k == len(_CHAIN) - 1 else f"{PREFIX}{body}_{k + 1}"
            if nxt != body:
                bodies.append(Body(nxt))
            name = f"{PREFIX}{body}_{freedom}"
            joints.append(MechanismJoint(name, kind, (prev, nxt), a, np.array(axis)))
            input_of[f"{body}.{freedom}"] = f"{name}.{'s' if kind == 'P' else 'theta'}"
            prev = nxt
    inputs = (*mech.inputs, *(input_of[f"{d.body}.{d.freedom}"] for d in mech.drives))
    return Mechanism(mech.name, tuple(bodies), tuple(joints), inputs, mech.points,
                     mech.length_scale, mech.outputs)


def virtual_names(mech: Mechanism) -> dict[str, str]:
    """The virtual chains' freedom names → the pose coordinates they are,
    ``"<body>.<x|y|z|roll|pitch|yaw>"`` (the drives' names)."""
    out = {}
    for body in dict.fromkeys(d.body for d in mech.drives):
        for kind, _, freedom in _CHAIN:
            out[f"{PREFIX}{body}_{freedom}.{'s' if kind == 'P' else 'theta'}"] = \
                f"{body}.{freedom}"
    return out


def rename_virtual(mech: Mechanism, text: str) -> str:
    """``text`` with the virtual chains' freedom names replaced by the pose coordinates."""
    for old, new in virtual_names(mech).items():
        text = text.replace(old, new)
    return text


def real_configuration(mech: Mechanism, conf: Configuration) -> Configuration:
    """The real joints' part of an augmented configuration (the chain's joints come last and
    have no ball joints)."""
    n = sum(len(j.freedoms) for j in mech.joints if j.kind != "S")
    return Configuration(conf.scalars[:, :n].copy(), conf.spherical.copy())


def restricted_mode(mech: Mechanism, md: object) -> object:
    """A mode of the augmented mechanism with the virtual chains removed: the real bodies'
    poses and twists, the real joints' variables, centres and axes."""
    from screwkit.kinematics.graph.motion import MechanismMode

    assert isinstance(md, MechanismMode)
    nb, nj = len(mech.bodies), len(mech.joints)
    real = set(mech.freedom_names) | {f"{j.name}.r{c}" for j in mech.joints if j.kind == "S"
                                      for c in "xyz"}

    def keep(table: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {k: v for k, v in table.items() if k in real}

    events = [rename_virtual(mech, ev) for ev in md.events]
    return replace(md, conf=real_configuration(mech, md.conf), variables=keep(md.variables),
                   velocities=keep(md.velocities), accelerations=keep(md.accelerations),
                   link_rotation=md.link_rotation[:, :nb],
                   link_origin=md.link_origin[:, :nb],
                   link_angular_velocity=md.link_angular_velocity[:, :nb],
                   link_origin_velocity=md.link_origin_velocity[:, :nb],
                   link_angular_acceleration=md.link_angular_acceleration[:, :nb],
                   link_origin_acceleration=md.link_origin_acceleration[:, :nb],
                   joint_centres=md.joint_centres[:, :nj], joint_axes=md.joint_axes[:, :nj],
                   events=events)

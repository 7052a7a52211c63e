"""A MuJoCo model (MJCF XML) of a loop: ``screwkit export-mjcf SPEC -o model.xml``.

MuJoCo simulates kinematic trees, so the loop is cut at one joint and closed again by an
equality constraint:

* the cut is the last spherical joint of the loop when there is one, closed by a ``connect``
  (three point constraints — exactly a ball joint); otherwise the last revolute joint that is
  not the input, closed by two ``connect`` constraints at two points of its axis (five
  independent constraints and one redundant one, which MuJoCo's soft constraints accept);
* the joints before the cut hang from the world in loop order (world → joint 1 → link 1 → …);
  those after it hang from the world in reverse order (world → last joint → last link → …);
* every body frame is its link's frame in the configuration of the loop at the start angle
  (so ``qpos0`` is assembled), with the link's mass properties: ``<inertial pos="CoM"
  fullinertia="Ixx Iyy Izz Ixy Ixz Iyz">`` about the centre of mass in body axes;
* R → ``hinge``, P → ``slide``, C → ``hinge`` + ``slide`` on one axis, S → ``ball``
  (H and U joints are not exported);
* the input joint has a ``motor`` actuator (torque, no limits) named ``input``, and the
  flywheel on the input shaft (``[drive] flywheel``) as its ``armature`` — MuJoCo adds a
  joint's armature to the diagonal of the mass matrix at its freedom, which is exactly a rotor
  turning with the input crank relative to the ground; contacts are disabled; capsules between
  the joint centres are drawn for viewing only (no mass, no contact);
* ``gravity`` is the option's gravity vector (the spec's, when the caller gives it).

An S–S rod spins freely about the line of its ball centres in MuJoCo, while screwkit's
kinematics gives it no spin: give such a rod an axisymmetric inertia about that line with its
centre of mass on it (the rule of docs/dynamics.md) and start it without spin, and the spin
stays zero (no joint can load it), so the two models agree.

``solref``/``solimp`` of the equality constraints and the ``timestep`` and ``integrator`` are
parameters: validation/mujoco/crosscheck.md measures what they do to the agreement.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
from scipy.spatial.transform import Rotation

from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.messages import listing, shown
from screwkit.model.linkage import Linkage
from screwkit.simulation.reduced import Array, SimulationError, joint_friction

#: equality-constraint defaults: a time constant of 20 time steps and an impedance at MuJoCo's
#: ceiling (hard constraints); validation/mujoco/crosscheck.md justifies them
DEFAULT_TIMESTEP = 1e-5
DEFAULT_SOLREF = (2e-4, 1.0)  # 20 time steps
DEFAULT_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)


@dataclass(frozen=True)
class MjcfLayout:
    """How the loop was cut: ``cut`` the joint index closed by equality constraints,
    ``forward`` the joint indices hanging from the world in loop order (joint k carries link
    k), ``backward`` those in reverse order (joint k carries link k − 1), ``dofs`` the MuJoCo
    joint names of each loop joint, ``spin_links`` the indices of S–S rods."""

    cut: int
    forward: tuple[int, ...]
    backward: tuple[int, ...]
    dofs: dict[str, tuple[str, ...]]
    spin_links: tuple[int, ...]


#: joint name -> (rotational, translational) viscous damping
Damping = Mapping[str, tuple[float, float]]


def loop_layout(linkage: Linkage) -> MjcfLayout:
    """Where to cut the loop and how the two chains hang (module docstring)."""
    kinds = [j.kind for j in linkage.joints]
    bad = [j.name for j in linkage.joints if j.kind in ("H", "U")]
    if bad:
        raise SimulationError(f"{linkage.name}: MJCF export handles R, P, C and S joints; "
                              f"{listing(bad)} {'is an H or U joint' if len(bad) == 1 else 'are H or U joints'}")
    inputs = {name.split(".")[0] for name in linkage.inputs}
    spheres = [k for k, kind in enumerate(kinds) if kind == "S"]
    hinges = [k for k, kind in enumerate(kinds)
              if kind == "R" and k > 0 and linkage.joints[k].name not in inputs]
    spheres = [k for k in spheres if k > 0]
    if spheres:
        cut = spheres[-1]
    elif hinges:
        cut = hinges[-1]
    else:
        raise SimulationError(f"{linkage.name}: MJCF export cuts the loop at a spherical joint "
                              "or at a revolute joint that is not the input; this loop has "
                              f"neither ({''.join(kinds)})")
    n = len(kinds)
    dofs: dict[str, tuple[str, ...]] = {}
    for j in linkage.joints:
        dofs[j.name] = ((f"{j.name}_theta", f"{j.name}_s") if j.kind == "C" else (j.name,))
    spin = tuple(k for k in range(n - 1) if kinds[k] == "S" and kinds[k + 1] == "S")
    return MjcfLayout(cut=cut, forward=tuple(range(cut)), backward=tuple(range(n - 1, cut, -1)),
                      dofs=dofs, spin_links=spin)


def xml_numbers(x: Any) -> str:
    return " ".join(f"{v:.17g}" for v in np.atleast_1d(np.asarray(x, dtype=float)))


def _quat(R: Array) -> Array:
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return np.array([w, x, y, z])


def start_configuration(linkage: Linkage, start: float, mode: int) -> ModeMotion:
    """The loop's configuration at input ``start`` in assembly ``mode`` (two samples, so a
    family's closed form and its mode numbering are used)."""
    motion = solve_motion(linkage, [start, start + 1e-3], rates=0.0, accelerations=0.0)
    md = motion.mode(mode)
    if not (md.assembles[0] and not md.singular[0]):
        raise SimulationError(f"{linkage.name}: mode {mode} does not assemble at the start "
                              f"angle {shown(start, 'angle')}")
    return md


def _joint_xml(linkage: Linkage, k: int, layout: MjcfLayout, centre: Array, axis: Array,
               indent: str, damping: Damping, armature: Mapping[str, float]) -> list[str]:
    j = linkage.joints[k]
    lines = []
    tags = {"R": ("hinge",), "P": ("slide",), "C": ("hinge", "slide"), "S": ("ball",)}[j.kind]
    rotation, translation = damping.get(j.name, (0.0, 0.0))
    for name, tag in zip(layout.dofs[j.name], tags, strict=True):
        extra = "" if tag == "ball" else f' axis="{xml_numbers(axis)}"'
        c = translation if tag == "slide" else rotation
        lines.append(f'{indent}<joint name={quoteattr(name)} type="{tag}" pos="{xml_numbers(centre)}"'
                     f'{extra} limited="false" damping="{float(c)!r}" '
                     f'armature="{float(armature.get(name, 0.0))!r}"/>')
    return lines


def _body_xml(linkage: Linkage, md: ModeMotion, link: int, joint: int, parent: int | None,
              layout: MjcfLayout, indent: str, damping: Damping,
              armature: Mapping[str, float]) -> list[str]:
    R, o = md.link_rotation[0, link], md.link_origin[0, link]
    if parent is None:
        pos, rot = o, R
    else:
        Rp, op = md.link_rotation[0, parent], md.link_origin[0, parent]
        pos, rot = Rp.T @ (o - op), Rp.T @ R
    lk = linkage.links[link]
    mp = lk.mass
    if mp is None:
        raise SimulationError(f"{linkage.name}: link {lk.name!r} has no mass properties; MJCF "
                              "export needs them for every moving link")
    I = mp.inertia
    centre = R.T @ (md.joint_centres[0, joint] - o)
    axis = R.T @ md.joint_axes[0, joint]
    lines = [f'{indent}<body name={quoteattr(lk.name)} pos="{xml_numbers(pos)}" quat="{xml_numbers(_quat(rot))}">',
             f'{indent}  <inertial pos="{xml_numbers(mp.com)}" mass="{mp.mass:.17g}" fullinertia="'
             f'{xml_numbers([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>']
    lines += _joint_xml(linkage, joint, layout, centre, axis, indent + "  ", damping, armature)
    ends = [R.T @ (md.joint_centres[0, k] - o) for k in (link, link + 1)]
    if np.linalg.norm(ends[1] - ends[0]) > 1e-9:
        lines.append(f'{indent}  <geom type="capsule" fromto="{xml_numbers(ends[0])} {xml_numbers(ends[1])}" '
                     f'size="{0.02 * linkage.length_scale:.6g}" mass="0" contype="0" '
                     'conaffinity="0"/>')
    return lines


def _chain(linkage: Linkage, md: ModeMotion, steps: list[tuple[int, int]],
           layout: MjcfLayout, damping: Damping, armature: Mapping[str, float]) -> list[str]:
    """Nested bodies for (link, joint) pairs from the world outwards."""
    opened: list[str] = []
    lines: list[str] = []
    parent = None
    for depth, (link, joint) in enumerate(steps):
        indent = "    " + "  " * depth
        lines += _body_xml(linkage, md, link, joint, parent, layout, indent, damping, armature)
        opened.append(indent + "</body>")
        parent = link
    return lines + opened[::-1]


def _equality(linkage: Linkage, md: ModeMotion, layout: MjcfLayout, solref: tuple[float, ...],
              solimp: tuple[float, ...]) -> list[str]:
    c = layout.cut
    body1, body2 = c - 1, c  # link before and after the cut joint (the ground after the last)
    R, o = md.link_rotation[0, body1], md.link_origin[0, body1]
    centre = md.joint_centres[0, c]
    points = [centre]
    if linkage.joints[c].kind == "R":
        u = md.joint_axes[0, c]
        arm = 0.1 * linkage.length_scale
        points = [centre + arm * u, centre - arm * u]
    name2 = linkage.links[body2].name if body2 < len(linkage.links) else "world"
    soft = f'solref="{xml_numbers(np.array(solref))}" solimp="{xml_numbers(np.array(solimp))}"'
    return [f'    <connect name="cut_{linkage.joints[c].name}_{k}" '
            f'body1={quoteattr(linkage.links[body1].name)} '
            f'body2={quoteattr(name2)} anchor="{xml_numbers(R.T @ (p - o))}" {soft}/>'
            for k, p in enumerate(points)]


def mjcf_model(linkage: Linkage, *, start: float = 0.0, mode: int = 0,
               gravity: Array | None = None, timestep: float = DEFAULT_TIMESTEP,
               integrator: str = "RK4", solref: tuple[float, ...] = DEFAULT_SOLREF,
               solimp: tuple[float, ...] = DEFAULT_SOLIMP, friction: Sequence[Any] = (),
               flywheel: float = 0.0) -> str:
    """The MJCF text of ``linkage`` in assembly ``mode`` posed at input ``start`` (module
    docstring). SI units; ``gravity`` (m/s², world) zero if omitted; ``friction``
    (:class:`~screwkit.io.drive_table.JointFriction` items) becomes the joints' viscous
    ``damping`` — MuJoCo's damping of a hinge, slide or ball is exactly this friction (a ball's
    on its relative angular velocity); ``flywheel`` (kg·m² on the input shaft; kg on a driven
    slide) the input freedom's ``armature``, the J_f of ``screwkit simulate``'s equation of
    motion (docs/simulation.md)."""
    if not (np.isfinite(flywheel) and flywheel >= 0):
        raise SimulationError(f"{linkage.name}: the flywheel is an inertia >= 0; got "
                              f"{flywheel!r}")
    if len(linkage.inputs) != 1:
        raise SimulationError(f"{linkage.name}: MJCF export drives one input; this loop has "
                              f"{listing(linkage.inputs)}")
    layout = loop_layout(linkage)
    damping: Damping = {f.joint: (float(f.rotation), float(f.translation))
                        for f in joint_friction(linkage, friction)}
    cut = linkage.joints[layout.cut].name
    if any(damping.get(cut, (0.0, 0.0))):
        raise SimulationError(f"{linkage.name}: joint {cut!r} has friction, but the MJCF model "
                              "closes the loop there by an equality constraint, which MuJoCo "
                              "cannot damp; export without its friction")
    md = start_configuration(linkage, start, mode)
    g = np.zeros(3) if gravity is None else np.asarray(gravity, dtype=float)
    n = len(linkage.joints)
    forward = [(k, k) for k in layout.forward]
    backward = [(k - 1, k) for k in layout.backward]
    input_joint = linkage.inputs[0].split(".")[0]
    input_dof = layout.dofs[input_joint][-1 if linkage.inputs[0].endswith(".s") else 0]
    lines = [f"<mujoco model={quoteattr(linkage.name)}>",
             "  <!-- written by screwkit export-mjcf: SI units; the loop is cut at joint "
             f"{linkage.joints[layout.cut].name!r} and closed by equality constraints -->",
             '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
             f'  <option timestep="{timestep:.17g}" integrator="{integrator}" '
             f'gravity="{xml_numbers(g)}">',
             '    <flag contact="disable"/>',
             "  </option>",
             "  <worldbody>"]
    armature = {input_dof: float(flywheel)}
    lines += _chain(linkage, md, forward, layout, damping, armature)
    lines += _chain(linkage, md, backward, layout, damping, armature)
    lines += ["  </worldbody>", "  <equality>"]
    lines += _equality(linkage, md, layout, solref, solimp)
    lines += ["  </equality>", "  <actuator>",
              f'    <motor name="input" joint={quoteattr(input_dof)} gear="1"/>',
              "  </actuator>", "</mujoco>", ""]
    assert n == len(layout.forward) + len(layout.backward) + 1
    return "\n".join(lines)

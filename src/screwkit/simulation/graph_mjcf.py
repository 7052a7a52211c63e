"""A MuJoCo model (MJCF XML) of a mechanism graph: ``screwkit export-mjcf SPEC -o model.xml``.

MuJoCo simulates kinematic trees, so the graph's spanning tree (the mechanism's own
:attr:`~screwkit.model.mechanism.Mechanism.topology`, found breadth-first from the ground)
becomes the body tree and every chord — the joint that closes a loop — an equality constraint:

* an S chord is one ``connect`` at its centre (three point constraints: exactly a ball joint);
* an R chord is two ``connect`` constraints at two points of its axis, 0.1 × the mechanism's
  length scale either side of its point (five independent constraints: exactly a hinge, and one
  redundant one along the axis, which MuJoCo's soft constraints accept — the single-loop export's
  choice, simulation/mjcf.py). A ``weld`` would remove the chord's freedom and a joint equality
  cannot act across the cut, so neither is used;
* a loop is never cut at a P, C or U joint: MuJoCo's equality constraints (``connect``,
  ``weld``) cannot leave a slide free, and a helper body sliding on a weld would add its mass.
  Where the mechanism's own spanning tree closes a loop at such a joint (a slider-crank listed
  crank first, slider last), the export takes another spanning tree (:func:`export_tree`): the
  P, C or U joint goes into the body tree as a ``slide`` (a ``hinge`` + ``slide``, two
  ``hinge`` joints) and the loop is cut at one of its R or S joints instead — the same
  mechanism, exactly, with no added mass. A loop with no R or S joint to cut (besides its
  inputs) is refused, naming it; H joints are not exported.

The model is written in the drawn configuration (and, given a ``start``, with a keyframe
``start`` at the drawn mode followed to those inputs): every body frame is the world frame of the
drawing (as in the spec), so ``qpos0`` is the drawing and closes every loop, a joint's ``pos``
and ``axis`` are its drawn point and axis, and a body's ``<inertial pos="com"
fullinertia="…">`` are its spec mass properties unchanged. Tree joints: R → ``hinge``,
P → ``slide``, C → ``hinge`` + ``slide``, U → two ``hinge`` joints (first axis, then second, as
M_j = rot(u)·rot(u₂)), S → ``ball``; where the tree runs from a joint's second body to its first
the axes are reversed (and a U's order too), so a hinge's or slide's ``qpos`` is the spec's
freedom value either way. H joints are not exported.

Each input has a ``motor`` actuator named after the input (``"OA.theta"``), with its flywheel as
the joint's ``armature``; joint friction is the joints' viscous ``damping`` (a chord's cannot be
damped: refused); contacts are off; capsules from each body's first joint point to its others
are drawn for viewing only (no mass, no contact). An S–S rod spins freely in MuJoCo and not in
screwkit: with its centre of mass on the line of its balls and an inertia symmetric about it
(docs/dynamics.md) the spin, started at zero, stays zero.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from screwkit.io.drive_table import JointFriction
from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.motion import format_inputs
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.messages import listing, shown_values
from screwkit.model.mechanism import GROUND, Mechanism
from screwkit.simulation.graph_eom import Array, checked_graph_friction, graph_masses
from screwkit.simulation.mjcf import DEFAULT_SOLIMP, DEFAULT_SOLREF, DEFAULT_TIMESTEP, xml_numbers
from screwkit.simulation.reduced import SimulationError


@dataclass(frozen=True)
class GraphMjcfLayout:
    """Which joints are in the tree (``tree``: (joint, parent, child), parents first) and which
    close loops (``chords``), and the MuJoCo joint name of every exported freedom (``dofs``:
    ``"OA.theta"`` → ``"OA_theta"``; a ball's three freedoms share one ``"TI_ball"``)."""

    chords: tuple[str, ...]
    dofs: dict[str, str]
    tree: tuple[tuple[int, str, str], ...] = ()
    chord_joints: tuple[int, ...] = ()


def _cuttable(mech: Mechanism, k: int, inputs: set[str]) -> bool:
    j = mech.joints[k]
    return j.kind in ("R", "S") and j.name not in inputs


def export_tree(mech: Mechanism) -> tuple[tuple[tuple[int, str, str], ...], tuple[int, ...]]:
    """The spanning tree of the export and its chords (module docstring): the mechanism's own
    topology when every chord is an R or S joint that is not an input; otherwise the tree grown
    (Kruskal's algorithm on the body graph) from the joints that cannot be cut — inputs, P, C,
    U, H — first, then the R and S joints, the topology's own chords last, so that every chord
    is an R or S joint wherever the loop has one. Parents are listed before their children
    (breadth-first from the ground)."""
    top = mech.topology
    inputs = {name.split(".")[0] for name in mech.inputs}
    if all(_cuttable(mech, k, inputs) for k in top.chords):
        return top.tree, top.chords

    def rank(k: int) -> tuple[int, int]:
        if not _cuttable(mech, k, inputs):
            return (0, k)
        return (2 if k in top.chords else 1, k)

    parent = {b: b for b in (GROUND, *mech.body_names)}

    def root(b: str) -> str:
        while parent[b] != b:
            parent[b] = parent[parent[b]]
            b = parent[b]
        return b

    used: list[int] = []
    for k in sorted(range(len(mech.joints)), key=rank):
        a, b = (root(x) for x in mech.joints[k].bodies)
        if a != b:
            parent[a] = b
            used.append(k)
    order: list[tuple[int, str, str]] = []
    seen, queue = {GROUND}, [GROUND]
    while queue:
        body = queue.pop(0)
        for k in sorted(used):
            a, b = mech.joints[k].bodies
            if body in (a, b):
                other = b if a == body else a
                if other not in seen:
                    seen.add(other)
                    order.append((k, body, other))
                    queue.append(other)
    return tuple(order), tuple(k for k in range(len(mech.joints)) if k not in used)


def graph_mjcf_layout(mech: Mechanism) -> GraphMjcfLayout:
    """The tree and the cut joints of the export (module docstring); a clear error for what
    it cannot write."""
    bad = [j.name for j in mech.joints if j.kind == "H"]
    if bad:
        raise SimulationError(f"{mech.name}: MJCF export does not write H (helical) joints; "
                              f"{listing(bad)} {'is' if len(bad) == 1 else 'are'}")
    tree, chord_joints = export_tree(mech)
    chords = [mech.joints[k] for k in chord_joints]
    for j in chords:
        if j.kind not in ("R", "S"):
            raise SimulationError(
                f"{mech.name}: the loop closed by joint {j.name!r} ({j.kind}) has no R or S "
                "joint other than an input to cut it at, and MJCF export closes loops only at "
                "R or S joints (by connect constraints; MuJoCo has no equality that leaves a "
                "slide free)")
    inputs = {name.split(".")[0] for name in mech.inputs}
    driven_chords = sorted(inputs & {j.name for j in chords})
    if driven_chords:
        raise SimulationError(f"{mech.name}: the input joint(s) {driven_chords} close a loop "
                              "in the spanning tree, and MuJoCo cannot drive an equality "
                              "constraint; list the input joints first, from the ground")
    dofs: dict[str, str] = {}
    for j in mech.joints:
        for f in j.freedoms:
            dofs[f"{j.name}.{f}"] = f"{j.name}_ball" if j.kind == "S" else f"{j.name}_{f}"
    return GraphMjcfLayout(tuple(j.name for j in chords), dofs, tree, chord_joints)


def _joint_lines(mech: Mechanism, k: int, reversed_: bool, indent: str,
                 damping: dict[str, tuple[float, float]], armature: dict[str, float]
                 ) -> list[str]:
    j = mech.joints[k]
    sign = -1.0 if reversed_ else 1.0
    rot, slide = damping.get(j.name, (0.0, 0.0))
    if j.kind == "S":
        return [f'{indent}<joint name={quoteattr(j.name + "_ball")} type="ball" '
                f'pos="{xml_numbers(j.at)}" limited="false" damping="{rot!r}"/>']
    items: list[tuple[str, str, Array]] = []
    if j.kind == "U":
        assert j.axis2 is not None
        pairs = [("theta1", j.axis), ("theta2", j.axis2)]
        items = [(f, "hinge", sign * u) for f, u in (pairs[::-1] if reversed_ else pairs)]
    elif j.kind == "R":
        items = [("theta", "hinge", sign * j.axis)]
    elif j.kind == "P":
        items = [("s", "slide", sign * j.axis)]
    else:  # C
        items = [("theta", "hinge", sign * j.axis), ("s", "slide", sign * j.axis)]
    lines = []
    for f, tag, u in items:
        name = f"{j.name}_{f}"
        c = slide if tag == "slide" else rot
        lines.append(f'{indent}<joint name={quoteattr(name)} type="{tag}" pos="{xml_numbers(j.at)}" '
                     f'axis="{xml_numbers(u)}" limited="false" damping="{c!r}" '
                     f'armature="{armature.get(name, 0.0)!r}"/>')
    return lines


def _body_lines(mech: Mechanism, body: str, children: dict[str, list[tuple[int, str]]],
                depth: int, damping: dict[str, tuple[float, float]],
                armature: dict[str, float], joint: int) -> list[str]:
    indent = "    " + "  " * depth
    b = next(x for x in mech.bodies if x.name == body)
    mp = b.mass
    assert mp is not None
    I = mp.inertia
    lines = [f'{indent}<body name={quoteattr(body)} pos="0 0 0" quat="1 0 0 0">',
             f'{indent}  <inertial pos="{xml_numbers(mp.com)}" mass="{mp.mass:.17g}" fullinertia="'
             f'{xml_numbers([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>']
    reversed_ = mech.joints[joint].bodies[1] != body  # the tree reaches body as the first
    lines += _joint_lines(mech, joint, reversed_, indent + "  ", damping, armature)
    points = [j.at for j in mech.joints if body in j.bodies]
    points += [p.at for p in mech.points if p.body == body]
    for p in points[1:]:
        if np.linalg.norm(p - points[0]) > 1e-9 * mech.length_scale:
            lines.append(f'{indent}  <geom type="capsule" fromto="{xml_numbers(points[0])} {xml_numbers(p)}" '
                         f'size="{0.02 * mech.length_scale:.6g}" mass="0" contype="0" '
                         'conaffinity="0"/>')
    for k, child in children.get(body, []):
        lines += _body_lines(mech, child, children, depth + 1, damping, armature, k)
    return [*lines, indent + "</body>"]


def _equality_lines(mech: Mechanism, chords: tuple[int, ...], solref: tuple[float, ...],
                    solimp: tuple[float, ...]) -> list[str]:
    soft = f'solref="{xml_numbers(np.array(solref))}" solimp="{xml_numbers(np.array(solimp))}"'
    lines = []
    for k in chords:
        j = mech.joints[k]
        a, b = j.bodies
        if a == GROUND:  # connect's first body must move: anchor it in the second
            a, b = b, a
        points = [j.at]
        if j.kind == "R":
            arm = 0.1 * mech.length_scale
            points = [j.at + arm * j.axis, j.at - arm * j.axis]
        name2 = "world" if b == GROUND else b
        for n, p in enumerate(points):
            lines.append(f'    <connect name={quoteattr(f"cut_{j.name}_{n}")} '
                         f'body1={quoteattr(a)} body2={quoteattr(name2)} anchor="{xml_numbers(p)}" '
                         f'{soft}/>')
    return lines


def _joint_qpos(mech: Mechanism, lay: GraphLayout, conf: Configuration, k: int,
                reversed_: bool) -> list[float]:
    """MuJoCo's ``qpos`` entries of tree joint ``k`` at ``conf`` (in the order
    :func:`_joint_lines` writes them): a hinge's or slide's value is the freedom's (the axis is
    reversed with the tree), a ball's quaternion (w, x, y, z) is its rotation (transposed where
    the tree runs backwards)."""
    j = mech.joints[k]
    f0 = lay.first_freedom[k]
    if j.kind == "S":
        R = conf.spherical[0, lay.spherical_of_joint[k]]
        x, y, z, w = Rotation.from_matrix(R.T if reversed_ else R).as_quat()
        return [float(w), float(x), float(y), float(z)]
    values = [float(conf.scalars[0, lay.scalar_col[f0 + n]]) for n in range(len(j.freedoms))]
    return values[::-1] if j.kind == "U" and reversed_ else values


def _start_qpos(mech: Mechanism, children: dict[str, list[tuple[int, str]]],
                start: ArrayLike) -> list[float]:
    """``qpos`` of the drawn mode followed to inputs ``start`` (the graph tracker), bodies in
    the depth-first order the XML lists them."""
    from screwkit.kinematics.graph.closure import graph_layout
    from screwkit.kinematics.graph.motion import solve_mechanism

    X = np.asarray(start, dtype=float).reshape(1, -1)
    md = solve_mechanism(mech, X, rates=0.0, accelerations=0.0).mode(0)
    if not md.assembles[0]:
        raise SimulationError(f"{mech.name}: the drawn mode does not assemble at the start "
                              f"inputs {format_inputs(mech, X[0])}")
    lay = graph_layout(mech)
    out: list[float] = []

    def visit(parent: str) -> None:
        for k, child in children.get(parent, []):
            out.extend(_joint_qpos(mech, lay, md.conf, k, mech.joints[k].bodies[1] != child))
            visit(child)

    visit(GROUND)
    return out


def graph_mjcf_model(mech: Mechanism, *, gravity: ArrayLike | None = None,
                     timestep: float = DEFAULT_TIMESTEP, integrator: str = "RK4",
                     solref: tuple[float, ...] = DEFAULT_SOLREF,
                     solimp: tuple[float, ...] = DEFAULT_SOLIMP,
                     friction: Sequence[JointFriction] = (),
                     flywheel: ArrayLike | None = None, start: ArrayLike | None = None
                     ) -> str:
    """The MJCF text of ``mech`` in its drawn configuration (module docstring). SI units;
    ``gravity`` (m/s², world) zero if omitted; ``friction`` the joints' viscous damping;
    ``flywheel`` (one per input, or one for all) the input freedoms' armature; ``start`` (one
    value per input, from the drawing) adds a keyframe ``start`` whose ``qpos`` is the drawn
    mode there (``mj_resetDataKeyframe``)."""
    graph_masses(mech)
    lay = graph_mjcf_layout(mech)
    n = len(mech.inputs)
    fw = np.zeros(n) if flywheel is None else np.asarray(flywheel, dtype=float) * np.ones(n)
    if not np.all(np.isfinite(fw) & (fw >= 0)):
        raise SimulationError(f"{mech.name}: a flywheel is an inertia >= 0; got {shown_values(fw, 'inertia')}")
    damping = {f.joint: (float(f.rotation), float(f.translation))
               for f in checked_graph_friction(mech, friction)}
    damped_chords = sorted(c for c in lay.chords if any(damping.get(c, (0.0, 0.0))))
    if damped_chords:
        raise SimulationError(f"{mech.name}: joint(s) {damped_chords} have friction, but the "
                              "MJCF model closes the loops there by equality constraints, "
                              "which MuJoCo cannot damp; export without their friction")
    armature = {lay.dofs[name]: float(fw[k]) for k, name in enumerate(mech.inputs)}
    g = np.zeros(3) if gravity is None else np.asarray(gravity, dtype=float)
    children: dict[str, list[tuple[int, str]]] = {}
    for k, parent, child in lay.tree:
        children.setdefault(parent, []).append((k, child))
    lines = [f"<mujoco model={quoteattr(mech.name)}>",
             "  <!-- written by screwkit export-mjcf: SI units, the drawn configuration; the "
             "spanning tree is the body tree and the loops are closed by connect constraints "
             f"at the joints {', '.join(lay.chords)} -->",
             '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
             f'  <option timestep="{timestep:.17g}" integrator="{integrator}" '
             f'gravity="{xml_numbers(g)}">',
             '    <flag contact="disable"/>',
             "  </option>",
             "  <worldbody>"]
    for k, child in children.get(GROUND, []):
        lines += _body_lines(mech, child, children, 0, damping, armature, k)
    lines += ["  </worldbody>", "  <equality>", *_equality_lines(mech, lay.chord_joints, solref, solimp),
              "  </equality>"]
    if start is not None:
        qpos = _start_qpos(mech, children, start)
        lines += ["  <keyframe>", f'    <key name="start" qpos="{xml_numbers(qpos)}"/>',
                  "  </keyframe>"]
    lines += ["  <actuator>"]
    for name in mech.inputs:
        lines.append(f'    <motor name={quoteattr(name)} joint={quoteattr(lay.dofs[name])} '
                     'gear="1"/>')
    return "\n".join([*lines, "  </actuator>", "</mujoco>", ""])

"""The report of a spec: its pipeline's motion (solved once), and the dynamics, balancing and
synthesis the spec asks for, as one scene (:mod:`screwkit.report.scene`) and one
self-contained HTML file (:mod:`screwkit.report.viewer`; docs/report.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from screwkit.errors import ScrewkitError
from screwkit.io.mechanism_spec import GraphSpec
from screwkit.io.results import jsonable
from screwkit.io.spec import Spec
from screwkit.kinematics.motion import ModeMotion
from screwkit.pipeline import Pipeline
from screwkit.report.synthesis_scene import (
    SynthesisedMotion,
    add_synthesised_plots,
    start_ghost,
    synthesised_motion,
)

Named = dict[str, Any]


def seed_tables(mode: ModeMotion) -> tuple[Named, Named, Named]:
    """A mode's variables, rates and accelerations under the seed's names only (no joint
    freedoms ``<joint>.<freedom>``), for the plots."""
    def seeds(table: Named) -> Named:
        return {k: v for k, v in table.items() if "." not in k}

    return seeds(mode.variables), seeds(mode.velocities), seeds(mode.accelerations)


def spec_scene(spec: Spec | Pipeline | GraphSpec, *, gravity: bool = False,
               dynamics_doc: dict[str, Any] | None = None,
               balance_doc: dict[str, Any] | None = None,
               synthesis_doc: dict[str, Any] | None = None) -> dict[str, Any]:
    """The report scene of a loaded spec (or of a pipeline, whose motion is reused): every
    mode's motion and, when the spec has them, the dynamics of ``[motion] mode`` (masses),
    balancing (``[balancing]``) and synthesis (``[synthesis]``) — computed here unless their
    documents are given. A graph spec (``[[joints]]``, docs/mechanisms.md) gives the scene of
    its drawn mode (:func:`screwkit.report.graph_scene.graph_spec_scene`: its loads when every
    body has masses, gravity as asked, and its ``[balancing]`` run; the documents are not
    taken)."""
    from screwkit.io.documents import synthesis_document
    from screwkit.report.scene import scene_from_motion

    if isinstance(spec, GraphSpec):
        from screwkit.report.graph_scene import graph_spec_scene

        return graph_spec_scene(spec, gravity=gravity)

    pipe = spec if isinstance(spec, Pipeline) else Pipeline(spec)
    s = pipe.spec
    m = pipe.motion
    notes = []
    dyn_mode = None
    if all(link.mass is not None for link in s.linkage.links):
        if dynamics_doc is None:
            dynamics_doc = pipe.dynamics(gravity).as_dict()
        dyn_mode = s.mode
        notes.append(f"Dynamics and balancing are of [motion] mode = {s.mode} of the spec.")
    else:
        dynamics_doc = None
    if balance_doc is None and s.balancing is not None:
        balance_doc = pipe.balance().as_dict()
    if synthesis_doc is None and s.synthesis is not None:
        synthesis_doc = synthesis_document(pipe.synthesize(), s.path)
    text = Path(s.path).read_text(encoding="utf-8")
    shown = synthesised_view(s, synthesis_doc, notes) if synthesis_doc is not None else None
    if shown is not None and dynamics_doc is not None:
        notes[:] = [n for n in notes if not n.startswith("Dynamics and balancing are of")]
        notes.append("The report draws no dynamics or balancing: they are of the spec's "
                     "mechanism, not the synthesised one shown; run them on a spec with its "
                     "dimensions.")
        dynamics_doc = balance_doc = dyn_mode = None
    motion = m if shown is None else shown.motion
    scene = scene_from_motion(s, motion, dynamics_doc=dynamics_doc, dynamics_mode=dyn_mode,
                              balance_doc=balance_doc, synthesis_doc=synthesis_doc,
                              spec_text=text,
                              seed_variables=[seed_tables(md) for md in motion.modes],
                              coupler_points={p.name: (p.link, p.point)
                                              for p in s.coupler_points},
                              solver=[motion.solver] if motion.solver else None, notes=notes,
                              linkage=None if shown is None else shown.linkage,
                              initial_mode=None if shown is None else shown.mode)
    if shown is not None and s.synthesis is not None and synthesis_doc is not None:
        add_synthesised_plots(scene, shown, s.synthesis)
        ghost = start_ghost(s.linkage, m, s.mode, float(synthesis_doc["dimensions"]["theta01"]))
        if ghost is not None:
            scene["ghost"] = jsonable(ghost)
        scene["description"] = synthesised_description(s, synthesis_doc, shown)
    if s.drive is not None and dynamics_doc is not None:
        add_simulation_plots(scene, s)
    return scene


def synthesised_view(spec: Spec, synthesis_doc: dict[str, Any],
                     notes: list[str]) -> SynthesisedMotion | None:
    """The synthesised mechanism the report animates (:mod:`screwkit.report.synthesis_scene`),
    with a note saying so; None (and a note why) when it cannot be followed, and the report
    shows the spec's mechanism, the synthesis start."""
    if spec.synthesis is None:
        return None
    try:
        shown = synthesised_motion(spec.synthesis, synthesis_doc, spec.family or "LOOP")
    except ScrewkitError as exc:
        notes.append(f"The 3-D view shows the spec's mechanism (the synthesis start), not the "
                     f"synthesised one: {exc}.")
        return None
    notes.append(f"The 3-D view and the kinematic plots show the synthesised mechanism (the "
                 f"synthesis's best result) over its design range, θ01 {'+' if shown.direction > 0 else '−'} θ; "
                 f"its mode {shown.mode} generates the synthesis's output at every design point "
                 "(to round-off).")
    return shown


def synthesised_description(spec: Spec, doc: dict[str, Any], shown: SynthesisedMotion) -> str:
    """One line on the synthesised mechanism: its dimensions in the spec's units, the design
    range of its input."""
    du = spec.display_units()
    angles = spec.synthesis.angles if spec.synthesis else frozenset()
    kinds = {k: "angle" if k in angles else "length" for k in doc["dimensions"]}
    dims = ", ".join(f"{k}={du.show(kinds[k], v):.6g} {du.label(kinds[k])}"
                     for k, v in doc["dimensions"].items())
    x = shown.motion.inputs.reshape(len(shown.theta), -1)[:, 0]
    return (f"{spec.name}: the synthesised {spec.family} ({''.join(j.kind for j in shown.linkage.joints)}) "
            f"{dims}; {len(x)} input samples {du.show('angle', x[0]):.6g}…"
            f"{du.show('angle', x[-1]):.6g} {du.label('angle')} (the design range)")


def add_simulation_plots(scene: dict[str, Any], spec: Spec) -> None:
    """Add the speed and torque plots of ``screwkit simulate`` (the spec's ``[drive]``) to a
    scene (docs/simulation.md)."""
    from screwkit.report.simulation_plots import simulation_scene_plots
    from screwkit.simulation.spec_run import simulate_spec

    doc = simulate_spec(spec).as_dict(loads=True)
    plots, groups = simulation_scene_plots(doc)
    scene["plots"] += plots
    scene["plot_groups"] += groups


def write_spec_report(spec: Spec | Pipeline | GraphSpec, path: str | Path, **docs: Any
                      ) -> dict[str, Any]:
    """Write the HTML report of a loaded spec (or pipeline, or graph spec) to ``path``
    atomically; returns its scene. ``docs``: ``gravity``, ``dynamics_doc``, ``balance_doc``,
    ``synthesis_doc`` (for a graph spec only ``gravity`` is used)."""
    from screwkit.io.results import write_atomic
    from screwkit.report.viewer import render_report_html

    scene = spec_scene(spec, **docs)
    write_atomic(path, render_report_html(scene))
    return scene

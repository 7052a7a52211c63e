"""The jobs a sweep runs on a design of a graph spec (docs/sweeps.md, "Graph specs"): the
drawn mode followed over the spec's inputs (:func:`~screwkit.kinematics.graph.solve_mechanism`,
the code path of ``screwkit analyze`` on a graph), summarised into scalar columns (SI, rad).

A design of a graph spec is *re-drawn*: its values replace the drawing's, so a moved hardpoint
moves the joint in both its bodies and the new drawing closes as drawn (a design change). The
as-built scatter of a part, where the drawing no longer closes, is the tolerance analysis'
(:mod:`screwkit.sweep.graph_tolerance`).

``analyze``: per named output (``[[outputs]]``; without any, every scalar joint freedom but the
inputs) its ``min``, ``max``, ``mean`` and ``range`` (max − min) over the samples where the mode
assembles; ``dynamics``: RMS and peak of every input's effort, the shaking force and moment and
every joint's reaction force and moment (:func:`~screwkit.dynamics.graph_inverse.
graph_inverse_dynamics`); ``modes``: every real assembly mode of each design by the
parameter homotopy from the topology's stored start solutions (:mod:`screwkit.sweep.modes_job`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.sweep.jobs import JobOptions, Row, where_text

GRAPH_JOBS = ("analyze", "dynamics", "modes")


def check_graph_job(spec: Any, job: str) -> None:
    """Refuse, before any design runs, a job a graph spec cannot have."""
    if job not in GRAPH_JOBS:
        raise InputError(f"--job {job!r}: a graph spec (bodies and joints) takes "
                         f"{', '.join(GRAPH_JOBS[:-1])} or {GRAPH_JOBS[-1]} in a sweep (docs/sweeps.md, \"Graph specs\")")
    missing = [b.name for b in spec.mechanism.bodies if b.mass is None]
    if job == "dynamics" and missing:
        raise InputError(f"{spec.path}: --job dynamics needs mass properties for every body; "
                         f"{', '.join(missing)} {'has' if len(missing) == 1 else 'have'} none "
                         "(mass, com and inertia in its [[bodies]] entry)")
    if job == "modes":
        from screwkit.errors import CapabilityError
        from screwkit.kinematics.modes.every_mode import closure_formulation

        try:
            closure_formulation(spec.mechanism)
        except CapabilityError as exc:
            raise CapabilityError(f"{spec.path}: --job modes solves every assembly mode by the "
                                  f"homotopy, and {exc}; --job analyze follows the drawn mode "
                                  "of any graph") from None


def graph_outputs(motion: Any) -> dict[str, np.ndarray]:
    """The named outputs of the drawn mode, or every scalar joint freedom but the inputs."""
    md = motion.modes[0]
    if md.outputs:
        return dict(md.outputs)
    inputs = set(motion.mechanism.inputs)
    return {n: v for n, v in md.variables.items()
            if n not in inputs and not n.split(".")[-1].startswith("r")}


def _stats(values: np.ndarray) -> dict[str, float]:
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not v.size:
        return dict.fromkeys(("min", "max", "mean", "range"), float("nan"))
    return {"min": float(v.min()), "max": float(v.max()), "mean": float(v.mean()),
            "range": float(v.max() - v.min())}


def graph_assembly(spec: Any, motion: Any) -> Row:
    """Where the drawn mode assembles (and is not singular) over the inputs."""
    md = motion.modes[0]
    ok = np.asarray(md.assembles) & ~np.asarray(md.singular)
    return {"modes": 1, "assembles": bool(ok.all()), "assembling_samples": int(ok.sum()),
            "where": where_text(spec.inputs[:, 0], ok, spec.input_is_angle)}


def graph_analyze_row(motion: Any) -> Row:
    """Output statistics over the motion (module docstring)."""
    md = motion.modes[0]
    row: Row = {"mode0.assembling_samples": int(np.sum(md.assembles))}
    for name, values in graph_outputs(motion).items():
        for stat, value in _stats(values).items():
            row[f"mode0.{name}.{stat}"] = value
    return row


def graph_dynamics_row(spec: Any, motion: Any, options: JobOptions) -> Row:
    """RMS and peak of every load over the motion (module docstring)."""
    from screwkit.dynamics.graph_inverse import graph_inverse_dynamics

    dyn = graph_inverse_dynamics(motion, 0, spec.gravity_vector if options.gravity else None)
    loads = {f"effort.{n}": dyn.efforts[:, k] for k, n in enumerate(dyn.input_names)}
    loads["shaking_force"] = np.linalg.norm(dyn.shaking_force, axis=1)
    loads["shaking_moment"] = np.linalg.norm(dyn.shaking_moment, axis=1)
    for j, n in enumerate(dyn.joint_names):
        loads[f"{n}.force"] = np.linalg.norm(dyn.reaction_force[:, j], axis=1)
        loads[f"{n}.moment"] = np.linalg.norm(dyn.reaction_moment[:, j], axis=1)
    row: Row = {}
    for name, values in loads.items():
        v = np.abs(np.asarray(values, dtype=float))
        v = v[np.isfinite(v)]
        row[f"{name}.rms"] = float(np.sqrt(np.mean(v ** 2))) if v.size else float("nan")
        row[f"{name}.peak"] = float(v.max()) if v.size else float("nan")
    return row


def graph_row(spec: Any, job: str, options: JobOptions) -> Row:
    """The row of one graph design: where it assembles, then the job's columns. A design whose
    drawn mode does not reach its first input row raises (an AssemblyError: a failed row)."""
    from screwkit.kinematics.graph import solve_mechanism

    if job == "modes":
        from screwkit.sweep.modes_job import modes_row

        return modes_row(spec)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                             accelerations=spec.acceleration)
    row = graph_assembly(spec, motion)
    if job == "dynamics":
        row.update(graph_dynamics_row(spec, motion, options))
    else:
        row.update(graph_analyze_row(motion))
    return row

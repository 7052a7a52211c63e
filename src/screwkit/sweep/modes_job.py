"""The ``modes`` job of a graph sweep (docs/sweeps.md, "Graph specs"): every real assembly mode
of each design, by the parameter homotopy from its topology's stored start solutions (issue 27).

Per design, :func:`~screwkit.kinematics.modes.every_mode.every_mode` solves the drawing's inputs
(all zero: inputs are measured from the drawing) and each row of the spec's inputs in one
batched parameter homotopy (Sommese & Wampler 2005, §7.1) from the start solutions of the
topology (:mod:`screwkit.kinematics.modes.starts`), so each design tracks exactly
``generic_count`` paths per input row. The start solutions are found once, on the sweep's
scheduler side (:func:`sweep_starts`: from memory, the store on disk, or a first solve), and
travel to each worker with the sweep's task (:func:`screwkit.kinematics.modes.starts.install`),
so no worker solves them again.

Columns: ``modes`` the real modes at the drawing, ``modes.certified`` those that passed Smale's
α-test, ``modes.complex`` the distinct complex solutions there; ``modes.min`` and ``modes.max``
over the spec's input rows; ``generic_count``; ``paths_tracked`` the paths the parameter
homotopy started for the design (generic_count × (rows + 1)); ``start_paths`` the paths the
worker tracked to find start solutions while it evaluated the design (0 when they were
shipped or stored); ``continuum_rows`` the rows whose singular ends lie on a curve of solutions.
``assembles`` says whether every row has a real mode, ``assembling_samples`` how many do, and
``where`` over which inputs.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.algebraic.solve import StartSolutions
from screwkit.sweep.jobs import Row, where_text


def sweep_starts(spec: Any) -> dict[str, StartSolutions]:
    """The start solutions of the topology of ``spec``'s mechanism, by topology key: what a
    sweep's scheduler side finds once and ships to its workers. Raises a CapabilityError when
    no polynomial formulation takes the mechanism."""
    from screwkit.kinematics.modes.every_mode import closure_formulation, formulation_start
    from screwkit.kinematics.modes.starts import system_key

    form = closure_formulation(spec.mechanism)
    return {system_key(form.system): formulation_start(form)}


def modes_row(spec: Any) -> Row:
    """The ``modes`` columns of one design (module docstring)."""
    from screwkit.kinematics.modes.every_mode import every_mode
    from screwkit.kinematics.modes.starts import first_solve_paths

    before = first_solve_paths()
    X = np.vstack([np.zeros((1, spec.inputs.shape[1])), spec.inputs])
    found = every_mode(spec.mechanism, X)
    counts = np.array([c.size for c in found.configurations], dtype=np.int64)
    certified = int(np.sum(found.certified[0]))
    rows = counts[1:]
    ok = rows > 0
    return {"modes": int(counts[0]), "assembles": bool(ok.all()),
            "assembling_samples": int(ok.sum()),
            "where": where_text(spec.inputs[:, 0], ok, spec.input_is_angle),
            "modes.certified": certified, "modes.complex": int(found.found[0]),
            "modes.min": int(rows.min()), "modes.max": int(rows.max()),
            "generic_count": int(found.generic_count),
            "paths_tracked": int(found.generic_count) * len(X),
            "start_paths": int(first_solve_paths() - before),
            "continuum_rows": int(found.continuum[1:].sum())}

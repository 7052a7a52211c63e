"""The samples of a simulation as one CSV table (SI units, one row per reported sample): the
motion, the torques, the energy, and every load of the loop from the inverse dynamics."""

from __future__ import annotations

import io

import numpy as np

from screwkit.simulation.reduced import Array
from screwkit.simulation.result import Simulation

#: sample columns and their units
SAMPLE_COLUMNS = (("time", "s"), ("angle", "rad"), ("cycle_angle", "rad"), ("speed", "rad/s"),
                  ("acceleration", "rad/s^2"), ("motor_torque", "N*m"),
                  ("output_force", "N*m or N"), ("load_torque", "N*m"),
                  ("gravity_torque", "N*m"), ("kinetic_energy", "J"))


def simulation_columns(sim: Simulation) -> tuple[list[str], Array]:
    """Column names (``name [unit]``) and values (M, C) of :func:`simulation_csv`."""
    s = sim.samples
    names = [f"{k} [{u}]" for k, u in SAMPLE_COLUMNS]
    cols = [s[k] for k, _ in SAMPLE_COLUMNS]
    if sim.run.cycles:
        dyn = sim.loads
        for name, e in dyn.efforts.items():
            names.append(f"shaft_torque {name} [N*m]")
            cols.append(e)
        for key, arr, unit in (("shaking_force", dyn.shaking_force, "N"),
                               ("shaking_moment", dyn.shaking_moment, "N*m")):
            names += [f"{key}_{a} [{unit}]" for a in "xyz"]
            cols += list(arr.T)
        for joint, r in dyn.reactions.items():
            names += [f"{joint}_force_{a} [N]" for a in "xyz"]
            names += [f"{joint}_moment_{a} [N*m]" for a in "xyz"]
            cols += list(r.force.T) + list(r.moment.T)
    return names, np.stack(cols, axis=1) if cols else np.zeros((0, 0))


def simulation_csv(sim: Simulation) -> str:
    """The CSV text (header line, then one row per sample, ``%.17g``)."""
    names, values = simulation_columns(sim)
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    np.savetxt(buf, values, delimiter=",", fmt="%.17g")
    return buf.getvalue()

"""The samples of a simulation as one table (one row per reported sample): the motion, the
torques, the energy, and every load of the loop from the inverse dynamics — a
:class:`~screwkit.tables.ResultTable`, written by ``screwkit simulate --csv``/``-o`` in the
display units like every other command's table."""

from __future__ import annotations

import numpy as np

from screwkit.simulation.result import Simulation
from screwkit.tables import Column, ResultTable, vector_columns

#: sample columns and their units
SAMPLE_COLUMNS = (("time", "s"), ("angle", "rad"), ("cycle_angle", "rad"), ("speed", "rad/s"),
                  ("acceleration", "rad/s^2"), ("motor_torque", "N*m"),
                  ("output_force", "N*m or N"), ("load_torque", "N*m"),
                  ("friction_torque", "N*m"), ("gravity_torque", "N*m"), ("kinetic_energy", "J"))


def simulation_table(sim: Simulation) -> ResultTable:
    """The reported samples (:data:`SAMPLE_COLUMNS`) as a :class:`~screwkit.tables.ResultTable`
    (each column with its quantity kind, so that ``screwkit simulate --csv`` and ``-o`` show it
    in the display units like every other command): time, angles, speed, acceleration,
    torques, kinetic energy, then the shaft torque, the shaking force and moment and every
    joint reaction with its point of application."""
    s = sim.samples
    load = getattr(sim.eom.drive, "load", None)
    output_kind = ("force" if load is not None and load.freedom.rsplit(".", 1)[-1] == "s"
                   else "moment")
    kinds = {"time": "time", "angle": "angle", "cycle_angle": "angle",
             "speed": "angular_velocity", "acceleration": "angular_acceleration",
             "motor_torque": "moment", "output_force": output_kind, "load_torque": "moment",
             "friction_torque": "moment", "gravity_torque": "moment", "kinetic_energy": "energy"}
    cols = [Column(k, kinds[k], np.asarray(s[k])) for k, _ in SAMPLE_COLUMNS]
    if sim.run.cycles:
        dyn = sim.loads
        for name, e in dyn.efforts.items():
            kind = "force" if name.rsplit(".", 1)[-1] == "s" else "moment"
            cols.append(Column(f"{name}.shaft_torque", kind, e))
        cols += vector_columns("shaking_force", "force", dyn.shaking_force)
        cols += vector_columns("shaking_moment", "moment", dyn.shaking_moment)
        for joint, r in dyn.reactions.items():
            cols += vector_columns(f"{joint}.force", "force", r.force)
            cols += vector_columns(f"{joint}.moment", "moment", r.moment)
            cols += vector_columns(f"{joint}.point", "length", r.point)
    return ResultTable(tuple(cols), "simulation: one row per reported sample")

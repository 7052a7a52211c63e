"""What a simulation reports: per cycle the period, mean, least and greatest speed, the
coefficient of speed fluctuation, the motor's and the load's work and the motor torque's RMS and
peak; the samples (speed against time and angle, torques, energy); and every load of the loop
from the inverse dynamics at the simulated speed and acceleration.

Coefficient of speed fluctuation (e.g. Shigley & Mischke, *Mechanical Engineering Design*,
"flywheels"): C_s = (ω_max − ω_min)/ω_mean, ω_mean = 2π/T the time-average speed over the
cycle. The extremes are refined between the grid samples by the parabola through the three
samples around each (error O(h⁴) in the grid step h)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from screwkit.dynamics import Dynamics
from screwkit.simulation.drive import motor_torque
from screwkit.simulation.integrate import TWO_PI, SimulationRun
from screwkit.simulation.reactions import loop_loads
from screwkit.simulation.reduced import Array


def refined_extremes(values: Array) -> tuple[Array, Array]:
    """Greatest and least value of each row (C, N) of a periodic sampled function, refined by
    the parabola through the sample at the extreme and its two neighbours."""
    def vertex(v: Array) -> Array:
        i = np.argmax(v, axis=1)
        rows = np.arange(v.shape[0])
        n = v.shape[1]
        y0, ym, yp = v[rows, i], v[rows, (i - 1) % n], v[rows, (i + 1) % n]
        curvature = ym - 2.0 * y0 + yp
        safe = np.where(curvature < 0, curvature, -1.0)
        return np.where(curvature < 0, y0 - (yp - ym) ** 2 / (8.0 * safe), y0)

    return vertex(values), -vertex(-values)


@dataclass(frozen=True, eq=False)
class Simulation:
    """The result of ``screwkit simulate`` (module docstring). ``run`` the integration,
    ``samples_per_cycle`` the reported samples per cycle (a divisor of the model grid)."""

    run: SimulationRun
    samples_per_cycle: int

    @property
    def eom(self) -> Any:
        return self.run.eom

    @property
    def flywheel(self) -> float:
        return float(self.run.eom.flywheel)

    @cached_property
    def cycle_statistics(self) -> dict[str, Array]:
        """Per completed cycle (C,): ``period`` (s), ``mean_speed``, ``min_speed``,
        ``max_speed`` (rad/s), ``fluctuation`` C_s, ``motor_work``, ``load_work``,
        ``friction_work`` (J; the joint friction's, ≤ 0),
        ``motor_torque_rms`` (time RMS), ``motor_torque_peak`` (N·m)."""
        r = self.run
        period = np.diff(r.cycle_times)
        mean = TWO_PI / period if period.size else np.zeros(0)
        hi, lo = refined_extremes(r.speed) if r.cycles else (np.zeros(0), np.zeros(0))
        motor = self.eom.drive.motor
        tau = np.abs(motor_torque(motor, np.concatenate([r.speed, hi[:, None], lo[:, None]],
                                                        axis=1)))
        return {"period": period, "mean_speed": mean, "min_speed": lo, "max_speed": hi,
                "fluctuation": (hi - lo) / mean if period.size else np.zeros(0),
                "motor_work": r.cycle_work["motor"], "load_work": r.cycle_work["load"],
                "friction_work": r.cycle_work["friction"],
                "motor_torque_rms": np.sqrt(r.torque_square / period) if period.size
                else np.zeros(0),
                "motor_torque_peak": tau.max(axis=1) if r.cycles else np.zeros(0)}

    def steady(self) -> dict[str, float]:
        """The statistics of the last completed cycle (the steady state once the transient
        has died out)."""
        st = self.cycle_statistics
        if not self.run.cycles:
            return {}
        return {k: float(v[-1]) for k, v in st.items()}

    @property
    def sample_step(self) -> int:
        return int(self.eom.model.grid.size // self.samples_per_cycle)

    @cached_property
    def samples(self) -> dict[str, Array]:
        """The reported samples (M = cycles × samples_per_cycle,), in time order: ``time``,
        ``angle`` (unwrapped, rad), ``cycle_angle`` (from the start of its cycle),
        ``speed``, ``acceleration``, ``motor_torque``, ``output_force`` (Q_out on the load
        freedom), ``load_torque`` (Q_load on the input), ``friction_torque`` (−B θ̇, the joint
        friction on the input), ``gravity_torque``,
        ``kinetic_energy`` (loop + flywheel), ``index`` (grid sample)."""
        r = self.run
        step = self.sample_step
        sel = np.s_[:, ::step]
        angle, speed = r.angle[sel], r.speed[sel]
        terms = self.eom.terms(angle, speed)
        grid = self.eom.model.grid
        idx = np.broadcast_to(np.arange(0, grid.size, step), angle.shape)
        J = self.eom.model.samples["inertia"][idx] + self.flywheel
        out = {"time": r.time[sel], "angle": angle, "cycle_angle": angle - grid[0]
               - TWO_PI * np.arange(r.cycles)[:, None], "speed": speed,
               "acceleration": r.acceleration[sel], "motor_torque": terms["motor"],
               "output_force": terms["output_force"], "load_torque": terms["load"],
               "friction_torque": terms["friction"], "gravity_torque": terms["gravity"],
               "kinetic_energy": 0.5 * J * speed ** 2, "index": idx}
        return {k: np.asarray(v).ravel() for k, v in out.items()}

    @cached_property
    def loads(self) -> Dynamics:
        """Every load of the loop at the reported samples (inverse dynamics at the simulated
        speed and acceleration, with gravity, the output load and the joint friction;
        simulation.reactions)."""
        s = self.samples
        load = self.eom.drive.load
        dyn, _ = loop_loads(self.eom.model, s["index"], s["speed"], s["acceleration"],
                            gravity=self.eom.model.gravity,
                            load_freedom=None if load is None else load.freedom,
                            output_force=s["output_force"], inputs=s["angle"][:, None],
                            friction=self.eom.drive.friction)
        return dyn

    def shaft_torque_check(self) -> float:
        """max |effort − (τ_motor − J_f θ̈)| / max |effort|: the input torque of the inverse
        dynamics against the torque the motor and flywheel put into the loop (two methods)."""
        s = self.samples
        effort = next(iter(self.loads.efforts.values()))
        expected = s["motor_torque"] - self.flywheel * s["acceleration"]
        scale = max(float(np.max(np.abs(effort))), float(np.max(np.abs(expected))), 1e-300)
        return float(np.max(np.abs(effort - expected)) / scale)

    def as_dict(self, *, loads: bool = True) -> dict[str, Any]:
        """JSON-able document (SI units; docs/simulation.md)."""
        m = self.eom.model
        J = m.samples["inertia"]
        doc: dict[str, Any] = {
            "units": {"time": "s", "angle": "rad", "speed": "rad/s", "torque": "N*m",
                      "energy": "J", "inertia": "kg*m^2"},
            "status": self.run.status, "message": self.run.message,
            "flywheel": self.flywheel, "initial_speed": self.run.initial_speed,
            "model": {"mode": m.mode_index, "grid_samples": int(m.grid.size),
                      "harmonics": m.series.harmonics, "converged": m.converged,
                      "interpolation_error": m.interpolation_error,
                      "inertia_mean": m.mean_inertia(), "inertia_min": float(J.min()),
                      "inertia_max": float(J.max())},
            "energy_error": self.run.energy_error,
            "cycles": [{"cycle": k + 1, **{n: float(v[k]) for n, v in
                                           self.cycle_statistics.items()}}
                       for k in range(self.run.cycles)],
            "steady": self.steady(),
            "samples": {k: v for k, v in self.samples.items() if k != "index"},
        }
        if loads and self.run.cycles:
            doc["loads"] = self.loads.as_dict()
            doc["shaft_torque_check"] = self.shaft_torque_check()
        return doc

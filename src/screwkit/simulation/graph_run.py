"""Forward integration of a mechanism graph's equations of motion
(:mod:`screwkit.simulation.graph_eom`) over a time span, sampled at equal times.

The state is (x, ẋ, W_motor, W_friction, W_load): the input coordinates and rates, and the work
of the motors, of the joint friction and of the ``[drive.load]`` integrated with the motion to
the same tolerance, so the energy balance E(t) − E(0) = W_motor + W_friction + W_load is checked at every sample without quadrature.
scipy's ``solve_ivp`` (DOP853, the single-loop path's integrator) runs from one sample time to
the next; every right-hand side closes the loops by the graph Newton from the configuration last
closed (the projection onto the constraint manifold: the passive freedoms are never states, so
neither the position nor the velocity closure can drift), and a run that reaches a dead centre
or stops assembling ends there with a message saying when and where.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import solve_ivp

from screwkit.messages import given
from screwkit.simulation.graph_eom import Array, GraphEquationOfMotion
from screwkit.simulation.reduced import SimulationError

#: most samples a run reports (each is one restart of the integrator and one closure)
MAX_SAMPLES = 100_000
#: right-hand sides per reported sample at the least (a DOP853 step of 12 stages and the
#: restart's first-step estimate): the time check is a lower bound, refused only when even it
#: is over the limit
CALLS_PER_SAMPLE = 14
#: one right-hand side (closure, partial rates, accelerations) in units of the graph
#: kinematics' per-sample cost (measured: ~1.4 ms for the Watt six-bar, 25 × its 56 µs)
EVALUATION_COST = 25.0


@dataclass(frozen=True, eq=False)
class GraphSimulation:
    """One run (SI): ``time`` (K,), ``inputs``/``rates``/``accelerations``/``motor``/
    ``friction``/``load`` (K, n) per input, ``kinetic_energy``/``potential_energy``/
    ``motor_work``/``friction_work``/``load_work`` (K,), ``output_force`` (K,) the load on its
    freedom, ``load_work`` that of the load and of the ``[drive.point_force]``,
    ``closure_residual`` (K,) the scaled loop residual of each sample,
    ``energy_error`` the largest |E − E₀ − W_motor − W_friction − W_load| relative to the
    energy scale of the run, ``status`` ``"completed"`` or ``"stopped"`` with a ``message``."""

    input_names: tuple[str, ...]
    time: Array
    inputs: Array
    rates: Array
    accelerations: Array
    motor: Array
    friction: Array
    kinetic_energy: Array
    potential_energy: Array
    motor_work: Array
    friction_work: Array
    closure_residual: Array
    energy_error: float
    status: str
    message: str
    load: Array | None = None
    output_force: Array | None = None
    load_work: Array | None = None
    load_freedom: str | None = None

    def as_dict(self) -> dict[str, Any]:
        per_input = {n: {"value": self.inputs[:, k], "rate": self.rates[:, k],
                         "acceleration": self.accelerations[:, k],
                         "motor": self.motor[:, k], "friction": self.friction[:, k],
                         **({} if self.load is None else {"load": self.load[:, k]})}
                     for k, n in enumerate(self.input_names)}
        extra = ({} if self.load_work is None else
                 {"output_force": self.output_force, "load_work": self.load_work,
                  "load_freedom": self.load_freedom})
        return {"status": self.status, "message": self.message, "time": self.time,
                "inputs": per_input, "kinetic_energy": self.kinetic_energy,
                "potential_energy": self.potential_energy, "motor_work": self.motor_work,
                "friction_work": self.friction_work, **extra,
                "closure_residual": self.closure_residual,
                "energy_error": self.energy_error,
                "units": {"time": "s", "angle": "rad", "length": "m", "energy": "J",
                          "torque": "N*m", "force": "N"}}


def _check(eom: GraphEquationOfMotion, duration: float, samples: int, x0: Array, v0: Array
           ) -> None:
    name = eom.mechanism.name
    if not (np.isfinite(duration) and duration > 0):
        raise SimulationError(f"{name}: the simulated duration must be > 0 s; got {duration!r}")
    if not 2 <= samples <= MAX_SAMPLES:
        raise SimulationError(f"{name}: report between 2 and {MAX_SAMPLES} samples; got "
                              f"{samples}")
    n = eom.inputs
    mech = eom.mechanism
    from screwkit.budget import check_time
    from screwkit.kinematics.graph.motion import SECONDS_PER_JOINT_SAMPLE

    loops = len(mech.topology.loops)
    per_call = EVALUATION_COST * SECONDS_PER_JOINT_SAMPLE * len(mech.joints) * (1 + 0.3 * loops)
    check_time(samples * CALLS_PER_SAMPLE * per_call, f"simulating {name} over {samples} samples",
               "report fewer samples ([drive] samples)")
    for what, v in (("initial inputs", x0), ("initial rates", v0)):
        if v.shape != (n,) or not np.all(np.isfinite(v)):
            raise SimulationError(f"{name}: give {n} finite {what} (one per input "
                                  f"{', '.join(eom.mechanism.inputs)}); got {given(v)}")


def simulate_graph(eom: GraphEquationOfMotion, *, duration: float, samples: int = 201,
                   initial_inputs: ArrayLike | None = None,
                   initial_rates: ArrayLike | None = None, rtol: float = 1e-10,
                   atol: float | None = None) -> GraphSimulation:
    """Integrate from ``initial_inputs`` (default the drawing, 0) at ``initial_rates``
    (default at rest) for ``duration`` seconds, reporting ``samples`` equal steps (module
    docstring). ``atol`` (rad, rad/s; m, m/s on slides) defaults to ``rtol``."""
    n = eom.inputs
    x0 = np.zeros(n) if initial_inputs is None else np.asarray(initial_inputs, dtype=float)
    v0 = np.zeros(n) if initial_rates is None else np.asarray(initial_rates, dtype=float)
    x0, v0 = x0 * np.ones(n), v0 * np.ones(n)
    _check(eom, duration, samples, x0, v0)
    times = np.linspace(0.0, float(duration), int(samples))
    eom.start_at(x0)

    def rhs(t: float, y: Array) -> Array:
        T = eom.terms(y[:n], y[n:2 * n])
        xd = y[n:2 * n]
        return np.concatenate([xd, T["acceleration"], [T["motor"] @ xd, T["friction"] @ xd,
                                                       T["load"] @ xd]])

    rows: list[dict[str, Any]] = []
    y = np.concatenate([x0, v0, [0.0, 0.0, 0.0]])
    status, message = "completed", f"simulated {duration:.6g} s"
    a_tol = rtol if atol is None else atol
    step = None
    for k, t in enumerate(times):
        if k:
            try:
                res = solve_ivp(rhs, (times[k - 1], t), y, method="DOP853", rtol=rtol,
                                atol=a_tol, first_step=step)
            except SimulationError as exc:
                status, message = "stopped", f"stopped between t = {times[k - 1]:.6g} s and " \
                                             f"t = {t:.6g} s: {exc}"
                break
            if res.status == -1:
                raise SimulationError(f"{eom.mechanism.name}: the integration failed: "
                                      f"{res.message}")
            y = res.y[:, -1]
            if res.t.size > 2:
                step = float(np.min(np.diff(res.t[-3:])))
        try:
            T = eom.terms(y[:n], y[n:2 * n])
        except SimulationError as exc:
            status, message = "stopped", f"stopped at t = {t:.6g} s: {exc}"
            break
        rows.append({"t": t, "y": y.copy(), **T})
    return _result(eom, rows, status, message)


def _result(eom: GraphEquationOfMotion, rows: list[dict[str, Any]], status: str, message: str
            ) -> GraphSimulation:
    n = eom.inputs
    if not rows:
        raise SimulationError(f"{eom.mechanism.name}: {message}")

    def col(key: str) -> Array:
        return np.array([r[key] for r in rows], dtype=float)

    y = np.array([r["y"] for r in rows])
    kinetic, potential = col("kinetic_energy"), col("potential_energy")
    w_motor, w_friction, w_load = y[:, 2 * n], y[:, 2 * n + 1], y[:, 2 * n + 2]
    balance = kinetic + potential - kinetic[0] - potential[0] - w_motor - w_friction - w_load
    scale = max(float(np.max(kinetic)), float(np.ptp(potential)), float(np.max(np.abs(w_motor))),
                float(np.max(np.abs(w_friction))), float(np.max(np.abs(w_load))), 1e-300)
    loaded = eom.load is not None or eom.point_force is not None
    return GraphSimulation(
        tuple(eom.mechanism.inputs), col("t"), y[:, :n], y[:, n:2 * n], col("acceleration"),
        col("motor"), col("friction"), kinetic, potential, w_motor, w_friction, col("residual"),
        float(np.max(np.abs(balance)) / scale), status, message,
        col("load") if loaded else None, col("output_force") if loaded else None,
        w_load if loaded else None, eom.load.freedom if eom.load is not None else None)

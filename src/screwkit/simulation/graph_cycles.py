"""Crank cycles of a one-input mechanism graph: cycle statistics, the steady state and flywheel
sizing, by direct integration of the graph's equations of motion
(:mod:`screwkit.simulation.graph_eom`; no tabulated model).

**Cycles.** The state is (x, ẋ, W_motor, W_friction, W_load, ∫τ² dt); scipy's ``solve_ivp``
(DOP853, dense output) runs one cycle at a time from the start angle x₀ until the terminal
event x = x₀ ± 2π(k + 1) (the direction of the initial rate), or a stall (ẋ = 0). Per cycle:
the period T, the mean speed 2π/T, the least and greatest speed, the coefficient of speed
fluctuation C_s = (ω_max − ω_min)/ω_mean (as a loop's, docs/simulation.md), the works and the
motor's RMS and peak torque. The extremes of the speed are taken from the dense output at
:data:`POINTS_PER_STEP` points in every integrator step (its own 7th-order interpolant, no new
right-hand sides), refined by the parabola through the extreme and its two neighbours: the
error is far below the sizing tolerance (the points are ~1e-3 of a cycle apart, and the vertex
of the parabola is exact to third order in that spacing).

**Steady state.** The cycle map P(ω₀) (the speed after one turn from x₀ at ω₀) has the steady
speed as its fixed point; the secant method on P(ω₀) − ω₀ from the initial speed and the speed
after one turn (P is close to linear near the fixed point: a few cycles). When the motor's work
per turn balances the load at every speed (P(ω₀) = ω₀ for all ω₀), the orbit through the
initial speed is taken.

**Flywheel sizing** (the loop's method, :mod:`screwkit.simulation.flywheel`): C_s falls as
1/(J(x) + J_f) to first order, so the secant method on 1/C_s(J_f) − 1/δ, started at J_f = 0 and
at J_f = J(x₀)(C_s(0)/δ − 1), finds the flywheel whose steady C_s is δ to :data:`SIZING_RTOL`
(relative). Only a mechanism with one rotating input has crank cycles: a mechanism with several
inputs has no single period, and is refused with that reason.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from screwkit.messages import listing
from screwkit.simulation.drive import motor_torque
from screwkit.simulation.flywheel import secant_flywheel
from screwkit.simulation.graph_eom import Array, GraphEquationOfMotion
from screwkit.simulation.reduced import SimulationError

TWO_PI = 2.0 * np.pi
#: dense-output points per integrator step where the speed's extremes are sought
POINTS_PER_STEP = 8
#: the longest step is the initial period over this (a ~0.2 rad turn of the crank)
MAX_STEP_FRACTION = 32
#: relative agreement |P(ω₀) − ω₀|/ω₀ of a steady cycle
STEADY_RTOL = 1e-9


def crank_input(eom: GraphEquationOfMotion) -> str:
    """The one rotating input whose turns are the cycles; a clear error otherwise."""
    mech = eom.mechanism
    if eom.inputs != 1:
        raise SimulationError(
            f"{mech.name}: crank cycles (statistics, --fluctuation) need one input that "
            f"turns; this mechanism has {eom.inputs} inputs ({listing(mech.inputs)}), which have "
            "no common period (simulate for [drive] duration instead)")
    name = mech.inputs[0]
    if name.endswith(".s"):
        raise SimulationError(f"{mech.name}: crank cycles need a rotating input; "
                              f"{name!r} is a slide (simulate for [drive] duration instead)")
    return name


@dataclass(frozen=True, eq=False)
class GraphCycles:
    """A cycles run (SI). ``cycle_times`` (C + 1,) from 0; per completed cycle (C,):
    ``period``, ``mean_speed``, ``min_speed``, ``max_speed``, ``fluctuation``, ``motor_work``,
    ``friction_work``, ``load_work``, ``motor_torque_rms``, ``motor_torque_peak``; the end
    state ``end`` (x, ẋ); ``energy_error`` the largest |E − E₀ − W| over the cycle ends relative
    to the energy scale; ``status`` ``completed``, ``stalled`` or ``stopped``; ``flywheel``;
    ``samples`` (when asked for: ``time``, ``angle``, ``cycle_angle`` — the turn from the start
    of its cycle in the sense of rotation, in [0, 2π) — ``speed`` and ``motor_torque`` at equal
    time steps in every completed cycle, from the dense output; not in ``as_dict``)."""

    input_name: str
    flywheel: float
    cycle_times: Array
    statistics: dict[str, Array]
    end: tuple[float, float]
    energy_error: float
    status: str
    message: str
    samples: dict[str, Array] | None = None

    @property
    def cycles(self) -> int:
        return int(self.cycle_times.size - 1)

    def steady(self) -> dict[str, float]:
        """The statistics of the last completed cycle."""
        if not self.cycles:
            return {}
        return {k: float(v[-1]) for k, v in self.statistics.items()}

    def as_dict(self) -> dict[str, Any]:
        return {"status": self.status, "message": self.message, "input": self.input_name,
                "flywheel": self.flywheel, "energy_error": self.energy_error,
                "cycle_times": self.cycle_times, "cycles": self.statistics,
                "steady": self.steady(),
                "units": {"time": "s", "speed": "rad/s", "work": "J", "torque": "N*m"}}


def _extremes(t: Array, w: Array) -> tuple[float, float]:
    """Greatest and least of samples ``w`` at times ``t``, refined at an interior extreme by
    the parabola through it and its two neighbours."""
    def top(v: Array) -> float:
        i = int(np.argmax(v))
        if 0 < i < v.size - 1:
            (t0, t1, t2), (y0, y1, y2) = t[i - 1:i + 2], v[i - 1:i + 2]
            # vertex of the parabola through the three points (unequal spacing)
            d1, d2 = (y1 - y0) / (t1 - t0), (y2 - y1) / (t2 - t1)
            a = (d2 - d1) / (t2 - t0)
            if a < 0:
                b = d1 - a * (t1 + t0)
                tv = -b / (2 * a)
                if t0 <= tv <= t2:
                    return float(y1 + a * (tv - t1) ** 2 + (b + 2 * a * t1) * (tv - t1))
        return float(v[i])

    return top(w), -top(-w)


def _cycle_statistics(res: Any, t: float, t_end: float, y: Array, y_end: Array,
                      motor: Any, sense: float) -> dict[str, float]:
    """One cycle's statistics (module docstring) from its ``solve_ivp`` result ``res`` (dense
    output) between ``t`` (state ``y``) and ``t_end`` (state ``y_end``)."""
    ts = np.asarray(res.sol.ts)
    ts = ts[ts <= t_end]
    fine = np.concatenate([np.linspace(a, b, POINTS_PER_STEP, endpoint=False)
                           for a, b in zip(ts[:-1], ts[1:], strict=True)] + [[t_end]])
    speed = res.sol(fine)[1]
    hi, lo = _extremes(fine, speed)
    T_k = t_end - t
    dy = y_end - y
    tau = np.abs(motor_torque(motor, np.array([*speed, hi, lo])))
    mean = TWO_PI / T_k
    return {"period": T_k, "mean_speed": sense * mean, "min_speed": lo, "max_speed": hi,
            "fluctuation": (hi - lo) / mean, "motor_work": float(dy[2]),
            "friction_work": float(dy[3]), "load_work": float(dy[4]),
            "motor_torque_rms": float(np.sqrt(dy[5] / T_k)),
            "motor_torque_peak": float(tau.max())}


#: what ``GraphCycles.samples`` holds, in this order
SAMPLE_KEYS = ("time", "angle", "cycle_angle", "speed", "motor_torque")


def _cycle_samples(res: Any, t: float, t_end: float, start: float, sense: float, motor: Any,
                   n: int) -> Array:
    """``n`` samples (rows: :data:`SAMPLE_KEYS`) at equal time steps of the cycle from ``t``
    (input ``start``) to ``t_end``, read from the dense output ``res.sol``."""
    ts = np.linspace(t, t_end, n, endpoint=False)
    xs, ws = res.sol(ts)[:2]
    return np.vstack([ts, xs, sense * (xs - start), ws, motor_torque(motor, ws)])


def _stack_samples(kept: list[Array]) -> dict[str, Array]:
    return dict(zip(SAMPLE_KEYS, np.hstack(kept) if kept else np.zeros((5, 0)), strict=True))


def simulate_graph_cycles(eom: GraphEquationOfMotion, *, cycles: int, initial_rate: float,
                          initial_input: float = 0.0, rtol: float = 1e-10,
                          atol: float | None = None, max_time: float | None = None,
                          samples_per_cycle: int = 0) -> GraphCycles:
    """Integrate ``cycles`` turns of the crank from ``initial_input`` at ``initial_rate``
    (module docstring); ``samples_per_cycle`` > 0 keeps that many samples of every completed
    cycle (``GraphCycles.samples``, from the dense output: no new right-hand sides)."""
    name = crank_input(eom)
    if not (np.isfinite(initial_rate) and initial_rate != 0):
        raise SimulationError(f"{eom.mechanism.name}: crank cycles need a nonzero initial "
                              f"rate of {name}; got {initial_rate!r} rad/s")
    if not 1 <= cycles <= 100_000:
        raise SimulationError(f"simulate between 1 and 100000 cycles; got {cycles}")
    x0, w0 = float(initial_input), float(initial_rate)
    sense = float(np.sign(w0))
    eom.start_at([x0])
    first = eom.terms([x0], [w0])
    energy = max(first["kinetic_energy"], 1e-300)
    period = TWO_PI / abs(w0)
    scales = np.array([TWO_PI, abs(w0), energy, energy, energy, energy ** 2 / period])
    atol_v = rtol * scales
    if atol is not None:
        atol_v[:2] = atol
    t_limit = max_time if max_time is not None else 1000.0 * cycles * period
    motor = eom.motors[0]

    def rhs(t: float, y: Array) -> Array:
        T = eom.terms(y[:1], y[1:2])
        w, tau = y[1], float(T["motor"][0])
        return np.array([w, T["acceleration"][0], tau * w, T["friction"][0] * w,
                         T["load"][0] * w, tau * tau])

    def stall(t: float, y: Array) -> float:
        return float(y[1] * sense)

    stall.terminal = True  # type: ignore[attr-defined]
    stall.direction = -1.0  # type: ignore[attr-defined]
    y = np.array([x0, w0, 0.0, 0.0, 0.0, 0.0])
    times, stats, ends = [0.0], [], [y.copy()]
    kept: list[Array] = []
    e0 = first["kinetic_energy"] + first["potential_energy"]
    balance = [0.0]
    # the first step, and the longest: short enough that the closure's first-order predictor
    # stays near the assembly branch (graph_eom.BRANCH_JUMP) even on a rejected trial step
    status, message, step = "completed", f"{cycles} cycle(s) simulated", 1e-3 * period
    t = 0.0
    for k in range(cycles):
        target = x0 + sense * TWO_PI * (k + 1)

        def hit(t: float, yy: Array, target: float = target) -> float:
            return float(yy[0] - target)

        hit.terminal = True  # type: ignore[attr-defined]
        try:
            res = solve_ivp(rhs, (t, t_limit), y, method="DOP853", rtol=rtol, atol=atol_v,
                            events=(hit, stall), dense_output=True, first_step=step,
                            max_step=period / MAX_STEP_FRACTION)
        except SimulationError as exc:
            status, message = "stopped", f"stopped during cycle {k + 1}: {exc}"
            break
        if res.status == -1:
            raise SimulationError(f"{eom.mechanism.name}: the integration failed: "
                                  f"{res.message}")
        if not res.t_events[0].size:
            if res.t_events[1].size:
                status = "stalled"
                message = (f"the input stopped (rate 0) at t = {res.t_events[1][0]:.6g} s "
                           f"during cycle {k + 1}: the motor cannot drive the mechanism "
                           "through its load")
            else:
                status = "max_time"
                message = f"only {k} of {cycles} cycle(s) completed in {t_limit:.6g} s"
            break
        t_end = float(res.t_events[0][0])
        y_end = res.y_events[0][0]
        stats.append(_cycle_statistics(res, t, t_end, y, y_end, motor, sense))
        if samples_per_cycle > 0:
            kept.append(_cycle_samples(res, t, t_end, target - sense * TWO_PI, sense, motor,
                                       samples_per_cycle))
        try:
            T = eom.terms(y_end[:1], y_end[1:2])
        except SimulationError as exc:
            status, message = "stopped", f"stopped at the end of cycle {k + 1}: {exc}"
            break
        balance.append(T["kinetic_energy"] + T["potential_energy"] - e0
                       - float(np.sum(y_end[2:5])))
        step = float(np.min(np.diff(res.t[-3:]))) if res.t.size > 2 else step
        t, y = t_end, np.asarray(y_end, dtype=float).copy()
        y[0] = target  # the event's root, to round-off
        times.append(t)
        ends.append(y.copy())
    keys = ("period", "mean_speed", "min_speed", "max_speed", "fluctuation", "motor_work",
            "friction_work", "load_work", "motor_torque_rms", "motor_torque_peak")
    table = {key: np.array([s[key] for s in stats], dtype=float) for key in keys}
    work = np.abs(np.array(ends)[:, 2:5]).max() if ends else 0.0
    scale = max(energy, float(work), 1e-300)
    return GraphCycles(name, float(eom.flywheel[0]), np.array(times), table,
                       (float(y[0]), float(y[1])), float(np.max(np.abs(balance)) / scale),
                       status, message, _stack_samples(kept) if samples_per_cycle else None)


def with_graph_flywheel(eom: GraphEquationOfMotion, flywheel: float) -> GraphEquationOfMotion:
    """The same equations of motion with flywheel ``flywheel`` on the input."""
    return GraphEquationOfMotion(eom.mechanism, motors=eom.motors, flywheel=flywheel,
                                 friction=eom.friction, gravity=eom.gravity, load=eom.load,
                                 point_force=eom.point_force)


def steady_graph_cycle(eom: GraphEquationOfMotion, guess: float, *, initial_input: float = 0.0,
                       rtol: float = 1e-10) -> GraphCycles:
    """One cycle of the steady state (module docstring), found from the speed ``guess``."""
    def one(w: float) -> GraphCycles:
        run = simulate_graph_cycles(eom, cycles=1, initial_rate=w,
                                    initial_input=initial_input, rtol=rtol)
        if run.status != "completed":
            raise SimulationError(f"{eom.mechanism.name}: no steady state near "
                                  f"{guess:.6g} rad/s: {run.message}")
        return run

    a, run_a = guess, one(guess)
    fa = run_a.end[1] - a
    if abs(fa) <= STEADY_RTOL * abs(a):
        return run_a
    b = run_a.end[1]
    run_b = one(b)
    fb = run_b.end[1] - b
    for _ in range(40):
        if abs(fb) <= STEADY_RTOL * abs(b):
            return run_b
        if fb == fa:
            break
        a, fa, b = b, fb, b - fb * (b - a) / (fb - fa)
        if not np.sign(b) == np.sign(guess):
            break
        run_b = one(b)
        fb = run_b.end[1] - b
    raise SimulationError(f"{eom.mechanism.name}: no steady state found from "
                          f"{guess:.6g} rad/s (the speed after a turn keeps changing: "
                          f"{fb:.3g} rad/s at {b:.6g} rad/s)")


@dataclass(frozen=True, eq=False)
class GraphFlywheelSizing:
    """The result of :func:`size_graph_flywheel`: the ``flywheel`` (kg·m²) whose steady
    fluctuation ``achieved`` matches the ``requested`` one, the first ``estimate``, the
    secant ``iterations`` and the ``steady`` cycle with that flywheel."""

    requested: float
    flywheel: float
    achieved: float
    estimate: float
    iterations: list[dict[str, float]]
    steady: GraphCycles

    def as_dict(self) -> dict[str, Any]:
        return {"requested_fluctuation": self.requested, "flywheel": self.flywheel,
                "achieved_fluctuation": self.achieved, "estimate": self.estimate,
                "iterations": self.iterations, "steady": self.steady.steady()}


def size_graph_flywheel(eom: GraphEquationOfMotion, fluctuation: float, guess: float, *,
                        initial_input: float = 0.0, rtol: float = 1e-10
                        ) -> GraphFlywheelSizing:
    """The flywheel on the crank whose steady-state C_s is ``fluctuation`` (module
    docstring); ``guess`` the speed the steady-state search starts from."""
    crank_input(eom)
    if not 0 < fluctuation < 1:
        raise SimulationError(f"--fluctuation must be between 0 and 1 (e.g. 0.02); got "
                              f"{fluctuation}")
    history: list[dict[str, float]] = []
    cache: dict[float, GraphCycles] = {}
    speed = [guess]

    def fluct(jf: float) -> float:
        run = steady_graph_cycle(with_graph_flywheel(eom, jf), speed[0],
                                 initial_input=initial_input, rtol=rtol)
        speed[0] = run.end[1]
        cache[jf] = run
        c = run.steady()["fluctuation"]
        history.append({"flywheel": jf, "fluctuation": c})
        return c

    base = float(eom.flywheel[0])
    c0 = fluct(base)
    if c0 <= fluctuation:
        return GraphFlywheelSizing(fluctuation, base, c0, base, history, cache[base])
    plain = with_graph_flywheel(eom, 0.0)
    plain.start_at([initial_input])
    inertia = float(plain.terms([initial_input], [guess])["mass_matrix"][0, 0])
    estimate = max((inertia + base) * c0 / fluctuation - inertia, 1e-12)
    b, achieved = secant_flywheel(fluct, base, c0, estimate, fluctuation)
    return GraphFlywheelSizing(fluctuation, b, achieved, estimate, history, cache[b])


"""Steady state and flywheel sizing.

**Steady state.** The cycle map P(ω_0) — the input speed after one turn from the start angle at
speed ω_0 — has the steady running speed as its fixed point P(ω*) = ω*, found by Brent's method
on P(ω_0) − ω_0 (shooting). When P(ω_0) = ω_0 for every ω_0 (a constant-torque motor whose work
per cycle exactly balances a speed-independent load) every speed is steady: the orbit through
the initial speed is taken.

**Flywheel sizing** (e.g. Shigley & Mischke, *Mechanical Engineering Design*, "flywheels";
Norton, *Design of Machinery*, ch. 11). Energy method first: at the mean speed ω_m where the
motor's mean torque balances the load's, the net torque at constant speed
τ(θ) = τ_motor(ω_m) + Q_g + Q_load − ½ J′ ω_m² integrates to the energy fluctuation
ΔE = max E − min E, E(θ) = ∫ τ dθ, and J_total = ΔE/(δ ω_m²), so J_f ≈ J_total − J_mean. The
estimate is then refined by simulation: the secant method on 1/C_s(J_f) (nearly linear in J_f)
until the steady-state coefficient C_s is within :data:`SIZING_RTOL` of the request δ."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import brentq

from screwkit.messages import shown
from screwkit.simulation.drive import EquationOfMotion, motor_torque, output_force
from screwkit.simulation.integrate import simulate_cycles
from screwkit.simulation.reduced import Array, SimulationError
from screwkit.simulation.result import Simulation

#: relative agreement of the sized flywheel's steady fluctuation with the request
SIZING_RTOL = 1e-3
#: secant iterations of the refinement
SIZING_STEPS = 30


def with_flywheel(eom: EquationOfMotion, flywheel: float) -> EquationOfMotion:
    return EquationOfMotion(eom.model, eom.drive, flywheel)


def _mean_generalised_force(eom: EquationOfMotion, speed: float) -> float:
    """Mean over one turn of the motor + load + joint-friction torque at constant input speed
    (the gravity and inertia terms average to zero over a turn)."""
    grid = eom.model.grid
    t = eom.terms(grid, np.full(grid.size, speed))
    return float(np.mean(t["motor"] + t["load"] + t["friction"]))


def balanced_speed(eom: EquationOfMotion, guess: float) -> float | None:
    """The constant speed at which the motor's mean torque balances the load's; None when the
    balance does not depend on speed (neutral) — raises when there is no such speed."""
    f = [_mean_generalised_force(eom, w) for w in (0.5 * guess, guess, 2.0 * guess)]
    scale = max(max(abs(x) for x in f), 1e-300)
    probe = abs(float(np.max(motor_torque(eom.drive.motor, [guess])))) + 1e-300
    if max(f) - min(f) < 1e-9 * max(scale, probe):
        if abs(f[1]) > 1e-6 * max(scale, probe):
            raise SimulationError(
                f"no steady state: the motor's work per turn does not balance the load's at any "
                f"speed (mean net torque {shown(f[1], 'moment')}, independent of speed); use a motor "
                "whose torque falls with speed (kind = \"linear\" or \"table\"), a damping "
                "load, or a motor torque that balances the load")
        return None
    lo, hi = 1e-3 * guess, guess
    for _ in range(60):
        if _mean_generalised_force(eom, lo) > 0 > _mean_generalised_force(eom, hi):
            return float(brentq(lambda w: _mean_generalised_force(eom, w), lo, hi, xtol=1e-12,
                                rtol=1e-12))
        hi *= 2.0
    raise SimulationError("no steady state: the motor's mean torque exceeds the load at every "
                          "speed tried (it would run away); add a load or a speed-limited motor")


def steady_simulation(eom: EquationOfMotion, guess: float, *, rtol: float = 1e-10
                      ) -> Simulation:
    """One cycle of the steady state (module docstring), as a :class:`Simulation`."""
    def after_one_turn(w0: float) -> float:
        run = simulate_cycles(eom, cycles=1, initial_speed=w0, rtol=rtol)
        if run.status != "completed":
            return -w0  # stalled: the speed after a turn is below any start speed
        return run.end[2] - w0

    w_m = balanced_speed(eom, guess)
    if w_m is None:
        w0 = guess
    else:
        lo, hi = 0.8 * w_m, 1.25 * w_m
        f_lo, f_hi = after_one_turn(lo), after_one_turn(hi)
        for _ in range(40):
            if f_lo > 0 > f_hi:
                break
            if f_lo <= 0:
                lo, f_lo = lo * 0.8, after_one_turn(lo * 0.8)
            if f_hi >= 0:
                hi, f_hi = hi * 1.25, after_one_turn(hi * 1.25)
        else:
            raise SimulationError("no steady state found by shooting around the balanced "
                                  f"speed {shown(w_m, 'angular_velocity')}")
        w0 = float(brentq(after_one_turn, lo, hi, xtol=1e-13 * hi, rtol=1e-13))
    run = simulate_cycles(eom, cycles=1, initial_speed=w0, rtol=rtol)
    if run.status != "completed":
        raise SimulationError(f"no steady state: {run.message}")
    return Simulation(run, int(eom.drive.samples_per_cycle))


def energy_estimate(eom: EquationOfMotion, fluctuation: float, speed: float) -> dict[str, float]:
    """The energy method (module docstring) at mean speed ``speed``: ΔE (J), J_total and the
    flywheel estimate (kg·m²)."""
    grid = eom.model.grid
    t = eom.terms(grid, np.full(grid.size, speed))
    net = (t["motor"] + t["gravity"] + t["load"] + t["friction"]
           - 0.5 * t["inertia_slope"] * speed ** 2)
    net = net - np.mean(net)  # the steady state: the work per turn balances
    h = grid[1] - grid[0]
    energy = np.concatenate([[0.0], np.cumsum(0.5 * (net + np.roll(net, -1)) * h)])
    delta_e = float(energy.max() - energy.min())
    total = delta_e / (fluctuation * speed ** 2)
    return {"energy_fluctuation": delta_e, "speed": speed, "total_inertia": total,
            "flywheel": max(total - eom.model.mean_inertia(), 0.0)}


@dataclass(frozen=True, eq=False)
class FlywheelSizing:
    """The result of :func:`size_flywheel`: the ``flywheel`` (kg·m²) whose steady fluctuation
    ``achieved`` matches the ``requested`` one, the energy-method ``estimate`` and the
    ``steady`` simulation with that flywheel; ``iterations`` of the refinement."""

    requested: float
    flywheel: float
    achieved: float
    estimate: dict[str, float]
    iterations: list[dict[str, float]]
    steady: Simulation

    def as_dict(self) -> dict[str, Any]:
        return {"requested_fluctuation": self.requested, "flywheel": self.flywheel,
                "achieved_fluctuation": self.achieved, "energy_method": self.estimate,
                "iterations": self.iterations, "steady": self.steady.steady()}


def size_flywheel(eom: EquationOfMotion, fluctuation: float, guess_speed: float
                  ) -> FlywheelSizing:
    """The smallest flywheel inertia on the input shaft whose steady-state coefficient of speed
    fluctuation is at most ``fluctuation`` (module docstring)."""
    if not 0 < fluctuation < 1:
        raise SimulationError(f"--fluctuation must be between 0 and 1 (e.g. 0.02); got "
                              f"{fluctuation}")
    w_m = balanced_speed(eom, guess_speed)
    estimate = energy_estimate(eom, fluctuation, guess_speed if w_m is None else w_m)
    history: list[dict[str, float]] = []
    cache: dict[float, Simulation] = {}

    def fluct(jf: float) -> float:
        sim = steady_simulation(with_flywheel(eom, jf), guess_speed if w_m is None else w_m)
        cache[jf] = sim
        c = sim.steady()["fluctuation"]
        history.append({"flywheel": jf, "fluctuation": c})
        return c

    c0 = fluct(0.0)
    if c0 <= fluctuation:
        return FlywheelSizing(fluctuation, 0.0, c0, estimate, history, cache[0.0])
    b, achieved = secant_flywheel(
        fluct, 0.0, c0, max(estimate["flywheel"], 1e-3 * estimate["total_inertia"], 1e-12),
        fluctuation)
    return FlywheelSizing(fluctuation, b, achieved, estimate, history, cache[b])


def secant_flywheel(fluct: Callable[[float], float], a: float, c_a: float, b: float,
                    fluctuation: float) -> tuple[float, float]:
    """The flywheel J_f whose steady fluctuation ``fluct(J_f)`` is ``fluctuation``, to
    :data:`SIZING_RTOL`, and that fluctuation: the secant method on 1/C_s(J_f) − 1/δ (nearly
    linear in J_f, C_s ∝ 1/J), from ``a`` (with its fluctuation ``c_a``) and the estimate ``b``,
    never stepping below half the last flywheel; a run that does not get there is an error."""
    c_b = fluct(b)
    ha, hb = 1.0 / c_a - 1.0 / fluctuation, 1.0 / c_b - 1.0 / fluctuation
    for _ in range(SIZING_STEPS):
        if abs(c_b / fluctuation - 1.0) < SIZING_RTOL or hb == ha:
            break
        a, ha, b = b, hb, max(b - hb * (b - a) / (hb - ha), 0.5 * b)
        c_b = fluct(b)
        hb = 1.0 / c_b - 1.0 / fluctuation
    if abs(c_b / fluctuation - 1.0) > 10 * SIZING_RTOL:
        raise SimulationError(f"flywheel sizing did not converge: fluctuation {c_b:.6g} "
                              f"with {shown(b, 'inertia')} for a request of {fluctuation}")
    return b, c_b


def fluctuation_curve(eom: EquationOfMotion, flywheels: Array, guess_speed: float) -> Array:
    """Steady fluctuation for each flywheel inertia (for plots and tests)."""
    return np.array([steady_simulation(with_flywheel(eom, float(j)), guess_speed).steady()
                     ["fluctuation"] for j in flywheels])


__all__ = ["FlywheelSizing", "balanced_speed", "energy_estimate", "output_force",
           "size_flywheel", "steady_simulation", "with_flywheel"]

"""Forward integration of the reduced equation of motion (:mod:`screwkit.simulation.drive`)
with scipy's ``solve_ivp`` (DOP853, dense output), an event counting the cycles (the input
passing start + 2πk) and terminal events for the last cycle and for a stall (θ̇ reaching zero).

The state is (θ, θ̇, W_motor, W_load, ∫τ² dt), with W_friction appended when joints have
friction (only then: scipy's error norm averages over the components): the motor's, the
load's and the joint friction's work and the integral of the squared motor torque are integrated with the motion, to the same tolerance, so
energy per cycle and RMS torque need no quadrature afterwards. Every completed cycle is then
sampled at the model's grid angles (the time at which θ reaches each, by Newton's method on
the dense output), where the full motion of the loop is known exactly
(:meth:`~screwkit.simulation.reduced.ReducedModel.motion_at`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import OdeSolution, solve_ivp
from scipy.optimize import brentq

from screwkit.messages import shown
from screwkit.simulation.drive import EquationOfMotion, motor_torque
from screwkit.simulation.reduced import Array, SimulationError

TWO_PI = 2.0 * np.pi
#: Newton iterations to find the time of a grid angle on the dense output (converges in ~3)
NEWTON_STEPS = 12


@dataclass(frozen=True, eq=False)
class SimulationRun:
    """One integration: the completed cycles sampled at the model's grid angles.

    ``cycle_times`` (C + 1,) the times the input passes start + 2πk; ``time``, ``speed``,
    ``acceleration`` (C, N) at the grid angles ``eom.model.grid`` of each completed cycle;
    ``cycle_work`` {``motor``, ``load``, ``friction``} (C,) the work per cycle (J; the load's
    and the friction's are negative when they resist); ``torque_square`` (C,)
    ∫τ² dt per cycle; ``status`` ``"completed"``, ``"stalled"`` or ``"max_time"`` with a
    ``message``; ``end`` the last state (t, θ, θ̇)."""

    eom: EquationOfMotion
    initial_speed: float
    cycle_times: Array
    time: Array
    speed: Array
    acceleration: Array
    cycle_work: dict[str, Array]
    torque_square: Array
    energy_error: float
    status: str
    message: str
    end: tuple[float, float, float]
    solution: OdeSolution

    @property
    def cycles(self) -> int:
        return int(self.time.shape[0])

    @property
    def angle(self) -> Array:
        """(C, N) unwrapped input angle at each sample."""
        grid = self.eom.model.grid
        return grid[None, :] + TWO_PI * np.arange(self.cycles)[:, None]

    def terms(self) -> dict[str, Array]:
        """Every term of the equation of motion at the samples (C, N) (EquationOfMotion.terms)."""
        return self.eom.terms(self.angle, self.speed)


def _rhs(eom: EquationOfMotion, direction: float | None = None):  # type: ignore[no-untyped-def]
    """(θ̇, θ̈, τω, Q_load ω, τ², −B ω²) of the augmented state. ``direction`` (±1) fixes the
    sign of the output's motion that a load against the motion opposes, over one segment
    between reversals (:func:`reversal_angles`), so that the right-hand side is smooth there;
    None takes it from the state."""
    motor = eom.drive.motor
    k = np.arange(eom.model.series.coefficients.shape[1])
    coeff = eom.model.series.coefficients
    slope_c = coeff[0] * (1j * k)
    start = eom.model.start
    row = None if eom.drive.load is None else eom.model.row(eom.drive.load.freedom)
    load_cfg = eom.drive.load
    fw = eom.flywheel
    fr = eom.friction_row

    def f(t: float, y: Array) -> Array:
        th, w = y[0], y[1]
        e = np.exp(1j * (th - start) * k)
        rows = (coeff @ e).real
        slope = (slope_c @ e).real
        load = 0.0
        if row is not None and load_cfg is not None:
            r = rows[row]
            q = r * w
            sign = np.sign(q) if direction is None else direction
            q_out = -load_cfg.damping * q - (load_cfg.constant * sign
                                             if load_cfg.against_motion else load_cfg.constant)
            load = q_out * r
        tau = float(motor_torque(motor, w))
        if fr is None:
            acc = (tau - 0.5 * slope * w * w + rows[1] + load) / (rows[0] + fw)
            return np.array([w, acc, tau * w, load * w, tau * tau])
        friction = -rows[fr] * w
        acc = (tau - 0.5 * slope * w * w + rows[1] + load + friction) / (rows[0] + fw)
        return np.array([w, acc, tau * w, load * w, tau * tau, friction * w])

    return f


def reversal_angles(eom: EquationOfMotion) -> Array:
    """Input angles in [start, start + 2π) where the output reverses (its velocity ratio r(θ)
    changes sign) when a constant load opposes the output's motion: the load jumps there, so
    the integration stops and restarts at each (a step across the jump would be integrated to
    low order). Empty when the load has no such part."""
    load = eom.drive.load
    if load is None or not load.against_motion or load.constant == 0.0:
        return np.zeros(0)
    model = eom.model
    row = model.row(load.freedom)
    grid = model.grid
    r = np.asarray(model.grid_mode.velocities[load.freedom], dtype=float)  # exact samples
    roots = []
    for i in np.flatnonzero(np.sign(r) != np.sign(np.roll(r, -1))):
        a, b = grid[i], grid[i] + (grid[1] - grid[0])
        fa, fb = r[i], r[(i + 1) % r.size]
        if fa == 0.0:
            roots.append(a)
            continue
        if fb == 0.0:
            continue  # found as the next sample's exact zero
        roots.append(brentq(lambda x: float(model.series(np.array([x]))[row][0]), a, b,
                            xtol=1e-15, rtol=1e-15))
    return np.sort(np.asarray(roots, dtype=float))


def _times_at_angles(sol: OdeSolution, t0: Array, t1: Array, targets: Array) -> Array:
    """Times (C, N) at which θ(t) = ``targets`` (C, N), θ increasing on [t0, t1] per row."""
    C, N = targets.shape
    frac = (np.arange(N) / N)[None, :]
    t = t0[:, None] + frac * (t1 - t0)[:, None]
    lo, hi = np.broadcast_to(t0[:, None], t.shape), np.broadcast_to(t1[:, None], t.shape)
    for _ in range(NEWTON_STEPS):
        y = sol(t.ravel()).reshape(-1, C, N)
        step = (y[0] - targets) / np.maximum(y[1], 1e-300)
        t = np.clip(t - step, lo, hi)
        if np.max(np.abs(y[0] - targets)) < 1e-13 * (1.0 + np.max(np.abs(targets))):
            break
    return t


def simulate_cycles(eom: EquationOfMotion, *, cycles: int, initial_speed: float,
                    rtol: float = 1e-9, atol: float | None = None,
                    max_time: float | None = None) -> SimulationRun:
    """Integrate from the start angle at ``initial_speed`` (rad/s) for ``cycles`` turns of the
    input (or until it stalls or ``max_time`` passes); module docstring."""
    if not initial_speed > 0:
        raise SimulationError(f"the initial speed must be > 0 rad/s; got {initial_speed}")
    if cycles < 1:
        raise SimulationError(f"simulate at least one cycle; got {cycles}")
    start = eom.model.start
    J0 = eom.model.mean_inertia() + eom.flywheel
    energy = 0.5 * J0 * initial_speed ** 2
    period = TWO_PI / initial_speed
    # absolute tolerances: θ (rad), θ̇ (rad/s), the works (J) and ∫τ² dt on their scales
    scales = [TWO_PI, initial_speed, energy, energy, energy ** 2 / period]
    if eom.friction_row is not None:
        scales.append(energy)
    atol_v = rtol * np.array(scales)
    if atol is not None:
        atol_v[:2] = atol
    t_end = max_time if max_time is not None else 1000.0 * cycles * period

    def cycle(t: float, y: Array) -> float:
        return float(np.sin(0.5 * (y[0] - start)))

    def done(t: float, y: Array) -> float:
        return float(y[0] - start - TWO_PI * cycles)

    def stall(t: float, y: Array) -> float:
        return float(y[1])

    done.terminal = True  # type: ignore[attr-defined]
    done.direction = 1.0  # type: ignore[attr-defined]
    stall.terminal = True  # type: ignore[attr-defined]
    stall.direction = -1.0  # type: ignore[attr-defined]
    y0 = np.zeros(len(scales))
    y0[:2] = start, initial_speed
    res, turns = _integrate(eom, y0, t_end, cycles, rtol, atol_v, (cycle, done, stall))
    # cycle ends: the counting event past the start, and the terminal event of the last cycle
    # (both may report the last end: keep one time per turn, by the angle reached)
    for t, y in zip([*res.t_events[0], *res.t_events[1]],
                    [*res.y_events[0], *res.y_events[1]], strict=True):
        k = int(round((y[0] - start) / TWO_PI))
        if k >= 1:
            turns.setdefault(k, float(t))
    ends = [turns[k] for k in sorted(turns)]
    status, message = "completed", f"{cycles} cycle(s) simulated"
    if res.t_events[2].size:
        t_s, th_s = float(res.t_events[2][0]), float(res.y_events[2][0][0])
        status = "stalled"
        message = (f"the input stopped (speed 0) at t = {t_s:.6g} s, input angle "
                   f"{shown(th_s - start, 'angle')} after the start, during cycle "
                   f"{len(ends) + 1}: the motor cannot drive the machine through its load")
    elif not res.t_events[1].size:
        status = "max_time"
        message = (f"only {len(ends)} of {cycles} cycle(s) completed in {t_end:.6g} s "
                   "(max_time); the input slows down too much")
    return _sampled(eom, res, np.array([0.0, *ends]), initial_speed, status, message)


@dataclass
class _Integration:
    """The pieces of a piecewise integration joined into one (``solve_ivp``'s fields that the
    sampling reads)."""

    t_events: list[Array]
    y_events: list[Array]
    t: Array
    y: Array
    sol: OdeSolution


def _integrate(eom: EquationOfMotion, y0: Array, t_end: float, cycles: int, rtol: float,
               atol: Array, events: tuple) -> tuple[_Integration, dict[int, float]]:  # type: ignore[type-arg]
    """``solve_ivp`` (DOP853, dense output) from y0, restarted at every reversal of the output
    (:func:`reversal_angles`) with the load's direction fixed over each piece; the pieces'
    events and dense outputs are joined. Also returns the turns that end exactly at a restart
    (turn index -> time), which the counting event cannot see there."""
    start = eom.model.start
    final = start + TWO_PI * cycles
    switches = reversal_angles(eom)
    load_row = eom.model.row(eom.drive.load.freedom) if eom.drive.load is not None else 0
    t0, y = 0.0, np.array(y0, dtype=float)
    ts: list[float] = [0.0]
    interpolants: list = []  # type: ignore[type-arg]
    t_events: list[list[float]] = [[] for _ in events]
    y_events: list[list[Array]] = [[] for _ in events]
    turns: dict[int, float] = {}
    last_t, last_y = t0, y
    while True:
        nxt = None
        if switches.size:
            after = switches + TWO_PI * np.ceil((y[0] + 1e-12 - switches) / TWO_PI)
            candidate = float(np.min(after))
            nxt = candidate if candidate < final - 1e-9 else None
        direction = None
        reach = []
        if switches.size:
            mid = 0.5 * (y[0] + (nxt if nxt is not None else final))
            ratio = eom.model.series(np.array([mid]))[load_row][0]
            direction = 1.0 if ratio * y[1] >= 0 else -1.0
            if nxt is not None:
                def hit(t: float, yy: Array, target: float = nxt) -> float:
                    return float(yy[0] - target)

                hit.terminal = True  # type: ignore[attr-defined]
                hit.direction = 1.0  # type: ignore[attr-defined]
                reach = [hit]
        res = solve_ivp(_rhs(eom, direction), (t0, t_end), y, method="DOP853", rtol=rtol,
                        atol=atol, dense_output=True, events=(*events, *reach))
        if res.status == -1:
            raise SimulationError(f"the integration failed: {res.message}")
        for i in range(len(events)):
            t_events[i] += list(res.t_events[i])
            y_events[i] += list(res.y_events[i])
        ts += list(res.sol.ts[1:])
        interpolants += list(res.sol.interpolants)
        last_t, last_y = float(res.t[-1]), res.y[:, -1]
        stopped = any(res.t_events[i].size for i in range(1, len(events)))
        if nxt is None or not (reach and res.status == 1 and res.t_events[-1].size
                               and not stopped):
            break
        t0, y = float(res.t_events[-1][0]), np.array(res.y_events[-1][0], dtype=float)
        y[0] = nxt
        k = (nxt - start) / TWO_PI
        if k >= 1 and abs(k - round(k)) < 1e-9:
            turns.setdefault(int(round(k)), t0)
    sol = OdeSolution(np.array(ts), interpolants)
    joined = _Integration([np.array(t) for t in t_events],
                          [np.array(v).reshape(-1, y0.size) for v in y_events],
                          np.array([last_t]), np.asarray(last_y)[:, None], sol)
    return joined, turns


def _sampled(eom: EquationOfMotion, res: object, cycle_times: Array, initial_speed: float,
             status: str, message: str) -> SimulationRun:
    sol = res.sol  # type: ignore[attr-defined]
    C = cycle_times.size - 1
    grid = eom.model.grid
    N = grid.size
    if C >= 1:
        targets = grid[None, :] + TWO_PI * np.arange(C)[:, None]
        t = _times_at_angles(sol, cycle_times[:-1], cycle_times[1:], targets)
        y = sol(t.ravel()).reshape(-1, C, N)
        speed = y[1]
        acc = eom.terms(targets, speed)["acceleration"]
        at_ends = sol(cycle_times)
        friction = at_ends[5] if at_ends.shape[0] > 5 else np.zeros(C + 1)
        work = {"motor": np.diff(at_ends[2]), "load": np.diff(at_ends[3]),
                "friction": np.diff(friction)}
        torque_square = np.diff(at_ends[4])
    else:
        t = speed = acc = np.zeros((0, N))
        work = {"motor": np.zeros(0), "load": np.zeros(0), "friction": np.zeros(0)}
        torque_square = np.zeros(0)
    t_last = float(res.t[-1])  # type: ignore[attr-defined]
    y_last = res.y[:, -1]  # type: ignore[attr-defined]
    e0 = float(eom.energy(grid[0], initial_speed))
    e1 = float(eom.energy(y_last[0], y_last[1]))
    w_friction = float(y_last[5]) if y_last.shape[0] > 5 else 0.0
    scale = max(abs(e0), abs(y_last[2]), abs(y_last[3]), abs(w_friction), 1e-300)
    energy_error = abs(e1 - e0 - y_last[2] - y_last[3] - w_friction) / scale
    return SimulationRun(eom=eom, initial_speed=initial_speed, cycle_times=cycle_times, time=t,
                         speed=speed, acceleration=acc, cycle_work=work,
                         torque_square=torque_square, energy_error=float(energy_error),
                         status=status, message=message,
                         end=(t_last, float(y_last[0]), float(y_last[1])), solution=sol)

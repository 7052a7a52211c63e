"""The generalised forces on the input coordinate of a driven loop and its equation of motion

    (J(θ) + J_f) θ̈ = τ_motor(θ̇) − ½ J′(θ) θ̇² + Q_g(θ) + Q_load(θ, θ̇) − B(θ) θ̇,

with J_f the flywheel on the input shaft, Q_g = −V′ the gravity torque, Q_load = Q_out · r(θ)
the load on the output freedom q_out carried to the input by the velocity ratio r = dq_out/dθ
(virtual work: Q_out δq_out = Q_out r δθ) and B(θ) the viscous joint friction
(:func:`~screwkit.simulation.reduced.friction_coefficient`: it dissipates B θ̇²). Motor models and the load law are those of the
``[drive]`` table (:class:`~screwkit.io.drive_table.DriveConfig`, docs/simulation.md)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from screwkit.io.drive_table import DriveConfig, LoadConfig, MotorConfig
from screwkit.model.linkage import Linkage
from screwkit.simulation.reduced import Array, ReducedModel, SimulationError, reduced_model


def motor_torque(motor: MotorConfig, speed: ArrayLike) -> Array:
    """Motor torque (N·m) at input speed ``speed`` (rad/s): constant, the linear torque–speed
    line τ = τ_stall (1 − ω/ω_0), or linear interpolation in a table (end values held)."""
    w = np.asarray(speed, dtype=float)
    if motor.kind == "constant":
        return np.full_like(w, motor.torque)
    if motor.kind == "linear":
        return motor.stall_torque * (1.0 - w / motor.no_load_speed)
    if motor.kind == "table":
        return np.interp(w, np.asarray(motor.speeds), np.asarray(motor.torques))
    return np.zeros_like(w)


def output_force(load: LoadConfig | None, output_rate: ArrayLike) -> Array:
    """Generalised force Q_out (N·m or N) of the load on its freedom at rate q̇_out: the constant
    part against the motion (−c·sign q̇) or fixed (−c), plus the damping part −d·q̇."""
    q = np.asarray(output_rate, dtype=float)
    if load is None:
        return np.zeros_like(q)
    constant = (-load.constant * np.sign(q) if load.against_motion
                else np.full_like(q, -load.constant))
    return constant - load.damping * q


class EquationOfMotion:
    """The reduced equation of motion of a loop with its drive (module docstring). Read only."""

    def __init__(self, model: ReducedModel, drive: DriveConfig, flywheel: float) -> None:
        self.model = model
        self.drive = drive
        self.flywheel = float(flywheel)
        c = model.series.coefficients
        self._k = np.arange(c.shape[1])
        self._slope = c[0] * (1j * self._k)
        self._ratio_row = None if drive.load is None else model.row(drive.load.freedom)
        self.friction_row = model.row("friction") if "friction" in model.rows else None

    def terms(self, theta: ArrayLike, speed: ArrayLike) -> dict[str, Array]:
        """Every term at (θ, θ̇) (arrays of the same shape): ``inertia`` J + J_f,
        ``inertia_slope`` J′, ``motor`` τ, ``gravity`` Q_g, ``load`` Q_load, ``output_force``
        Q_out, ``ratio`` r, ``friction`` −B θ̇ (the joints' viscous friction on the input),
        ``acceleration`` θ̈."""
        th = np.asarray(theta, dtype=float)
        w = np.asarray(speed, dtype=float)
        e = np.exp(1j * np.multiply.outer(th - self.model.start, self._k))
        rows = np.real(np.einsum("rk,...k->r...", self.model.series.coefficients, e))
        slope = np.real(np.einsum("k,...k->...", self._slope, e))
        J = rows[0] + self.flywheel
        row = self._ratio_row
        ratio = rows[row] if row is not None else np.zeros_like(th)
        q_out = output_force(self.drive.load, ratio * w)
        tau = motor_torque(self.drive.motor, w)
        load = q_out * ratio
        fr = self.friction_row
        friction = -rows[fr] * w if fr is not None else np.zeros_like(th * w)
        acc = (tau - 0.5 * slope * w * w + rows[1] + load + friction) / J
        return {"inertia": J, "inertia_slope": slope, "motor": tau, "gravity": rows[1],
                "load": load, "output_force": q_out, "ratio": ratio, "friction": friction,
                "acceleration": acc}

    def rhs(self, t: float, y: Array) -> Array:
        """(θ̇, θ̈) for scipy's ``solve_ivp`` (one state: the fast path of :meth:`terms`)."""
        th, w = y[0], y[1]
        e = np.exp(1j * (th - self.model.start) * self._k)
        rows = np.real(self.model.series.coefficients @ e)
        slope = float(np.real(self._slope @ e))
        row = self._ratio_row
        load = 0.0
        if row is not None:
            r = rows[row]
            load = float(output_force(self.drive.load, r * w)) * r
        tau = float(motor_torque(self.drive.motor, w))
        friction = -rows[self.friction_row] * w if self.friction_row is not None else 0.0
        acc = (tau - 0.5 * slope * w * w + rows[1] + load + friction) / (rows[0] + self.flywheel)
        return np.array([w, acc])

    def energy(self, theta: ArrayLike, speed: ArrayLike) -> Array:
        """Kinetic energy of loop and flywheel plus the potential energy of gravity (relative
        to the start angle), J."""
        J, _ = self.model.inertia(theta)
        w = np.asarray(speed, dtype=float)
        return 0.5 * (J + self.flywheel) * w * w + self.model.potential(theta)


def equation_of_motion(linkage: Linkage, drive: DriveConfig, *, mode: int = 0,
                       start: float = 0.0, gravity: ArrayLike | None = None,
                       flywheel: float | None = None, method: str = "auto"
                       ) -> EquationOfMotion:
    """The reduced model of ``linkage`` (assembly ``mode``, one turn from ``start``) with the
    drive's load freedom among its velocity ratios and its joint friction, and its equation of
    motion."""
    ratios = () if drive.load is None else (drive.load.freedom,)
    model = reduced_model(linkage, mode=mode, start=start,
                          gravity=gravity if drive.gravity else None, ratios=ratios,
                          samples_per_cycle=drive.samples_per_cycle, method=method,
                          friction=drive.friction)
    fw = drive.flywheel if flywheel is None else float(flywheel)
    if not fw >= 0:
        raise SimulationError(f"the flywheel inertia must be >= 0; got {fw}")
    return EquationOfMotion(model, drive, fw)

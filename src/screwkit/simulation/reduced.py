"""The reduced equation of motion of a one-degree-of-freedom loop in its input coordinate θ.

With every link's twist linear in the input rate (the velocity coefficients ω̂_l(θ), v̂_l(θ):
the link motion of :func:`~screwkit.kinematics.solve_motion.solve_motion` at unit rate and zero
input acceleration), the kinetic energy is T = ½ J(θ) θ̇² with the generalised inertia

    J(θ) = Σ_l  m_l v̂_c·v̂_c + ω̂_l·I_l ω̂_l,            v̂_c = v̂_o + ω̂ × R c,  I_l = R I_c Rᵀ,

and Lagrange's equation reads (e.g. Uicker, Pennock & Shigley, *Theory of Machines and
Mechanisms*, "equation of motion of a one-degree-of-freedom system")

    J(θ) θ̈ + ½ J′(θ) θ̇² = Q(θ, θ̇),        Q = τ_motor − V′(θ) + Q_load.

The motion at unit rate and zero acceleration has, as its accelerations, exactly the quadratic
velocity terms â = dv̂/dθ, α̂ = dω̂/dθ, so J′ = 2 Σ (m v̂_c·â_c + ω̂·I α̂) is exact too (the
term ω̂·İ ω̂ = ω̂·(ω̂ × Iω̂ − I(ω̂ × ω̂)) vanishes). Gravity's generalised force is
−V′ = Σ m g·v̂_c.

The S–S rod's spin: the kinematics gives a rod between two balls zero spin about the line of its
ball centres (Rahman 1996 §1.2), and the inverse dynamics assumes it. J uses the same twists. For
an axisymmetric rod with its centre of mass on that line (the rule of docs/dynamics.md) the spin
is a decoupled cyclic coordinate that no joint can load, so it stays zero and J is the true
kinetic energy of the loop.

During integration J, J′ and the other θ-dependent coefficients are evaluated from truncated
Fourier series fitted to exact samples on a uniform grid over one turn (the coefficients are
smooth periodic functions, so the series converge geometrically); the grid is refined until the
discarded harmonics are below :data:`FOURIER_TOLERANCE` of the largest value, and J′ is taken as
the exact derivative of J's series, so the integrated model conserves its own energy exactly.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import cross
from screwkit.errors import InputError
from screwkit.io.drive_table import DriveConfigError, checked_friction
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.messages import listing
from screwkit.model.linkage import Linkage
from screwkit.model.mass import MassProperties

Array = NDArray[np.float64]

#: discarded Fourier harmonics (sum of magnitudes) relative to the largest |value| of a
#: coefficient; 1e-12 keeps the interpolation error far below every test tolerance (1e-8)
FOURIER_TOLERANCE = 1e-12
#: largest grid (samples per turn) tried before the fit is declared not converged
MAX_GRID = 9216


class SimulationError(InputError):
    """A simulation that cannot run as asked; the message says why and how to fix it."""


def _masses(linkage: Linkage) -> list[MassProperties]:
    missing = [link.name for link in linkage.links if link.mass is None]
    if missing:
        raise SimulationError(f"{linkage.name}: the equation of motion needs mass properties for "
                              f"every moving link; missing for {listing(missing)}")
    return [link.mass for link in linkage.links]  # type: ignore[misc]


def link_kinematics(linkage: Linkage, mode: ModeMotion) -> tuple[Array, Array, Array, Array]:
    """World angular velocity, CoM velocity, angular acceleration and CoM acceleration of every
    link (N, L, 3) of a mode, and the world inertia tensors are formed by the callers."""
    masses = _masses(linkage)
    com = np.stack([mp.com for mp in masses])
    R = mode.link_rotation
    rc = np.einsum("nlij,lj->nli", R, com)
    w, al = mode.link_angular_velocity, mode.link_angular_acceleration
    v_c = mode.link_origin_velocity + cross(w, rc)
    a_c = mode.link_origin_acceleration + cross(al, rc) + cross(w, cross(w, rc))
    return w, v_c, al, a_c


def energy_coefficients(linkage: Linkage, mode: ModeMotion,
                        gravity: ArrayLike | None = None) -> dict[str, Array]:
    """Exact samples of J(θ), J′(θ) and the gravity torque −V′(θ) (N,) from a mode solved at
    unit input rate and zero input acceleration (module docstring). SI: kg·m² (or kg for a
    translating input), kg·m²/rad, N·m."""
    masses = _masses(linkage)
    m = np.array([mp.mass for mp in masses])
    w, v_c, al, a_c = link_kinematics(linkage, mode)
    R = mode.link_rotation
    I_w = np.einsum("nlij,ljk,nlmk->nlim", R, np.stack([mp.inertia for mp in masses]), R)
    Iw = np.einsum("nlij,nlj->nli", I_w, w)
    J = np.einsum("l,nli,nli->n", m, v_c, v_c) + np.einsum("nli,nli->n", w, Iw)
    dJ = 2.0 * (np.einsum("l,nli,nli->n", m, v_c, a_c) + np.einsum("nli,nli->n", al, Iw))
    g = np.zeros(3) if gravity is None else np.asarray(gravity, dtype=float)
    Qg = np.einsum("l,nli,i->n", m, v_c, g)
    return {"inertia": J, "inertia_slope": dJ, "gravity_torque": Qg}


def relative_angular_velocity(mode: ModeMotion, joint: int) -> Array:
    """(N, 3) angular velocity of joint ``joint``'s distal link relative to its proximal one
    (world frame; the ground is still): joint i joins moving link i − 1 (the ground for the
    first joint) to moving link i (the ground for the last)."""
    w = mode.link_angular_velocity
    links = w.shape[1]
    distal = w[:, joint] if joint < links else 0.0
    proximal = w[:, joint - 1] if joint >= 1 else 0.0
    return np.asarray(distal - proximal, dtype=float) * np.ones((w.shape[0], 3))


def sliding_rate(linkage: Linkage, mode: ModeMotion, joint: int) -> Array:
    """(N,) rate of a P or C joint's sliding freedom (m/s at unit input rate)."""
    name = f"{linkage.joints[joint].name}.s"
    return np.asarray(mode.velocities[name], dtype=float)


def joint_friction(linkage: Linkage, friction: Sequence[Any]) -> tuple[Any, ...]:
    """``friction`` (JointFriction items) checked against the loop and merged by joint
    (:func:`~screwkit.io.drive_table.checked_friction`); a :class:`SimulationError` says what
    is wrong."""
    try:
        return checked_friction(linkage, friction)
    except DriveConfigError as exc:
        raise SimulationError(f"{linkage.name}: {exc}") from None


def friction_coefficient(linkage: Linkage, mode: ModeMotion, friction: Sequence[Any]) -> Array:
    """Exact samples (N,) of B(θ) = Σ_j c_rot,j |ω̂_rel,j|² + c_slide,j ŝ_j² from a mode at unit
    input rate: viscous joint friction dissipates B θ̇², so its generalised force on the input is
    −B(θ) θ̇ (N·m·s/rad). ``friction``: :class:`~screwkit.io.drive_table.JointFriction` items."""
    index = {j.name: i for i, j in enumerate(linkage.joints)}
    B = np.zeros(mode.link_angular_velocity.shape[0])
    for f in joint_friction(linkage, friction):
        j = index[f.joint]
        if f.rotation:
            w = relative_angular_velocity(mode, j)
            B += f.rotation * np.einsum("ni,ni->n", w, w)
        if f.translation:
            B += f.translation * sliding_rate(linkage, mode, j) ** 2
    return B


@dataclass(frozen=True)
class FourierSeries:
    """Real periodic functions of θ (period 2π) as truncated Fourier series about ``start``:
    ``f_r(θ) = Re Σ_k c_rk e^{ik(θ − start)}``, one row r per function."""

    start: float
    coefficients: NDArray[np.complex128]  # (R, K + 1)

    @property
    def harmonics(self) -> int:
        return int(self.coefficients.shape[1] - 1)

    def basis(self, theta: ArrayLike) -> NDArray[np.complex128]:
        k = np.arange(self.coefficients.shape[1])
        return np.exp(1j * np.multiply.outer(np.asarray(theta, dtype=float) - self.start, k))

    def __call__(self, theta: ArrayLike, derivative: int = 0) -> Array:
        """Values (R, …) at ``theta``; ``derivative`` 1 or 2 gives d/dθ or d²/dθ²."""
        k = np.arange(self.coefficients.shape[1])
        c = self.coefficients * (1j * k) ** derivative
        return np.real(np.einsum("rk,...k->r...", c, self.basis(theta)))

    def integral(self, theta: ArrayLike) -> Array:
        """∫ from ``start`` to θ of each row's oscillating part (the mean term excluded)."""
        k = np.arange(1, self.coefficients.shape[1])
        c = self.coefficients[:, 1:] / (1j * k)
        e = self.basis(theta)[..., 1:]
        return np.real(np.einsum("rk,...k->r...", c, e - 1.0))


def fit_fourier(start: float, samples: Array, tolerance: float = FOURIER_TOLERANCE
                ) -> tuple[FourierSeries, bool]:
    """Truncated series of the rows of ``samples`` (R, N) on θ_j = start + 2πj/N; the number of
    harmonics K is the smallest whose discarded tail is below ``tolerance`` of each row's largest
    value. ``converged`` is False when that needs K ≥ N/4 (the grid is too coarse)."""
    R, N = samples.shape
    c = np.fft.rfft(samples, axis=1) / N
    c[:, 1:] *= 2.0
    if N % 2 == 0:
        c[:, -1] /= 2.0  # the Nyquist term is counted once
    scale = np.maximum(np.max(np.abs(samples), axis=1), 1e-300)
    tails = np.cumsum(np.abs(c[:, ::-1]), axis=1)[:, ::-1] / scale[:, None]  # tail from k on
    K = 0
    for r in range(R):
        above = np.flatnonzero(tails[r] > tolerance)
        K = max(K, int(above[-1]) if above.size else 0)
    converged = K < N // 4
    return FourierSeries(start, c[:, : K + 1]), converged


@dataclass(frozen=True, eq=False)
class ReducedModel:
    """The reduced equation of motion of one assembly mode of a one-input loop (module
    docstring): exact samples on ``grid`` (one turn from ``start``), their Fourier series, and
    the grid motion at unit rate (to rebuild the full motion at any simulated speed).

    ``coefficients`` rows: ``inertia`` J, ``gravity_torque`` −V′, then the velocity ratios of
    the freedoms in ``ratio_names`` (dq/dθ, the load's), then ``friction`` B(θ) when the drive
    has joint friction (:func:`friction_coefficient`).
    """

    linkage: Linkage
    mode_index: int
    grid: Array  # (N,) one turn
    samples: dict[str, Array]
    series: FourierSeries
    rows: tuple[str, ...]
    grid_mode: ModeMotion
    gravity: Array
    converged: bool
    interpolation_error: float  # max |J′(series) − J′(exact)| / max |J′| on the grid
    ratio_names: tuple[str, ...] = field(default_factory=tuple)

    @property
    def start(self) -> float:
        return float(self.grid[0])

    def row(self, name: str) -> int:
        return self.rows.index(name)

    def inertia(self, theta: ArrayLike) -> tuple[Array, Array]:
        """J(θ) and J′(θ) from the series."""
        r = self.row("inertia")
        sub = FourierSeries(self.series.start, self.series.coefficients[r:r + 1])
        return sub(theta)[0], sub(theta, 1)[0]

    def mean_inertia(self) -> float:
        return float(np.real(self.series.coefficients[self.row("inertia"), 0]))

    def potential(self, theta: ArrayLike) -> Array:
        """V(θ) − V(start) from the gravity series (V′ = −gravity torque)."""
        r = self.row("gravity_torque")
        sub = FourierSeries(self.series.start, self.series.coefficients[r:r + 1])
        return -sub.integral(theta)[0]

    def evaluate(self, theta: ArrayLike) -> tuple[Array, Array]:
        """Every row and its θ-derivative at ``theta``: two arrays (R, …)."""
        return self.series(theta), self.series(theta, 1)

    def kinetic_energy(self, theta: ArrayLike, speed: ArrayLike) -> Array:
        J, _ = self.inertia(theta)
        return 0.5 * J * np.asarray(speed, dtype=float) ** 2

    def motion_at(self, indices: ArrayLike, speed: ArrayLike, acceleration: ArrayLike
                  ) -> ModeMotion:
        """The mode at grid samples ``indices`` (M,) moving at input ``speed`` and
        ``acceleration`` (M,): velocities ω̂θ̇, accelerations âθ̇² + ω̂θ̈ (exact: the grid
        mode's accelerations are the quadratic terms at unit rate)."""
        i = np.asarray(indices, dtype=int)
        w = np.asarray(speed, dtype=float)
        a = np.asarray(acceleration, dtype=float)
        g = self.grid_mode

        def vel(x: Array) -> Array:
            return x[i] * w.reshape(-1, *([1] * (x.ndim - 1)))

        def acc(v: Array, q: Array) -> Array:
            shape = (-1, *([1] * (v.ndim - 1)))
            return q[i] * (w ** 2).reshape(shape) + v[i] * a.reshape(shape)

        return replace(
            g,
            assembles=g.assembles[i], singular=g.singular[i],
            conf=g.conf,
            variables={k: v[i] for k, v in g.variables.items()},
            velocities={k: vel(v) for k, v in g.velocities.items()},
            accelerations={k: acc(g.velocities[k], q) for k, q in g.accelerations.items()
                           if k in g.velocities},
            link_rotation=g.link_rotation[i], link_origin=g.link_origin[i],
            link_angular_velocity=vel(g.link_angular_velocity),
            link_origin_velocity=vel(g.link_origin_velocity),
            link_angular_acceleration=acc(g.link_angular_velocity, g.link_angular_acceleration),
            link_origin_acceleration=acc(g.link_origin_velocity, g.link_origin_acceleration),
            joint_centres=g.joint_centres[i], joint_axes=g.joint_axes[i],
            closure_residual=g.closure_residual[i],
        )


def _one_input_crank(linkage: Linkage) -> None:
    if len(linkage.inputs) != 1:
        raise SimulationError(f"{linkage.name}: the reduced equation of motion is for a loop "
                              f"with one input; this one has {listing(linkage.inputs)}")
    if linkage.inputs[0].endswith(".s"):
        raise SimulationError(f"{linkage.name}: simulation needs a rotating input (a crank that "
                              f"turns); the input {linkage.inputs[0]!r} is a translation")


def _solve_grid(linkage: Linkage, grid: Array, mode: int, method: str) -> ModeMotion:
    motion: Motion = solve_motion(linkage, grid, rates=1.0, accelerations=0.0, method=method)
    try:
        md = motion.mode(mode)
    except ValueError as exc:
        raise SimulationError(str(exc)) from None
    bad = ~(md.assembles & ~md.singular)
    if bad.any():
        where = np.degrees(grid[bad][:6])
        raise SimulationError(
            f"{linkage.name}: assembly mode {mode} does not turn fully — it does not assemble "
            f"(or is singular) at {int(bad.sum())} of {grid.size} input angles over one turn "
            f"(e.g. {', '.join(f'{x:.4g}' for x in where)} deg); simulation needs a crank "
            "that turns through 360 deg")
    return md


def reduced_model(linkage: Linkage, *, mode: int = 0, start: float = 0.0,
                  gravity: ArrayLike | None = None, ratios: tuple[str, ...] = (),
                  samples_per_cycle: int = 72, method: str = "auto",
                  tolerance: float = FOURIER_TOLERANCE,
                  friction: Sequence[Any] = ()) -> ReducedModel:
    """The reduced equation of motion of assembly ``mode`` of a one-input loop whose input
    turns fully (module docstring), on a grid of ``samples_per_cycle``·2^k angles from
    ``start`` refined until the Fourier series of J, −V′, the velocity ratios of ``ratios``
    (freedom names, dq/dθ) and, with ``friction`` (JointFriction items), the viscous friction
    coefficient B(θ) converge to ``tolerance``. SI units."""
    _one_input_crank(linkage)
    _masses(linkage)
    g = np.zeros(3) if gravity is None else np.asarray(gravity, dtype=float)
    friction = joint_friction(linkage, friction)
    for name in ratios:
        if name not in linkage.freedom_names:
            raise SimulationError(f"{linkage.name}: no freedom {name!r}; the freedoms are "
                                  f"{listing(linkage.freedom_names)}")
    n = int(samples_per_cycle)
    if n < 8:
        raise SimulationError(f"samples_per_cycle must be at least 8; got {n}")
    while True:
        n *= 2
        grid = start + 2.0 * np.pi * np.arange(n) / n
        md = _solve_grid(linkage, grid, mode, method)
        coeff = energy_coefficients(linkage, md, g)
        rows = ("inertia", "gravity_torque", *ratios)
        data = [coeff["inertia"], coeff["gravity_torque"], *[md.velocities[r] for r in ratios]]
        if friction:
            rows += ("friction",)
            coeff["friction"] = friction_coefficient(linkage, md, friction)
            data.append(coeff["friction"])
        series, converged = fit_fourier(start, np.stack(data), tolerance)
        if converged or 2 * n > MAX_GRID:
            break
    slope = series(grid, 1)[0]
    exact = coeff["inertia_slope"]
    err = float(np.max(np.abs(slope - exact)) / max(np.max(np.abs(exact)), 1e-300))
    return ReducedModel(linkage=linkage, mode_index=mode, grid=grid, samples=coeff,
                        series=series, rows=rows, grid_mode=md, gravity=g, converged=converged,
                        interpolation_error=err, ratio_names=tuple(ratios))

"""The equations of motion of a mechanism graph in its input coordinates x (one per input).

The same reduction as a single loop's (:mod:`screwkit.simulation.reduced`), with n inputs and
the graph kinematics in place of the loop's. At a configuration closed by the graph Newton
(:func:`~screwkit.kinematics.graph.newton.newton`, the inputs fixed at x) every freedom rate is
linear in the input rates, q̇ = G(x) ẋ (the stacked closure J q̇ = 0 solved for the passive
freedoms, :func:`~screwkit.kinematics.graph.newton.rates`; idle rod spins held still,
kinematics/graph/idle.py), so each body's angular velocity and centre-of-mass velocity are
ω = Σ_k ω̂_k ẋ_k and v_c = Σ_k v̂_c,k ẋ_k. Kane's equations (Kane & Levinson, *Dynamics: Theory
and Applications*, 1985, ch. 6: generalized active and inertia forces, the partial velocities
ω̂_k, v̂_c,k) read

    M(x) ẍ = τ_motor(ẋ) + Q_g(x) + Q_f(x, ẋ) + Q_load(x, ẋ) − h(x, ẋ),

    M_kl = Σ_b m v̂_c,k·v̂_c,l + ω̂_k·I ω̂_l   (+ J_f,k on the diagonal: a flywheel on input k),
    h_k  = Σ_b m a⁰_c·v̂_c,k + (I α⁰ + ω × I ω)·ω̂_k,
    Q_g,k = Σ_b m g·v̂_c,k,
    Q_f,k = −Σ_j c_rot,j ω_rel,j·ω̂_rel,j,k + c_slide,j ṡ_j ŝ_j,k,
    Q_load,k = Q_out(q̇_out) G_out,k + F·v̂_P,k,

where I = R I_c Rᵀ is a body's inertia about its centre of mass in world axes, a⁰_c and α⁰ its
accelerations at ẍ = 0 (the velocity-product terms:
:func:`~screwkit.kinematics.graph.newton.accelerations` with zero input accelerations) and the
friction is the viscous joint friction of ``[drive.friction]`` (the moment −c ω_rel between a
joint's two bodies, the force −c ṡ along a slide) and Q_load the ``[drive.load]``: the force
or torque Q_out (:func:`~screwkit.simulation.drive.output_force`) on one joint freedom q_out,
carried to the inputs by its partial rates G_out,k = ∂q̇_out/∂ẋ_k (virtual work, as a loop's
Q_out·r), plus a constant world force F at a named point P of a body (``[drive.point_force]``),
whose generalised force is F·v̂_P,k with v̂_P,k = v̂_0,k + ω̂_k × p the point's partial
velocities (Kane's generalised active force). A motor on a slide input is a force motor (N against m/s, the same laws). h is Lagrange's ½ Ṁ ẋ terms and the
centripetal ones, so d/dt(½ ẋᵀ(M + J_f)ẋ + V) = (τ + Q_f + Q_load)·ẋ with V = −Σ m g·c: the energy
balance that the simulation checks.

Nothing here is tabulated: every evaluation closes the loops anew, so the closure holds to the
Newton tolerance at every state the integrator visits, and the passive rates are never states,
so they satisfy the velocity closure exactly.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import cross
from screwkit.dynamics.checks import MissingMassError
from screwkit.io.drive_table import JointFriction, LoadConfig, MotorConfig
from screwkit.kinematics.graph.closure import (
    GraphLayout,
    body_accelerations,
    body_twists,
    graph_layout,
    zero_configuration,
)
from screwkit.kinematics.graph.newton import (
    Linearised,
    accelerations,
    column_scale,
    difference,
    increment,
    newton,
    rates,
)
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.messages import given, listing
from screwkit.model.mass import MassProperties
from screwkit.model.mechanism import GROUND, Mechanism
from screwkit.simulation.drive import motor_torque, output_force
from screwkit.simulation.reduced import SimulationError

Array = NDArray[np.float64]

#: scaled closure residual a state must reach (the graph Newton's own target is 1e-13; this
#: leaves room for round-off on large mechanisms and is the bound the runs report against)
CLOSURE_LIMIT = 1e-10
#: near a limit (this fraction) a large Newton correction is the limit's doing, reported so
NEAR_SINGULAR = 1e-2
#: largest Newton correction (rad, or the mechanism's length scale) accepted after the
#: first-order predictor: its error is second order in the input step, so a larger one means
#: a step too long to be sure the closure stayed on its assembly branch (refused, not guessed)
BRANCH_JUMP = 0.05
#: a state whose passive block's smallest kept singular value falls below this fraction of the
#: largest is at a dead centre or limit position: the input coordinates stop describing it
SINGULAR_RATIO = 1e-6


def graph_masses(mech: Mechanism) -> list[MassProperties]:
    """Every moving body's mass properties; a clear error naming the bodies without."""
    missing = [b.name for b in mech.bodies if b.mass is None]
    if missing:
        raise MissingMassError(
            f"{mech.name}: simulation needs the mass properties of every moving body; "
            f"{', '.join(missing)} {'has' if len(missing) == 1 else 'have'} none (give mass, "
            "com and inertia in its [[bodies]] entry)")
    return [b.mass for b in mech.bodies if b.mass is not None]


def checked_graph_friction(mech: Mechanism, friction: Sequence[JointFriction]
                           ) -> tuple[JointFriction, ...]:
    """``friction`` merged by joint and checked against the mechanism's joints: a rotation
    coefficient needs a joint that turns (not P), a translation one a joint that slides (P or
    C); coefficients are ≥ 0."""
    names = {j.name: j for j in mech.joints}
    from screwkit.model.spin_groups import spin_groups

    rod_balls = {mech.joints[k].name: g.label for g in spin_groups(mech) for k in g.balls}
    merged: dict[str, JointFriction] = {}
    for f in friction:
        j = names.get(f.joint)
        if j is None:
            raise SimulationError(f"{mech.name}: friction on joint {f.joint!r}, which is not a "
                                  f"joint of it; joints are {listing(sorted(names))}")
        if not (f.rotation >= 0 and f.translation >= 0):
            raise SimulationError(f"{mech.name}: joint {f.joint!r}: friction coefficients are "
                                  ">= 0")
        if f.rotation and f.joint in rod_balls:
            raise SimulationError(
                f"{mech.name}: joint {f.joint!r} is a ball joint of the rod "
                f"{rod_balls[f.joint]!r}, which lies between two ball joints (a body, or a "
                "telescopic leg slid between them): its spin about "
                "its own axis is idle and held at zero, so friction there, which would drive "
                "that spin, is not modelled; put friction on the other joints")
        if f.rotation and j.kind == "P":
            raise SimulationError(f"{mech.name}: joint {f.joint!r} is a P joint, it does not "
                                  "turn: give it translation friction only")
        if f.translation and j.kind not in ("P", "C"):
            raise SimulationError(f"{mech.name}: joint {f.joint!r} is a {j.kind} joint, it "
                                  "does not slide: give it rotation friction only")
        old = merged.get(f.joint, JointFriction(f.joint))
        merged[f.joint] = JointFriction(f.joint, old.rotation + f.rotation,
                                        old.translation + f.translation)
    return tuple(merged.values())


@dataclass(frozen=True)
class GraphState:
    """One closed state: the configuration, its linearisation, every freedom's rate at the
    input rates (``qd``, (m,)) and the partial rates (``G``, (m, n): column k at unit rate of
    input k, the others still)."""

    conf: Configuration
    lin: Linearised
    G: Array
    residual: float
    singular_ratio: float


class GraphEquationOfMotion:
    """The equations of motion of a mechanism graph with its drive (module docstring).

    ``motors`` one :class:`~screwkit.io.drive_table.MotorConfig` per input (kind ``none`` for
    an undriven one); ``flywheel`` (n,) inertia on each input (kg·m², kg on a slide);
    ``friction`` joint friction; ``gravity`` (3,) m/s²; ``load`` the load on one joint
    freedom (:class:`~screwkit.io.drive_table.LoadConfig`); ``point_force`` (point name, force
    (3,) N in world axes) a constant force at a named point of a body. The configuration last closed is kept
    and starts the next Newton solve (the integrator moves in small steps), so one object
    follows one run."""

    def __init__(self, mech: Mechanism, *, motors: Sequence[MotorConfig] | None = None,
                 flywheel: ArrayLike | None = None, friction: Sequence[JointFriction] = (),
                 gravity: ArrayLike | None = None, load: LoadConfig | None = None,
                 point_force: tuple[str, ArrayLike] | None = None) -> None:
        self.mechanism = mech
        self.layout: GraphLayout = graph_layout(mech)
        n = len(mech.inputs)
        self.inputs = n
        masses = graph_masses(mech)
        self.mass = np.array([mp.mass for mp in masses])
        self.com = np.stack([mp.com for mp in masses])
        self.inertia = np.stack([mp.inertia for mp in masses])
        self.motors = tuple(motors) if motors is not None else (MotorConfig(),) * n
        if len(self.motors) != n:
            raise SimulationError(f"{mech.name}: {len(self.motors)} motor(s) for {n} input(s)")
        fw = np.zeros(n) if flywheel is None else np.asarray(flywheel, dtype=float) * np.ones(n)
        if not np.all(np.isfinite(fw) & (fw >= 0)):
            raise SimulationError(f"{mech.name}: a flywheel is an inertia >= 0; got {fw}")
        self.flywheel = fw
        self.friction = checked_graph_friction(mech, friction)
        self.gravity = np.zeros(3) if gravity is None else np.asarray(gravity, dtype=float)
        self.load = load
        self._load_row = None if load is None else self._loaded_freedom(load)
        self.point_force = point_force
        self._point = None if point_force is None else self._forced_point(*point_force)
        from screwkit.kinematics.graph.motion import expected_rank

        self.rank = expected_rank(mech, self.layout)
        self._idle = self.rank < len(self.layout.passive)
        self._conf = zero_configuration(self.layout)
        self._last: tuple[Array, Array] | None = None  # inputs and G of the last closure

    def _loaded_freedom(self, load: LoadConfig) -> int:
        """The row of q (and of G) of the loaded freedom; a clear error for a freedom the
        mechanism lacks or a ball's rotation."""
        mech, lay = self.mechanism, self.layout
        names = [f for j in mech.joints if j.kind != "S" for f in j.freedom_names()]
        if load.freedom not in names:
            raise SimulationError(f"{mech.name}: a load on {load.freedom!r}, which is not a "
                                  f"freedom of it (ball joints excluded); the freedoms are "
                                  f"{listing(names)}")
        k = next(i for i, j in enumerate(mech.joints) if load.freedom in j.freedom_names())
        return int(lay.first_freedom[k] + mech.joints[k].freedom_names().index(load.freedom))

    def _forced_point(self, name: str, force: ArrayLike) -> tuple[int, Array, Array]:
        """The body index, drawn position and force of the point force; clear errors."""
        mech = self.mechanism
        points = {p.name: p for p in mech.points}
        if name not in points:
            raise SimulationError(f"{mech.name}: a force at point {name!r}, which is not a "
                                  f"point of it; the points are {listing(sorted(points))} (add it as a "
                                  "[[points]] entry on its body)")
        pt = points[name]
        if pt.body not in self.layout.body_of or pt.body == GROUND:
            raise SimulationError(f"{mech.name}: point {name!r} is on the ground, which does "
                                  "not move: a force there does no work on the mechanism")
        F = np.asarray(force, dtype=float).reshape(-1)
        if F.shape != (3,) or not np.all(np.isfinite(F)):
            raise SimulationError(f"{mech.name}: the force at point {name!r} is three finite "
                                  f"components (N, world axes); got {given(F)}")
        return self.layout.body_of[pt.body], np.asarray(pt.at, dtype=float), F

    def start_at(self, x: ArrayLike) -> None:
        """Start the closures from the drawn mode followed to inputs ``x`` (n,) (the graph
        tracker, :func:`~screwkit.kinematics.graph.motion.solve_mechanism`), so that a run
        starting away from the drawing stays in the drawn assembly mode."""
        from screwkit.kinematics.graph.motion import solve_mechanism

        X = np.asarray(x, dtype=float).reshape(1, -1)
        self._last = None
        if np.all(X == 0.0):
            self._conf = zero_configuration(self.layout)
            return
        md = solve_mechanism(self.mechanism, X, rates=0.0, accelerations=0.0).mode(0)
        if not md.assembles[0]:
            raise SimulationError(f"{self.mechanism.name}: the drawn mode does not assemble at "
                                  f"the start inputs {self._shown(X[0])}")
        self._conf = md.conf.take(np.array([0]))

    # --- kinematics --------------------------------------------------------------------
    def close(self, x: ArrayLike) -> GraphState:
        """The configuration at inputs ``x`` (n,), closed by the graph Newton from the last
        one, and the partial rates G."""
        mech, lay = self.mechanism, self.layout
        X = np.asarray(x, dtype=float).reshape(1, -1)
        start = self._conf
        if self._last is not None:  # first-order predictor along the last partial rates
            x_last, G_last = self._last
            start = increment(start, (G_last @ (X[0] - x_last))[None], lay)
        conf, err, lin = newton(mech, lay, start, X, max_iter=20)
        if not err[0] <= CLOSURE_LIMIT:
            raise SimulationError(
                f"{mech.name}: the loops do not close at inputs {self._shown(X[0])} (scaled "
                f"residual {err[0]:.3g}): the motion has left the assembled range")
        s = lin.sigma[0]
        ratio = float(s[self.rank - 1] / s[0]) if self.rank and s.size else 1.0
        correction = difference(conf, start, lay) / column_scale(lay)
        if self._last is not None and float(np.max(np.abs(correction))) > BRANCH_JUMP:
            if ratio < NEAR_SINGULAR:  # the passive rates grow without bound at a limit
                raise self._singular_error(X[0])
            raise SimulationError(
                f"{mech.name}: closing the loops at inputs {self._shown(X[0])} moved the "
                f"passive freedoms by {float(np.max(np.abs(correction))):.3g} (rad, or length "
                "scales) from the predicted configuration, too far to be sure it stayed on its "
                "assembly branch; integrate with a smaller rtol (smaller steps)")
        self._conf = conf
        G = np.empty((lay.m, self.inputs))
        for k in range(self.inputs):
            e = np.zeros((1, self.inputs))
            e[0, k] = 1.0
            qd = rates(mech, lay, lin, e)
            if self._idle:
                from screwkit.kinematics.graph.idle import hold_rod_spin

                qd = hold_rod_spin(mech, lay, lin, qd)
            G[:, k] = qd[0]
        self._last = (X[0].copy(), G)
        return GraphState(conf, lin, G, float(err[0]), ratio)

    def _singular_error(self, x: Array) -> SimulationError:
        return SimulationError(
            f"{self.mechanism.name}: the motion reaches a dead centre or limit position at "
            f"inputs {self._shown(x)}, where the inputs stop describing it (the equations of "
            "motion in the input coordinates are singular there)")

    def _shown(self, x: Array) -> str:
        lay = self.layout
        return ", ".join(f"{n} = {v:.6g} {'m' if lay.is_translation[f] else 'rad'}"
                         for n, f, v in zip(self.mechanism.inputs, lay.inputs, x, strict=True))

    def _body_frames(self, st: GraphState) -> tuple[Array, Array]:
        """World centres of mass (B, 3) and inertias about them (B, 3, 3)."""
        nb = len(self.mechanism.bodies)
        R, p = st.lin.frames.R[0, :nb], st.lin.frames.p[0, :nb]
        c = np.einsum("bij,bj->bi", R, self.com) + p
        I_w = np.einsum("bij,bjk,blk->bil", R, self.inertia, R)
        return c, I_w

    def _partials(self, st: GraphState, c: Array) -> tuple[Array, Array, Array]:
        """Partial angular and centre-of-mass velocities (n, B, 3) of every body, and the
        partial twists (n, B + 1, 6) of every body and the ground (the twists are linear in
        the input rates: every twist is Σ_k ẋ_k of these, so they are computed once)."""
        mech, lay = self.mechanism, self.layout
        nb = len(mech.bodies)
        screws = np.repeat(st.lin.frames.screws, self.inputs, axis=0)
        V, _ = body_twists(mech, lay, screws, st.G.T)
        w = V[:, :nb, :3]
        return w, V[:, :nb, 3:] + cross(w, np.broadcast_to(c, w.shape)), V

    # --- dynamics ----------------------------------------------------------------------
    def terms(self, x: ArrayLike, xd: ArrayLike) -> dict[str, Any]:
        """Every term of the equations of motion at (x, ẋ) (module docstring): ``mass_matrix``
        M + diag(J_f) (n, n), ``velocity_terms`` h, ``gravity`` Q_g, ``friction`` Q_f,
        ``load`` Q_load (n,), ``output_force`` Q_out on the loaded freedom, ``motor`` τ,
        ``acceleration`` ẍ, ``kinetic_energy``, ``potential_energy`` (−Σ m g·c),
        the ``state`` and the closure ``residual``."""
        mech, lay = self.mechanism, self.layout
        xd = np.asarray(xd, dtype=float)
        st = self.close(x)
        if st.singular_ratio < SINGULAR_RATIO:
            raise self._singular_error(np.asarray(x, dtype=float))
        c, I_w = self._body_frames(st)
        w_k, v_k, V_k = self._partials(st, c)
        m = self.mass
        M = (np.einsum("b,kbi,lbi->kl", m, v_k, v_k)
             + np.einsum("kbi,bij,lbj->kl", w_k, I_w, w_k)) + np.diag(self.flywheel)
        qd = st.G @ xd
        qdd, bias = accelerations(mech, lay, st.lin, qd[None], np.zeros((1, self.inputs)))
        if self._idle:
            from screwkit.kinematics.graph.idle import hold_rod_spin

            qdd = hold_rod_spin(mech, lay, st.lin, qdd, bias)
        nb = len(mech.bodies)
        V = np.einsum("k,kbj->bj", xd, V_k)[None]  # the twists at ẋ (linear in ẋ)
        A = body_accelerations(mech, lay, st.lin.frames.screws, qdd, bias)
        w, v0 = V[0, :nb, :3], V[0, :nb, 3:]
        al, a0 = A[0, :nb, :3], A[0, :nb, 3:]
        v_c = v0 + cross(w, c)
        a_c = a0 + cross(al, c) + cross(w, v_c)
        Iw = np.einsum("bij,bj->bi", I_w, w)
        moment = np.einsum("bij,bj->bi", I_w, al) + cross(w, Iw)
        h = np.einsum("b,bi,kbi->k", m, a_c, v_k) + np.einsum("bi,kbi->k", moment, w_k)
        Qg = np.einsum("b,i,kbi->k", m, self.gravity, v_k)
        Qf = self._friction(st, V[0], V_k, qd)
        tau = np.array([float(motor_torque(mo, xd[k])) for k, mo in enumerate(self.motors)])
        q_out, Ql = 0.0, np.zeros(self.inputs)
        if self._load_row is not None:
            q_out = float(output_force(self.load, qd[self._load_row]))
            Ql = q_out * st.G[self._load_row]
        if self._point is not None:
            b, at, F = self._point
            p = st.lin.frames.R[0, b] @ at + st.lin.frames.p[0, b]
            Ql = Ql + (V_k[:, b, 3:] + cross(V_k[:, b, :3], np.broadcast_to(p, (self.inputs, 3)))) @ F
        acc = np.linalg.solve(M, tau + Qg + Qf + Ql - h)
        kinetic = 0.5 * (np.einsum("b,bi,bi->", m, v_c, v_c) + np.einsum("bi,bi->", w, Iw)
                         + float(self.flywheel @ xd ** 2))
        return {"mass_matrix": M, "velocity_terms": h, "gravity": Qg, "friction": Qf,
                "load": Ql, "output_force": q_out, "motor": tau, "acceleration": acc, "kinetic_energy": float(kinetic),
                "potential_energy": float(-np.einsum("b,i,bi->", m, self.gravity, c)),
                "state": st, "residual": st.residual}

    def _friction(self, st: GraphState, V: Array, Vk: Array, qd: Array) -> Array:
        """Q_f (n,): the joints' viscous friction on the inputs (module docstring)."""
        mech, lay = self.mechanism, self.layout
        Q = np.zeros(self.inputs)
        if not self.friction:
            return Q
        index = {j.name: i for i, j in enumerate(mech.joints)}
        for f in self.friction:
            i = index[f.joint]
            a, b = (lay.body_of[x] for x in mech.joints[i].bodies)
            if f.rotation:
                rel = V[b, :3] - V[a, :3]
                rel_k = Vk[:, b, :3] - Vk[:, a, :3]
                Q -= f.rotation * rel_k @ rel
            if f.translation:
                s = lay.first_freedom[i] + (1 if mech.joints[i].kind == "C" else 0)
                Q -= f.translation * st.G[s] * qd[s]
        return Q

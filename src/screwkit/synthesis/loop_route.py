"""Dimensional synthesis of any loop (the generic route): the problem and its residuals with the
exact Jacobian from the loop's screw Jacobian.

The loop closes, G(q, p) = Π J_i(q_i) L_i(p) = I, for every dimension vector p. Differentiating at
a fixed input (the variations δG·G⁻¹ as twists in the ground frame):

    J_p(q) dq_p/dp_u = −ξ_u,    ξ_u = Σ_k Ad(A_k)·(dL_k/dp_u · L_k⁻¹) + Σ_j (d offset_j/dp_u) ζ_j

with J_p the passive columns of the loop's screw Jacobian (Bagci 1969 eqs. 3.19–3.26), A_k the
frame after joint k (where L_k acts), ζ_j the twist of joint j's constant offset (a translation
along its axis; a rotation about it for a P joint). dL_k/dp_u and d offset_j/dp_u come by
complex-step differentiation of the family's geometry (:mod:`screwkit.model.geometry`), exact to
rounding; the input θ01 enters as J_p dq_p/dθ01 = −J_in (the rate equation). The derivative of
an output is its row of dq_p: exact, no finite differences (tested against them).

Residuals, as Bagci 1969 §5.1 for any output (eq. 5.4 with eq. 5.1's reference at θ = 0):
R_φ(θ_i) = ψ_d(θ_i) − s_out [y(θ_i) − y(0)] (wrapped), R_S(θ_i) = [S_d(θ_i) − (z(θ_i) − z(0))]/L,
y the rotation output (e.g. the RSSR's φ0), z the translation output, at the inputs
x_i = θ01 ± θ_i. The assembly mode is held by continuation: every new dimension vector is reached
from the last accepted one in small steps, each a first-order prediction (the derivatives above)
corrected by Gauss–Newton on the loop closure; a step whose correction is not small against the
step would change branch and is refused.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import vee, wrap_angle
from screwkit.errors import InputError
from screwkit.kinematics.registry import output_freedom
from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    LoopFrames,
    apply_increment,
    forward,
    layout,
)
from screwkit.kinematics.tracker.loop_jets import close_loop
from screwkit.messages import given, listing
from screwkit.model.geometry import LoopGeometry
from screwkit.model.linkage import Linkage, LinkageError
from screwkit.synthesis.residuals import Evaluation, NotAssembled
from screwkit.synthesis.targets import ScrewTarget

__all__ = ["LoopResidualModel", "LoopSynthesisProblem", "closure_sensitivities"]

_STEP = 1e-30  # complex step


@dataclass(frozen=True)
class LoopSynthesisProblem:
    """A synthesis of any loop by the generic route (module docstring; SI units, radians).

    ``build`` makes the loop from every dimension (``kinds``: name → "length" or "angle"),
    ``geometry`` its link transforms and offsets (complex-safe); ``start`` holds every dimension
    and ``theta01``; ``rotation_output``/``translation_output`` name the variables that generate
    the target's rotation and translation; ``mode`` is the start's assembly mode (the numbering
    of ``screwkit analyze``; None tries every mode).
    """

    family: str
    build: Callable[[Mapping[str, float]], Linkage]
    geometry: Callable[[Mapping[str, Any]], LoopGeometry]
    kinds: Mapping[str, str]
    target: ScrewTarget
    start: Mapping[str, float]
    unknowns: tuple[str, ...]
    rotation_output: str | None = None
    translation_output: str | None = None
    bounds: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    mode: int | None = None
    input_direction: int = 1
    output_direction: int = 1
    length_scale: float = 0.0254
    max_iterations: int = 200
    time_limit: float = 10.0

    def __post_init__(self) -> None:
        allowed = set(self.kinds) | {"theta01"}
        if not self.unknowns or len(set(self.unknowns)) != len(self.unknowns):
            raise InputError(f"unknowns must be distinct and not empty, got {self.unknowns!r}")
        bad = [u for u in self.unknowns if u not in allowed]
        if bad:
            raise InputError(f"unknown(s) {listing(bad)} cannot be solved for; choose among "
                             f"{listing(sorted(allowed))}")
        missing = sorted(allowed - set(self.start))
        if missing:
            raise InputError(f"start/constants lack {listing(missing)}: give a value for every dimension")
        for name, value in self.start.items():
            if not math.isfinite(float(value)):
                raise InputError(f"start value of {name} must be finite, got {given(value)}")
        for name, (lo, hi) in self.bounds.items():
            if name not in self.unknowns:
                raise InputError(f"bounds given for {name!r}, which is not an unknown")
            if not lo < hi:
                raise InputError(f"bounds of {name}: lower {lo!r} must be below upper {hi!r}")
        if self.target.rotation is not None and self.rotation_output is None:
            raise InputError(f"a {self.family} has no rotation output to generate the target "
                             "rotation")
        if self.target.translation is not None and self.translation_output is None:
            raise InputError(f"a {self.family}'s output has no translation, so it cannot "
                             "generate a desired translation; prescribe the rotation only")
        if self.input_direction not in (1, -1) or self.output_direction not in (1, -1):
            raise InputError("input_direction and output_direction must be +1 or -1")
        if not (self.length_scale > 0.0 and math.isfinite(self.length_scale)):
            raise InputError(f"length_scale must be a positive length, got {given(self.length_scale)}")
        if self.mode is not None and self.mode < 0:
            raise InputError(f"mode must be an assembly mode index ≥ 0, got {self.mode}")

    def dimensions(self, x: Array) -> dict[str, float]:
        """Every dimension and theta01 at the unknown vector ``x``."""
        out = {k: float(v) for k, v in self.start.items()}
        out.update({n: float(v) for n, v in zip(self.unknowns, x, strict=True)})
        return out

    def start_vector(self) -> NDArray[np.float64]:
        return np.array([float(self.start[n]) for n in self.unknowns])

    def scale(self, name: str) -> float:
        """The size of a unit step in ``name``: the length scale for a length, 1 rad else."""
        return self.length_scale if self.kinds.get(name) == "length" else 1.0


def closure_sensitivities(linkage: Linkage, fr: LoopFrames, geometry: Callable[
        [Mapping[str, Any]], LoopGeometry], dims: Mapping[str, float],
        names: tuple[str, ...]) -> Array:
    """(N, 6, len(names)) ξ_u: the twist (ground frame, (ω; v) with v at the ground origin) by
    which the loop closure moves per unit of each dimension ``names`` at closed configurations
    whose frames are ``fr`` (:func:`~screwkit.kinematics.tracker.loop.forward`; module docstring)."""
    N = fr.screws.shape[0]
    out = np.zeros((N, 6, len(names)))
    base = geometry(dims)
    for u, name in enumerate(names):
        geo = geometry({**dims, name: dims[name] + 1j * _STEP})
        for k in range(len(linkage.joints)):
            R = np.real(np.asarray(base.rotations[k], dtype=complex))
            t = np.real(np.asarray(base.translations[k], dtype=complex))
            Rd = np.imag(np.asarray(geo.rotations[k], dtype=complex)) / _STEP
            td = np.imag(np.asarray(geo.translations[k], dtype=complex)) / _STEP
            if not (Rd.any() or td.any()):
                continue
            w = vee(0.5 * (Rd @ R.T - R @ Rd.T))  # dR/dp·Rᵀ is skew
            v = td - np.cross(w, t)
            AR, Ap = fr.after_R[:, k], fr.after_p[:, k]
            wg = AR @ w
            out[:, :3, u] += wg
            out[:, 3:, u] += AR @ v + np.cross(Ap, wg)
        for j, joint in enumerate(linkage.joints):
            od = float(np.imag(complex(geo.offsets[j])) / _STEP)
            if od == 0.0 or joint.kind == "C":
                continue
            axis, origin = fr.before_R[:, j, :, 2], fr.before_p[:, j]
            if joint.kind == "P":  # a constant turn about the slide axis
                out[:, :3, u] += od * axis
                out[:, 3:, u] += od * np.cross(origin, axis)
            else:  # a constant shift along the joint axis
                out[:, 3:, u] += od * axis
    return out


class LoopResidualModel:
    """Residuals r(x) and their exact Jacobian for a :class:`LoopSynthesisProblem` on one mode
    (module docstring); the configuration at every design point is followed from the last
    accepted evaluation."""

    def __init__(self, problem: LoopSynthesisProblem, mode: int | None = None) -> None:
        from screwkit.kinematics.solve_motion import solve_motion

        self.problem = problem
        tgt = problem.target
        self.theta = tgt.theta_all
        where = {float(t): i for i, t in enumerate(self.theta)}
        self.rot_idx = np.array([where[float(t)] for t in tgt.theta_rotation], dtype=np.int64)
        self.tr_idx = np.array([where[float(t)] for t in tgt.theta_translation], dtype=np.int64)
        self.psi_d = tgt.desired_rotation(tgt.theta_rotation)
        self.s_d = tgt.desired_translation(tgt.theta_translation)
        self.n_residuals = self.rot_idx.size + self.tr_idx.size
        self.mode = problem.mode if mode is None else mode
        dims = problem.dimensions(problem.start_vector())
        linkage = self._build(dims)
        self.layout = layout(linkage)
        self.outputs = [output_freedom(linkage, n) if n is not None else None
                        for n in (problem.rotation_output, problem.translation_output)]
        x = self.inputs(dims)
        order = np.argsort(x, kind="stable")
        motion = solve_motion(linkage, x[order])
        if self.mode is None or not 0 <= self.mode < len(motion.modes):
            raise NotAssembled(f"the start has {len(motion.modes)} assembly mode(s) over the "
                               f"design points; mode {self.mode} asked for")
        md = motion.modes[self.mode]
        good = md.assembles & ~md.singular
        if not good.all():
            bad = np.degrees(self.theta[order][~good])
            raise NotAssembled(
                f"the start does not assemble (or is singular) on mode {self.mode} at design "
                f"point(s) theta = {', '.join(f'{v:.6g}' for v in bad[:8])} deg; change the "
                "start, theta01 or the mode")
        back = np.empty_like(order)
        back[order] = np.arange(order.size)
        self.dims = dims
        self.linkage = linkage
        self.conf = md.conf.take(back)
        self.derivatives: Array | None = None  # dq/du at the remembered state
        self._trial: tuple[bytes, Linkage, Configuration, dict[str, float], Array] | None = None

    # -- the loop at a dimension vector -----------------------------------------------------
    def _build(self, dims: Mapping[str, float]) -> Linkage:
        try:
            return self.problem.build(dims)
        except (LinkageError, ValueError) as exc:
            raise NotAssembled(f"not a mechanism: {exc}") from None

    def inputs(self, dims: Mapping[str, float]) -> Array:
        return np.asarray(dims["theta01"] + self.problem.input_direction * self.theta)

    def _sensitivity(self, linkage: Linkage, conf: Configuration, dims: Mapping[str, float]
                     ) -> Array:
        """(N, m, n_u) dq/du of every freedom (passive rows; the input's row for theta01)."""
        pr, lay = self.problem, self.layout
        fr = forward(linkage, conf, lay)
        names = [n for n in pr.unknowns if n != "theta01"]
        xi = np.zeros((conf.size, 6, len(pr.unknowns)))
        if names:
            sens = closure_sensitivities(linkage, fr, pr.geometry, dims, tuple(names))
            for c, n in enumerate(names):
                xi[:, :, pr.unknowns.index(n)] = sens[:, :, c]
        f_in = lay.names.index(linkage.inputs[0])
        if "theta01" in pr.unknowns:
            xi[:, :, pr.unknowns.index("theta01")] = fr.screws[:, :, f_in]
        L = linkage.length_scale
        rows = np.array([1, 1, 1, 1 / L, 1 / L, 1 / L])
        cols = np.array([L if t else 1.0 for t in lay.is_translation])
        pidx = [k for k, n in enumerate(lay.names) if n not in linkage.inputs]
        Jp = fr.screws[:, :, pidx] * rows[None, :, None] * cols[pidx][None, None, :]
        d = np.zeros((conf.size, len(lay.names), len(pr.unknowns)))
        d[:, pidx] = -np.einsum("npi,niu->npu", np.linalg.pinv(Jp, rcond=1e-10),
                                xi * rows[None, :, None]) * cols[pidx][None, :, None]
        if "theta01" in pr.unknowns:
            d[:, f_in, pr.unknowns.index("theta01")] = 1.0
        return d

    def _step(self, dims: dict[str, float], conf: Configuration, d: Array,
              nxt: dict[str, float]) -> tuple[Linkage, Configuration] | None:
        """One predictor–corrector step from ``dims`` to ``nxt``; None if it would leave the
        branch (the correction is not small against the step) or does not close."""
        pr, lay = self.problem, self.layout
        linkage = self._build(nxt)
        du = np.array([nxt[n] - dims[n] for n in pr.unknowns])
        size = float(np.max(np.abs(du) / np.array([pr.scale(n) for n in pr.unknowns])))
        guess = apply_increment(conf, np.einsum("nmu,u->nm", d, du), lay)
        q = guess.scalars.copy()
        q[:, lay.scalar_col[lay.names.index(linkage.inputs[0])]] = self.inputs(nxt)
        closed, ok = close_loop(linkage, Configuration(q, guess.spherical), lay)
        unit = np.array([linkage.length_scale if lay.is_translation[f] else 1.0
                         for f in range(len(lay.names)) if lay.scalar_col[f] >= 0])
        moved = float(np.max(np.abs(closed.scalars - q) / unit[None, :]))
        if not ok.all() or moved > min(0.2, 1e-3 + 0.3 * size):
            return None
        return linkage, closed

    def _follow(self, x: Array) -> tuple[Linkage, Configuration, dict[str, float], Array]:
        """The loop and configurations at unknowns ``x``, continued from the remembered state
        along the straight path in the unknowns, in steps halved until each keeps the branch
        (module docstring)."""
        pr = self.problem
        target = pr.dimensions(x)
        dims, conf, linkage = dict(self.dims), self.conf, self.linkage
        d = self.derivatives if self.derivatives is not None else \
            self._sensitivity(linkage, conf, dims)
        done, step = 0.0, 1.0
        while done < 1.0:
            to = min(1.0, done + step)
            nxt = {**dims, **{n: self.dims[n] + (target[n] - self.dims[n]) * to
                              for n in pr.unknowns}}
            moved = self._step(dims, conf, d, nxt)
            if moved is None:
                step /= 2.0
                if step < 1.0 / 256:
                    raise NotAssembled("the mechanism does not stay on its assembly mode at "
                                       "every design point for these dimensions")
                continue
            linkage, conf = moved
            dims, done, step = nxt, to, min(2.0 * step, 1.0)
            d = self._sensitivity(linkage, conf, dims)
        return linkage, conf, dims, d

    def accept(self, x: Array) -> bool:
        """Make the last trial evaluation, if it was at ``x``, the state to follow from."""
        x = np.asarray(x, dtype=np.float64)
        if self._trial is None or self._trial[0] != x.tobytes():
            return False
        _, self.linkage, self.conf, self.dims, self.derivatives = self._trial
        return True

    def evaluate(self, x: Array, *, jacobian: bool = True, remember: bool = True) -> Evaluation:
        """Residuals (and the exact Jacobian) at ``x``; raises NotAssembled off the mode."""
        x = np.asarray(x, dtype=np.float64)
        pr = self.problem
        linkage, conf, dims, d = self._follow(x)
        lay = self.layout
        (fr_name, fr_sign), tr = (self.outputs[0] or ("", 0.0)), self.outputs[1]
        scal = conf.scalars
        y = (fr_sign * scal[:, lay.scalar_col[lay.names.index(fr_name)]] if fr_name
             else np.zeros(self.theta.size))
        z = (tr[1] * scal[:, lay.scalar_col[lay.names.index(tr[0])]] if tr is not None
             else np.zeros(self.theta.size))
        r_phi = wrap_angle(self.psi_d - pr.output_direction * (y[self.rot_idx] - y[0]))
        r_s = (self.s_d - (z[self.tr_idx] - z[0])) / pr.length_scale
        jac = phi_jac = None
        if jacobian:
            dy = fr_sign * d[:, lay.names.index(fr_name)] if fr_name else np.zeros_like(d[:, 0])
            dz = tr[1] * d[:, lay.names.index(tr[0])] if tr is not None else np.zeros_like(dy)
            j_phi = -pr.output_direction * (dy[self.rot_idx] - dy[:1])
            j_s = -(dz[self.tr_idx] - dz[:1]) / pr.length_scale
            jac = np.vstack([j_phi, j_s])
            phi_jac = dy
        if remember:
            self.dims, self.conf, self.linkage, self.derivatives = dims, conf, linkage, d
        else:
            self._trial = (x.tobytes(), linkage, conf, dims, d)
        x_in = self.inputs(dims)
        return Evaluation(x, dims, self.theta, x_in, y, z, 0.0,
                          np.concatenate([r_phi, r_s]), jac, phi_jac)

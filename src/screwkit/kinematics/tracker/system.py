"""The closure system a continuation follows (:class:`~screwkit.kinematics.tracker.continuation.Tracker`):
what the tracker needs of a set of closure equations F(q) = 0 with the inputs among the
freedoms, whoever forms them. Two systems implement it: one closed loop in frame form
(:class:`LoopSystem`, the loop functions of tracker/loop.py, rates.py and solve.py) and the
stacked closure of a mechanism's loops (graph/system.py).

The predictor asks for *directional* jets only: at a closed configuration q and an input move
d, the first and second derivatives of the branch along d, q' = q_X d and q'' = q_XX(d, d),
from one rate solve J_p q̇_p = −J_in d and one acceleration solve J_p q̈_p = −bias(q̇) (the
velocity-product term, zero input acceleration); Rahman's rate equations (eq. 2.10–2.12 of the
loop closure), whatever the number of inputs. Along a straight sweep every target of a front
lies along one direction, so a front needs one jet per wave: q(x + s u) ≈ q + s q'_u + ½ s² q''_u.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    Layout,
    apply_increment,
    configuration_difference,
    forward,
)
from screwkit.kinematics.tracker.rates import (
    freedom_rates,
    joint_rates,
    rate_equations,
    spin_links,
)
from screwkit.kinematics.tracker.solve import (
    CLOSURE_TOL,
    Correction,
    correct,
    set_inputs,
    signature,
)
from screwkit.kinematics.tracker.tracks import TrackRates, closure_residual, polished
from screwkit.model.linkage import Linkage

#: closure residual at which an interpolated sample of a loop is kept as it is (else Newton
#: corrects it), or 8× the round-off of the corrected samples on either side where that is more
FILL_TOL = 1e-14


class ClosureSystem(Protocol):
    """What :class:`~screwkit.kinematics.tracker.continuation.Tracker` follows (module
    docstring). Configurations are :class:`~screwkit.kinematics.tracker.loop.Configuration`
    batches; increments are over all ``m`` freedoms, inputs included."""

    n_scalar: int
    n_spherical: int
    m: int
    #: per freedom, 1/length for a slide (a step's size in scaled freedoms)
    col_scale: Array
    #: per input, 1/length for a slide
    in_scale: Array
    #: each ball joint's three freedoms
    balls: list[list[int]]
    #: closure residual at which an interpolated sample is kept as it is (else Newton corrects
    #: it; the tracker's FILL_TOL for a loop whose samples are used as they are)
    fill_tol: float
    #: whether the system has idle freedoms the Motion's build turns afterwards (S–S rods of a
    #: loop): then an interpolated sample is kept at the corrector's tolerance, and no rates
    idle_spin: bool

    def polished(self, conf: Configuration) -> Configuration: ...

    def residual(self, conf: Configuration) -> tuple[Array, Any]:
        """Scaled closure residual max|ξ| (B,), and what :meth:`sample_rates` reuses."""
        ...

    def sigma(self, conf: Configuration) -> Array:
        """σ_min/σ_max of the passive Jacobian at its regular rank (B,)."""
        ...

    def jets(self, conf: Configuration, D: Array, exact_sigma: bool = True,
             ) -> tuple[Array, Array, Array, Array]:
        """q_X d and q_XX(d, d) (B, m) along the input moves ``D`` (B, n_in), the σ ratio (B,)
        (NaN where not needed with ``exact_sigma=False``) and the scaled passive Jacobian."""
        ...

    def set_inputs(self, conf: Configuration, X: Array) -> Configuration: ...

    def increment(self, conf: Configuration, delta: Array) -> Configuration: ...

    def difference(self, a: Configuration, b: Configuration) -> Array: ...

    def correct(self, conf: Configuration, reach: Array, contraction: float | Array,
                max_iter: int = 7) -> Correction: ...

    def signature(self, conf: Configuration) -> Array: ...

    def sample_rates(self, checked: Any, closed: NDArray[np.bool_],
                     near: tuple[Array, Array] | None, Xd: Array, Xdd: Array) -> TrackRates:
        """Rates and accelerations of samples whose residual was just found (``checked``)."""
        ...


def ball_freedoms(joint_of: tuple[int, ...], spherical_of_joint: dict[int, int],
                  ) -> list[list[int]]:
    """Each ball joint's freedoms (the three of its rotation), from a layout's columns."""
    return [[f for f, jj in enumerate(joint_of) if jj == j] for j in spherical_of_joint]


class LoopSystem:
    """One closed loop in frame form (a :class:`~screwkit.model.linkage.Linkage`): the loop
    engine's closure, rate equations and corrector."""

    def __init__(self, linkage: Linkage, lay: Layout) -> None:
        self.linkage, self.lay = linkage, lay
        self.n_scalar, self.n_spherical, self.m = lay.n_scalar, lay.n_spherical, len(lay.names)
        L = linkage.length_scale
        self.col_scale = np.array([1.0 / L if t else 1.0 for t in lay.is_translation])
        self.in_scale = np.array([1.0 / L if n.endswith(".s") else 1.0
                                  for n in linkage.inputs])
        self.idle_spin = bool(spin_links(linkage))
        self.balls = ball_freedoms(lay.joint_of, lay.spherical_of_joint)
        # round-off closure, as polished as a corrected sample; with S–S rods the Motion's
        # build turns the rods and polishes every sample afterwards: the corrector's tolerance
        self.fill_tol = CLOSURE_TOL if self.idle_spin else FILL_TOL

    def polished(self, conf: Configuration) -> Configuration:
        return polished(self.linkage, self.lay, conf)

    def residual(self, conf: Configuration) -> tuple[Array, Any]:
        fr = forward(self.linkage, conf, self.lay, frames=False)
        return closure_residual(self.linkage, fr.closure_R, fr.closure_p), fr

    def sigma(self, conf: Configuration) -> Array:
        return np.asarray(rate_equations(self.linkage, self.lay,
                                         forward(self.linkage, conf, self.lay)).sigma_ratio)

    def jets(self, conf: Configuration, D: Array, exact_sigma: bool = True,
             ) -> tuple[Array, Array, Array, Array]:
        """Directional jets (module docstring; the minimum-norm solution where the rate
        equations are singular: on a continuum the least motion that follows the input)."""
        eq = rate_equations(self.linkage, self.lay,
                            forward(self.linkage, conf, self.lay, frames=self.idle_spin),
                            exact_sigma=exact_sigma)
        v, a, _ = freedom_rates(self.linkage, self.lay, eq, D, np.zeros_like(D), True)
        return v, a, eq.sigma_ratio, eq.passive

    def set_inputs(self, conf: Configuration, X: Array) -> Configuration:
        return set_inputs(conf, self.lay, self.linkage.inputs, X)

    def increment(self, conf: Configuration, delta: Array) -> Configuration:
        return apply_increment(conf, delta, self.lay)

    def difference(self, a: Configuration, b: Configuration) -> Array:
        return configuration_difference(a, b, self.lay)

    def correct(self, conf: Configuration, reach: Array, contraction: float | Array,
                max_iter: int = 7) -> Correction:
        return correct(self.linkage, conf, self.lay, reach, contraction, max_iter=max_iter)

    def signature(self, conf: Configuration) -> Array:
        return signature(self.linkage, conf, self.lay)

    def sample_rates(self, checked: Any, closed: NDArray[np.bool_],
                     near: tuple[Array, Array] | None, Xd: Array, Xdd: Array) -> TrackRates:
        eq = rate_equations(self.linkage, self.lay, checked, closed, exact_sigma=False,
                            near=near)
        jr = joint_rates(self.linkage, self.lay, eq, closed, Xd, Xdd)
        return TrackRates(jr.qd, jr.qdd, jr.singular, closed.copy())


__all__ = ["ClosureSystem", "LoopSystem", "ball_freedoms"]

"""The loop-closure map of a :class:`~screwkit.model.Linkage`, batched over samples.

A configuration holds every freedom: one column per scalar freedom (R, P, C, H, U) and one
rotation matrix per spherical joint. :func:`forward` walks the loop once and returns, for every
joint, its frame before and after its motion (as (R, d) pairs — the real form of the screw
matrix R + ε[d]×R), the closure displacement G = Π J_i L_i (identity when the loop closes), and
the unit screws of every freedom in the ground frame, which are the columns of the loop-closure
Jacobian (Bagci 1969 eqs. 3.19–3.26: the skew operator of joint i, carried to the base).

Screws are 6-vectors (ω; v): ω the direction (angular part) and v the velocity of the point at
the ground origin, so a revolute about the line through c along u is (u; c × u), a prismatic
along u is (0; u) and a helical of pitch h is (u; c × u + h u).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import rot_y, skew
from screwkit.errors import InputError
from screwkit.model.linkage import Linkage

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Configuration:
    """Joint state of a batch of samples.

    ``scalars`` (N, n_scalar): the scalar freedoms (R/P/C/H/U) in loop order;
    ``spherical`` (N, n_S, 3, 3): the rotation of each spherical joint (child frame relative to
    the joint frame).
    """

    scalars: Array
    spherical: Array

    @property
    def size(self) -> int:
        return int(self.scalars.shape[0])

    def take(self, index: NDArray[np.intp] | slice) -> Configuration:
        return Configuration(self.scalars[index], self.spherical[index])


@dataclass(frozen=True)
class Layout:
    """Where each freedom of a linkage lives in a :class:`Configuration` and in the Jacobian,
    and the loop's constants the hot paths need (link transforms as arrays, length scale)."""

    names: tuple[str, ...]  # all freedoms, loop order (Jacobian columns)
    joint_of: tuple[int, ...]  # joint index of each freedom
    scalar_col: tuple[int, ...]  # column in Configuration.scalars, or -1 for S freedoms
    spherical_of_joint: dict[int, int]  # joint index -> index in Configuration.spherical
    is_translation: tuple[bool, ...]  # P/C s freedoms carry length units
    n_scalar: int
    n_spherical: int
    #: the linkage the constants below were read from (a layout fits every loop with the same
    #: joints, but its constants only this one: see :func:`constants`)
    source: Linkage | None = field(default=None, compare=False, repr=False)
    link_rotations: Array = field(default_factory=lambda: np.zeros((0, 3, 3)), compare=False,
                                  repr=False)
    link_translations: Array = field(default_factory=lambda: np.zeros((0, 3)), compare=False,
                                     repr=False)
    link_scale: float = field(default=1.0, compare=False, repr=False)


def constants(linkage: Linkage, lay: Layout) -> tuple[Array, Array, float]:
    """The link rotations (n, 3, 3), translations (n, 3) and length scale of ``linkage``: from
    the layout when it was made for this very linkage (the hot paths), else read anew (a layout
    reused for another loop with the same joints, e.g. a synthesis trial's dimensions)."""
    if lay.source is linkage:
        return lay.link_rotations, lay.link_translations, lay.link_scale
    return (np.stack([np.asarray(t.real, dtype=float) for t in linkage.link_transforms]),
            np.stack([np.asarray(t.translation, dtype=float) for t in linkage.link_transforms]),
            linkage.length_scale)


@dataclass(frozen=True)
class FreedomColumns:
    """Where the freedoms of a list of joints live: their names ``"<joint>.<freedom>"`` in
    joint order, each one's joint, its column among the scalar freedoms (−1 for a ball's), whether
    it is a slide, each joint's first freedom and each ball joint's index among the balls."""

    names: tuple[str, ...]
    joint_of: tuple[int, ...]
    scalar_col: tuple[int, ...]
    is_translation: tuple[bool, ...]
    first: tuple[int, ...]
    spherical_of_joint: dict[int, int]
    n_scalar: int


def freedom_columns(joints: Sequence[Any]) -> FreedomColumns:
    """The :class:`FreedomColumns` of ``joints`` (anything with ``name``, ``kind`` and
    ``freedoms``: a loop's joints or a mechanism graph's)."""
    names: list[str] = []
    joint_of: list[int] = []
    scalar_col: list[int] = []
    is_tr: list[bool] = []
    first: list[int] = []
    sph: dict[int, int] = {}
    col = 0
    for i, j in enumerate(joints):
        first.append(len(names))
        if j.kind == "S":
            sph[i] = len(sph)
        for f in j.freedoms:
            names.append(f"{j.name}.{f}")
            joint_of.append(i)
            is_tr.append(f == "s")
            if j.kind == "S":
                scalar_col.append(-1)
            else:
                scalar_col.append(col)
                col += 1
    return FreedomColumns(tuple(names), tuple(joint_of), tuple(scalar_col), tuple(is_tr),
                          tuple(first), sph, col)


def layout(linkage: Linkage) -> Layout:
    fc = freedom_columns(linkage.joints)
    rotations = np.stack([np.asarray(t.real, dtype=float) for t in linkage.link_transforms])
    translations = np.stack([np.asarray(t.translation, dtype=float)
                             for t in linkage.link_transforms])
    return Layout(fc.names, fc.joint_of, fc.scalar_col, fc.spherical_of_joint, fc.is_translation,
                  fc.n_scalar, len(fc.spherical_of_joint), linkage, rotations, translations,
                  linkage.length_scale)


@dataclass(frozen=True)
class LoopFrames:
    """Frames of one pass round the loop (ground frame), batch-first.

    ``before_R/before_p`` (N, n, 3, 3)/(N, n, 3): joint i's frame before its motion;
    ``after_R/after_p``: after it (= the body frame of moving link i for i < n);
    ``closure_R/closure_p``: G = Π J_i L_i; ``screws`` (N, 6, m): unit freedom screws;
    ``centres`` (N, n, 3): joint centres (origin of the joint frame after the offset);
    ``axes`` (N, n, 3): joint z axes.
    """

    before_R: Array
    before_p: Array
    after_R: Array
    after_p: Array
    closure_R: Array
    closure_p: Array
    screws: Array
    centres: Array
    axes: Array


def _turn_z(R: Array, th: Array) -> Array:
    """R · Rz(θ), column by column."""
    c, s = np.cos(th)[:, None], np.sin(th)[:, None]
    out = np.empty_like(R)
    out[:, :, 0] = c * R[:, :, 0] + s * R[:, :, 1]
    out[:, :, 1] = c * R[:, :, 1] - s * R[:, :, 0]
    out[:, :, 2] = R[:, :, 2]
    return out


def _screw(u: Array, centre: Array, pitch: float = 0.0, out: Array | None = None) -> Array:
    """The unit screw (u; c × u + h u) of a rotation about the line through c along u (N, 6),
    written into ``out`` when given."""
    if out is None:
        out = np.empty(u.shape[:-1] + (6,))
    out[..., :3] = u
    c0, c1, c2 = centre[..., 0], centre[..., 1], centre[..., 2]
    u0, u1, u2 = u[..., 0], u[..., 1], u[..., 2]
    out[..., 3] = c1 * u2 - c2 * u1
    out[..., 4] = c2 * u0 - c0 * u2
    out[..., 5] = c0 * u1 - c1 * u0
    if pitch:
        out[..., 3:] += pitch * u
    return out


def _slide(u: Array) -> Array:
    out = np.zeros(u.shape[:-1] + (6,))
    out[..., 3:] = u
    return out


def forward(linkage: Linkage, conf: Configuration, lay: Layout | None = None,
            frames: bool = True, points: bool | None = None) -> LoopFrames:
    """Walk the loop J_1 L_1 ··· J_n L_n for every sample (vectorised over samples). With
    ``frames=False`` only the closure and the screws are filled (a Newton step's needs; the
    frame arrays are then left unset); ``points=True`` fills the joint centres and axes all the
    same (the transmission's needs; by default they follow ``frames``)."""
    points = frames if points is None else points
    lay = lay or layout(linkage)
    link_R, link_p, _ = constants(linkage, lay)
    N = conf.size
    n = len(linkage.joints)
    R = np.broadcast_to(np.eye(3), (N, 3, 3)).copy()
    p = np.zeros((N, 3))
    shape = (N, n) if frames else (1, n)
    bR = np.empty((*shape, 3, 3))
    bp = np.empty((*shape, 3))
    aR = np.empty((*shape, 3, 3))
    ap = np.empty((*shape, 3))
    centres = np.empty(((N, n) if points else (1, n)) + (3,))
    axes = np.empty_like(centres)
    screws = np.empty((N, 6, len(lay.names)))
    q = conf.scalars
    fi = 0  # running freedom index
    for i, joint in enumerate(linkage.joints):
        u = R[:, :, 2]
        kind = joint.kind
        centre = p if kind == "P" or joint.offset == 0.0 else p + joint.offset * u
        if frames:
            bR[:, i] = R
            bp[:, i] = p
        if points:
            centres[:, i] = centre
            axes[:, i] = u
        col = lay.scalar_col[fi]
        if kind == "R":
            R = _turn_z(R, q[:, col])
            _screw(u, centre, out=screws[:, :, fi])
            p = centre
        elif kind == "P":
            R = _turn_z(R, np.full(N, joint.offset))
            screws[:, :, fi] = _slide(u)
            p = p + q[:, col, None] * u
        elif kind == "C":
            R = _turn_z(R, q[:, col])
            _screw(u, centre, out=screws[:, :, fi])
            screws[:, :, fi + 1] = _slide(u)
            p = p + q[:, col + 1, None] * u
        elif kind == "H":
            th = q[:, col]
            R = _turn_z(R, th)
            _screw(u, centre, joint.pitch, out=screws[:, :, fi])
            p = p + (joint.offset + joint.pitch * th)[:, None] * u
        elif kind == "U":
            R = _turn_z(R, q[:, col])
            u2 = R[:, :, 1].copy()
            _screw(u, centre, out=screws[:, :, fi])
            _screw(u2, centre, out=screws[:, :, fi + 1])
            R = R @ rot_y(q[:, col + 1])
            p = centre
        else:  # S
            R = R @ conf.spherical[:, lay.spherical_of_joint[i]]
            for k in range(3):
                _screw(R[:, :, k], centre, out=screws[:, :, fi + k])
            p = centre
        fi += joint.dof
        if frames:
            aR[:, i] = R
            ap[:, i] = p
        # then the constant link transform: T <- T · L (R·l by columns: a batched matmul
        # with a vector is several times slower)
        lp = link_p[i]
        if lp.any():
            p = p + R[:, :, 0] * lp[0] + R[:, :, 1] * lp[1] + R[:, :, 2] * lp[2]
        R = R @ link_R[i]
    return LoopFrames(bR, bp, aR, ap, R, p, screws, centres, axes)


def closure_twist(R: Array, p: Array) -> Array:
    """The twist ξ (ω; v) with exp(ξ) = G = (R, p): the exact SE(3) logarithm, batched.

    Its norm is the loop-closure error; Newton drives it to zero."""
    w = rotation_vector(R)
    th = np.linalg.norm(w, axis=-1)
    W = skew(w)
    small = th < 1e-6
    ths = np.where(small, 1.0, th)
    # V^{-1} = I - W/2 + (1/θ²)(1 - (θ/2) cot(θ/2)) W²
    coef = np.where(small, 1.0 / 12.0, (1.0 - (ths / 2.0) / np.tan(ths / 2.0)) / ths**2)
    Vinv = np.eye(3) - 0.5 * W + coef[..., None, None] * (W @ W)
    v = np.einsum("...ij,...j->...i", Vinv, p)
    return np.concatenate([w, v], -1)


def rotation_vector(R: Array) -> Array:
    """The rotation vector (axis × angle, angle in [0, π]) of rotation matrices (..., 3, 3):
    from the skew part and the trace, and near a half turn, where the skew part loses digits,
    the axis from the symmetric part, (R + Rᵀ)/2 − cos θ·I = (1 − cos θ) u uᵀ (its largest
    column, signed by the skew part; no scipy, whose import costs 0.3 s of start-up)."""
    vee = 0.5 * np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                          R[..., 1, 0] - R[..., 0, 1]], -1)
    cos = np.clip(0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0), -1.0, 1.0)
    sin = np.linalg.norm(vee, axis=-1)
    angle = np.arctan2(sin, cos)
    scale = np.where(sin > 1e-300, angle / np.maximum(sin, 1e-300), 1.0)
    w = vee * scale[..., None]
    near_half = cos < -0.9
    if np.any(near_half):
        Rh, c = R[near_half], cos[near_half]
        B = 0.5 * (Rh + np.swapaxes(Rh, -1, -2)) - c[:, None, None] * np.eye(3)
        k = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        u = np.take_along_axis(B, k[:, None, None], axis=-1)[..., 0]
        u /= np.linalg.norm(u, axis=-1, keepdims=True)
        sign = np.where(np.einsum("...i,...i->...", u, vee[near_half]) < 0, -1.0, 1.0)
        w[near_half] = u * (sign * angle[near_half])[:, None]
    return np.asarray(w)


def apply_increment(conf: Configuration, delta: Array, lay: Layout) -> Configuration:
    """Move a configuration by freedom increments ``delta`` (N, m): scalars add, spherical
    joints turn by exp([δ]) about their own moving axes (R ← R·exp([δ]))."""
    q = conf.scalars.copy()
    sph = conf.spherical.copy()
    cols = np.array(lay.scalar_col)
    scal = cols >= 0
    q[:, cols[scal]] += delta[:, np.nonzero(scal)[0]]
    if lay.spherical_of_joint:  # every ball at once, with one ball's arithmetic
        ks, idx = _ball_columns(lay)
        sph[:, ks] = sph[:, ks] @ _rotation_matrices(delta[:, idx])
    return Configuration(q, sph)


def _ball_columns(lay: Layout) -> tuple[list[int], NDArray[np.intp]]:
    """The spherical indices of the balls (in ``spherical_of_joint``'s order) and their
    freedom columns (n_balls, 3)."""
    key = id(lay)
    if key not in _BALLS or _BALLS[key][0] is not lay:
        if len(_BALLS) >= 8:
            _BALLS.pop(next(iter(_BALLS)))
        idx = np.array([[f for f, jj in enumerate(lay.joint_of) if jj == j]
                        for j in lay.spherical_of_joint], dtype=np.intp)
        _BALLS[key] = (lay, list(lay.spherical_of_joint.values()), idx)
    return _BALLS[key][1], _BALLS[key][2]


#: the last few layouts' ball columns (:func:`_ball_columns`), kept with their layouts
_BALLS: dict[int, tuple[Any, list[int], NDArray[np.intp]]] = {}


def rotation_matrix(w: Array) -> Array:
    """exp([w]×) of rotation vectors w (N, 3) by Rodrigues' formula (series near zero), as
    cos θ I + a [w]× + b w wᵀ (a = sin θ/θ, b = (1 − cos θ)/θ², [w]×² = w wᵀ − θ² I)."""
    th2 = np.einsum("ni,ni->n", w, w)
    th = np.sqrt(th2)
    small = th2 < 1e-8
    safe = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(safe)) / np.where(small, 1.0, th2))
    c = 1.0 - b * th2
    out = np.empty((w.shape[0], 3, 3))
    w0, w1, w2 = w[:, 0], w[:, 1], w[:, 2]
    bw0, bw1 = b * w0, b * w1
    out[:, 0, 0] = c + bw0 * w0
    out[:, 1, 1] = c + bw1 * w1
    out[:, 2, 2] = c + b * w2 * w2
    out[:, 0, 1] = bw0 * w1 - a * w2
    out[:, 1, 0] = bw0 * w1 + a * w2
    out[:, 0, 2] = bw0 * w2 + a * w1
    out[:, 2, 0] = bw0 * w2 - a * w1
    out[:, 1, 2] = bw1 * w2 - a * w0
    out[:, 2, 1] = bw1 * w2 + a * w0
    return out


def _rotation_matrices(w: Array) -> Array:
    """:func:`rotation_matrix` of rotation vectors w (N, n, 3) (the freedoms of n balls, as
    ``delta[:, idx]`` gathers them): the same operations on the same operands, so each ball's
    rotation is :func:`rotation_matrix` of its own (N, 3) columns bit for bit (the squared
    angle's einsum included; tests/kinematics/test_tracker_batched_balls.py)."""
    th2 = np.einsum("nbi,nbi->nb", w, w)
    th = np.sqrt(th2)
    small = th2 < 1e-8
    safe = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(safe)) / np.where(small, 1.0, th2))
    c = 1.0 - b * th2
    out = np.empty(w.shape[:2] + (3, 3))
    w0, w1, w2 = w[..., 0], w[..., 1], w[..., 2]
    bw0, bw1 = b * w0, b * w1
    out[..., 0, 0] = c + bw0 * w0
    out[..., 1, 1] = c + bw1 * w1
    out[..., 2, 2] = c + b * w2 * w2
    out[..., 0, 1] = bw0 * w1 - a * w2
    out[..., 1, 0] = bw0 * w1 + a * w2
    out[..., 0, 2] = bw0 * w2 + a * w1
    out[..., 2, 0] = bw0 * w2 - a * w1
    out[..., 1, 2] = bw1 * w2 - a * w0
    out[..., 2, 1] = bw1 * w2 + a * w0
    return out


def configuration_difference(a: Configuration, b: Configuration, lay: Layout) -> Array:
    """Freedom increments (N, m) taking ``b`` to ``a``: scalar differences (angles wrapped to
    (−π, π]) and, for a spherical joint, the rotation vector of R_bᵀR_a (its own axes)."""
    out = np.zeros((a.size, len(lay.names)))
    cols = np.array(lay.scalar_col)
    scal = np.nonzero(cols >= 0)[0]
    d = a.scalars[:, cols[scal]] - b.scalars[:, cols[scal]]
    turn = ~np.array(lay.is_translation)[scal]
    d[:, turn] = np.pi - np.mod(np.pi - d[:, turn], 2 * np.pi)
    out[:, scal] = d
    if lay.spherical_of_joint:  # every ball at once (the same arithmetic as one at a time)
        ks, idx = _ball_columns(lay)
        rel = np.swapaxes(b.spherical[:, ks], -1, -2) @ a.spherical[:, ks]
        out[:, idx] = rotation_vector(rel)
    return out


def closure_error(R: Array, p: Array) -> Array:
    """A first-order closure twist (½ vee(R − Rᵀ); p): equal to :func:`closure_twist` up to
    second order near closure, with the same derivative there — the residual of a corrector
    that starts close (a prediction), at a fraction of the cost of the exact logarithm."""
    out = np.empty(p.shape[:-1] + (6,))
    out[..., 0] = 0.5 * (R[..., 2, 1] - R[..., 1, 2])
    out[..., 1] = 0.5 * (R[..., 0, 2] - R[..., 2, 0])
    out[..., 2] = 0.5 * (R[..., 1, 0] - R[..., 0, 1])
    out[..., 3:] = p
    return out


def lie_bracket(a: Array, b: Array) -> Array:
    """[a, b] of twists (ω; v): (ωa × ωb; ωa × vb − ωb × va), written out by components."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    a0, a1, a2, a3, a4, a5 = (a[..., k] for k in range(6))
    b0, b1, b2, b3, b4, b5 = (b[..., k] for k in range(6))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    out[..., 3] = a1 * b5 - a2 * b4 - b1 * a5 + b2 * a4
    out[..., 4] = a2 * b3 - a0 * b5 - b2 * a3 + b0 * a5
    out[..., 5] = a0 * b4 - a1 * b3 - b0 * a4 + b1 * a3
    return out


def close_spherical_joint(linkage: Linkage, scalars: Array, lay: Layout | None = None,
                          spherical: Array | None = None, joint: int | None = None,
                          ) -> Configuration:
    """The configuration of a loop whose scalar freedoms and all spherical joints but one are
    known (e.g. from a closed form): the remaining ball joint's rotation is what closes the loop.

    ``spherical`` (N, n_S, 3, 3) holds the known rotations (default: identity; the loop's only
    ball when ``joint`` is None); ``joint`` is the index of the ball to close. With that ball at
    rest (R = I) the loop product is G₀ = P·Q′ (P up to the ball's frame); the closing rotation
    is the conjugate R = R_Pᵀ R_G₀ᵀ R_P, exact wherever the known freedoms close the loop's
    translation (which is what a closed form guarantees; the closure residual checks it).
    """
    lay = lay or layout(linkage)
    if joint is None:
        if lay.n_spherical != 1:
            raise InputError(f"{linkage.name}: close_spherical_joint needs exactly one spherical "
                             f"joint or the joint to close; this loop has {lay.n_spherical}")
        joint = next(iter(lay.spherical_of_joint))
    N = scalars.shape[0]
    rot = (np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)) if spherical is None
           else spherical).copy()
    k = lay.spherical_of_joint[joint]
    rot[:, k] = np.eye(3)
    fr = forward(linkage, Configuration(scalars, rot), lay)
    RP = fr.before_R[:, joint]
    rot[:, k] = np.einsum("nji,nkj,nkl->nil", RP, fr.closure_R, RP)
    return Configuration(scalars, rot)

"""Every solution of a 6R loop by elimination: a 24 × 24 eigenproblem instead of 16 paths.

The classical solver of the general 6R (Raghavan & Roth, "Inverse kinematics of the general 6R
manipulator and related linkages", J. Mech. Des. 115, 1993; Manocha & Canny, "Efficient inverse
kinematics for general 6R manipulators", IEEE T-RA 10(5), 1994), on the loop of
:mod:`.loop6r`:

- the loop's Denavit–Hartenberg chain A_i = Rot_z(θ_i)·Trans_z(d_i)·Trans_x(a_i)·Rot_x(α_i)
  closes, A_1⋯A_6 = I; written A_3A_4A_5 = A_2⁻¹A_1⁻¹A_6⁻¹, the z axis l and origin p of the
  right side do not depend on θ_6;
- the 14 quantities p, l, p·p, p·l, p×l, (p·p)l − 2(p·l)p are, on the left, linear in the nine
  products {s4s5, s4c5, c4s5, c4c5, s4, c4, s5, c5, 1} with coefficients in {s3, c3, 1}, and on
  the right linear in {s1s2, s1c2, c1s2, c1c2, s1, c1, s2, c2, 1};
- the coefficients are *fitted* per instance: the quantities at fixed sample angles (the same
  for every instance) times a fixed pseudo-inverse of the basis, one matrix product over a
  batch; the fit's residual is round-off when the structure holds (:func:`fit_residual`);
- the eight θ1θ2 products are eliminated (the left null space of their 14 × 8 coefficients):
  six equations; with half-angle tangents x3, x4, x5 (of the angles shifted by fixed offsets,
  so that no solution sits at x = ∞ except on a set of measure zero) and the six equations
  also multiplied by x4, a 12 × 12 matrix polynomial Σ(x3) = A x3² + B x3 + C in the monomials
  x4^i x5^j (i ≤ 3, j ≤ 2), whose determinant has degree 24; 8 of its roots are the spurious
  x3 = ±i of the factors 1 + x3²; the other 16 are the solutions. The 24 × 24 companion
  eigenproblem gives x3, and each eigenvector x4, x5; a least-squares solve of the 14
  equations gives (c1, s1, c2, s2), and the axes z2..z5 follow from θ1..θ4.

``shift`` relabels the loop cyclically first (joint i + k plays joint i), for geometries that
make Σ singular in one labelling. :func:`.loop6r_solve.solve_loop6r` polishes every solution
by Newton's method on the polynomial system of :mod:`.loop6r`, certifies it (α-test,
algebraic/certify.py), tries the other labellings on the instances not settled, solves what is
still unsettled by the parameter homotopy, and says which route ran for each instance.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError

Complex = NDArray[np.complex128]
Array = NDArray[np.float64]

#: samples per angle of the fit: 3 (the least: the bases are then square and invertible)
#: per instance, 5 in :func:`fit_residual` (a term of degree 2 or 3 in an angle would not alias
#: onto the basis there, so the residual shows whether the structure holds)
SAMPLES = 3
CHECK_SAMPLES = 5
#: the fixed offsets of θ3, θ4, θ5 behind the half-angle tangents (x = tan((θ − φ)/2)): any
#: values not special to a geometry
OFFSETS = (0.6180339887, 1.2247448714, -0.7071067812)


def _cross(a: Complex, b: Complex) -> Complex:
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], -1)


def _dot(a: Complex, b: Complex) -> Complex:
    return np.einsum("...i,...i->...", a, b)


def _as_parameters(params: ArrayLike) -> Complex:
    """Parameters (B, 23), real (float) when every one is real."""
    p = np.atleast_2d(np.asarray(params))
    if p.ndim != 2 or p.shape[1] != 23:
        raise InputError(f"6R parameters must have shape (23,) or (B, 23); got {p.shape}")
    if np.iscomplexobj(p) and np.all(p.imag == 0):
        p = p.real
    return np.asarray(p, dtype=complex if np.iscomplexobj(p) else float)


def _safe_solve(A: Complex, b: Complex) -> tuple[Complex, Array]:
    """A⁻¹b over a batch (B, n, n), (B, n, k), NaN where A is singular to working precision
    or not finite (a batched solve would raise for the whole batch); and cond(A) (B,)."""
    finite = np.asarray(np.isfinite(A).all(axis=(1, 2)) & np.isfinite(b).all(axis=(1, 2)),
                        dtype=bool)
    A = np.where(finite[:, None, None], A, np.eye(A.shape[1]))
    sv = np.linalg.svd(A, compute_uv=False)  # cond(A) = σ_max/σ_min (∞ for A = 0)
    with np.errstate(all="ignore"):
        cond = np.where(finite, sv[:, 0] / sv[:, -1], np.inf)
    cond = np.where(np.isnan(cond), np.inf, cond)
    good = cond < 1e13
    x = np.linalg.solve(np.where(good[:, None, None], A, np.eye(A.shape[1])),
                        np.where(good[:, None, None], b, 0.0))
    return np.where(good[:, None, None], x, np.nan), np.asarray(cond, dtype=float)


def dh_chain(params: Complex) -> tuple[Complex, Complex, Complex, Complex, Complex]:
    """The Denavit–Hartenberg loop of 6R parameters (B, 23) (:mod:`.loop6r`): cos α, sin α,
    a, d (B, 6 each, joint/link 1..6, link 6 the ground from joint 6 to joint 1) and the
    rotation R0 (B, 3, 3) of frame 0 (x along the ground's common normal, z = z1) in the
    world. sin α_i is the principal √(1 − cos²α_i), a_i = k_i sin α_i; the ground's k6, d1, d6
    come from g = k6 z6 × z1 + d1 z1 + d6 z6."""
    z1, z6 = params[:, 0:3], params[:, 3:6]
    cos_a = np.concatenate([params[:, 6:11], _dot(z6, z1)[:, None]], 1)
    sin_a = np.sqrt(1.0 - cos_a * cos_a if np.iscomplexobj(params)
                    else np.maximum(1.0 - cos_a * cos_a, 0.0))
    w6 = _cross(z6, z1)
    ground = _safe_solve(np.stack([w6, z1, z6], -1), params[:, 20:23, None])[0][..., 0]
    a = np.concatenate([params[:, 11:16], ground[:, :1]], 1) * sin_a
    d = np.concatenate([ground[:, 1:2], params[:, 16:20], ground[:, 2:3]], 1)
    x6 = w6 / sin_a[:, 5:6]
    R0 = np.stack([x6, _cross(z1, x6), z1], -1)
    return cos_a, sin_a, a, d, R0


def _rz_rx(c_t: Complex, s_t: Complex, c_a: Complex, s_a: Complex) -> Complex:
    """Rot_z(θ)·Rot_x(α) (…, 3, 3) from the cosines and sines (broadcast together)."""
    shape = np.broadcast_shapes(np.shape(c_t), np.shape(c_a))
    R = np.zeros(shape + (3, 3), dtype=np.result_type(c_t, c_a))
    R[..., 0, 0], R[..., 0, 1], R[..., 0, 2] = c_t, -s_t * c_a, s_t * s_a
    R[..., 1, 0], R[..., 1, 1], R[..., 1, 2] = s_t, c_t * c_a, -c_t * s_a
    R[..., 2, 1], R[..., 2, 2] = s_a, c_a
    return R


def _link(c_t: Complex, s_t: Complex, c_a: Complex, s_a: Complex, a: Complex, d: Complex
          ) -> tuple[Complex, Complex]:
    """A_i as (R, t): R = Rot_z(θ)Rot_x(α), t = Rot_z(θ)(a, 0, d)."""
    R = _rz_rx(c_t, s_t, c_a, s_a)
    t = np.zeros(R.shape[:-1], dtype=R.dtype)
    t[..., 0], t[..., 1], t[..., 2] = c_t * a, s_t * a, d
    return R, t


def _quantities(p: Complex, l: Complex) -> Complex:
    """The 14 quantities (…, 14) of Raghavan & Roth: p, l, p·p, p·l, p×l, (p·p)l − 2(p·l)p."""
    pp, pl = _dot(p, p), _dot(p, l)
    return np.concatenate([p, l, pp[..., None], pl[..., None], _cross(p, l),
                           pp[..., None] * l - 2.0 * pl[..., None] * p], -1)


def _trig3(theta: Array) -> Array:
    """[sin, cos, 1] of angles (…,) as (…, 3)."""
    return np.stack([np.sin(theta), np.cos(theta), np.ones_like(theta)], -1)


def _products(t_a: Array, t_b: Array) -> Array:
    """The nine products [sa·sb, sa·cb, ca·sb, ca·cb, sa, ca, sb, cb, 1] (…, 9) of two
    [sin, cos, 1] rows: the outer product in the order of the module docstring."""
    o = t_a[..., :, None] * t_b[..., None, :]  # (…, 3, 3): [s, c, 1] × [s, c, 1]
    return o.reshape(o.shape[:-2] + (9,))[..., _PRODUCT_ORDER]


#: the entries (3·row + column of the outer product) in the order of :func:`_products`
_PRODUCT_ORDER = np.array([0, 1, 3, 4, 2, 5, 6, 7, 8])


@lru_cache(maxsize=2)
def sample_design(samples: int) -> dict[str, NDArray[Any]]:
    """The fixed sample angles (``samples`` per angle) and the pseudo-inverses of the two
    bases at them."""
    grid = 2.0 * np.pi * np.arange(samples) / samples + 0.1
    t3, t4, t5 = (v.ravel() for v in np.meshgrid(grid, grid, grid, indexing="ij"))
    shifted = [_trig3(t - phi) for t, phi in zip((t3, t4, t5), OFFSETS, strict=True)]
    left = (shifted[0][:, :, None] * _products(shifted[1], shifted[2])[:, None, :])
    left = left.reshape(len(t3), 27)  # column 9·k3 + j45
    t1, t2 = (v.ravel() for v in np.meshgrid(grid, grid, indexing="ij"))
    right = _products(_trig3(t1), _trig3(t2))
    D = {"t3": t3, "t4": t4, "t5": t5, "t1": t1, "t2": t2, "left": left, "right": right,
         "left_pinv": np.linalg.pinv(left), "right_pinv": np.linalg.pinv(right)}
    # the angles of links 3, 4, 5 (3, S3) and of links 1, 2, 6 (3, S2) for two vectorised
    # passes; θ6 = 0 (e_z and the origin do not see it)
    left_angles, right_angles = np.stack([t3, t4, t5]), np.stack([t1, t2, 0.0 * t1])
    D["cos_left"], D["sin_left"] = np.cos(left_angles), np.sin(left_angles)
    D["cos_right"], D["sin_right"] = np.cos(right_angles), np.sin(right_angles)
    return D


def _sides(params: Complex, samples: int = SAMPLES, shift: int = 0
           ) -> tuple[Complex, Complex, tuple[Complex, ...]]:
    """The 14 quantities at the sample angles: left (B, S3, 14) over θ3, θ4, θ5 and right
    (B, S2, 14) over θ1, θ2, lengths scaled to order one; and the chain. Real parameters are
    kept real. ``shift`` k relabels the loop cyclically (the elimination's joint i is the
    loop's joint i + k): the product A_{k+1}⋯A_6A_1⋯A_k is the identity as well."""
    chain = dh_chain(params)
    cos_a, sin_a, a, d = (np.roll(v, -shift, axis=1) if shift else v for v in chain[:4])
    scale = np.sqrt(np.mean(np.abs(a) ** 2 + np.abs(d) ** 2, axis=1))
    scale = np.where(scale > 0, scale, 1.0)[:, None]
    a, d = a / scale, d / scale
    D = sample_design(samples)
    S2 = len(D["t1"])
    # links 3, 4, 5 at once, R (3, B, S3, 3, 3), t (3, B, S3, 3) (the link first, so that
    # each link's block is contiguous); links 1, 2, 6 likewise
    ca, sa, a, d = (v.T[:, :, None] for v in (cos_a, sin_a, a, d))  # (6, B, 1)
    c, s = D["cos_left"][:, None], D["sin_left"][:, None]  # (3, 1, S3)
    (R3, R4, R5), (t3, t4, t5) = _link(c, s, ca[2:5], sa[2:5], a[2:5], d[2:5])
    right = [0, 1, 5]
    c, s = D["cos_right"][:, None], D["sin_right"][:, None]  # (3, 1, S2)
    (R1, R2, R6), (t1, t2, t6) = _link(c, s, ca[right], sa[right], a[right], d[right])
    R6, t6 = R6[:, 0], t6[:, 0]
    # A3A4A5: l = R3R4R5 e_z, p = t3 + R3(t4 + R4 t5)
    R34 = R3 @ R4
    l_left = np.einsum("bsij,bsj->bsi", R34, R5[..., :, 2])
    p_left = t3 + np.einsum("bsij,bsj->bsi", R3, t4) + np.einsum("bsij,bsj->bsi", R34, t5)
    # A2⁻¹A1⁻¹A6⁻¹ applied to e_z and the origin; A_i⁻¹ x = Rᵀ(x − t)
    l6 = R6[..., 2, :]
    p6 = -np.einsum("bji,bj->bi", R6, t6)
    l1 = np.einsum("bsji,bj->bsi", R1, l6)
    p1 = np.einsum("bsji,bsj->bsi", R1, p6[:, None] - t1)
    l_right = np.einsum("bsji,bsj->bsi", R2, l1)
    p_right = np.einsum("bsji,bsj->bsi", R2, p1 - t2)
    q = _quantities(np.concatenate([p_left, p_right], 1), np.concatenate([l_left, l_right], 1))
    return q[:, :-S2], q[:, -S2:], chain


def fitted_coefficients(params: ArrayLike) -> tuple[Complex, Complex]:
    """The fitted coefficients of the 14 equations of instances (B, 23): left (B, 14, 27)
    (column 9·k3 + j45, k3 over [s3, c3, 1] of θ3 − φ3, j45 over the nine products of θ4 − φ4,
    θ5 − φ5) and right (B, 14, 9) (the nine products of θ1, θ2)."""
    p = _as_parameters(params)
    left, right, _ = _sides(p, CHECK_SAMPLES)
    D = sample_design(CHECK_SAMPLES)
    return (np.einsum("ks,bsq->bqk", D["left_pinv"], left),
            np.einsum("ks,bsq->bqk", D["right_pinv"], right))


def fit_residual(params: ArrayLike) -> Array:
    """The largest residual (B,) of the fit relative to the largest sampled quantity: round-off
    when the quantities lie in the span of the bases (the structure of Raghavan & Roth)."""
    p = _as_parameters(params)
    left, right, _ = _sides(p, CHECK_SAMPLES)
    L, R = fitted_coefficients(p)
    D = sample_design(CHECK_SAMPLES)
    rl = np.abs(np.einsum("sk,bqk->bsq", D["left"], L) - left).max(axis=(1, 2))
    rr = np.abs(np.einsum("sk,bqk->bsq", D["right"], R) - right).max(axis=(1, 2))
    big = np.maximum(np.abs(left).max(axis=(1, 2)), np.abs(right).max(axis=(1, 2)))
    return np.asarray(np.maximum(rl, rr) / big, dtype=float)



#: (1 + x²)·[sin ψ, cos ψ, 1] with x = tan(ψ/2), over the powers [1, x, x²]
_HALF = np.array([[0.0, 2.0, 0.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0]])
#: the (s, c, 1) factors of the nine products, in the order of :func:`_products`
_PAIRS = ((0, 0), (0, 1), (1, 0), (1, 1), (0, 2), (1, 2), (2, 0), (2, 1), (2, 2))


@lru_cache(maxsize=1)
def monomial_map() -> Array:
    """(3, 9, 3, 9): from the coefficients over [s3, c3, 1] × products of θ4, θ5 to those over
    x3^k × x4^i x5^j (column 3i + j), all three factors (1 + x²) multiplied out."""
    T45 = np.array([np.outer(_HALF[f4], _HALF[f5]).ravel() for f4, f5 in _PAIRS])
    return np.einsum("km,jn->kjmn", _HALF, T45)


def _shifted_trig(x: Complex, phi: ArrayLike) -> tuple[Complex, Complex]:
    """(cos θ, sin θ) of θ = ψ + φ, x = tan(ψ/2); φ (scalar, or one per leading row of x)."""
    den = 1.0 + x * x
    s, c = 2.0 * x / den, (1.0 - x * x) / den
    phi = np.asarray(phi, dtype=float).reshape(np.shape(phi) + (1,) * (x.ndim - np.ndim(phi)))
    cp, sp = np.cos(phi), np.sin(phi)
    return c * cp - s * sp, s * cp + c * sp


def _axes_from_angles(chain: tuple[Complex, ...], c: Complex, s: Complex) -> Complex:
    """z2..z5 (B, M, 12) in the world from cos θ_i, sin θ_i (4, B, M) of joints 1..4."""
    cos_a, sin_a, _, _, R0 = chain
    A = _rz_rx(c, s, cos_a[:, :4].T[:, :, None], sin_a[:, :4].T[:, :, None])  # (4, B, M, 3, 3)
    R = np.broadcast_to(R0[:, None], c.shape[1:] + (3, 3))
    out = []
    for i in range(4):
        R = R @ A[i]
        out.append(R[..., :, 2])
    return np.concatenate(out, -1)


def eliminate(params: ArrayLike, shift: int = 0, compiled: bool = True
              ) -> tuple[Complex, Complex, Array]:
    """The 16 solutions (B, 16, 12) of 6R instances (B, 23) by the eigenproblem (module
    docstring), unpolished; their x3 (B, 16) (for real parameters, exact conjugate pairs and
    exactly real values, as LAPACK returns the eigenvalues of a real matrix, so that a
    solution with Im x3 < 0 is the conjugate of one with Im x3 > 0); and the condition number
    (B,) of Σ's leading matrix (the companion form divides by it). ``shift`` k relabels the
    loop cyclically first (joint i of the elimination is the loop's joint i + k): a geometry
    that makes Σ singular for one labelling (two consecutive axes that meet, say) may not for
    another. ``compiled``: real parameters go through the numba kernels of
    :mod:`.sixr_compiled` when numba is there (the same steps, one instance at a time; the
    results equal this module's numpy route to round-off), else through the numpy route."""
    p = _as_parameters(params)
    if shift not in range(6):
        raise InputError(f"the cyclic shift of a 6R loop is 0..5; got {shift}")
    if compiled and not np.iscomplexobj(p):
        from screwkit.kinematics.modes import sixr_compiled

        if sixr_compiled.AVAILABLE:
            return sixr_compiled.eliminate_real(p.real, shift)
    with np.errstate(all="ignore"):
        return _eliminate(p, shift)


def _eliminate(p: Complex, shift: int) -> tuple[Complex, Complex, Array]:
    left, right, chain = _sides(p, SAMPLES, shift)
    bad = np.asarray(~(np.isfinite(left).all(axis=(1, 2)) & np.isfinite(right).all(axis=(1, 2))),
                     dtype=bool)
    if bad.any():
        left = np.where(bad[:, None, None], 0.0, left)
        right = np.where(bad[:, None, None], 0.0, right)
    D = sample_design(SAMPLES)
    L = np.einsum("ks,bsq->bqk", D["left_pinv"], left)  # (B, 14, 27)
    R = np.einsum("ks,bsq->bqk", D["right_pinv"], right)  # (B, 14, 9)
    L[:, :, 26] -= R[:, :, 8]  # the right side's constant moves to the left
    Q = R[:, :, :8]
    U, sv, Vh = np.linalg.svd(Q)
    N = np.swapaxes(U[:, :, 8:], 1, 2).conj()  # (B, 6, 14): N Q = 0
    M = (N @ L).reshape(-1, 6, 3, 9)
    P = np.einsum("bekj,kjmn->bemn", M, monomial_map())  # (B, 6, x3 power, 9)
    B = len(p)
    S = np.zeros((B, 3, 12, 12), dtype=complex)
    S[:, :, :6, :9] = np.swapaxes(P, 1, 2)
    S[:, :, 6:, 3:] = np.swapaxes(P, 1, 2)
    if not np.iscomplexobj(p):
        S = S.real  # type: ignore[assignment]
    solve, lead_cond = _safe_solve(S[:, 2], np.concatenate([S[:, 0], S[:, 1]], -1))
    bad |= ~np.isfinite(solve).all(axis=(1, 2))
    comp = np.zeros((B, 24, 24), dtype=S.dtype)
    comp[:, :12, 12:] = np.eye(12)
    comp[:, 12:] = np.where(bad[:, None, None], 0.0, -solve)
    lam, W = np.linalg.eig(comp)
    # drop the spurious roots: the eight nearest ±i
    idx = np.argsort(np.minimum(np.abs(lam - 1j), np.abs(lam + 1j)), 1)[:, 8:]
    x3 = np.take_along_axis(lam, idx, 1)
    W = np.take_along_axis(W, idx[:, None, :], 2)  # (B, 24, 16)
    v = np.where((np.abs(x3) <= 1.0)[:, None, :], W[:, :12], W[:, 12:])
    v = np.swapaxes(v, 1, 2).reshape(B, 16, 4, 3)  # v[..., i, j] ∝ x4^i x5^j
    x4 = (np.sum(v[..., :3, :].conj() * v[..., 1:, :], (-2, -1))
          / np.sum(np.abs(v[..., :3, :]) ** 2, (-2, -1)))
    x5 = (np.sum(v[..., :, :2].conj() * v[..., :, 1:], (-2, -1))
          / np.sum(np.abs(v[..., :, :2]) ** 2, (-2, -1)))
    # cos, sin of ψ3, ψ4, ψ5 (φ = 0) and of θ3, θ4, θ5 = ψ + φ: rows of (6, B, 16)
    x345 = np.stack([x3, x4, x5])
    c, s = _shifted_trig(np.concatenate([x345, x345]), (0.0, 0.0, 0.0) + OFFSETS)
    one = np.ones_like(c[0])
    m45 = _products(np.stack([s[1], c[1], one], -1), np.stack([s[2], c[2], one], -1))
    t3 = np.stack([s[0], c[0], one], -1)  # (B, 16, 3), (B, 16, 9)
    rhs = np.einsum("bqkj,bmk,bmj->bmq", L.reshape(B, 14, 3, 9), t3, m45)
    pinv = np.einsum("bji,bj,bkj->bik", Vh.conj(), 1.0 / sv, U[:, :, :8].conj())  # (B, 8, 14)
    m12 = np.moveaxis(np.einsum("bik,bmk->ibm", pinv, rhs)[4:].reshape(2, 2, B, 16), 1, 0)
    n = np.sqrt(m12[1] * m12[1] + m12[0] * m12[0])  # m12: [s1, s2], [c1, c2] (2, 2, B, 16)
    cos_t = np.concatenate([m12[1] / n, c[3:]])  # θ1..θ5 (5, B, 16)
    sin_t = np.concatenate([m12[0] / n, s[3:]])
    if shift:  # θ6 too (by closure: Rot_z(θ6)Rot_x(α6) = (R1⋯R5)ᵀ), then relabel
        cos_a, sin_a = (np.roll(v, -shift, axis=1) for v in chain[:2])
        A = _rz_rx(cos_t, sin_t, cos_a[:, :5].T[:, :, None], sin_a[:, :5].T[:, :, None])
        R = A[0]
        for i in range(1, 5):
            R = R @ A[i]
        cos_t = np.concatenate([cos_t, R[None, ..., 0, 0]])
        sin_t = np.concatenate([sin_t, R[None, ..., 0, 1]])
        order = [(j - shift) % 6 for j in range(4)]
        cos_t, sin_t = cos_t[order], sin_t[order]
    axes = np.where(bad[:, None, None], np.nan, _axes_from_angles(chain, cos_t[:4], sin_t[:4]))
    return axes, np.where(bad[:, None], np.nan, x3), lead_cond

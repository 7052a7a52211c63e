"""The closure of a single loop of R, P and C joints with six free freedoms as a polynomial
system whose parameters are free (issue 27, "Algebraic closure"; docs/kinematics.md).

The loop's free joints j = 0..n−1 are taken in order round the loop, each in a frame whose z
axis is its line; between joint j and j+1 the link (with any driven joints folded into it) is a
rigid motion, written in the Denavit–Hartenberg way after the joint's own z-screw:

    ∏_j  Z_j(q_j) · Rz(φ_j) Tz(b_j) · Tx(a_j) Rx(α_j)  =  I

(Denavit & Hartenberg 1955; the product-of-exponentials loop of Murray, Li & Sastry 1994 §3.2
with each joint's frame on its line). Z_j is Rz(θ) for an R joint, Tz(d) for a P joint and
Rz(θ)Tz(d) for a C joint; a z-rotation offset φ_j is a parameter only where the joint does not
turn (P), a z-offset b_j only where it does not slide (R): otherwise they are absorbed into the
joint's own variable (the offsets from the drawing are kept by the formulation).

Unknowns: (c_j, s_j) per turning joint with c_j² + s_j² − 1 = 0, d_j per sliding joint.
Parameters: the angles φ_j and α_j as half-angle pairs (u, v), each rotation written as its
quadratic numerator over u² + v² (so any complex pair is an instance, and every real angle
is one: no pole at α = π), and the lengths b_j, a_j. Every parameter is free, as the monodromy
loops and the parameter homotopy need (algebraic/monodromy.py).

The loop is split into two half-chains A = Z_0 K_0 ⋯ Z_{m−1} K_{m−1} and
B = (Z_m K_m ⋯ Z_{n−1} K_{n−1})⁻¹ of about three freedoms each (as the 6R system splits its
loop); with each half as a homogeneous pair (R, t)/δ, A = B is R_A δ_B = R_B δ_A (9) and
t_A δ_B = t_B δ_A (3). The three translation equations are kept; the nine rotation equations
are replaced by three fixed generic real combinations of them (the randomisation of Sommese &
Wampler 2005, §13.5), which makes the system square and adds isolated solutions where only
the three combinations vanish: every solution is checked against the full closure
(:func:`full_closure_residual`, and every_mode's graph_forward for a real mode).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.errors import CapabilityError

Complex = NDArray[np.complex128]
#: the freedoms of each free joint kind: turning, sliding
TURNS = {"R": True, "P": False, "C": True}
SLIDES = {"R": False, "P": True, "C": True}


def freedom_count(kinds: str) -> int:
    """The freedoms of free joints ``kinds`` (R 1, P 1, C 2)."""
    return sum(int(TURNS[k]) + int(SLIDES[k]) for k in kinds)


def _combination() -> NDArray[np.float64]:
    """Three fixed generic real combinations (3, 9) of the nine rotation equations: rows of
    cosines at incommensurate arguments (deterministic, full rank, no entry zero)."""
    r = np.arange(3)[:, None]
    j = np.arange(9)[None, :]
    return np.cos(1.0 + np.sqrt(2.0) * (r + 1) * (j + 1) + np.sqrt(3.0) * r)


@dataclass(frozen=True)
class LoopLayout:
    """Where each symbol of the system is: per free joint its unknowns (c, s or −1; d or −1)
    and parameters (φ pair or −1, b or −1, a, α pair), and the split index m."""

    kinds: str
    cs: tuple[int, ...]
    d: tuple[int, ...]
    phi: tuple[int, ...]
    b: tuple[int, ...]
    a: tuple[int, ...]
    alpha: tuple[int, ...]
    n_unknowns: int
    n_parameters: int
    split: int


def loop_layout(kinds: str) -> LoopLayout:
    """The symbol layout of the system for free joints ``kinds`` (module docstring)."""
    if set(kinds) - set(TURNS) or freedom_count(kinds) != 6:
        raise CapabilityError(f"the general loop system takes free R, P and C joints with six "
                              f"freedoms in all; got {kinds!r}")
    cs, d, n = [], [], 0
    for k in kinds:
        cs.append(n if TURNS[k] else -1)
        n += 2 if TURNS[k] else 0
        d.append(n if SLIDES[k] else -1)
        n += 1 if SLIDES[k] else 0
    phi, b, a, alpha, p = [], [], [], [], n
    for k in kinds:
        phi.append(p if k == "P" else -1)
        p += 2 if k == "P" else 0
        b.append(p if k == "R" else -1)
        p += 1 if k == "R" else 0
        a.append(p)
        alpha.append(p + 1)
        p += 3
    total, split = 0, 0
    for i, k in enumerate(kinds):
        if total >= 3:
            break
        total += int(TURNS[k]) + int(SLIDES[k])
        split = i + 1
    return LoopLayout(kinds, tuple(cs), tuple(d), tuple(phi), tuple(b), tuple(a),
                      tuple(alpha), n, p - n, split)


Half = tuple[list[list[Poly]], list[Poly], Poly]  # (R numerator, t numerator, δ)


def _identity() -> Half:
    one, zero = Poly.constant(1.0), Poly()
    return ([[one if r == c else zero for c in range(3)] for r in range(3)],
            [zero, zero, zero], one)


def _times(x: Half, y: Half) -> Half:
    """(R1, t1, δ1)·(R2, t2, δ2) = (R1 R2, R1 t2 + δ2 t1, δ1 δ2)."""
    R1, t1, d1 = x
    R2, t2, d2 = y
    R = [[sum((R1[r][k] * R2[k][c] for k in range(3)), Poly()) for c in range(3)]
         for r in range(3)]
    t = [sum((R1[r][k] * t2[k] for k in range(3)), Poly()) + d2 * t1[r] for r in range(3)]
    return R, t, d1 * d2


def _turn(axis: int, c: Poly, s: Poly, den: Poly) -> Half:
    """A rotation about coordinate axis ``axis`` with numerator cos c, sin s over δ = den."""
    i, j = (axis + 1) % 3, (axis + 2) % 3
    zero = Poly()
    R = [[zero, zero, zero] for _ in range(3)]
    R[axis][axis] = den
    R[i][i], R[i][j], R[j][i], R[j][j] = c, -s, s, c
    return R, [zero, zero, zero], Poly.constant(1.0) * den


def _slide(axis: int, length: Poly) -> Half:
    R, _, one = _identity()
    t = [Poly(), Poly(), Poly()]
    t[axis] = length
    return R, t, one


def _half_turn(axis: int, u: Poly, v: Poly, inverse: bool) -> Half:
    """A rotation by the angle whose half-angle pair is (u, v): (u² − v², 2uv) over u² + v²."""
    v = -v if inverse else v
    return _turn(axis, u * u - v * v, 2.0 * u * v, u * u + v * v)


def _factors(lay: LoopLayout, j: int, inverse: bool) -> list[Half]:
    """Joint j's z-screw and link j as elementary factors (inverted and reversed if asked)."""
    sym = Poly.variable
    out: list[Half] = []
    sign = -1.0 if inverse else 1.0
    if lay.cs[j] >= 0:
        out.append(_turn(2, sym(lay.cs[j]), sign * sym(lay.cs[j] + 1), Poly.constant(1.0)))
    if lay.d[j] >= 0:
        out.append(_slide(2, sign * sym(lay.d[j])))
    if lay.phi[j] >= 0:
        out.append(_half_turn(2, sym(lay.phi[j]), sym(lay.phi[j] + 1), inverse))
    if lay.b[j] >= 0:
        out.append(_slide(2, sign * sym(lay.b[j])))
    out.append(_slide(0, sign * sym(lay.a[j])))
    out.append(_half_turn(0, sym(lay.alpha[j]), sym(lay.alpha[j] + 1), inverse))
    return out[::-1] if inverse else out


def _chain(factors: Sequence[Half]) -> Half:
    out = _identity()
    for f in factors:
        out = _times(out, f)
    return out


@lru_cache(maxsize=16)
def general_loop_system(kinds: str) -> PolynomialSystem:
    """The compiled system of free joints ``kinds`` (module docstring)."""
    lay = loop_layout(kinds)
    A = _chain([f for j in range(lay.split) for f in _factors(lay, j, False)])
    B = _chain([f for j in range(len(kinds) - 1, lay.split - 1, -1)
                for f in _factors(lay, j, True)])
    (RA, tA, dA), (RB, tB, dB) = A, B
    rot = [RA[r][c] * dB - RB[r][c] * dA for r in range(3) for c in range(3)]
    eqs = [sym_circle(lay.cs[j]) for j in range(len(kinds)) if lay.cs[j] >= 0]
    for row in _combination():
        eqs.append(sum((float(w) * e for w, e in zip(row, rot, strict=True)), Poly()))
    eqs += [tA[r] * dB - tB[r] * dA for r in range(3)]
    names = []
    for j, k in enumerate(kinds):
        names += [f"c{j}", f"s{j}"] if TURNS[k] else []
        names += [f"d{j}"] if SLIDES[k] else []
    params = []
    for j, k in enumerate(kinds):
        params += [f"phi{j}_u", f"phi{j}_v"] if k == "P" else []
        params += [f"b{j}"] if k == "R" else []
        params += [f"a{j}", f"alpha{j}_u", f"alpha{j}_v"]
    return compile_system(eqs, names, params)


def sym_circle(index: int) -> Poly:
    """c² + s² − 1 for the pair at ``index``."""
    c, s = Poly.variable(index), Poly.variable(index + 1)
    return c * c + s * s - 1.0


# --- numeric transforms (complex), for instances and the full closure check ----------------

def rz(c: complex, s: complex) -> Complex:
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=complex)


def rx(c: complex, s: complex) -> Complex:
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]], dtype=complex)


def trans(axis: int, length: complex) -> Complex:
    T = np.eye(4, dtype=complex)
    T[axis, 3] = length
    return T


def pair_angle(u: complex, v: complex) -> tuple[complex, complex]:
    """(cos, sin) of the angle whose half-angle pair is (u, v)."""
    n = u * u + v * v
    return (u * u - v * v) / n, 2 * u * v / n


def angle_pair(c: complex, s: complex) -> tuple[complex, complex]:
    """A half-angle pair (u, v) of the angle with cosine c and sine s (c² + s² = 1)."""
    u = np.sqrt((1 + c) / 2 + 0j)
    if abs(u) < 1e-6:  # the angle is π: (0, 1)
        return 0j, 1 + 0j
    return complex(u), complex(s / (2 * u))


def loop_transforms(kinds: str, x: Complex, p: Complex) -> list[Complex]:
    """Each free joint's z-screw times its link (4×4, complex) at unknowns x and parameters p."""
    lay = loop_layout(kinds)
    out = []
    for j in range(len(kinds)):
        T = np.eye(4, dtype=complex)
        if lay.cs[j] >= 0:
            T = T @ rz(x[lay.cs[j]], x[lay.cs[j] + 1])
        if lay.d[j] >= 0:
            T = T @ trans(2, x[lay.d[j]])
        if lay.phi[j] >= 0:
            T = T @ rz(*pair_angle(p[lay.phi[j] - lay.n_unknowns],
                                   p[lay.phi[j] - lay.n_unknowns + 1]))
        if lay.b[j] >= 0:
            T = T @ trans(2, p[lay.b[j] - lay.n_unknowns])
        i = lay.alpha[j] - lay.n_unknowns
        out.append(T @ trans(0, p[lay.a[j] - lay.n_unknowns]) @ rx(*pair_angle(p[i], p[i + 1])))
    return out


def full_closure_residual(kinds: str, x: Complex, p: Complex) -> float:
    """max |∏ (Z_j K_j) − I| at one solution: zero exactly where the whole loop closes."""
    T = np.eye(4, dtype=complex)
    for M in loop_transforms(kinds, x, p):
        T = T @ M
    return float(np.abs(T - np.eye(4)).max())


def split_link(H: ArrayLike) -> tuple[tuple[complex, complex], complex, complex,
                                    tuple[complex, complex], tuple[complex, complex], complex]:
    """H = Rz(φ) Tz(b) Tx(a) Rx(α) Rz(ψ) Tz(e) for a rigid motion H (4×4, complex, with
    sin α ≠ 0): ((cos φ, sin φ), b, a, (cos α, sin α), (cos ψ, sin ψ), e), the z–x–z angles
    read from H's third column and row. sin α is the length of the third column's (x, y)
    part, (sin φ sin α, −cos φ sin α): √(1 − cos²α) would keep only ~1e-16/sin²α of it near
    α = 0 or π (a relative error 1e-2 at α = 1e-7)."""
    H = np.asarray(H, dtype=complex)
    R, t = H[:3, :3], H[:3, 3]
    ca = R[2, 2]
    sa = np.sqrt(R[0, 2] * R[0, 2] + R[1, 2] * R[1, 2] + 0j)
    cphi, sphi = -R[1, 2] / sa, R[0, 2] / sa
    cpsi, spsi = R[2, 1] / sa, R[2, 0] / sa
    cols = np.array([[0, cphi, R[0, 2]], [0, sphi, R[1, 2]], [1, 0, R[2, 2]]], dtype=complex)
    b, a, e = np.linalg.solve(cols, t)
    return (cphi, sphi), b, a, (ca, sa), (cpsi, spsi), e


def _turned(c: complex, s: complex, by: tuple[complex, complex]) -> tuple[complex, complex]:
    return c * by[0] - s * by[1], s * by[0] + c * by[1]


def random_closing_instance(kinds: str, rng: np.random.Generator
                            ) -> tuple[Complex, Complex]:
    """A random complex instance (1, k) with one known solution (1, n): random joint values and
    links, then the last link and the offsets at the first and last joint chosen to close the
    loop (:func:`split_link` of what is left)."""
    lay = loop_layout(kinds)
    n = len(kinds)

    def draw(*shape: int) -> Complex:
        return (rng.normal(size=shape) + 1j * rng.normal(size=shape)).astype(complex)

    x = np.zeros(lay.n_unknowns, dtype=complex)
    p = draw(lay.n_parameters)
    for j in range(n):
        if lay.cs[j] >= 0:
            z = draw(1)[0] * 0.5
            x[lay.cs[j]], x[lay.cs[j] + 1] = np.cos(z), np.sin(z)
        if lay.d[j] >= 0:
            x[lay.d[j]] = draw(1)[0]
    T = np.eye(4, dtype=complex)
    for M in loop_transforms(kinds, x, p)[:-1]:
        T = T @ M
    last = n - 1
    if lay.cs[last] >= 0:
        T = T @ rz(x[lay.cs[last]], x[lay.cs[last] + 1])
    if lay.d[last] >= 0:
        T = T @ trans(2, x[lay.d[last]])
    phi, b, a, alpha, psi, e = split_link(np.linalg.inv(T))
    k = lay.n_unknowns
    if lay.phi[last] >= 0:
        p[lay.phi[last] - k: lay.phi[last] - k + 2] = angle_pair(*phi)
    else:
        i = lay.cs[last]
        x[i], x[i + 1] = _turned(x[i], x[i + 1], phi)
    if lay.b[last] >= 0:
        p[lay.b[last] - k] = b
    else:
        x[lay.d[last]] += b
    p[lay.a[last] - k] = a
    p[lay.alpha[last] - k: lay.alpha[last] - k + 2] = angle_pair(*alpha)
    # what is left, Rz(ψ) Tz(e), stands before joint 0's z-screw and commutes with it
    if lay.phi[0] >= 0:
        i = lay.phi[0] - k
        p[i: i + 2] = angle_pair(*_turned(*pair_angle(p[i], p[i + 1]), psi))
    else:
        i = lay.cs[0]
        x[i], x[i + 1] = _turned(x[i], x[i + 1], psi)
    if lay.b[0] >= 0:
        p[lay.b[0] - k] += e
    else:
        x[lay.d[0]] += e
    return p[None, :], x[None, :]


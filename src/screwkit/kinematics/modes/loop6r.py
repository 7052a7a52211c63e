"""A 6R loop as a polynomial system in its joint-axis directions: 16 complex solutions.

The inverse kinematics of a 6R arm is a 6R loop closed by the target pose, and a 7R loop at one
value of its input is a 6R loop (the two links at the input joint become one). Joint i (i = 1..6)
joins link i−1 to link i; link 0 is the ground and carries joints 6 and 1. With z_i the unit axis
of joint i, link i between joints i and i+1 keeps z_i·z_{i+1} = cos α_i and its common normal
n_i = k_i z_i × z_{i+1} (k_i = a_i / sin α_i); joint i keeps the offset d_i between the feet of
n_{i−1} and n_i along z_i. The loop closes when

    g + Σ_{i=1..5} k_i z_i × z_{i+1} + Σ_{i=2..5} d_i z_i = 0,   g = n_6 + d_1 z_1 + d_6 z_6

(the loop equation of Duffy, *Analysis of Mechanisms and Robot Manipulators*, 1980, ch. 2; the
same as the Σ(a_i x_i + d_i z_i) = 0 of a Denavit–Hartenberg chain). The unknowns are the moving
axes z_2..z_5 (12), the equations z_i·z_i = 1 (4), the five link angles and the closure (3):
the formulation of the 6R case study in Sommese & Wampler 2005, ch. 9 (after Tsai & Morgan 1985 and Wampler & Morgan
1991), whose generic count is 16. Once the axes are known every joint angle follows: θ_i is the
angle from n_{i−1} to n_i about z_i, so the cos/sin of every joint are rational in the solution
and no spurious solution is added. The parameters (z_1, z_6, cos α_1..5, k_1..5, d_2..5, g: 23)
are free: any complex values are an instance.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.algebraic.solve import StartSolutions
from screwkit.errors import InputError
from screwkit.kinematics.modes.starts import start_solutions

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]

#: the generic number of complex solutions of a 6R loop (Lee & Liang 1988; Raghavan & Roth 1993)
LOOP6R_GENERIC_COUNT = 16
PARAMETER_NAMES = (*(f"z1_{c}" for c in "xyz"), *(f"z6_{c}" for c in "xyz"),
                   *(f"cos_alpha{i}" for i in range(1, 6)), *(f"k{i}" for i in range(1, 6)),
                   *(f"d{i}" for i in range(2, 6)), *(f"g_{c}" for c in "xyz"))


def _cross(a: list, b: list) -> list:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a: list, b: list) -> Poly:
    return sum((a[r] * b[r] for r in range(3)), Poly())


@lru_cache(maxsize=1)
def loop6r_system() -> PolynomialSystem:
    """The compiled 6R system (module docstring): unknowns z2..z5 (x, y, z each), parameters
    :data:`PARAMETER_NAMES`."""
    s = [Poly.variable(k) for k in range(12 + len(PARAMETER_NAMES))]
    z = [s[12:15], s[0:3], s[3:6], s[6:9], s[9:12], s[15:18]]  # z_1 … z_6
    cos_a, k, d, g = s[18:23], s[23:28], s[28:32], s[32:35]
    eqs = [_dot(z[i], z[i]) - 1.0 for i in range(1, 5)]
    eqs += [_dot(z[i], z[i + 1]) - cos_a[i] for i in range(5)]
    for r in range(3):
        e = g[r]
        for i in range(5):
            e = e + k[i] * _cross(z[i], z[i + 1])[r]
        for i in range(1, 5):
            e = e + d[i - 1] * z[i][r]
        eqs.append(e)
    names = [f"z{i}_{c}" for i in range(2, 6) for c in "xyz"]
    return compile_system(eqs, names, PARAMETER_NAMES)


@dataclass(frozen=True)
class PlacedLink:
    """A link as the two joint lines it carries, placed anywhere: its first joint (point ``a``,
    axis ``u``) and its second (point ``b``, axis ``v``), the axes oriented along the loop. The
    points must be the joints' own points (fixed in both bodies of the joint), which is what
    lets offsets along a joint be measured from two different placements."""

    a: Array
    u: Array
    b: Array
    v: Array


def _normal_feet(link: PlacedLink) -> tuple[float, float, Array]:
    """Axial coordinates of the common normal's feet on the first and second line (from the
    joints' points) and the normal vector from the first foot to the second."""
    c = float(link.u @ link.v)
    if 1.0 - c * c < 1e-12:
        raise InputError("two consecutive joint axes of the loop are parallel; the 6R "
                         "formulation needs a spatial loop (for a planar loop use "
                         "screwkit.kinematics.modes.planar)")
    dv = link.b - link.a
    sa = ((dv @ link.u) - (dv @ link.v) * c) / (1.0 - c * c)
    sb = ((dv @ link.u) * c - (dv @ link.v)) / (1.0 - c * c)
    n = (link.b + sb * link.v) - (link.a + sa * link.u)
    return float(sa), float(sb), n


def loop6r_parameters(links: list[PlacedLink]) -> Array:
    """Parameters (23,) of a 6R loop given as its six links, the ground (joint 6 → joint 1)
    first and then links 1..5 (joint i → joint i+1), each in any placement."""
    if len(links) != 6:
        raise InputError(f"a 6R loop has six links (the ground first); got {len(links)}")
    feet = [_normal_feet(lk) for lk in links]
    # d_i = (foot of n_i on joint i) − (foot of n_{i−1} on joint i); link i starts at joint i
    d = [feet[i % 6][0] - feet[i - 1][1] for i in range(1, 7)]  # d_1 … d_6
    z1, z6 = links[0].v, links[0].u
    cos_a = [float(links[i].u @ links[i].v) for i in range(1, 6)]
    k = []
    for i in range(1, 6):
        w = np.cross(links[i].u, links[i].v)
        k.append(float(feet[i][2] @ w / (w @ w)))
    g = feet[0][2] + d[0] * z1 + d[5] * z6
    return np.concatenate([z1, z6, cos_a, k, d[1:5], g])


def loop6r_axes(solution: ArrayLike, params: ArrayLike) -> NDArray[Any]:
    """All six axes (…, 6, 3) of solutions (…, 12) with their parameters (…, 23) or (23,)."""
    solution = np.asarray(solution)
    p = np.broadcast_to(params, solution.shape[:-1] + (len(PARAMETER_NAMES),))
    return np.concatenate([p[..., None, 0:3], solution.reshape(*solution.shape[:-1], 4, 3),
                           p[..., None, 3:6]], axis=-2)


def loop6r_angles(axes: ArrayLike) -> Array:
    """Joint angles (…, 6) of real solutions' axes (…, 6, 3): θ_i from n_{i−1} to n_i about
    z_i, n_i ∥ z_i × z_{i+1} (defined up to one constant per joint, which the drawn
    configuration fixes)."""
    axes = np.asarray(axes, dtype=float)
    w = np.cross(axes, np.roll(axes, -1, axis=-2))  # w_i = z_i × z_{i+1}
    w_prev = np.roll(w, 1, axis=-2)
    sin = np.einsum("...i,...i->...", np.cross(w_prev, w), axes)
    return np.arctan2(sin, np.einsum("...i,...i->...", w_prev, w))


def random_loop6r(rng: np.random.Generator, count: int, complex_values: bool = False
                  ) -> tuple[Complex, Complex]:
    """``count`` random instances with one known solution each: parameters (count, 23) and the
    solution (count, 12). The axes are random unit vectors (complex ones with z·z = 1 for a
    generic complex instance), the lengths random and g closes the loop."""
    def draw(*shape: int) -> Complex:
        v = rng.normal(size=shape).astype(complex)
        return v + 1j * rng.normal(size=shape) if complex_values else v

    z = draw(count, 6, 3)
    z = z / np.sqrt(np.sum(z * z, -1))[..., None]
    k, d = draw(count, 5), draw(count, 4)
    cos_a = np.sum(z[:, :5] * z[:, 1:], -1)
    g = -(np.einsum("ni,nij->nj", k, np.cross(z[:, :5], z[:, 1:]))
          + np.einsum("ni,nij->nj", d, z[:, 1:5]))
    p = np.concatenate([z[:, 0], z[:, 5], cos_a, k, d, g], -1)
    return p, z[:, 1:5].reshape(count, 12)


def loop6r_start() -> StartSolutions:
    """The 16 start solutions at a random complex instance (monodromy; cached per process)."""
    return start_solutions(loop6r_system(), lambda rng: random_loop6r(rng, 1, True),
                           LOOP6R_GENERIC_COUNT)

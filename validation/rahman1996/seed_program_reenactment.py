"""Re-enactment of Rahman's (1996) FORTRAN dynamics, bugs included — validation only, never src/.

This ports what the seed program computes for Tables 5.3–5.7 (reference SPEC §3, "as-run"
readings of §7) so that each of its departures from physics can be switched off one at a time and
its effect measured (``validation/rahman1996/dynamics.py`` does that). Units are the program's:
inch, lbf, second, masses in lbf·s²/in (weight / 386.4).

Kinematics come from ``kinematics.py`` (next to this file): the program's least-squares loop
closure ("STEP 1", SPEC §1.3) and least-squares rates (SPEC §1.4), or — switch ``exact_kinematics``
— the exact closed form (library ``cssp_motion``) fed into the same dynamics.

Quirks (``Quirks``; the defaults are the program "as run", every field False is the physics the
text intends):

* ``pair_full_mass``: each ± point-mass pair acts with the full pair mass m/4 at both points
  (p_k = −(a₊ + a₋)) instead of m/8 each (SPEC §3.2); crank and rod act with 7/4 of their mass;
* ``slider_mass_twice``: the slider's per-unit-mass force already holds M3 and is multiplied by
  x9 = M3 again (SPEC §3.2);
* ``stale_slider_moment``: the slider's moment uses the previous angle's force and the wrong
  components, (0, a4·f_z,prev, a4·f_y,prev) instead of P × F (SPEC §3.2);
* ``rod_spin``: the rod's point masses move with the two-angle slider-side frame
  M4Rᵀ·L3Rᵀ(θ3, η3) (SPEC §3.1), which spins about the rod axis — near θ3 = −90° (the rod close to
  the slider axis, a gimbal point of Z(θ3)Y(η3)) at thousands of rad/s — so the off-axis y and z
  pairs add a spurious moment; the physical setting moves them with the zero-spin rod
  (ω = u × u̇, α = u × ü, the library's rule);
* ``frames_mixed``: crank vectors in frame {2}, rod in {3}, slider in {4} summed as if in one
  frame (SPEC §3.3–3.4);
* ``stale_f3x8``: f3_x of the rod's CoM variable is never assigned and carries the previous angle's
  rotated value (SPEC §3.5);
* ``in_place_rotations``: the frame changes of f2, f3, f4 overwrite components while still using
  them (SPEC §3.5);
* ``t1_moment_bugs``: t1_x = a1·t1_z − s1 f1_y for the rod/slider variables and no sin/cos
  (SPEC §3.5); switched off, t1_x, t1_y take the original-link form's sin/cos (SPEC §3.5, last
  paragraph) — a reading of the intent, not physics either;
* ``stale_state``: both stale values start from the end of a first pass over the angles (the
  tables are the program's second pass); False starts them at zero.

Reaction formulas about O for the bearings, the "bearing force" as the magnitude of the vector
sum of four joint forces and the "bearing moment" including the input torque are what the tables
*define*; they are reported, not switched (``dynamics.py`` compares them with per-joint physics).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

import kinematics as kin  # validation/rahman1996/kinematics.py (the program's STEP 1)

HERE = Path(__file__).resolve().parent
EXAMPLE = HERE.parents[1] / "examples" / "rahman_cssp.toml"
A1, A2, A4, S1 = kin.A1_IN, kin.A2_IN, kin.A4_IN, kin.S1_IN
ALPHA4 = np.radians(kin.ALPHA4_DEG)
OMEGA = kin.RPM * 2 * np.pi / 60.0
ANGLES_DEG = kin.ANGLES_DEG  # 0, 10, …, 360 (37 angles, 360 repeated as the program does)
G_PROGRAM = 386.4  # in/s², the program's g: its masses are weight / g (lbf·s²/in)


@dataclass(frozen=True)
class Quirks:
    """Which of the program's departures from physics are on (module docstring)."""

    exact_kinematics: bool = False
    pair_full_mass: bool = True
    slider_mass_twice: bool = True
    rod_spin: bool = True
    stale_slider_moment: bool = True
    frames_mixed: bool = True
    stale_f3x8: bool = True
    in_place_rotations: bool = True
    t1_moment_bugs: bool = True
    stale_state: bool = True

    @classmethod
    def physics(cls) -> Quirks:
        """Every quirk off and the exact kinematics on."""
        return cls(exact_kinematics=True, **{f.name: False for f in fields(cls)
                                             if f.name != "exact_kinematics"})

    def without(self, name: str) -> Quirks:
        """This reading with one quirk switched to its physical setting."""
        if name == "exact_kinematics":
            return replace(self, exact_kinematics=True)
        return replace(self, **{name: False})


@dataclass(frozen=True)
class MassData:
    """The program's masses and point-mass distances (SPEC §2, §5.2), seed units."""

    crank_mass: float
    rod_mass: float
    slider_mass: float
    crank_com_x: float  # G1, from the crank pin (frame {2})
    rod_com_x: float  # G2, from the slider ball (frame {3})
    crank_distances: np.ndarray  # X1, Y1, Z1
    rod_distances: np.ndarray  # X2, Y2, Z2

    @property
    def design_variables(self) -> np.ndarray:
        """x = (m11, m12, m13, m14, m21, …, m24, M3): quarter masses and the slider (SPEC §3)."""
        q1, q2 = self.crank_mass / 4, self.rod_mass / 4
        return np.array([q1, q1, q1, q1, q2, q2, q2, q2, self.slider_mass])


def mass_data() -> MassData:
    """Masses and inertias from examples/rahman_cssp.toml (Rahman 1996 §5.2), in seed units;
    REAL*4 masses 1.9/G as the program has them (SPEC §5: below 1e−7, immaterial)."""
    spec = tomllib.loads(EXAMPLE.read_text(encoding="utf-8"))
    links = spec["links"]

    def weight(name: str) -> float:
        value, unit = links[name]["weight"].split()
        assert unit == "lbf"
        return float(np.float32(float(value)) / np.float32(G_PROGRAM))

    def distances(name: str, mass: float) -> np.ndarray:
        ix, iy, iz = links[name]["inertia"]
        quarter = mass / 4
        return np.sqrt(np.array([iy + iz - ix, ix + iz - iy, ix + iy - iz]) / (2 * quarter))

    m1, m2, m3 = weight("crank"), weight("rod"), weight("slider")
    a1 = spec["dimensions"]["a1"]
    a2 = spec["dimensions"]["a2"]
    # the toml puts the CoMs in screwkit's frames (from the crank axis, from the crank pin);
    # the program measures them from the pin (G1) and from the slider ball (G2)
    g1 = links["crank"]["com"][0] - a1
    g2 = links["rod"]["com"][0] - a2
    return MassData(m1, m2, m3, g1, g2, distances("crank", m1), distances("rod", m2))


# ---------------------------------------------------------------------------------------------
# kinematic inputs per angle: q = (θ2, η2, θ3, η3, s4), rates in the program's unknown order
# (θ̇2, θ̇3, η̇2, η̇3, ṡ4) and the same for accelerations
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class AngleKinematics:
    theta1: float
    q: np.ndarray
    rates: np.ndarray
    accelerations: np.ndarray


def program_kinematics() -> tuple[list[AngleKinematics], list[AngleKinematics]]:
    """Pass 1 and pass 2 of the program's STEP 1 and its least-squares rates (SPEC §1.3–1.4)."""
    out = []
    for angles in kin.seed_program_step1():
        rows = []
        for p in angles:
            dot, ddot, _ = kin.program_rates(p.q, OMEGA)
            rows.append(AngleKinematics(np.radians(p.theta1_deg), p.q.copy(), dot, ddot))
        out.append(rows)
    return out[0], out[1]


def exact_kinematics() -> list[AngleKinematics]:
    """The same inputs from the exact closed form (library, SI → inch)."""
    m = kin.exact_motion()
    to_in = 1 / 0.0254
    rows = []
    for k in range(m.theta1.size):
        q = np.array([m.theta2[k], m.eta2[k], m.theta3[k], m.eta3[k], m.s4[k] * to_in])
        dot = np.array([m.theta2_dot[k], m.theta3_dot[k], m.eta2_dot[k], m.eta3_dot[k],
                        m.s4_dot[k] * to_in])
        ddot = np.array([m.theta2_ddot[k], m.theta3_ddot[k], m.eta2_ddot[k], m.eta3_ddot[k],
                         m.s4_ddot[k] * to_in])
        rows.append(AngleKinematics(float(m.theta1[k]), q, dot, ddot))
    return rows


# ---------------------------------------------------------------------------------------------
# building blocks
# ---------------------------------------------------------------------------------------------
Jet = tuple[float, float, float]  # value and first two time derivatives


def _jmul(a: Jet, b: Jet) -> Jet:
    return (a[0] * b[0], a[1] * b[0] + a[0] * b[1], a[2] * b[0] + 2 * a[1] * b[1] + a[0] * b[2])


def _trig_jets(angle: float, rate: float, acc: float) -> tuple[Jet, Jet]:
    c, s = np.cos(angle), np.sin(angle)
    return (c, -s * rate, -c * rate**2 - s * acc), (s, c * rate, -s * rate**2 + c * acc)


def _l3r_transposed(th3: float, th3d: float, th3dd: float, et3: float, et3d: float,
                    et3dd: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """L3Rᵀ = R_{4←3} of L3 = Z(θ3)Y(η3)X(π/2) and its exact first and second time derivatives
    (the listing's L3RD, L3RDD, SPEC §3.1), by the product rule on (value, ˙, ¨) jets."""
    c3, s3 = _trig_jets(th3, th3d, th3dd)
    ce, se = _trig_jets(et3, et3d, et3dd)
    neg = lambda j: (-j[0], -j[1], -j[2])  # noqa: E731
    zero: Jet = (0.0, 0.0, 0.0)
    entries = [
        [_jmul(c3, ce), _jmul(s3, ce), neg(se)],
        [_jmul(c3, se), _jmul(s3, se), ce],
        [s3, neg(c3), zero],
    ]
    value = np.array([[e[0] for e in row] for row in entries])
    first = np.array([[e[1] for e in row] for row in entries])
    second = np.array([[e[2] for e in row] for row in entries])
    return value, first, second


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _z(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _l2r(th2: float, et2: float) -> np.ndarray:
    c2, s2, ce, se = np.cos(th2), np.sin(th2), np.cos(et2), np.sin(et2)
    return np.array([[c2 * ce, -s2, c2 * se], [s2 * ce, c2, s2 * se], [-se, 0.0, ce]])


def _m4r() -> np.ndarray:
    ca, sa = np.cos(ALPHA4), np.sin(ALPHA4)
    return np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])


def _rotate(m: np.ndarray, v: np.ndarray, in_place: bool, columns: int = 3) -> np.ndarray:
    """M v; ``in_place`` re-enacts DO 50/60/70 (each new component reused at once, SPEC §3.5);
    ``columns=2`` uses only M's first two columns (the f4 rotation)."""
    x = v.astype(float).copy()
    if columns == 2:
        x[2] = 0.0
    if not in_place:
        return m @ x
    x[0] = m[0, 0] * x[0] + m[0, 1] * x[1] + m[0, 2] * x[2]
    x[1] = m[1, 0] * x[0] + m[1, 1] * x[1] + m[1, 2] * x[2]
    x[2] = m[2, 0] * x[0] + m[2, 1] * x[1] + m[2, 2] * x[2]
    return x


@dataclass
class _State:
    """Values the program carries from one angle to the next (static FORTRAN variables)."""

    f3x8: float = 0.0
    slider_force_frame4: np.ndarray | None = None


@dataclass(frozen=True)
class AngleLoads:
    """Per-unit-mass columns (3, 9) and the tabulated quantities for design variables x."""

    force: np.ndarray  # f_k (as summed for the shaking force)
    moment: np.ndarray  # t_k
    f1: np.ndarray
    f2: np.ndarray
    f3: np.ndarray
    f4: np.ndarray
    t1: np.ndarray


def _point_inertia(r_dist: np.ndarray, accel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """−a and −r × a of one point (per unit mass), moment about O."""
    return -accel, -np.cross(r_dist, accel)


def _angle_loads(k: AngleKinematics, md: MassData, qk: Quirks, state: _State) -> AngleLoads:
    th1 = k.theta1
    th2, et2, th3, et3, s4 = k.q
    th3d, et3d = k.rates[1], k.rates[3]
    th3dd, et3dd, s4dd = k.accelerations[1], k.accelerations[3], k.accelerations[4]
    c1, s1t = np.cos(th1), np.sin(th1)
    c2, s2 = np.cos(th2), np.sin(th2)
    ce2, se2 = np.cos(et2), np.sin(et2)
    c3, s3 = np.cos(th3), np.sin(th3)
    ce3, se3 = np.cos(et3), np.sin(et3)
    sa, ca = np.sin(ALPHA4), np.cos(ALPHA4)
    w = OMEGA
    pair_weight = 1.0 if qk.pair_full_mass else 0.5

    p = np.zeros((3, 9))  # per-unit-mass inertia force, frame {1}
    q = np.zeros((3, 9))  # per-unit-mass inertia moment about O, frame {1}
    # crank (SPEC §3.1): R = Z(θ1), D = D1, θ̈1 = 0
    r1 = _z(th1)
    d1 = np.array([A1 * c1, A1 * s1t, S1])
    d1dd = np.array([-A1 * c1 * w**2, -A1 * s1t * w**2, 0.0])
    r1dd = -(w**2) * np.array([[c1, -s1t, 0.0], [s1t, c1, 0.0], [0.0, 0.0, 0.0]])
    # rod from the slider side: R = M4Rᵀ L3Rᵀ, D = D2 (SPEC §3.1)
    m4r = _m4r()
    l3t, l3t_d, l3t_dd = _l3r_transposed(th3, th3d, th3dd, et3, et3d, et3dd)
    r2 = m4r.T @ l3t
    r2dd = m4r.T @ l3t_dd
    if not qk.rod_spin:
        # zero-spin rod: R̈ l → α × (R l) + ω × (ω × (R l)) with ω = u × u̇, α = u × ü
        u, ud, udd = r2[:, 0], (m4r.T @ l3t_d)[:, 0], r2dd[:, 0]
        w_rod, al_rod = np.cross(u, ud), np.cross(u, udd)
        r2dd = (_skew(al_rod) + _skew(w_rod) @ _skew(w_rod)) @ r2
    k4 = np.array([0.0, sa, ca])
    d2 = np.array([-A4, -s4 * sa, -s4 * ca])
    d2dd = -s4dd * k4
    for base, (R, D, Ddd, com_x, dist) in enumerate(
        ((r1, d1, d1dd, md.crank_com_x, md.crank_distances),
         (r2, d2, d2dd, md.rod_com_x, md.rod_distances))
    ):
        com = np.array([com_x, 0.0, 0.0])
        for axis in range(3):
            col = 4 * base + axis
            force = np.zeros(3)
            moment = np.zeros(3)
            for sign in (1.0, -1.0):
                local = com.copy()
                local[axis] += sign * dist[axis]
                f, m = _point_inertia(D + R @ local, Ddd + R_dd_apply(R, local, base, r1dd, r2dd))
                force += f
                moment += m
            p[:, col] = pair_weight * force
            q[:, col] = 0.5 * moment
        f, m = _point_inertia(D + R @ com, Ddd + R_dd_apply(R, com, base, r1dd, r2dd))
        p[:, 4 * base + 3] = f
        q[:, 4 * base + 3] = m
    # slider (SPEC §3.2): p9 = M3 s̈4 k4 (M3 once too many), moment stale
    p[:, 8] = (md.slider_mass if qk.slider_mass_twice else 1.0) * s4dd * k4
    if qk.stale_slider_moment:
        prev = state.slider_force_frame4
        fy_prev, fz_prev = (0.0, 0.0) if prev is None else (prev[1], prev[2])
        q[:, 8] = [0.0, A4 * fz_prev, A4 * fy_prev]
    else:
        q[:, 8] = np.cross(d2, p[:, 8])

    # frames of the summed vectors (SPEC §3.3)
    r12 = r1 @ _l2r(th2, et2)  # M1R·L2R: rod frame {3} seen from the crank side
    f = np.zeros((3, 9))
    t = np.zeros((3, 9))
    f[:, :4] = r1.T @ p[:, :4]
    t[:, :4] = r1.T @ q[:, :4]
    f[:, 4:8] = r12.T @ p[:, 4:8]
    t[:, 4:8] = r12.T @ q[:, 4:8]
    f[:, 8] = m4r @ p[:, 8]
    t[:, 8] = m4r @ q[:, 8]
    state.slider_force_frame4 = f[:, 8].copy()

    # bearing reactions per unit mass, "as run" (SPEC §3.5)
    f1 = np.zeros((3, 9))
    f2 = np.zeros((3, 9))
    f3 = np.zeros((3, 9))
    f4 = np.zeros((3, 9))
    t1 = np.zeros((3, 9))
    ip = qk.in_place_rotations
    for col in range(4, 8):
        fx, fy, fz = f[:, col]
        tx, ty, tz = t[:, col]
        f3y = -(fy + tz / A2)
        f3z = -(fz + ty / A2)
        f3x = state.f3x8 if (col == 7 and qk.stale_f3x8) else c3 * f3y / s3
        f4x = se3 * f3z - c3 * ce3 * f3x - s3 * ce3 * f3y
        f4y = -(ce3 * f3z + c3 * se3 * f3x + s3 * se3 * f3y)
        f2x = -(f3x + fx) * c2 * ce2 + (f3y + fy) * s2 - ty * se2 * c2 / A2
        f2y = -(f3x + fx) * s2 * ce2 - (f3y + fy) * c2 - ty * se2 * s2 / A2
        f2z = -(fz + f3z + f2y * s2 * se2 + f2x * c2 * se2) / ce2
        f3[:, col] = _rotate(r12, np.array([f3x, f3y, f3z]), ip)
        f2[:, col] = _rotate(r1, np.array([f2x, f2y, f2z]), ip)
        f4[:, col] = _rotate(m4r.T, np.array([f4x, f4y, 0.0]), ip, columns=2)
        if col == 7:
            state.f3x8 = float(f3[0, col])
    fx9, fy9, fz9 = f[:, 8]
    f3x9 = fz9 / s3
    f3[:, 8] = [f3x9, 0.0, 0.0]
    f4[:, 8] = [-c3 * ce3 * f3x9 - fx9, c3 * se3 * f3x9 + fy9, 0.0]
    f2x9 = -f3x9 * c2 * ce2
    f2y9 = -f3x9 * s2 * ce2
    f2[:, 8] = [f2x9, f2y9, -(f2y9 * s2 * se2 + f2x9 * c2 * se2) / ce2]
    for col in range(9):
        g = f[:, col] if col < 4 else f2[:, col]
        f1x = -g[0] * c1 + g[1] * s1t
        f1y = -(g[0] * s1t + g[1] * c1)
        f1z = -g[2]
        t1z = A1 * (f1y * c1 - f1x * s1t) - (t[2, col] if col < 4 else 0.0)
        if col < 4:
            tx, ty = t[0, col], t[1, col]
            t1x = -S1 * f1y - tx * c1 + A1 * f1z + ty * s1t
            t1y = S1 * f1x - A1 * f1z - tx * s1t - ty * c1
        elif qk.t1_moment_bugs:
            t1x = A1 * t1z - S1 * f1y
            t1y = S1 * f1x - A1 * f1z
        else:  # the original-link form with its sin and cos (SPEC §3.5, last paragraph)
            t1x = -S1 * f1y + A1 * f1z * s1t
            t1y = S1 * f1x - A1 * f1z * c1
        f1[:, col] = [f1x, f1y, f1z]
        t1[:, col] = [t1x, t1y, t1z]
    if not qk.frames_mixed:
        f, t = p, q
    return AngleLoads(f, t, f1, f2, f3, f4, t1)


def R_dd_apply(R: np.ndarray, local: np.ndarray, base: int, r1dd: np.ndarray,
               r2dd: np.ndarray) -> np.ndarray:  # noqa: N802 - the listing's R̈
    """R̈ l for the crank (base 0) or the rod (base 1)."""
    return (r1dd if base == 0 else r2dd) @ local


@dataclass(frozen=True)
class ProgramTables:
    """The program's Tables 5.3–5.7 "before" columns (and per-unit-mass columns) per angle."""

    angles_deg: np.ndarray
    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    bearing_force: np.ndarray
    bearing_moment: np.ndarray
    input_torque: np.ndarray
    loads: list[AngleLoads]


def run(quirks: Quirks | None = None, x: np.ndarray | None = None) -> ProgramTables:
    """The program's two passes over θ1 = 0…360° (SPEC §5 "program flow"); returns pass 2
    evaluated at design variables ``x`` (default the original masses)."""
    qk = quirks or Quirks()
    md = mass_data()
    xs = md.design_variables if x is None else np.asarray(x, dtype=float)
    if qk.exact_kinematics:
        exact = exact_kinematics()
        passes = [exact, exact]
    else:
        passes = list(program_kinematics())
    state = _State()
    if not qk.stale_state:
        passes = passes[1:]
    loads: list[AngleLoads] = []
    for angles in passes:
        loads = [_angle_loads(k, md, qk, state) for k in angles]
    sf, sm, bf, bm, t0 = [], [], [], [], []
    for ld in loads:
        sf.append(np.linalg.norm(ld.force @ xs))
        sm.append(np.linalg.norm(ld.moment @ xs))
        total = (ld.f1 + ld.f2 + ld.f3 + ld.f4) @ xs
        total[2] = ((ld.f1 + ld.f2 + ld.f3)[2]) @ xs  # f4_z is left out (SPEC §3.6)
        bf.append(np.linalg.norm(total))
        bm.append(np.linalg.norm(ld.t1 @ xs))
        t0.append(ld.t1[2] @ xs)
    return ProgramTables(ANGLES_DEG.copy(), np.array(sf), np.array(sm), np.array(bf),
                         np.array(bm), np.array(t0), loads)


if __name__ == "__main__":
    res = run()
    for row in zip(res.angles_deg, res.shaking_force, res.shaking_moment, res.bearing_force,
                   res.bearing_moment, res.input_torque, strict=True):
        print(" ".join(f"{v:12.4f}" for v in row))

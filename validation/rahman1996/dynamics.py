"""Rahman (1996) CSSP example: inverse dynamics with correct physics, against Tables 5.3–5.7.

Run ``python validation/rahman1996/dynamics.py`` to print the report, ``--write`` to also write
``validation/rahman1996/dynamics.md`` next to this file (exit status 1 if a check fails).

* **screwkit**: the example of examples/rahman_cssp.toml (a1 = 2 in, a2 = 8 in, a4 = 1 in,
  s1 = 0.4 in, α4 = 250°, 3000 rpm, masses and inertias of §5.2), exact closed-form kinematics
  through ``screwkit.kinematics.closed_forms.cssp_motion.cssp_mode_motion`` and ``screwkit.dynamics
  .inverse_dynamics``, in SI, printed in lbf and lbf·in at the boundary (pint).
* **program**: ``seed_program_reenactment.py`` (next to this file), the seed's FORTRAN dynamics
  with its bugs; each bug can be switched off alone to measure what it does to each table.
* **tables**: /work/shared/reference/rahman1996/tables/ (the "before" columns, original masses).

Independent physics checks (DESIGN validation level 2): shaking force = −dP/dt and shaking moment
= −dH_O/dt from the momenta on a fine periodic grid (spectral derivative), input power
T·ω = dKE/dt; and a second method (level 3): the generic solver's ``motion`` gives the same loads,
and the re-enacted program with every bug off gives the same shaking force and moment.
"""

from __future__ import annotations

import argparse
import csv
import sys
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pint

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import seed_program_reenactment as seed  # noqa: E402

from screwkit.dynamics import Dynamics, inverse_dynamics  # noqa: E402
from screwkit.dynamics.checks import check_link_masses  # noqa: E402
from screwkit.io.spec import load_spec  # noqa: E402
from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion  # noqa: E402
from screwkit.kinematics.motion import ModeMotion  # noqa: E402
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion  # noqa: E402
from screwkit.model.linkage import Linkage  # noqa: E402

UREG = pint.UnitRegistry()
LBF = UREG.Quantity(1.0, "lbf").to("N").magnitude
LBF_IN = UREG.Quantity(1.0, "lbf*inch").to("N*m").magnitude
TABLES = Path("/work/shared/reference/rahman1996/tables")
EXAMPLE = HERE.parents[1] / "examples" / "rahman_cssp.toml"
ANGLES_DEG = np.arange(0.0, 361.0, 10.0)
# SPEC §5.1: printing typos (excluded from error statistics) and the copied 360° row
TYPO_ROWS = {"shaking_moment": [240.0]}
SPEC_SECTION6_MEDIANS = {  # SPEC §6, "before" medians of a port of the listing
    "shaking_force": 5.9e-4, "shaking_moment": 3.0e-3, "bearing_force": 3.4e-3,
    "bearing_moment": 2.2e-3, "input_torque": 2.4e-3,
}
TABLE_FILES = {
    "shaking_force": ("table5_3_shaking_force.csv", "5.3"),
    "shaking_moment": ("table5_4_shaking_moment.csv", "5.4"),
    "bearing_force": ("table5_5_bearing_force.csv", "5.5"),
    "bearing_moment": ("table5_6_bearing_torque.csv", "5.6"),
    "input_torque": ("table5_7_input_torque.csv", "5.7"),
}
QUIRK_TEXT = {
    "exact_kinematics": "exact kinematics instead of the non-closing least-squares loop (§1.3–1.4)",
    "pair_full_mass": "point-mass pairs with their ½ (pairs act with m/4, not m/2)",
    "slider_mass_twice": "slider mass applied once (not M3²)",
    "rod_spin": "rod point masses move with the zero-spin rod, not the spinning two-angle frame",
    "stale_slider_moment": "slider moment P × F of this angle (not the previous angle's, wrong components)",
    "frames_mixed": "all vectors summed in frame {1} (not {2}, {3}, {4} mixed)",
    "stale_f3x8": "f3_x of the rod CoM variable computed (not left over from the last angle)",
    "in_place_rotations": "frame rotations as matrix products (not in place)",
    "t1_moment_bugs": "t1_x, t1_y with the original-link sin/cos (not a1·t1_z)",
    "stale_state": "stale values start at zero (no first pass)",
}


def read_table(name: str) -> np.ndarray:
    """The 'before' column of a seed table (37 rows, 0…360°)."""
    path = TABLES / TABLE_FILES[name][0]
    with path.open(encoding="utf-8") as fh:
        rows = list(csv.reader(fh))[1:]
    return np.array([float(r[1]) for r in rows])


# ---------------------------------------------------------------------------------------------
# screwkit, correct physics
# ---------------------------------------------------------------------------------------------
def example() -> tuple[Linkage, float]:
    spec = load_spec(EXAMPLE)
    return spec.linkage, float(spec.speed)


def physics(theta_deg: np.ndarray = ANGLES_DEG) -> tuple[Linkage, ModeMotion, Dynamics]:
    """Loads of the example over ``theta_deg`` (constant crank speed, no gravity: the program
    has none), assembly mode +1 (the seed's branch)."""
    lk, omega = example()
    mode = cssp_mode_motion(lk, np.radians(theta_deg), omega, 0.0)
    return lk, mode, inverse_dynamics(lk, mode)


def seed_units(dyn: Dynamics) -> dict[str, np.ndarray]:
    """Our loads in the seed's units and definitions: magnitudes in lbf, lbf·in; per-joint
    reactions (on the moving link, moment about the joint centre); the crank bearing moment
    about O as well (the seed takes every moment about O, SPEC §3.2)."""
    out = {
        "shaking_force": np.linalg.norm(dyn.shaking_force, axis=1) / LBF,
        "shaking_moment": np.linalg.norm(dyn.shaking_moment, axis=1) / LBF_IN,
        "input_torque": dyn.efforts["crank.theta"] / LBF_IN,
    }
    total = np.zeros_like(dyn.shaking_force)
    for k, (joint, r) in enumerate(dyn.reactions.items()):
        out[f"{joint}.force"] = np.linalg.norm(r["force"], axis=1) / LBF
        out[f"{joint}.moment"] = np.linalg.norm(r["moment"], axis=1) / LBF_IN
        total = total + r["force"]
        if k == 0:
            about_o = r["moment"] + np.cross(dyn.joint_centres[:, 0], r["force"])
            out["crank.moment_about_O"] = np.linalg.norm(about_o, axis=1) / LBF_IN
    out["vector_sum_of_joint_forces"] = np.linalg.norm(total, axis=1) / LBF
    return out


def _spectral_derivative(values: np.ndarray, period: float) -> np.ndarray:
    """d/dθ of samples of a smooth periodic function on a uniform grid (axis 0)."""
    n = values.shape[0]
    k = np.fft.fftfreq(n, d=period / n) * 2 * np.pi
    if n % 2 == 0:
        k[n // 2] = 0.0
    spec = np.fft.fft(values, axis=0)
    return np.real(np.fft.ifft(1j * k.reshape((-1,) + (1,) * (values.ndim - 1)) * spec, axis=0))


def physical_law_checks(samples: int = 1024) -> dict[str, float]:
    """Largest disagreement, relative to the peak load, of: shaking force vs −dP/dt, shaking
    moment about O vs −dH_O/dt, input power T·ω vs dKE/dt — momenta and kinetic energy from
    the link kinematics alone, derivatives spectral over one crank turn (exact for these
    band-limited periodic signals to ~1e−12 of the peak at 1024 samples)."""
    lk, omega = example()
    theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    mode = cssp_mode_motion(lk, theta, omega, 0.0)
    dyn = inverse_dynamics(lk, mode)
    masses = check_link_masses(lk)
    P = np.zeros((samples, 3))
    H = np.zeros((samples, 3))
    KE = np.zeros(samples)
    for l, mp in enumerate(masses):
        R = mode.link_rotation[:, l]
        w = mode.link_angular_velocity[:, l]
        rc = np.einsum("nij,j->ni", R, mp.com)
        pc = mode.link_origin[:, l] + rc
        vc = mode.link_origin_velocity[:, l] + np.cross(w, rc)
        Iw = np.einsum("nij,jk,nlk,nl->ni", R, mp.inertia, R, w)
        P += mp.mass * vc
        H += mp.mass * np.cross(pc, vc) + Iw
        KE += 0.5 * mp.mass * np.sum(vc * vc, axis=1) + 0.5 * np.sum(w * Iw, axis=1)
    dP = omega * _spectral_derivative(P, 2 * np.pi)
    dH = omega * _spectral_derivative(H, 2 * np.pi)
    dKE = omega * _spectral_derivative(KE, 2 * np.pi)
    force_peak = np.abs(dyn.shaking_force).max()
    moment_peak = np.abs(dyn.shaking_moment).max()
    power = dyn.efforts["crank.theta"] * omega
    return {
        "shaking force vs −dP/dt": float(np.abs(dyn.shaking_force + dP).max() / force_peak),
        "shaking moment vs −dH_O/dt": float(np.abs(dyn.shaking_moment + dH).max() / moment_peak),
        "input power vs dKE/dt": float(np.abs(power - dKE).max() / np.abs(power).max()),
        "idle rod-spin residual": float(np.nanmax(dyn.relative_residual)),
    }


def generic_solver_difference() -> float:
    """Largest difference of every load between the closed-form path and the generic solver's
    ``motion`` over 0…350°, relative to the peak joint load."""
    lk, omega = example()
    theta = np.radians(ANGLES_DEG[:-1])
    fast = inverse_dynamics(lk, cssp_mode_motion(lk, theta, omega, 0.0))
    m = motion(lk, theta, omega, 0.0)
    s4 = cssp_mode_motion(lk, theta, omega, 0.0).variables["slider.s"]
    mode = min(m.modes, key=lambda md: float(np.nanmax(np.abs(md.variables["slider.s"] - s4))))
    slow = inverse_dynamics(lk, mode)
    diffs = [np.abs(fast.shaking_force - slow.shaking_force).max(),
             np.abs(fast.shaking_moment - slow.shaking_moment).max() / lk.length_scale,
             np.abs(fast.efforts["crank.theta"] - slow.efforts["crank.theta"]).max()
             / lk.length_scale]
    for j in fast.reactions:
        diffs.append(np.abs(fast.reactions[j]["force"] - slow.reactions[j]["force"]).max())
        diffs.append(np.abs(fast.reactions[j]["moment"] - slow.reactions[j]["moment"]).max()
                     / lk.length_scale)
    return float(max(diffs) / slow.residual_scale)


# ---------------------------------------------------------------------------------------------
# re-enactment statistics
# ---------------------------------------------------------------------------------------------
def program_columns(res: seed.ProgramTables) -> dict[str, np.ndarray]:
    return {
        "shaking_force": res.shaking_force, "shaking_moment": res.shaking_moment,
        "bearing_force": res.bearing_force, "bearing_moment": res.bearing_moment,
        "input_torque": res.input_torque,
    }


def relative_errors(name: str, values: np.ndarray) -> np.ndarray:
    """|value − table|/|table| over 0…350° without the typo rows (SPEC §5.1, §6)."""
    table = read_table(name)
    keep = ANGLES_DEG < 360.0
    for angle in TYPO_ROWS.get(name, []):
        keep &= ANGLES_DEG != angle
    return np.asarray(np.abs(values[keep] - table[keep]) / np.abs(table[keep]))


def _fmt(v: float) -> str:
    return f"{v:.1e}" if v < 0.1 else f"{v:.2f}"


def build_report() -> tuple[str, list[tuple[str, bool]]]:
    lk, mode, dyn = physics()
    ours = seed_units(dyn)
    as_run = program_columns(seed.run())
    phys_program = program_columns(seed.run(seed.Quirks.physics()))
    tables = {name: read_table(name) for name in TABLE_FILES}
    laws = physical_law_checks()
    generic = generic_solver_difference()
    checks: list[tuple[str, bool]] = []
    for text, value in laws.items():
        checks.append((f"{text}: {value:.1e} of peak", value < 1e-9))
    checks.append((f"closed-form path = generic solver (every load): {generic:.1e} of the peak "
                   "joint load", generic < 1e-10))
    for name in ("shaking_force", "shaking_moment"):
        d = np.abs(phys_program[name] - ours[name]).max() / ours[name].max()
        # the program keeps REAL*4 masses (1.9/386.4 in single precision): ~1e−8 relative
        checks.append((f"re-enacted program with every bug off = screwkit, {name.replace('_', ' ')}"
                       f": {d:.1e} of peak", d < 1e-7))
    fidelity = {}
    for name in TABLE_FILES:
        e = relative_errors(name, as_run[name])
        fidelity[name] = (float(np.median(e)), float(e.max()))
        target = SPEC_SECTION6_MEDIANS[name]
        checks.append((f"re-enactment, Table {TABLE_FILES[name][1]} median error "
                       f"{fidelity[name][0]:.1e} (SPEC §6: {target:.1e})",
                       fidelity[name][0] < 1.5 * target))
    # one quirk off at a time, from the as-run reading
    ablation = {}
    for f in fields(seed.Quirks):
        res = program_columns(seed.run(seed.Quirks().without(f.name)))
        ablation[f.name] = {n: float(np.median(relative_errors(n, res[n]))) for n in TABLE_FILES}
    # cumulative: from the program to physics, one bug at a time; distance to screwkit
    order = ["exact_kinematics", "pair_full_mass", "slider_mass_twice", "frames_mixed",
             "rod_spin", "stale_slider_moment"]
    cumulative = []
    q = seed.Quirks()
    for name in ["(as run)", *order]:
        if name != "(as run)":
            q = q.without(name)
        res = program_columns(seed.run(q))
        rel = {n: np.abs(res[n] - ours[n]) / np.abs(ours[n])
               for n in ("shaking_force", "shaking_moment")}
        cumulative.append((name, {f"{n}.{stat}": float(fn(r)) for n, r in rel.items()
                                  for stat, fn in (("median", np.median), ("max", np.max))}))
    # the seed does not say which way its T0 acts: compare with the sign that fits it better
    err_same, err_opposite = (float(np.median(np.abs(sign * ours["input_torque"][:-1]
                                                     - tables["input_torque"][:-1])
                                              / np.abs(tables["input_torque"][:-1])))
                              for sign in (1.0, -1.0))
    # ours against the tables (physics vs the seed's numbers)
    versus = {n: float(np.median(np.abs(ours[n][:-1] - tables[n][:-1]) / np.abs(tables[n][:-1])))
              for n in ("shaking_force", "shaking_moment")}
    versus["input_torque"] = min(err_same, err_opposite)
    # the rod-spin effect alone, on exact kinematics with every other bug off
    spin = program_columns(seed.run(replace(seed.Quirks.physics(), rod_spin=True)))
    spin_effect = float(np.abs(spin["shaking_moment"] - ours["shaking_moment"]).max())
    spin_angle = float(ANGLES_DEG[np.argmax(np.abs(spin["shaking_moment"]
                                                   - ours["shaking_moment"]))])
    versus["bearing_force"] = float(np.median(
        np.abs(ours["vector_sum_of_joint_forces"][:-1] - tables["bearing_force"][:-1])
        / tables["bearing_force"][:-1]))
    versus["bearing_moment"] = float(np.median(
        np.abs(ours["crank.moment_about_O"][:-1] - tables["bearing_moment"][:-1])
        / tables["bearing_moment"][:-1]))

    L: list[str] = []
    L += [
        "# Rahman (1996) CSSP example — inverse dynamics: correct physics vs Tables 5.3–5.7",
        "",
        "Generated by `validation/rahman1996/dynamics.py --write`. Example: a1 = 2 in, a2 = 8 in,",
        "a4 = 1 in, s1 = 0.4 in, α4 = 250°, 3000 rpm, weights 1.9 / 7.6 / 6.0 lbf and the inertias",
        "of Rahman §5.2 (examples/rahman_cssp.toml; masses = weight / 386.4 in/s² as in the seed),",
        "no gravity (the program has none). Units: lbf, lbf·in, as the seed prints them.",
        "",
        "* **screwkit** — exact closed-form kinematics (`cssp_mode_motion`, assembly mode +1, zero",
        "  rod spin) and Newton–Euler loop statics (`inverse_dynamics`), SI inside.",
        "* **program** — `seed_program_reenactment.py`: the FORTRAN listing's dynamics (SPEC §3,",
        "  \"as-run\" readings of §7) on its own least-squares kinematics, bugs included.",
        "* **table** — the seed's \"before\" column (original masses).",
        "",
        "## Checks",
        "",
    ]
    L += [f"- [{'x' if ok else ' '}] {text}" for text, ok in checks]
    L += [
        "",
        "The physical-law checks use only the links' kinematics (momenta, kinetic energy) on a",
        "1024-point grid over one turn and differentiate spectrally; they do not share code with",
        "the loop statics. The rod is axisymmetric (Iyy = Izz, CoM on its axis), so its free spin",
        "about its own axis carries no load (idle residual 0).",
        "",
        "## How close the re-enactment gets to the seed's tables",
        "",
        "Relative error |program − table| / |table| over 0…350° (the 360° row is a copy of 0°; the",
        "Table 5.4 240° \"before\" entry is a misprint, SPEC §5.1):",
        "",
        "| table | median | max | SPEC §6 median |",
        "|---|---:|---:|---:|",
    ]
    for name, (med, mx) in fidelity.items():
        L.append(f"| {TABLE_FILES[name][1]} {name.replace('_', ' ')} | {med:.1e} | {mx:.1e} "
                 f"| {SPEC_SECTION6_MEDIANS[name]:.1e} |")
    L += [
        "",
        "The port reaches the residual that SPEC §6 reports for its own port (≈ 6e−4 … 3e−3",
        "median); the largest errors sit where the value is small (Table 5.7 at 190°, where",
        "|T0| ≈ 99 lbf·in). The remaining 0.05–0.5 % is not explained (SPEC §6 lists what it is",
        "not); the program that printed the tables probably differed from the listing in some",
        "further detail. The program's own 360° input torque is "
        f"{as_run['input_torque'][-1]:.0f} lbf·in against {as_run['input_torque'][0]:.0f} at 0°",
        "(stale variables), which is why the seed copied the 0° row.",
        "",
        "## What each bug does (one switched off at a time, from the as-run program)",
        "",
        "Median relative error against the seed's table with that single bug fixed; a fix that",
        "moves the program away from the table (by orders of magnitude) is evidence the tables",
        "contain that bug.",
        "",
        "| bug fixed | 5.3 F_sh | 5.4 M_sh | 5.5 bearing F | 5.6 bearing M | 5.7 T0 |",
        "|---|---:|---:|---:|---:|---:|",
        "| none (as run) | " + " | ".join(_fmt(fidelity[n][0]) for n in TABLE_FILES) + " |",
    ]
    for name, errs in ablation.items():
        L.append(f"| {QUIRK_TEXT[name]} | " + " | ".join(_fmt(errs[n]) for n in TABLE_FILES)
                 + " |")
    L += [
        "",
        "## From the program to physics, one fix at a time (cumulative)",
        "",
        "Median relative difference of the program's shaking force and moment from screwkit's after",
        "each fix is added to the previous ones. The shaking loads need six fixes; with all of them",
        "the program equals screwkit to single-precision round-off (checks above).",
        "",
        "| fixes so far | F_sh vs screwkit, median | max | M_sh vs screwkit, median | max |",
        "|---|---:|---:|---:|---:|",
    ]
    for name, d in cumulative:
        text = name if name == "(as run)" else "+ " + QUIRK_TEXT[name]
        L.append(f"| {text} | " + " | ".join(
            _fmt(d[f"{n}.{stat}"]) for n in ("shaking_force", "shaking_moment")
            for stat in ("median", "max")) + " |")
    L += [
        "",
        "The bearing force, bearing moment and input torque of the program cannot be fixed by",
        "switches: the Fischer–Rahman reaction formulas are applied to per-point inertia vectors",
        "about O in mixed frames, with signs meant for m·a fed −m·a (SPEC §7), so the program has",
        "no physical reaction to converge to. screwkit's reactions come from the Newton–Euler",
        "balance of each link with moments about the joint centres, and are checked by the energy",
        "balance above and, in tests/dynamics, by per-link balance.",
        "",
        "## Per angle: shaking force, shaking moment (about O) and input torque",
        "",
        "Input torque: screwkit's T is the torque the drive exerts on the crank about +z1 (power",
        "T·ω > 0 drives the crank; T·ω = dKE/dt is checked above). The seed does not state its",
        f"sign convention; the median difference from Table 5.7 is {err_same:.0%} with T and "
        f"{err_opposite:.0%} with −T: with either sign the curves have different shapes.",
        "",
        "| θ1 (°) | F_sh screwkit | F_sh table 5.3 | F_sh program | M_sh screwkit | M_sh table 5.4 "
        "| M_sh program | T screwkit | T0 table 5.7 | T0 program |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for k, th in enumerate(ANGLES_DEG):
        L.append(
            f"| {th:.0f} | {ours['shaking_force'][k]:.1f} | {tables['shaking_force'][k]:.1f} "
            f"| {as_run['shaking_force'][k]:.1f} | {ours['shaking_moment'][k]:.1f} "
            f"| {tables['shaking_moment'][k]:.1f} | {as_run['shaking_moment'][k]:.1f} "
            f"| {ours['input_torque'][k]:.1f} | {tables['input_torque'][k]:.1f} "
            f"| {as_run['input_torque'][k]:.1f} |"
        )
    L += [
        "",
        "## Per angle: joint reactions (screwkit) and the seed's bearing quantities",
        "",
        "screwkit: magnitude of the force on the moving link at each joint (lbf) and of the moment",
        "about the joint centre (lbf·in; the ball joints carry none). For comparison with the",
        "seed's definitions: |Σ_j f_j| (the seed's \"bearing force\", Table 5.5, is the magnitude",
        "of the vector sum of its four joint forces — not a physical load) and the crank bearing's",
        "moment about O (Table 5.6 takes moments about O and includes the input torque).",
        "",
        "| θ1 (°) | crank F | pin F | ball F | slider F | crank M | slider M | |Σ f_j| "
        "| table 5.5 | crank M about O | table 5.6 |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for k, th in enumerate(ANGLES_DEG):
        L.append(
            f"| {th:.0f} | {ours['crank.force'][k]:.1f} | {ours['pin.force'][k]:.1f} "
            f"| {ours['ball.force'][k]:.1f} | {ours['slider.force'][k]:.1f} "
            f"| {ours['crank.moment'][k]:.1f} | {ours['slider.moment'][k]:.1f} "
            f"| {ours['vector_sum_of_joint_forces'][k]:.1f} | {tables['bearing_force'][k]:.1f} "
            f"| {ours['crank.moment_about_O'][k]:.1f} | {tables['bearing_moment'][k]:.1f} |"
        )
    L += [
        "",
        "## screwkit against the tables",
        "",
        "Median relative difference over 0…350°: shaking force "
        f"{versus['shaking_force']:.0%}, shaking moment {versus['shaking_moment']:.0%}, input",
        f"torque {versus['input_torque']:.0%} (better sign); like-for-like bearing quantities: |Σ f_j| vs 5.5 "
        f"{versus['bearing_force']:.0%}, crank moment about O vs 5.6 {versus['bearing_moment']:.0%}.",
        "These are deviations of the seed (DESIGN validation level 4), not of screwkit:",
        "",
        *ACCOUNT,
        "",
        "Rod spin (item 5), measured: on the exact kinematics with every other bug off, the",
        f"spinning frame alone changes the shaking moment by up to {spin_effect:.0f} lbf·in "
        f"(at {spin_angle:.0f}°).",
        "",
    ]
    return "\n".join(L), checks


ACCOUNT = [
    "1. **Kinematics (SPEC §1.3–1.4).** The program closes its loop by least squares on an",
    "   over-determined, inconsistent system (a two-angle ball joint 3 cannot close the rotation",
    "   loop): s4 is wrong by up to 0.56 in and s̈4 by up to 7.5e4 in/s² (kinematics.md). Feeding",
    "   the exact kinematics into the otherwise unchanged program moves every table by several",
    "   to tens of percent (row \"exact kinematics\" above).",
    "2. **Point-mass pairs without ½ (SPEC §3.2).** Each ± pair acts with m/4 at both points, so",
    "   in every force the crank and rod weigh 7/4 of their mass; the pair moments keep their ½.",
    "   This is the largest single effect on the shaking force.",
    "3. **Slider mass twice (SPEC §3.2).** The slider's force is M3²·s̈4 instead of M3·s̈4",
    "   (M3 = 0.0155 lbf·s²/in), so the slider — the heaviest reciprocating mass — is effectively",
    "   left out of the shaking force and moment.",
    "4. **Frames mixed (SPEC §3.3–3.4).** Crank vectors in frame {2}, rod in {3} and slider in",
    "   {4} are added component by component as if in one frame.",
    "5. **Rod spin.** The rod's point masses move with the slider-side two-angle frame",
    "   Z(θ3)Y(η3)X(90°), which passes near its gimbal point (θ3 ≈ −90°, rod nearly along the",
    "   slider axis; η̇3 reaches ~2500 rad/s at 120°): the off-axis y/z pairs whirl about the",
    "   rod axis and add a spurious moment (measured below).",
    "   screwkit's rod has zero spin; an axisymmetric rod's spin carries no load anyway.",
    "6. **Slider moment (SPEC §3.2).** (0, a4 f_z, a4 f_y) of the previous angle instead of",
    "   P × F. In the as-run program it hardly matters because the slider's force is scaled",
    "   down by M3 (item 3); once the slider mass is right it is the largest remaining error",
    "   of the shaking moment (cumulative table).",
    "7. **Reactions (SPEC §3.5–3.6).** Moments about O instead of the joint centres, formulas",
    "   written for m·a fed −m·a, f2 rotated twice and in place, f3_x(8) stale, t1_x = a1·t1_z",
    "   (torque × length), f4_z left out; the tabulated \"bearing force\" is the magnitude of a",
    "   vector sum of four joint forces and the \"bearing moment\" includes the input torque.",
    "   None of these has a physical counterpart; the table above shows screwkit's per-joint",
    "   loads and the two seed-like combinations, which differ from Tables 5.5/5.6 in size and",
    "   shape.",
    "8. **Input torque (SPEC §3.6).** T0 = Σ x_k t1_z(k) of the reactions above; physically the",
    "   crank adds nothing (it turns at constant speed about a principal axis) and T0 comes from",
    "   the rod and slider. screwkit's T satisfies T·ω = dKE/dt to round-off; the program's",
    "   does not (its 360° value even differs from its 0° value).",
]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="write dynamics.md")
    args = parser.parse_args()
    report, checks = build_report()
    print(report)
    if args.write:
        out = HERE / "dynamics.md"
        out.write_text(report, encoding="utf-8")
        print(f"wrote {out}")
    return 1 if any(not ok for _, ok in checks) else 0


if __name__ == "__main__":
    raise SystemExit(main())

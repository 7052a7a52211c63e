"""Re-run Bagci's synthesis examples 1-9 with `screwkit.synthesis` and compare with the seed.

For each example the spec file examples/bagci_example<k>_synthesis.toml states the seed's
target, design points, design constants, initial guess and assembly mode.  The seed's printed
optimum is evaluated under the same problem (same target, points, mode and limits), then the
problem is solved from the seed's initial guess.  The seed's printed optima are not stationary
points (SPEC / PROGRAMS.md §6), so the test is: ours is a true local optimum (projected gradient
~ 0) and its E is no larger than the seed's.

Examples 8 and 9 (graphical overlay, no numbers printed) are re-done from their spec files
with `screwkit.synthesis.overlay_synthesis.synthesize_overlay`; Example 5 by the overlay with two
dwells (it must be Program C's construction).  Also: the equality-constrained route against the
parameters of constraint (Example 4), and the whole-range check of the printed Example 7
mechanism (it does not assemble for theta0 ~ 299-318 deg).

Usage::

    python validation/bagci1969/synthesis.py           # print the comparison
    python validation/bagci1969/synthesis.py --write   # also write synthesis.md
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
DATA = ROOT / "tests" / "data" / "bagci1969"
EXAMPLES = ROOT / "examples"

from screwkit.io.spec import load_spec  # noqa: E402
from screwkit.io.synthesis_table import overlay_problem_from_spec, problem_from_spec  # noqa: E402
from screwkit.synthesis.equality_constrained import (  # noqa: E402
    RangeConstraint,
    synthesize_equality_constrained,
)
from screwkit.synthesis.overlay import OverlayDwell, ellipse_curvature_radius  # noqa: E402
from screwkit.synthesis.overlay_synthesis import (  # noqa: E402
    OverlayOutcome,
    OverlayProblem,
    synthesize_overlay,
)
from screwkit.synthesis.problem import RSRCSynthesisProblem  # noqa: E402
from screwkit.synthesis.solve import SynthesisResult, evaluate_design, synthesize  # noqa: E402

IN = 0.0254
D = math.radians

#: the table whose printed mechanism is the seed's result of each example
SEED_TABLE = {1: "I", 2: "II", 3: "III", 4: "V", 5: "IX", 6: "XI", 7: "XII"}


def load_table(name: str) -> dict[str, Any]:
    return json.loads((DATA / f"table_{name}.json").read_text())


def load_problem(example: int) -> RSRCSynthesisProblem:
    problem, _ = problem_from_spec(load_spec(EXAMPLES / f"bagci_example{example}_synthesis.toml"))
    return problem


def seed_design(example: int, problem: RSRCSynthesisProblem) -> RSRCSynthesisProblem:
    """The problem started at the seed's printed optimum (in the problem's own unknowns)."""
    meta = load_table(SEED_TABLE[example])
    mech = meta["mechanism_stated"]
    other = meta.get("other_stated", {})
    rec = meta.get("q_reconstruction", {})
    start = dict(problem.start)
    for name in ("d1", "d2", "d3", "a", "b", "e"):
        if mech.get(name) is not None:
            start[name] = float(mech[name]) * IN
    for name in ("delta0", "lambda0", "theta01"):
        start[name] = D(float(mech[f"{name}_deg"]))
    if "d2_used" in rec:  # Table V was computed with d2 = 3.7600 (tables/REPRODUCTION.md)
        start["d2"] = float(rec["d2_used"]) * IN
    for q in ("q1", "q2"):
        if f"{q}_deg" in other:
            start[q] = D(float(other[f"{q}_deg"]))
    if example == 3:
        # the plane case: Program C's theta01 is taken in the construction frame, where eq. 5.13
        # gives q1 = theta01; the printed q1 is that value
        start["theta01"] = D(float(other["q1_deg"]))
    return dataclasses.replace(problem, start=start)


def projected_gradient_ok(result: SynthesisResult) -> bool:
    """A true local optimum: the projected gradient is tiny against 2 |J| |r| (or E ~ 0)."""
    return result.relative_gradient <= 1e-6 or result.objective <= 1e-20


@dataclass(frozen=True)
class Comparison:
    example: int
    ours: SynthesisResult
    seed: SynthesisResult
    seed_stated_rmse_phi_deg: float | None


def compare(example: int) -> Comparison:
    problem = load_problem(example)
    seed = evaluate_design(seed_design(example, problem))
    ours = synthesize(problem)
    meta = load_table(SEED_TABLE[example])
    stated = meta.get("stated_results", {}).get("RMSE_phi_deg")
    if stated is None:
        stated = meta.get("other_stated", {}).get("RMSE_phi_deg")
    return Comparison(example, ours, seed, stated)


def equality_cross_check() -> tuple[SynthesisResult, SynthesisResult]:
    """Example 4: parameters of constraint vs equality-constrained least squares."""
    problem = load_problem(4)
    by_parameters = synthesize(problem)
    start = dict(problem.start)
    derived = problem.parameters(problem.start_vector()[None, :])
    for name in ("d3", "a", "b"):
        start[name] = float(np.real(derived[name][0]))
    unconstrained = dataclasses.replace(problem, construction=None, start=start,
                                        unknowns=("d2", "d3", "a", "b"), inversion=2)
    by_equality = synthesize_equality_constrained(
        unconstrained, dwells=(0.0,), ranges=(RangeConstraint(0.0, D(47.5), D(40.0)),))
    return by_parameters, by_equality


def overlay_problem(example: int) -> OverlayProblem:
    spec = load_spec(EXAMPLES / f"bagci_example{example}_overlay.toml")
    problem, _ = overlay_problem_from_spec(spec)
    return problem


def overlay_examples() -> dict[str, tuple[OverlayProblem, list[OverlayOutcome]]]:
    """Examples 8 (helix, both output senses, four mechanisms) and 9 (x^3/4 with the dwell at
    theta = 0: d2 refined, d2 = 1.96 in as the seed, d2 = the ellipse's curvature radius) from the
    spec files, and Example 5 by the overlay with two dwells (Program C's construction)."""
    out: dict[str, tuple[OverlayProblem, list[OverlayOutcome]]] = {}
    p8 = overlay_problem(8)
    out["8"] = (p8, synthesize_overlay(p8))
    p9 = overlay_problem(9)
    out["9 (d2 refined)"] = (p9, synthesize_overlay(p9))
    fixed = dataclasses.replace(p9, refine_d2=False)
    out["9 (d2 = 1.96 in, the seed's)"] = (fixed, synthesize_overlay(fixed))
    rho = float(ellipse_curvature_radius(p9.d1, p9.lambda0, p9.theta01))
    curv = dataclasses.replace(fixed, d2=rho)
    out["9 (d2 = curvature radius)"] = (curv, synthesize_overlay(curv))
    p5 = load_problem(5)
    two = OverlayProblem(p5.target, d1=2 * IN, d2=9.886017 * IN, lambda0=D(60), theta01=D(90),
                         dwells=(OverlayDwell(0.0, "exterior"), OverlayDwell(D(240), "interior")))
    out["5 (two dwells, Table IX's d2)"] = (two, synthesize_overlay(two))
    return out


def _overlay_lines() -> list[str]:
    lines = ["| case | mechanism | sense | d2 | d3 | a | b | max circle miss | RMSE_phi (deg) | "
             "max dev (deg) | RMSE_S (in) | min \\|sin chi0\\| | whole range |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for label, (_, outcomes) in overlay_examples().items():
        for k, o in enumerate(outcomes):
            r = o.result
            dm = r.dimensions
            name = str(k + 1)
            if label == "8":  # the seed's naming: A, B counter-clockwise, C, D clockwise
                same = [x for x in outcomes if x.output_direction == o.output_direction]
                name = ("AB" if o.output_direction > 0 else "CD")[same.index(o)]
            lines.append(
                f"| {label} | {name} | {'ccw' if o.output_direction > 0 else 'cw'} | "
                f"{dm['d2'] / IN:.5g} | {dm['d3'] / IN:.5g} | {dm['a'] / IN:.5g} | "
                f"{dm['b'] / IN:.5g} | {o.max_circle_miss / IN:.3g} | "
                f"{math.degrees(r.rmse_phi):.4g} | {math.degrees(abs(r.max_dev_phi)):.4g} | "
                f"{r.rmse_S / IN:.4g} | {r.range_check.min_transmission:.3f} | "
                f"{'ok' if r.range_check.ok else 'NO'} |")
    return lines


def _dims_text(dims: dict[str, float]) -> str:
    parts = []
    for k, v in dims.items():
        if k in ("d1", "d2", "d3", "a", "b", "e"):
            parts.append(f"{k}={v / IN:.6g}")
        else:
            parts.append(f"{k}={math.degrees(v):.6g}°")
    return ", ".join(parts)


def report() -> str:
    lines = ["# Bagci 1969 synthesis examples — screwkit.synthesis vs the seed", "",
             "Generated by `python validation/bagci1969/synthesis.py --write`. Lengths in inches,",
             "angles in degrees; E = E_phi [rad²] + E_S / (1 in)² (Bagci's \"screw of unit",
             "radius\"). \"seed\" = the seed's printed mechanism evaluated on the same problem",
             "(target, design points, mode, limits); \"ours\" = solved from the seed's initial",
             "guess (examples/bagci_example<k>_synthesis.toml). |g| = norm of the projected",
             "gradient of E at our result relative to 2|J||r| (a local optimum has |g| ≈ 0;",
             "bounds that are active are excluded).", "",
             "| Ex. | E seed | E ours | RMSE_phi seed / ours (deg) | RMSE_S seed / ours (in) | "
             "iterations | time (s) | \\|g\\| | status | whole range (ours) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    details = []
    for k in range(1, 8):
        c = compare(k)
        o, s = c.ours, c.seed
        lines.append(
            f"| {k} | {s.objective:.6g} | {o.objective:.6g} | {math.degrees(s.rmse_phi):.5g} / "
            f"{math.degrees(o.rmse_phi):.5g} | {s.rmse_S / IN:.5g} / {o.rmse_S / IN:.5g} | "
            f"{o.iterations} | {o.time:.3f} | {o.relative_gradient:.1e} | {o.status} | "
            f"{'ok' if o.range_check.ok else 'NO'} |")
        details += [f"### Example {k}", "",
                    f"- seed (printed): {_dims_text(s.dimensions)}",
                    f"  - whole-range check: {s.range_check.message}",
                    f"- ours: {_dims_text(o.dimensions)}",
                    f"  - whole-range check: {o.range_check.message}"]
        if c.seed_stated_rmse_phi_deg is not None:
            details.append(f"- the seed states (RMSE)_phi = {c.seed_stated_rmse_phi_deg}°")
        details.append("")
    p, e = equality_cross_check()
    lines += ["", "## Two routes to a constrained design (Example 4)", "",
              "Dwell at theta = 0 and exact range 40° at theta = 47.5°, d2 <= 3.76 in:", "",
              f"- parameters of constraint (eqs. 5.13-5.21, unknowns d2, q2): E = "
              f"{p.objective:.12g}; {_dims_text(p.dimensions)}",
              f"- equality-constrained least squares (SLSQP, unknowns d2, d3, a, b): E = "
              f"{e.objective:.12g}; {_dims_text(e.dimensions)}",
              f"- largest difference in d3, a, b: "
              f"{max(abs(p.dimensions[n] - e.dimensions[n]) for n in ('d3', 'a', 'b')) / IN:.2e} in",
              ""]
    lines += ["## Overlay technique (Examples 8 and 9)", "",
              "No numbers are printed in the seed (Figs. 25, 26). The overlay fit puts one output",
              "circle through the family of coupler circles (`screwkit.synthesis.overlay`); each",
              "circle's mechanism is re-analysed with the closed form on one branch",
              "(`overlay_synthesis.synthesize_overlay`, spec files examples/bagci_example{8,9}_overlay.toml).",
              "Lengths in inches; the RMSEs are those of the analysed mechanism.", ""]
    lines += _overlay_lines()
    lines += ["", "## Notes and deviations", "",
              "- Examples 1, 2: without limits the optimum runs away (a, d3 -> infinity, E -> 0),",
              "  as Bagci warns. The spec files use Program B's own safeguards as bounds",
              "  (|a|, |b| <= 30 in, |e| <= 10 in); our optima sit on a = 30 in (Ex. 2 also on",
              "  e = -10 in) with the gradient of the free unknowns ~ 0. Program B's dS/dx uses",
              "  +sqrt(d2^2 - W1^2) for d2 sin(chi0), wrong in Example 2 (sin chi0 < 0): one",
              "  reason its printed optimum is not stationary. The seed's stated E_phi, E_S of both",
              "  examples are reproduced from its printed dimensions (tests).",
              "- Examples 3, 4: d2 -> infinity at the unconstrained optimum (Bagci says so for",
              "  Ex. 4); d2 is bounded by the seed's printed value (Ex. 4: 3.76 in, the value",
              "  Table V was computed with), so ours is the best mechanism no larger than the seed's.",
              "- Example 5: the seed gives no start for d2; 8 in is used. The target is Table IX",
              "  column 4 (row 18's theta0 corrected 225 -> 255).",
              "- Example 6: the target is x^3/4 at all 9 points of the text; Table XI lists 8 (theta",
              "  = 15 deg is missing). The seed's mechanism misses theta = 15 deg by 5.1 deg, hence",
              "  2.11 deg here against its stated 0.635 deg. q2 follows eq. 5.13 (49.70092 deg, not",
              "  the printed 49.70775). d1, d2 are both free and only the rotation is fitted, so",
              "  the overall size is free (a null direction of E).",
              "- Example 7: q1 follows eq. 5.13 at theta01 (the printed q1 differs by 1.5e-4 deg).",
              "  The printed mechanism (d3 rebuilt) leaves its branch for theta0 ~ 299-318 deg; ours",
              "  runs the whole turn.",
              "- Example 8: d1 = 10 / 1.224745 = 8.16497 in (the seed prints 8.162). dS = -10 in",
              "  needs theta0 to run 45 -> -45 deg (the seed's straight part of the sine), so",
              "  theta01 = 45 deg with a clockwise input (theta01 = 135 deg counter-clockwise is its",
              "  mirror image). With d2 = d1 the overlay has exactly two sensible circles per output",
              "  sense, each pair mirror images across the ellipse's major axis (b -> -b): A, B",
              "  (counter-clockwise) and C, D (clockwise), the seed's count. The best circle fits",
              "  with the centre on the major axis (b = 0: d3 = 6.19 in ccw, 9.14 in cw) are",
              "  rejected: the overlay point at theta0 = 0 sits at a dead centre and the analysed",
              "  mechanism does not reach it (the old report's \"one design point out of reach\").",
              "  The translation is the sine, not fitted: RMSE_S = 0.139 in against the straight",
              "  helix, the same for every mechanism.",
              "- Example 9: the seed puts theta01 = 210 deg at x = 0 (theta = 0, the inflection),",
              "  so the design points are theta = -60..60 deg; the old script took theta = 0..120",
              "  deg from theta01 = 210 deg (its 4.4 deg RMSE). The overlay point at theta = 0 is",
              "  on the inward normal (q1 = 49.107 deg by eq. 5.13; the seed prints 49.06). The",
              "  ellipse's radius of curvature there is 1.7363 in; Bagci's hand-picked d2 = 1.96",
              "  in is close to the d2 that minimises the circle misses (1.9365 in, refined), and",
              "  d2 = 1.7363 in (exact second-order dwell) costs RMSE 2.18 deg against 1.89 deg.",
              "- Example 5 by the overlay with two dwells (rotation limits at theta0 = 90 deg,",
              "  exterior, and 330 deg, interior) and Table IX's d2 gives Program C's d3, a, b",
              "  (eqs. 5.19-5.21) and the table's own max deviation 1.0935 deg and RMSE 0.3813 deg",
              "  (the printed RMSE 0.255711 deg does not follow from the table).", ""]
    lines += ["## Details", ""] + details
    return "\n".join(lines) + "\n"


def overlay_failures() -> list[str]:
    """The overlay checks: Example 8 gives two mechanisms per sense that run the whole range;
    Example 9's best runs the whole range; Example 5 by two dwells is Table IX's construction."""
    bad = []
    results = overlay_examples()
    _, o8 = results["8"]
    if sorted(o.output_direction for o in o8) != [-1, -1, 1, 1] or not all(
            o.result.range_check.ok for o in o8):
        bad.append("Example 8: expected mechanisms A-D that run the whole range")
    _, o9 = results["9 (d2 refined)"]
    if not o9[0].result.range_check.ok:
        bad.append("Example 9: the best overlay mechanism does not run the whole range")
    _, o5 = results["5 (two dwells, Table IX's d2)"]
    expect = load_table("IX")["q_reconstruction"]["gives"]
    for name in ("d3", "a", "b"):
        if abs(o5[0].result.dimensions[name] / IN - expect[name]) > 2e-6:
            bad.append(f"Example 5 by two dwells: {name} differs from Table IX's construction")
    return bad


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="write synthesis.md")
    args = parser.parse_args(argv)
    text = report()
    sys.stdout.write(text)
    if args.write:
        (HERE / "synthesis.md").write_text(text, encoding="utf-8")
    failures = overlay_failures()
    for f in failures:
        sys.stderr.write(f"CHECK FAILED: {f}\n")
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())

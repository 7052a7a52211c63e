"""Speed of screwkit.synthesis (issue #7 targets).

* Bagci's Example 1 from the seed's initial guess to the optimum (8 unknowns, 18 residuals, the
  exact Jacobian of `ResidualModel`): target <= 0.2 s.
* The same problem with scipy ``least_squares`` and 2-point finite-difference Jacobians on the
  same residuals, bounds and tolerances: ours should be >= 10x faster.
* A 100-start global run (`synthesize_multistart`, Example 1, every assembly mode): the time.
* The overlay technique from the spec files of Examples 8 (both output senses, 4 mechanisms)
  and 9 (a dwell, d2 refined), circle fits plus the closed-form re-analysis: target <= 0.5 s
  each (`screwkit demo` runs them).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import least_squares

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "bagci_example1_synthesis.toml"
OVERLAY = Path(__file__).resolve().parents[1] / "examples" / "bagci_example{}_overlay.toml"


def _problem() -> Any:
    from screwkit.io.spec import load_spec
    from screwkit.io.synthesis_table import problem_from_spec

    problem, _ = problem_from_spec(load_spec(EXAMPLE))
    return problem


def _best(fn: Any, repeat: int = 5) -> tuple[float, Any]:
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return float(best), out


def _finite_difference_run(problem: Any) -> tuple[float, int]:
    """scipy least_squares, jac='2-point', same residuals / bounds / tolerances / x_scale."""
    from screwkit.synthesis.residuals import NotAssembled, ResidualModel

    model = ResidualModel(problem)
    x0 = problem.start_vector()
    big = 1e3 * (1.0 + float(np.max(np.abs(model.evaluate(x0).residuals))))

    def fun(x: np.ndarray) -> np.ndarray:
        try:
            return model.evaluate(x, jacobian=False, remember=False).residuals
        except (NotAssembled, ValueError):
            return np.full(model.n_residuals, big)

    sol = least_squares(fun, x0, jac="2-point", bounds=problem.bound_vectors(), method="trf",
                        x_scale="jac", max_nfev=20000, gtol=1e-14, xtol=1e-15, ftol=1e-15)
    return float(np.sum(sol.fun**2)), int(sol.nfev)


def run() -> list[dict[str, Any]]:
    from screwkit.synthesis.solve import synthesize, synthesize_multistart

    problem = _problem()
    t_exact, result = _best(lambda: synthesize(problem))
    t_fd, (e_fd, nfev_fd) = _best(lambda: _finite_difference_run(problem), repeat=2)
    t0 = time.perf_counter()
    runs = synthesize_multistart(problem, n_starts=100, seed=0, keep=3, time_limit=600.0)
    t_multi = time.perf_counter() - t0
    rows = []
    for example in (8, 9):
        from screwkit.io.spec import load_spec
        from screwkit.io.synthesis_table import overlay_problem_from_spec
        from screwkit.synthesis.overlay_synthesis import synthesize_overlay

        overlay, _ = overlay_problem_from_spec(load_spec(str(OVERLAY).format(example)))
        t_ov, outcomes = _best(lambda p=overlay: synthesize_overlay(p), repeat=3)
        best = outcomes[0].result
        rows.append({"name": f"overlay Example {example} (spec file)", "value": t_ov, "unit": "s",
                     "target": "<= 0.5 s",
                     "note": f"{len(outcomes)} mechanism(s), best RMSE_phi "
                             f"{np.degrees(best.rmse_phi):.4g} deg, {best.evaluations} "
                             "circle-fit evaluations"})
    return rows + [
        {"name": "synthesis Example 1 (exact Jacobian)", "value": t_exact, "unit": "s",
         "target": "<= 0.2 s",
         "note": f"E = {result.objective:.4g}, {result.iterations} iterations, "
                 f"{result.evaluations} evaluations, {result.status}"},
        {"name": "synthesis Example 1 (scipy, finite differences)", "value": t_fd, "unit": "s",
         "target": ">= 10x slower than exact",
         "note": f"E = {e_fd:.4g}, {nfev_fd} residual calls (+ 8 per Jacobian); speed-up "
                 f"{t_fd / t_exact:.1f}x"},
        {"name": "synthesis 100-start global run (Example 1)", "value": t_multi, "unit": "s",
         "target": "report",
         "note": f"best E = {runs[0].objective:.4g}; {len(runs)} distinct kept"},
    ]


if __name__ == "__main__":
    for row in run():
        print(f"{row['name']}: {row['value']:.3g} {row['unit']} (target {row['target']}) "
              f"{row['note']}")

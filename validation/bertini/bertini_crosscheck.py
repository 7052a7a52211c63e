"""Every assembly mode against Bertini 2: the same closure polynomials solved by screwkit's own
homotopy (``screwkit.algebraic``, a parameter homotopy from stored start solutions) and by
Bertini 2 (Bates, Hauenstein, Sommese, Wampler; the ``bertini2`` wheel, GPL-3, only in the
optional ``crosscheck`` extra, never a dependency of screwkit) from its own total-degree start
with adaptive precision.

Bertini sees only the polynomials in the unknowns at the instance's parameters (the coefficients
of every monomial, ``PolynomialSystem.coefficients_at``): its start system, path tracking,
endgame and precision are its own. The check is that both find the same finite solutions, one to
one, and the same real ones:

* 6-6 Stewart–Gough platforms in Study coordinates (40 generic poses; 128 total-degree paths);
* 6R loops in their joint-axis directions (16 generic assemblies).

Run: ``python validation/bertini/bertini_crosscheck.py`` (prints a Markdown table).
"""

from __future__ import annotations

import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.algebraic.solve import StartSolutions, solve_all
from screwkit.kinematics.modes.loop6r import loop6r_start, loop6r_system, random_loop6r
from screwkit.kinematics.modes.stewart import random_stewart, stewart_start, stewart_system

#: a solution is real when its imaginary part is below this fraction of its size
REAL_TOL = 1e-8


def bertini_system(system: PolynomialSystem, p: np.ndarray) -> Any:
    """``system`` at the parameters ``p`` (k,) as a Bertini ``System``: one function per
    equation, the sum of coefficient × monomial over its distinct monomials in the unknowns."""
    import bertini  # type: ignore[import-not-found]

    eqs, exps, coef = system.coefficients_at(p)
    names = [bertini.Variable(n) for n in system.variables]
    out = bertini.System()
    out.add_variable_group(bertini.VariableGroup(names))
    for e in range(system.size):
        f = None
        for g in np.flatnonzero(eqs == e):
            c = complex(coef[0, g])
            if c == 0:
                continue
            term = bertini.complex_mp(repr(c.real), repr(c.imag))
            for i, k in enumerate(exps[g]):
                if k:
                    term = term * (names[i] ** int(k) if k > 1 else names[i])
            f = term if f is None else f + term
        out.add_function(f)
    return out


def bertini_solutions(system: PolynomialSystem, p: np.ndarray, seed: int = 1) -> np.ndarray:
    """Bertini's finite solutions (m, n) of ``system`` at ``p``: total-degree start, adaptive
    precision, its default endgame; records go to a temporary folder."""
    import bertini

    with tempfile.TemporaryDirectory() as folder:
        result = bertini.solve(bertini_system(system, p), seed=seed, directory=folder,
                               show_progress=False)
        return np.array([np.asarray(s, dtype=complex) for s in result.solutions])


@dataclass(frozen=True)
class Comparison:
    """One instance: solutions found by each, real ones, and the largest distance from a
    solution of one solver to the nearest of the other's (relative to its size, ∞-norm)."""

    family: str
    ours: int
    theirs: int
    ours_real: int
    theirs_real: int
    mismatch: float
    seconds_ours: float
    seconds_theirs: float

    @property
    def agree(self) -> bool:
        return (self.ours == self.theirs and self.ours_real == self.theirs_real
                and self.mismatch < 1e-7)


def _real_count(x: np.ndarray) -> int:
    size = np.maximum(1.0, np.abs(x).max(axis=1))
    return int(np.sum(np.abs(x.imag).max(axis=1) <= REAL_TOL * size))


def _mismatch(a: np.ndarray, b: np.ndarray) -> float:
    if len(a) == 0 or len(b) == 0:
        return 0.0 if len(a) == len(b) else float("inf")
    scale = np.maximum(1.0, np.maximum(np.abs(a).max(1)[:, None], np.abs(b).max(1)[None, :]))
    d = np.abs(a[:, None, :] - b[None, :, :]).max(-1) / scale
    return float(max(d.min(1).max(), d.min(0).max()))


def compare(family: str, system: PolynomialSystem, start: StartSolutions, p: np.ndarray,
            seed: int = 1) -> Comparison:
    """Solve ``system`` at ``p`` (k,) both ways and compare."""
    t0 = time.perf_counter()
    ours = solve_all(system, p, start)
    t1 = time.perf_counter()
    theirs = bertini_solutions(system, p, seed)
    t2 = time.perf_counter()
    x = ours.of(0)
    return Comparison(family, len(x), len(theirs), _real_count(x), _real_count(theirs),
                      _mismatch(x, theirs), t1 - t0, t2 - t1)


#: the families checked: name, system, its start solutions, random real instances
FAMILIES: dict[str, tuple[Callable[[], PolynomialSystem], Callable[[], StartSolutions],
                          Callable[[np.random.Generator, int], tuple[Any, Any]]]] = {
    "Stewart–Gough 6-6": (stewart_system, stewart_start, random_stewart),
    "6R loop": (loop6r_system, loop6r_start, random_loop6r),
}


#: instances per family: Bertini's 1,024 total-degree paths of a 6R loop take about a minute
#: each in adaptive precision, its 128 paths of a Stewart platform a quarter of a second
INSTANCES = {"Stewart–Gough 6-6": 10, "6R loop": 2}


def run(seed: int = 2026) -> list[Comparison]:
    rng = np.random.default_rng(seed)
    rows = []
    for name, (make, start, draw) in FAMILIES.items():
        system, s, n = make(), start(), INSTANCES[name]
        p, _ = draw(rng, n)
        rows += [compare(name, system, s, p[i].real.astype(complex)) for i in range(n)]
    return rows


def main() -> int:
    try:
        import bertini  # noqa: F401
    except ImportError:
        print("Bertini 2 is not installed: pip install -e '.[crosscheck]' (GPL-3, optional)")
        return 1
    rows = run()
    print("# Every mode: screwkit's homotopy against Bertini 2\n")
    print("| family | found (screwkit / Bertini) | real (screwkit / Bertini) | largest mismatch "
          "| screwkit s | Bertini s |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r.family} | {r.ours} / {r.theirs} | {r.ours_real} / {r.theirs_real} | "
              f"{r.mismatch:.1e} | {r.seconds_ours:.3f} | {r.seconds_theirs:.3f} |")
    bad = [r for r in rows if not r.agree]
    print(f"\n{len(rows) - len(bad)} of {len(rows)} instances agree (same solutions one to one, "
          "same real ones, mismatch < 1e-7).")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

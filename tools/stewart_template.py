"""Make the Stewart–Gough elimination template (src/screwkit/kinematics/modes/
stewart_template_data.py) once, offline: ``PYTHONPATH=src python tools/stewart_template.py
[OUT]`` (a few CPU minutes; OUT, when given, instead of the package's file).

At a random complex instance whose 40 solutions the parameter homotopy gives, it builds the
Macaulay matrix of modes/stewart_template.py's docstring (the y-linear six times the monomials
of degree ≤ 4 with at most one y, leg 0 times those in ξ only), checks that its null space on
the monomials of degree ≤ 6 with at most one y is spanned by the 40 solutions' monomial vectors
(Telen, Mourrain & Van Barel 2018), picks the basis B (1 and the seven unknowns, then the
lowest-degree monomials that raise the rank of the null space's rows: a truncated normal form),
R = ξ1·B ∖ B, and drops rows greedily (in chunks, bisected) as long as the rows still
determine R in terms of B after eliminating the other monomials E: rank [M_E M_R] =
rank M_E + |R| (Kukelova, Bujnak & Pajdla 2008, "Automatic generator of minimal problem
solvers", ECCV; Larsson, Åström & Oskarsson 2017). A column basis of M_E is kept (the others are
combinations of it at a generic instance), and the rows are then exactly as many as the kept
columns: the template is square; of the bases pivoted QR gives at a few random instances, the
one whose square matrix has the smallest largest block in its block triangular form.
"""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import numpy as np
import scipy.linalg as sla
from scipy.sparse import csr_matrix

from screwkit.algebraic.solve import solve_all
from screwkit.kinematics.modes.stewart import random_stewart, stewart_start, stewart_system
from screwkit.kinematics.modes.stewart_template import (
    UNKNOWNS,
    block_triangular,
    chart,
    coefficients,
    monomials,
)

DEGREE = 6
OUT = Path(__file__).resolve().parents[1] / "src/screwkit/kinematics/modes/stewart_template_data.py"


def ydeg(e: tuple[int, ...]) -> int:
    return sum(e[3:])


def pair_exponents() -> list[tuple[int, ...]]:
    out = []
    for i in range(8):
        for k in range(i, 8):
            e = [0] * UNKNOWNS
            for v in (i, k):
                if v > 0:
                    e[v - 1] += 1
            out.append(tuple(e))
    return out


def macaulay(coef: np.ndarray, mults: list[tuple[int, int]], mono: list[tuple[int, ...]]
             ) -> np.ndarray:
    where = {e: i for i, e in enumerate(mono)}
    pairs = pair_exponents()
    M = np.zeros((len(mults), len(mono)), dtype=coef.dtype)
    for r, (eq, mult) in enumerate(mults):
        for t, e in enumerate(pairs):
            if coef[eq, t] != 0:
                M[r, where[tuple(a + b for a, b in zip(e, mono[mult], strict=True))]] += coef[eq, t]
    return M


def rank(A: np.ndarray) -> int:
    if A.size == 0:
        return 0
    d = np.abs(np.diag(sla.qr(A, mode="r", pivoting=True, check_finite=False)[0]))
    return int((d > d[0] * 1e-10).sum())


def main() -> None:
    mono = monomials(DEGREE)
    mults = [(eq, i) for i, m in enumerate(monomials(DEGREE - 2))
             for eq in range(7) if ydeg(m) <= (0 if eq == 6 else 1)]
    # the 40 solutions of a random complex instance (the homotopy), in the chart
    p, _ = random_stewart(np.random.default_rng(2026), 1, True)
    sol = solve_all(stewart_system(), p[0], stewart_start())
    if sol.found[0] != 40:
        sys.exit(f"the homotopy found {sol.found[0]} solutions, not 40")
    w = np.linalg.solve(chart(), sol.x.T).T[:, 1:]
    M = macaulay(coefficients(p)[0], mults, mono)
    values = np.prod(w[:, None, :] ** np.array(mono)[None], axis=2)
    assert np.abs(M @ values.T).max() < 1e-6 * np.abs(M).max() * np.abs(values).max()
    _, s, vh = np.linalg.svd(M)
    null = vh[int((s > s[0] * 1e-10).sum()):].conj().T
    low = [i for i, e in enumerate(mono) if ydeg(e) <= 1]
    if np.linalg.matrix_rank(null[low], 1e-8) != 40:
        sys.exit("the null space on the monomials with at most one y is not the 40 solutions'")
    unit = [tuple(int(j == k) for j in range(UNKNOWNS)) for k in range(-1, UNKNOWNS)]
    order = unit + sorted((e for e in mono if sum(e) < DEGREE and ydeg(e) <= 1
                           and e not in unit), key=lambda e: (sum(e), ydeg(e), e))
    where = {e: i for i, e in enumerate(mono)}
    basis: list[tuple[int, ...]] = []
    Qb = np.zeros((null.shape[1], 0), dtype=complex)
    for e in order:
        v = null[where[e]].conj()
        r = v - Qb @ (Qb.conj().T @ v)
        if np.linalg.norm(r) > 1e-6 * np.linalg.norm(v):
            basis.append(e)
            Qb = np.column_stack([Qb, r / np.linalg.norm(r)])
        if len(basis) == 40:
            break
    action = 0
    up = [tuple(a + (j == action) for j, a in enumerate(e)) for e in basis]
    R = [e for e in up if e not in basis]
    Bi = np.array([where[e] for e in basis])
    Ri = np.array([where[e] for e in R])
    # prune at a random real instance (the pattern is generic)
    q, _ = random_stewart(np.random.default_rng(7), 1)
    Mr = macaulay(coefficients(q.real)[0], mults, mono)
    NZ = Mr != 0
    keep_col = np.zeros(len(mono), dtype=bool)
    keep_col[Bi] = keep_col[Ri] = True

    def e_cols(rows: list[int]) -> np.ndarray:
        return np.flatnonzero(NZ[rows].any(0) & ~keep_col)

    def determines(rows: list[int]) -> bool:
        ME = Mr[rows][:, e_cols(rows)]
        return rank(np.column_stack([ME, Mr[rows][:, Ri]])) == rank(ME) + len(Ri)

    def singletons(rows: list[int]) -> list[int]:
        while True:  # a row alone in one of its E columns only determines that column
            single = (NZ[rows].sum(0) == 1) & ~keep_col
            if not single.any():
                return rows
            drop = set(np.flatnonzero(NZ[rows][:, single].any(1)))
            rows = [r for i, r in enumerate(rows) if i not in drop]

    def prune(rows: list[int], chunk: list[int]) -> list[int]:
        chunk = [c for c in chunk if c in set(rows)]
        if not chunk:
            return rows
        cand = singletons([r for r in rows if r not in set(chunk)])
        if determines(cand):
            return cand
        if len(chunk) == 1:
            return rows
        return prune(prune(rows, chunk[:len(chunk) // 2]), chunk[len(chunk) // 2:])

    rows = singletons(list(range(len(mults))))
    assert determines(rows)
    by_degree = sorted(rows, key=lambda r: (-sum(mono[mults[r][1]]), -ydeg(mono[mults[r][1]]),
                                            mults[r][0]))
    for i in range(0, len(by_degree), 24):
        rows = prune(rows, by_degree[i:i + 24])
        print(f"{i}: {len(rows)} rows", flush=True)
    Ec = e_cols(rows)
    kept = rank(Mr[rows][:, Ec])
    # a column basis of M_E by pivoted QR at a few random instances: the one whose square
    # matrix splits into the smallest blocks (block triangular form) is kept
    best: tuple[int, list[int]] | None = None
    for seed in range(24):
        q, _ = random_stewart(np.random.default_rng(100 + seed), 1)
        Mq = macaulay(coefficients(q.real)[0], mults, mono)
        piv = sla.qr(Mq[rows][:, Ec], mode="economic", pivoting=True)[2]
        cand = list(np.asarray(Ec)[np.sort(piv[:kept])]) + list(Ri)
        largest = max(len(r) for r, _ in block_triangular(csr_matrix(Mr[rows][:, cand] != 0)))
        print(f"column basis {seed}: largest block {largest}", flush=True)
        if best is None or largest < best[0]:
            best = (largest, cand)
    assert best is not None
    square = best[1]
    if len(square) != len(rows):
        sys.exit(f"{len(rows)} rows for {len(square)} columns: not square")
    write(rows=[v for r in rows for v in mults[r]], square=square, kept=kept,
          basis=list(Bi), action=action, out=Path(sys.argv[1]) if len(sys.argv) > 1 else OUT)


def write(rows: list[int], square: list[int], kept: int, basis: list[int], action: int,
          out: Path = OUT) -> None:
    def block(name: str, values: list[int]) -> str:
        text = " ".join(str(int(v)) for v in values)
        lines = textwrap.wrap(text, 92)
        body = "\n".join(f'    "{line} "' for line in lines)
        return f"{name} = tuple(int(v) for v in (\n{body}\n).split())\n"

    out.write_text(
        '"""The Stewart–Gough elimination template of modes/stewart_template.py, made by\n'
        "tools/stewart_template.py (do not edit): monomials are numbered as\n"
        ":func:`.stewart_template.monomials` numbers them.\n\n"
        "``ROWS``: per template row, its equation (0 the Study quadric, 1..5 legs 1..5 minus leg 0,\n"
        "6 leg 0) and its multiplier; ``SQUARE``: the columns of the square matrix, the ``KEPT``\n"
        "E monomials then R = ξ1·B ∖ B; ``BASIS``: B; ``ACTION``: the unknown whose action matrix\n"
        'is formed (0: ξ1)."""\n\n'
        f"DEGREE = {DEGREE}\nACTION = {action}\nKEPT = {kept}\n"
        + block("ROWS", rows) + block("SQUARE", square) + block("BASIS", basis))


if __name__ == "__main__":
    main()

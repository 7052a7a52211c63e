"""Stewart–Gough forward kinematics by an elimination template: all 40 poses from one linear
solve and a 40 × 40 eigenproblem per instance (issue 27).

The system is modes/stewart.py's (Husty 1996: the Study quadric and six leg quadrics in the
Study coordinates (x; y) on the patch r·x = 1), written in the affine chart x = P·(1, ξ),
ξ ∈ C³ (P's first column r/‖r‖², the others an orthonormal basis of r⊥), with the unknowns
w = (ξ1, ξ2, ξ3, y0, …, y3). Subtracting leg 0 from legs 1..5 cancels 4 y·y, so the Study
quadric and these five differences are linear in y (Husty 1996, §3), and leg 0 is the only
equation with y·y. A Macaulay matrix of these seven quadrics times monomials (the y-linear six
times the monomials of degree ≤ 4 with at most one y, leg 0 times those in ξ only: degree ≤ 6,
at most two y's) has the 40 solutions' monomial vectors in its null space, and on the
monomials of degree ≤ 6 with at most one y it has no other null vectors (Telen, Mourrain &
Van Barel 2018, "Solving polynomial systems via truncated normal forms", SIAM J. Matrix Anal.
Appl. 39(3), checked numerically when the template was made). Its rows that matter were kept
by tools/stewart_template.py (Kukelova et al. 2008's automatic generator, pruned greedily;
the indices are in :mod:`.stewart_template_data`): a square matrix [M_E M_R] (526 × 526) over
the other monomials E and the monomials R = ξ1·B ∖ B, times the values at the 40 basis
monomials B on the right, so that one solve gives every R in terms of B. The action matrix of
ξ1 on B (a row of the identity where ξ1·b is in B, a row of that solve where it is in R) has
the 40 values of ξ1 as its eigenvalues and the basis monomials' values as its eigenvectors
(Stetter 2004, *Numerical Polynomial Algebra*, ch. 2; Cox, Little & O'Shea, *Using Algebraic
Geometry*, ch. 2 §4); B contains 1 and the seven unknowns, which are read off them.

Dropped E columns are combinations of the kept ones at a generic instance: only the column
space of M_E takes part in the elimination, so they change nothing.

The square matrix is solved in its block triangular form (:func:`block_triangular`: blocks of
6, 1, 313 and 206), each block's matrix and its coupling to earlier blocks filled on its own
(:func:`_plan`). Only the rows of R enter the action matrix, and the last block is read by no
later block and holds one of them: it is solved for that row alone, as the row of its inverse
times the right-hand side (one transposed solve of its LU with one right-hand side, not 40;
Golub & Van Loan 2013, *Matrix Computations*, §3.2). That is the LAPACK route; a whole
group of :data:`.stewart_sparse.GROUP` real instances takes the sparse route instead
(:mod:`.stewart_sparse`: one pivot sequence for every instance, the group side by side in
vector operations, ~2.3× less CPU per instance in a batch; its rejects go to the LAPACK route),
and a lone instance, a short group or a complex one the LAPACK route (``route`` of
:func:`template_solve` takes one of the two alone: modes/stewart_solve.py's passes).
So an instance's raw points alone and in a batch can differ (two pivotings); after the polish
they agree to ~1e-10 (relative). A batch's chunks are spread over the
cores in threads (LAPACK releases the GIL; BLAS's own threads held at one meanwhile, by
threadpoolctl); each instance's arithmetic is the same on either. The points are unpolished;
modes/stewart_solve.py polishes, certifies and falls back to the homotopy.
"""

from __future__ import annotations

import itertools
import os
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import lapack

from screwkit.algebraic import hessenberg_eig
from screwkit.algebraic.blas import blas_controller
from screwkit.algebraic.polynomial import Complex
from screwkit.errors import InputError
from screwkit.kinematics.modes import stewart_sparse
from screwkit.kinematics.modes import stewart_template_data as data
from screwkit.kinematics.modes.stewart import PATCH, quaternion_product, rotation_numerator

Index = NDArray[np.intp]
#: affine unknowns w = (ξ1, ξ2, ξ3, y0, y1, y2, y3)
UNKNOWNS = 7
#: instances eliminated together: one group of the sparse route (:mod:`.stewart_sparse`); the
#: LAPACK route's solves are one by one, so its chunk size matters little
CHUNK = stewart_sparse.GROUP
#: how :func:`template_solve` eliminates: the sparse route where it applies and the LAPACK
#: route elsewhere, the sparse route alone, the LAPACK route alone
EITHER, SPARSE, LAPACK = ROUTES = ("either", "sparse", "lapack")
#: threads over the chunks of a batch: the cores this process may use
THREADS = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def monomials(degree: int) -> list[tuple[int, ...]]:
    """The exponents of the monomials in the 7 affine unknowns of degree ≤ ``degree``,
    graded, each degree in the order of itertools.combinations_with_replacement: the
    numbering of :mod:`.stewart_template_data`."""
    out = []
    for d in range(degree + 1):
        for combo in itertools.combinations_with_replacement(range(UNKNOWNS), d):
            e = [0] * UNKNOWNS
            for k in combo:
                e[k] += 1
            out.append(tuple(e))
    return out


@lru_cache(maxsize=8)
def chart(label: int = 0) -> NDArray[np.float64]:
    """T (8, 8): the Study coordinates z = T·(1, w), x = P·(1, ξ) on the patch r·x = 1
    (module docstring), y = y; label 0 on the system's patch (r = modes/stewart.py's), the
    others on random real patches (a pose with r·x ≈ 0 is far out in one chart, ill-conditioned
    there, and near the middle of another)."""
    r = PATCH if label == 0 else np.random.default_rng(label).normal(size=4)
    q, _ = np.linalg.qr(np.column_stack([r, np.eye(4)[:, :3]]))
    T = np.eye(8)
    T[:4, 0] = r / (r @ r)
    T[:4, 1:4] = q[:, 1:4]
    return T


@lru_cache(maxsize=1)
def _forms() -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The constant tensors of the leg quadrics: G[r, k, l] and H[r, k, l], the coefficients
    of x_k y_l in vec(x̄ y)_r and vec(y x̄)_r; S[k, l] the symmetric bilinear form of R'(x)
    (3 × 3 each)."""
    E = np.eye(4)

    def conj(q: list) -> list:
        return [q[0], -q[1], -q[2], -q[3]]

    G, H, S = np.zeros((3, 4, 4)), np.zeros((3, 4, 4)), np.zeros((4, 4, 3, 3))
    for k in range(4):
        for m in range(4):
            G[:, k, m] = quaternion_product(conj(list(E[k])), list(E[m]))[1:]
            H[:, k, m] = quaternion_product(list(E[m]), conj(list(E[k])))[1:]
            both = np.array(rotation_numerator(list(E[k] + E[m])), dtype=float)
            S[k, m] = (both - np.array(rotation_numerator(list(E[k])), dtype=float)
                       - np.array(rotation_numerator(list(E[m])), dtype=float)) / 2
            if k == m:
                S[k, m] = np.array(rotation_numerator(list(E[k])), dtype=float)
    return G, H, S


def quadric_forms() -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """G, H and S of :func:`quadrics` (the constant tensors of the leg quadrics), for its
    compiled twin (modes/stewart_kernels.py)."""
    return _forms()


def quadrics(params: Complex, absolute: bool = False) -> Complex:
    """The symmetric matrices (B, 7, 8, 8) of modes/stewart.py's Study quadric and six leg
    quadrics (its module docstring) at the parameter rows (B, 42): zᵀ Q z is the equation.
    ``absolute``: the same sums with every product replaced by its modulus (|A|, |B|, |L²| and
    the forms' |entries|, every − a +), so that |z|ᵀ Q |z| is Σ|terms| of the expanded
    equation (the rounding scale of the α-test, algebraic/certify.py)."""
    G, H, S = _forms()
    sign = 1.0
    if absolute:
        params, G, H, S, sign = np.abs(params).astype(complex), abs(G), abs(H), abs(S), -1.0
    A = params[:, :18].reshape(-1, 6, 3)
    Bp = params[:, 18:36].reshape(-1, 6, 3)
    c = np.sum(A * A, -1) + np.sum(Bp * Bp, -1) - sign * params[:, 36:]
    Q = np.zeros((len(params), 7, 8, 8), dtype=params.dtype)
    Q[:, 0, :4, 4:] = Q[:, 0, 4:, :4] = 0.5 * np.eye(4)
    # Σ_rs A_ir S_klrs B_is and Σ_r (B_ir G_rkl − A_ir H_rkl) as matrix products
    AB = (A[..., :, None] * Bp[..., None, :]).reshape(-1, 6, 9)
    Q[:, 1:, :4, :4] = c[..., None, None] * np.eye(4) - sign * 2 * (
        AB @ S.reshape(16, 9).T).reshape(-1, 6, 4, 4)
    Q[:, 1:, 4:, 4:] = 4 * np.eye(4)
    xy = 2 * (Bp @ G.reshape(3, 16) - sign * A @ H.reshape(3, 16)).reshape(-1, 6, 4, 4)
    Q[:, 1:, :4, 4:] = xy
    Q[:, 1:, 4:, :4] = np.swapaxes(xy, -1, -2)
    return Q


@lru_cache(maxsize=1)
def _layout() -> dict[str, Any]:
    """Where each coefficient goes (module docstring): for each template row and each of the
    36 products w_i w_k (i ≤ k, w_0 = 1) of its equation, the flat index into the square
    matrix or into the right-hand side (-1: nowhere, a dropped E column), and the source of
    each; the basis positions of the action matrix's rows."""
    mono = monomials(data.DEGREE)
    rows = np.asarray(data.ROWS, dtype=np.intp).reshape(-1, 2)
    square = [mono[i] for i in data.SQUARE]
    basis = [mono[i] for i in data.BASIS]
    n = len(square)
    col_sq = {e: c for c, e in enumerate(square)}
    col_b = {e: c for c, e in enumerate(basis)}
    pairs = [(i, k) for i in range(8) for k in range(i, 8)]

    def exponent(i: int, k: int) -> tuple[int, ...]:
        e = [0] * UNKNOWNS
        for v in (i, k):
            if v > 0:
                e[v - 1] += 1
        return tuple(e)

    sq_dst, sq_src, b_dst, b_src = [], [], [], []
    for r, (eq, mult) in enumerate(rows):
        m = mono[mult]
        for t, (i, k) in enumerate(pairs):
            e = tuple(a + b for a, b in zip(exponent(i, k), m, strict=True))
            if e in col_sq:
                sq_dst.append(r * n + col_sq[e])
                sq_src.append(eq * len(pairs) + t)
            elif e in col_b:
                b_dst.append(r * len(basis) + col_b[e])
                b_src.append(eq * len(pairs) + t)
    g = data.ACTION
    action = np.empty(len(basis), dtype=np.intp)  # ≥ 0: a basis column; < 0: −1 − R row
    r_of = {e: c for c, e in enumerate(square[data.KEPT:])}
    for i, e in enumerate(basis):
        ge = tuple(a + (j == g) for j, a in enumerate(e))
        action[i] = col_b[ge] if ge in col_b else -1 - r_of[ge]
    unit = np.array([col_b[tuple(int(j == k) for j in range(UNKNOWNS))]
                     for k in range(-1, UNKNOWNS)], dtype=np.intp)  # 1, then the unknowns
    blocks = _blocks(n, np.array(sq_dst), np.array(sq_src))
    # rows and columns renumbered block by block, so that each block is a contiguous slice
    new_row, new_col = np.empty(n, dtype=np.intp), np.empty(n, dtype=np.intp)
    new_row[np.concatenate([r for r, _ in blocks])] = np.arange(n)
    new_col[np.concatenate([c for _, c in blocks])] = np.arange(n)
    row, col = np.divmod(np.array(sq_dst), n)
    brow, bcol = np.divmod(np.array(b_dst), len(basis))
    bounds = np.cumsum([0] + [len(r) for r, _ in blocks])
    return {"bounds": bounds, "sq_dst": new_row[row] * n + new_col[col],
            "sq_src": np.array(sq_src), "b_dst": new_row[brow] * len(basis) + bcol,
            "b_src": np.array(b_src), "action": action, "unit": unit,
            "r_pos": new_col[data.KEPT:]}


def layout() -> dict[str, Any]:
    """Where each coefficient of the template goes (flat indices into the square matrix and
    the right-hand side, rows and columns renumbered block by block), the block bounds, the
    action matrix's rows and R's columns (``r_pos``): for :mod:`.stewart_sparse`."""
    return _layout()


def _blocks(n: int, dst: Index, src: Index) -> list[tuple[Index, Index]]:
    """:func:`block_triangular` of the square matrix, its pattern read at a random instance (a
    structural zero, such as y·y in the differences, is exactly zero there)."""
    from scipy.sparse import csr_matrix

    rng = np.random.default_rng(0)
    c = coefficients(rng.normal(size=(1, 42)).astype(complex)).reshape(-1)
    nz = c[src] != 0
    return block_triangular(csr_matrix((np.ones(int(nz.sum())), divmod(dst[nz], n)),
                                       shape=(n, n)))


def block_triangular(pattern: Any) -> list[tuple[Index, Index]]:
    """The block triangular form of a square sparsity pattern (scipy CSR; Duff & Reid 1978,
    "An implementation of Tarjan's algorithm for the block triangularization of a matrix",
    ACM TOMS 4(2)): its rows matched to columns (a structural transversal), the strongly
    connected components of the matched graph, in the order they can be solved (every
    block's rows touch only its own columns and those of blocks before it), as (rows,
    columns) per block. The template's 526 unknowns fall into blocks of 313, 206, 6 and 1,
    so its solve costs about a quarter of one dense LU."""
    from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching

    n = pattern.shape[0]
    match = maximum_bipartite_matching(pattern, perm_type="column")  # row i ↔ column match[i]
    if (match < 0).any():
        raise RuntimeError("the Stewart template is structurally singular")
    graph = pattern[:, match]  # row i → row j when row i touches row j's matched column
    count, label = connected_components(graph, directed=True, connection="strong")
    # a block is solved after every block it touches: a depth-first order of the condensation
    coo = graph.tocoo()
    after: list[set[int]] = [set() for _ in range(count)]
    for i, j in zip(label[coo.row], label[coo.col], strict=True):
        if i != j:
            after[i].add(int(j))
    order: list[int] = []
    seen = np.zeros(count, dtype=bool)

    def visit(k: int) -> None:
        seen[k] = True
        for j in after[k]:
            if not seen[j]:
                visit(j)
        order.append(k)

    for k in range(count):
        if not seen[k]:
            visit(k)
    assert sum(int((label == k).sum()) for k in order) == n
    return [(np.flatnonzero(label == k), match[label == k]) for k in order]


def coefficients(params: Complex, label: int = 0) -> Complex:
    """The coefficients (B, 7, 36) of the template's equations at the products w_i w_k
    (i ≤ k, w_0 = 1) in the chart ``label``: the Study quadric, legs 1..5 minus leg 0 (free of
    y·y), leg 0."""
    T = chart(label)
    i, k = np.triu_indices(8)  # the products w_i w_k, i ≤ k, in the layout's order
    Q = T.T @ quadrics(params) @ T  # T_ai Q_ab T_bk
    c = Q[:, :, i, k] * np.where(i == k, 1.0, 2.0)
    out = np.empty_like(c)
    out[:, 0] = c[:, 0]
    out[:, 1:6] = c[:, 2:7] - c[:, 1:2]
    out[:, 6] = c[:, 1]
    return out


def template_solve(params: Complex, label: int = 0, threads: int | None = None,
                   route: str = EITHER) -> tuple[Complex, Complex]:
    """The 40 points (B, 40, 8) of the instances (B, 42) in Study coordinates on the patch,
    unpolished, eliminated in the chart ``label``, and their ξ1 (B, 40): the action matrix's
    eigenvalues (for real parameters the template and the action matrix are real, so the
    points come in exact conjugate pairs with conjugate ξ1 and the real ones have real ξ1).
    An instance whose template is singular or not finite gets NaN points. A batch of more
    than one chunk is split into :data:`THREADS` contiguous parts eliminated side by side
    (LAPACK and the sparse kernel release the GIL); each instance's arithmetic is the same
    either way. It is the same as alone, but for the instances in whole groups of real ones
    (the sparse route, module docstring); a real instance's is real in a batch with complex
    ones too. ``threads`` caps the threads (1: all on the calling thread, for a batch
    already split among threads by the caller). ``route`` (:data:`ROUTES`): the sparse route
    for whole groups of real instances and the LAPACK route for the others (``"either"``),
    the sparse route alone (``"sparse"``: the others, and the sparse route's growth-check
    rejects, get NaN points, for a caller that tries the LAPACK route next), or the LAPACK
    route alone (``"lapack"``)."""
    if route not in ROUTES:
        raise InputError(f"template_solve: route must be one of {ROUTES}, not {route!r}")
    B = len(params)
    m = len(data.BASIS)
    points = np.full((B, m, 8), np.nan, dtype=complex)
    keys = np.full((B, m), np.nan, dtype=complex)

    real = np.all(params.imag == 0, axis=1)

    def part(lo: int, hi: int) -> None:
        work: dict[str, Any] = {}
        with np.errstate(all="ignore"):
            for s in range(lo, hi, CHUNK):
                # a chunk's real and complex instances apart: a real instance is eliminated
                # in real arithmetic (exact conjugate pairs) whatever its batch holds
                for mine in (real[s:s + CHUNK], ~real[s:s + CHUNK]):
                    rows = s + np.flatnonzero(mine[:hi - s])
                    if len(rows):
                        points[rows], keys[rows] = _chunk(params[rows], label, work, route)

    threads = min(THREADS if threads is None else threads, -(-B // CHUNK))
    # BLAS's own threads held at one: with a batch in threads, else each part's LAPACK calls
    # start threads of their own on the same cores (56 against 1.8 ms per instance in a batch
    # of 1,000 by the LAPACK route, 2.8 against 1.8 by the sparse route, OPENBLAS_NUM_THREADS
    # unset; 2 cores, load ~3); alone too, so that the arithmetic (a threaded LU sums in
    # another order) is the same whatever the threads
    fewest = stewart_sparse.GROUP if route == EITHER else stewart_sparse.FEWEST
    if stewart_sparse.AVAILABLE and route != LAPACK and real.sum() >= fewest:
        stewart_sparse.prepare()
    if hessenberg_eig.AVAILABLE and real.any():
        hessenberg_eig.prepare()
    with blas_controller().limit(limits=1, user_api="blas"):
        if threads <= 1:
            part(0, B)
            return points, keys
        # parts of whole chunks, as even as they come
        cuts = [CHUNK * (-(-B // CHUNK) * t // threads) for t in range(threads)] + [B]
        with ThreadPoolExecutor(threads) as pool:
            for f in [pool.submit(part, a, b)
                      for a, b in zip(cuts[:-1], cuts[1:], strict=True)]:
                f.result()
    return points, keys


def _chunk(p: Complex, label: int, work: dict[str, Any], route: str = EITHER
           ) -> tuple[Complex, Complex]:
    """:func:`template_solve` of a few instances: the action matrices, their eigenproblem
    and the points read off the eigenvectors (a real action matrix's by
    :func:`.hessenberg_eig.eig_rows`: the eigenvalues and the 8 rows read, 0.22 against
    0.28–0.29 ms per matrix by numpy's eig; a complex one's by numpy's eig)."""
    lay = _layout()
    m = len(data.BASIS)
    Am, good = action_matrices(p, label, work, route)
    if not good.any():  # (the sparse route alone on instances it does not take)
        return np.full((len(p), m, 8), np.nan, dtype=complex), np.full((len(p), m), np.nan,
                                                                       dtype=complex)
    if Am.dtype == np.float64 and hessenberg_eig.AVAILABLE:
        # eigenvalues, and the eigenvectors at the 8 rows read (1 and the unknowns) alone
        vals, vecs, fine = hessenberg_eig.eig_rows(Am, lay["unit"])
        good &= fine
        w = vecs[:, 1:, :] / vecs[:, :1, :]  # (b, 7, 40)
    else:
        vals, vecs = np.linalg.eig(Am)
        w = vecs[:, lay["unit"][1:], :] / vecs[:, lay["unit"][:1], :]
    one = np.ones((len(p), 1, m))
    z = np.einsum("ij,bjm->bmi", chart(label), np.concatenate([one, w], axis=1))
    z /= (z[..., :4] @ PATCH)[..., None]  # on the system's patch
    return np.where(good[:, None, None], z, np.nan), np.where(good[:, None], vals, np.nan)


def action_matrices(p: Complex, label: int = 0, work: dict[str, Any] | None = None,
                    route: str = EITHER) -> tuple[Any, NDArray[np.bool_]]:
    """The action matrices of ξ1 (B, 40, 40) of the instances p (B, 42) in the chart
    ``label`` (module docstring; real for real parameters), by the sparse route or the
    block-triangular solve of :func:`_plan` (``route``: :func:`template_solve`), and whether
    each is finite (an instance whose template is singular or not finite, or not taken by the
    sparse route alone, gets the identity, marked False). ``work`` keeps one thread's
    zero-filled arrays from call to call: every call writes the same (structurally nonzero)
    entries of them, and LAPACK's solves do not overwrite them."""
    work = {} if work is None else work
    lay = _layout()
    real = bool(np.all(p.imag == 0))
    m = len(data.BASIS)
    c: Any = coefficients(p, label).reshape(len(p), -1)
    c = c.real if real else c
    good: NDArray[np.bool_] = np.asarray(np.isfinite(c).all(axis=1), dtype=bool)
    # a whole group of real instances: the sparse route (a group, padded to whole, costs about
    # what the LAPACK route costs per instance, so a lone instance stays with LAPACK); the
    # sparse route alone (a retry pass, whose instances are few) from FEWEST instances
    fewest = stewart_sparse.GROUP if route == EITHER else stewart_sparse.FEWEST
    sparse = real and stewart_sparse.AVAILABLE and len(p) >= fewest
    if route == SPARSE and not sparse:
        return np.broadcast_to(np.eye(m), (len(p), m, m)), np.zeros(len(p), dtype=bool)
    if sparse and route != LAPACK:
        R, fine = stewart_sparse.r_rows(np.where(good[:, None], c, 0.0), work)
        redo = np.flatnonzero(good & ~fine)  # the growth check's rejects: by LAPACK
        if route == SPARSE:
            good &= fine
        elif len(redo):
            some = good[redo]
            R[redo] = _r_by_blocks(c[redo], some, work)
            good[redo] = some
    else:
        R = _r_by_blocks(c, good, work)
    act = lay["action"]
    Am: Any = np.zeros((len(p), m, m), dtype=R.dtype)
    inside = np.flatnonzero(act >= 0)
    Am[:, inside, act[inside]] = 1.0
    Am[:, act < 0] = R[:, -1 - act[act < 0]]
    good &= np.isfinite(Am).all(axis=(1, 2))
    if not good.all():
        Am[~good] = np.eye(m)
    return Am, good


def _r_by_blocks(c: Any, good: NDArray[np.bool_], work: dict[str, Any]) -> Any:
    """X_R (B, 29, 40) of the template coefficients c (B, 252), real or complex, by the
    block-triangular solve of :func:`_plan` with LAPACK's LU (partial pivoting within each
    block); an instance whose blocks are singular is cleared in ``good``."""
    dtype = c.dtype.type
    n, m = len(data.SQUARE), len(data.BASIS)
    X: Any = np.empty((len(c), n, m), dtype=dtype)  # rows no R reads stay unset

    def zeros(name: str, i: int, shape: tuple[int, int]) -> Any:
        key = f"{name}{i}{dtype.__name__}{len(c)}"
        if key not in work:
            work[key] = np.zeros((len(c), shape[0] * shape[1]), dtype=dtype)
        return work[key]

    for i, blk in enumerate(_plan()):
        a, b, k = blk["start"], blk["stop"], blk["stop"] - blk["start"]
        S: Any = zeros("S", i, (k, k))
        S[:, blk["diag_dst"]] = c[:, blk["diag_src"]]
        S = S.reshape(-1, k, k)
        if not good.all():
            S = S.copy()
            S[~good] = np.eye(k)
        rhs: Any = zeros("rhs", i, (k, m))
        rhs[:, blk["rhs_dst"]] = -c[:, blk["rhs_src"]]
        rhs = rhs.reshape(-1, k, m)
        used = blk["used"]
        below: Any = None
        if len(used):
            below = zeros("below", i, (k, len(used)))
            below[:, blk["below_dst"]] = c[:, blk["below_src"]]
            below = below.reshape(-1, k, len(used))
        want = blk["want"]
        if want is None:  # every row: later blocks read this one
            known = rhs if below is None else rhs - below @ X[:, used]
            X[:, a:b] = _solve(S, known, good)
            continue
        # only the rows ``want`` (R monomials, read by no later block): the rows of S⁻¹ they
        # take, Z = S⁻ᵀ E, then X_want = Zᵀ (rhs − below · X_used)
        Zt = np.swapaxes(_transposed_solve(S, np.eye(k, dtype=dtype)[:, want], good), -1, -2)
        rows = Zt @ rhs
        if below is not None:
            rows = rows - (Zt @ below) @ X[:, used]
        X[:, a + want] = rows
    return X[:, _layout()["r_pos"]]


@lru_cache(maxsize=1)
def _plan() -> list[dict[str, Any]]:
    """The block-triangular solve of the template (:func:`_layout`), block by block: where
    each coefficient goes in the block's diagonal matrix (k × k), in its coupling to the
    columns of earlier blocks it touches (``used``; k × |used|) and in its right-hand side
    (k × 40), as flat indices (``*_dst``) and their sources in the coefficients (``*_src``);
    ``want``: the rows needed when no later block reads this one (only the R monomials in
    it), else None (every row). Only X_R enters the action matrix, so such a block is solved
    for those rows alone: one transposed solve with |want| right-hand sides instead of 40,
    and no coupling product with 40 columns (the last block, 206 × 206, holds one R row)."""
    lay = _layout()
    n, m = len(data.SQUARE), len(data.BASIS)
    row, col = np.divmod(lay["sq_dst"], n)
    brow, bcol = np.divmod(lay["b_dst"], m)
    src, bsrc = lay["sq_src"], lay["b_src"]
    bounds = lay["bounds"]
    r_pos = np.asarray(lay["r_pos"])
    plan: list[dict[str, Any]] = []
    read = np.zeros(n, dtype=bool)  # columns read by a later block
    for a, b in reversed(list(zip(bounds[:-1], bounds[1:], strict=True))):
        k = b - a
        mine = (row >= a) & (row < b)
        # (a row's entries in the columns of later blocks are structural zeros: _blocks)
        diag, low = mine & (col >= a) & (col < b), mine & (col < a)
        used = np.unique(col[low])
        rhs = (brow >= a) & (brow < b)
        want = np.sort(r_pos[(r_pos >= a) & (r_pos < b)]) - a
        plan.append({
            "start": int(a), "stop": int(b),
            "diag_dst": (row[diag] - a) * k + col[diag] - a, "diag_src": src[diag],
            "below_dst": (row[low] - a) * len(used) + np.searchsorted(used, col[low]),
            "below_src": src[low], "used": used,
            "rhs_dst": (brow[rhs] - a) * m + bcol[rhs], "rhs_src": bsrc[rhs],
            "want": None if read[a:b].any() or len(want) >= min(k, m) else want})
        read[used] = True
    return plan[::-1]


def _solve(S: Any, rhs: Any, good: NDArray[np.bool_]) -> Any:
    """S⁻¹·rhs for the stacked systems; one exactly singular system (LAPACK raises for the
    whole stack) is solved alone and left NaN (``good`` cleared)."""
    try:
        return np.linalg.solve(S, rhs)
    except np.linalg.LinAlgError:
        out = np.full(rhs.shape, np.nan, dtype=rhs.dtype)
        for b in range(len(S)):
            try:
                out[b] = np.linalg.solve(S[b], rhs[b])
            except np.linalg.LinAlgError:
                good[b] = False
        return out


def _transposed_solve(S: Any, rhs: Any, good: NDArray[np.bool_]) -> Any:
    """S⁻ᵀ·rhs for the stacked systems S (B, k, k) and one right-hand side (k, q): LAPACK's
    LU of S with partial pivoting (getrf, the factorization np.linalg.solve makes of S) and
    the transposed triangular solves (getrs, 'T'). An exactly singular or not finite system
    is left NaN (``good`` cleared)."""
    getrf, getrs = lapack.get_lapack_funcs(("getrf", "getrs"), (S,))
    out = np.full((len(S),) + rhs.shape, np.nan, dtype=S.dtype)
    for b in range(len(S)):
        if not good[b]:
            continue
        lu, piv, info = getrf(S[b])
        if info == 0:
            out[b], info = getrs(lu, piv, rhs, trans=1)
        good[b] &= info == 0
    return out

"""Rank-tolerant solves of the constrained equations ``M u' = f + G^T lam``, ``G u' = gamma``
(``kernels.constrained``); the projection's minimum-norm steps are in ``kernels.min_norm``.

Outside runs the rank is decided by a rank-revealing (column-pivoted) QR of ``Y = L^-1 G^T``
(``constrained_solve``, ``kernels.rank_qr``) and the multipliers are the minimum-norm ones.  A run knows its
rank (decided at every projected step) and solves on rows: the complement ``S = Y^T Y``
factored by Cholesky with complete pivoting stopped at that rank (``_pivoted_solve``), or,
cheaper, on the rows the last projection chose (``_chosen_rows_solve``); ``u'`` is the
same (it is unique), the multipliers a basic solution.  A mass matrix that is only
semi-definite takes the augmented system by least squares (``augmented_solve``).
"""
import numpy as np
from numba import njit

from .rank_qr import add_back_solved, pivoted_back, qr_solve, work_size
from .views import UNCOUNTED, c_view
from .internal import internal

#: pivots of the column-pivoted QR of ``Y = L^-1 G^T`` (which follow its singular values)
#: below this fraction of the first are taken as zero (redundant constraints, or a
#: singular configuration)
RANK_TOLERANCE = 1e-9
#: during a run, a singular value of ``Y`` below this fraction of the largest is dropped
#: although the mechanism's rank counts it: the configuration is (nearly) singular, where
#: the stages of a step, off the manifold, would divide a residual by its square; the
#: motion then follows its inertia along that direction for the step, and the projection
#: puts it back on the constraints (a smooth passage, docs/constraints.md)
PASSAGE_TOLERANCE = 1e-6
#: ``info`` (``compiled.layout.constraints``): rank, conditioning, the rank a run holds (-1:
#: none), the lowest rank and conditioning a run met; then, from ``ROWS``, how many rows
#: the last pivoted factorisation of a projection chose (-1: none yet), those rows (``m``
#: slots), and last the conditioning of that factorisation (``chosen_conditioning``)
ROWS = 5


def solve_work(nu, m):
    """Floats of scratch ``constrained_solve`` takes (``m`` rows, ``nu`` free speeds)."""
    return max(work_size(nu, m), nu * m + m * m + 4 * m + nu)


@internal(**UNCOUNTED)
def constrained_solve(M, L, ud, G, gamma, lam, info, work):
    """``ud`` (holding ``M^-1 f`` on entry, ``L`` the Cholesky factor of ``M``) corrected
    to the constrained accelerations; ``lam`` the minimum-norm multipliers.  ``info[0]``:
    the rank of ``G``, ``info[1]``: the last pivot kept over the first, which follows the
    smallest singular value kept over the largest (how far from a singular configuration).
    During a run (its rank known) the rows' solves below; else ``rank_qr.qr_solve``.
    ``work``: ``solve_work`` floats of scratch (no allocation, no reference counting: an
    evaluation's kernels pass the model's scratch, free once ``M`` and ``f`` are made)."""
    m = G.shape[0]
    if m == 0:
        info[0], info[1] = 0.0, 1.0
        return
    keep = info[2]               # during a run: the rank at the last projected state
    if keep >= 0:
        _pivoted_solve(L, ud, G, gamma, lam, info, int(keep), work)
        return
    qr_solve(L, ud, G, gamma, lam, info, RANK_TOLERANCE, work)


@internal(forceinline=True, **UNCOUNTED)
def _add_correction(L, ud, Y, lam, z, m):
    """``ud += M^-1 G^T lam = L^-T (Y lam)`` over the first ``m`` columns of ``Y`` (``z``:
    nu floats of scratch)."""
    nu = Y.shape[0]
    for i in range(nu):
        acc = 0.0
        for j in range(m):
            acc += Y[i, j] * lam[j]
        z[i] = acc
    add_back_solved(L, z, ud)


@internal(forceinline=True, **UNCOUNTED)
def _pivoted_cholesky(A, keep, perm):
    """``A`` (symmetric, positive semi-definite) factored in place by Cholesky with
    complete pivoting: at most ``keep`` pivots, none below ``PASSAGE_TOLERANCE^2`` of the
    first (a nearly singular direction).  ``perm`` the chosen order (row numbers, as floats:
    it lives in a float scratch); returns the number
    of pivots, the rank used."""
    m = A.shape[0]
    for j in range(m):
        perm[j] = j
    rank = 0
    first = 0.0
    for k in range(min(keep, m)):
        p = k
        for j in range(k + 1, m):
            if A[j, j] > A[p, p]:
                p = j
        if k == 0:
            first = A[p, p]
        if first <= 0.0 or not (A[p, p] > PASSAGE_TOLERANCE * PASSAGE_TOLERANCE * first):
            break
        if p != k:                                  # symmetric swap of rows and columns
            for j in range(m):
                A[k, j], A[p, j] = A[p, j], A[k, j]
            for j in range(m):
                A[j, k], A[j, p] = A[j, p], A[j, k]
            perm[k], perm[p] = perm[p], perm[k]
        A[k, k] = np.sqrt(A[k, k])
        for i in range(k + 1, m):
            A[i, k] /= A[k, k]
        for j in range(k + 1, m):
            for i in range(j, m):
                A[i, j] -= A[i, k] * A[j, k]
            for i in range(j + 1, m):
                A[j, i] = A[i, j]
        rank += 1
    return rank


@internal(**UNCOUNTED)
def _pivoted_solve(L, ud, G, gamma, lam, info, keep, work):
    """The constrained ``ud`` during a run, whose rank ``keep`` is known: ``S = Y^T Y``
    (``L Y = G^T``) factored by Cholesky with complete pivoting (``_pivoted_cholesky``),
    and the multipliers of the rows it chose solved for, the others zero.  The rows left
    out are combinations of the rows kept, so ``u'`` is the same as by the SVD (it is
    unique); ``lam`` is a basic solution, not the minimum-norm one (reactions are computed
    by ``constrained_solve`` outside runs).  An SVD costs more than a small tree's whole
    evaluation; this, a fraction of it.  ``work``: ``nu m + m^2 + 4 m + nu`` floats; no
    allocation, no reference counting."""
    m, nu = G.shape[0], G.shape[1]
    Y, A = c_view(work, 0, (nu, m)), c_view(work, nu * m, (m, m))
    at = nu * m + m * m
    res, perm, x, z = (c_view(work, at, (m,)), c_view(work, at + m, (m,)),
                       c_view(work, at + 2 * m, (m,)), c_view(work, at + 3 * m, (nu,)))
    if keep > 0 and info[ROWS] == keep and _chosen_rows_solve(L, ud, G, gamma, lam, info,
                                                              keep, Y, A, res, x, z):
        return
    for j in range(m):
        perm[j] = j
    first = _schur_rows(L, ud, G, gamma, perm, m, Y, A, res)
    rank = _pivoted_cholesky(A, keep, perm)
    pivoted_back(A, perm, rank, res, lam, x)
    _add_correction(L, ud, Y, lam, z, m)
    info[0] = rank
    info[1] = A[rank - 1, rank - 1] / np.sqrt(first) if rank and first > 0 else 1.0


@internal(**UNCOUNTED)
def chosen_solve(L, ud, G, gamma, lam, info, work):
    """A run's constrained ``ud`` (holding ``M^-1 f``) on the rows its last projection
    chose (``_chosen_rows_solve``), when it has chosen as many as the rank it holds.
    Returns False, having changed nothing but ``work``, when there are no such rows or
    they are no longer independent enough (then the caller evaluates every row and
    pivots: ``constrained_solve``)."""
    keep = int(info[2])
    if keep <= 0 or info[ROWS] != keep:
        return False
    m, nu = G.shape[0], G.shape[1]
    Y, A = c_view(work, 0, (nu, keep)), c_view(work, nu * keep, (keep, keep))
    at = nu * keep + keep * keep
    res, x, z = (c_view(work, at, (m,)), c_view(work, at + m, (keep,)),
                 c_view(work, at + m + keep, (nu,)))
    return _chosen_rows_solve(L, ud, G, gamma, lam, info, keep, Y, A, res, x, z)


@internal(forceinline=True, **UNCOUNTED)
def _schur_rows(L, ud, G, gamma, rows, r, Y, A, res):
    """For the rows ``rows[:r]`` (row numbers, as floats): the residual ``res = gamma -
    G ud`` at those rows, ``Y = L^-1 G_r^T`` and ``A = Y^T Y`` (both triangles), the Schur
    complement ``G_r M^-1 G_r^T``.  Returns ``A``'s largest diagonal entry."""
    nu = G.shape[1]
    for j in range(r):
        i = int(rows[j])
        s = gamma[i]
        for k in range(nu):
            s -= G[i, k] * ud[k]
        res[i] = s
    for j in range(r):                              # L Y = G_r^T, column by column
        row = int(rows[j])
        for i in range(nu):
            s = G[row, i]
            for k in range(i):
                s -= L[i, k] * Y[k, j]
            Y[i, j] = s / L[i, i]
    first = 0.0
    for i in range(r):
        for j in range(i + 1):
            acc = 0.0
            for k in range(nu):
                acc += Y[k, i] * Y[k, j]
            A[i, j] = acc
            A[j, i] = acc
        first = max(first, A[i, i])
    return first


@internal(forceinline=True, **UNCOUNTED)
def _chosen_rows_solve(L, ud, G, gamma, lam, info, r, Y, A, res, x, z):
    """``_pivoted_solve`` on the ``r`` rows the last projection's factorisation chose
    (``info[ROWS + 1:]``): the same ``u'`` (those rows span the others while the rank
    holds), ``S`` of size ``r`` instead of ``m`` and no pivoting.  Returns False, having
    changed nothing, when a pivot falls below ``PASSAGE_TOLERANCE^2`` of the largest
    diagonal entry (the rows no longer independent enough: the caller pivots again)."""
    rows = info[ROWS + 1:ROWS + 1 + r]
    first = _schur_rows(L, ud, G, gamma, rows, r, Y, A, res)
    for k in range(r):                              # Cholesky, lower triangle
        d = A[k, k]
        for j in range(k):
            d -= A[k, j] * A[k, j]
        if not d > PASSAGE_TOLERANCE * PASSAGE_TOLERANCE * first:
            return False
        A[k, k] = np.sqrt(d)
        for i in range(k + 1, r):
            s = A[i, k]
            for j in range(k):
                s -= A[i, j] * A[k, j]
            A[i, k] = s / A[k, k]
    pivoted_back(A, rows, r, res, lam, x)          # the rows' multipliers, 0 elsewhere
    _add_correction(L, ud, Y, x, z, r)
    info[0] = r
    info[1] = A[r - 1, r - 1] / np.sqrt(first) if first > 0 else 1.0
    return True


@internal(cache=True, _nrt=True)   # allocates: counted even under an uncounted caller
def augmented_solve(M, f, G, gamma, ud, lam, info):
    """The same equations as one least-squares system ``[[M, G^T], [G, 0]] [u', -lam] =
    [f, gamma]`` (minimum norm): for a mass matrix that is only semi-definite.  Returns
    False when ``u'`` is not determined (the constrained mass matrix is singular)."""
    m, nu = G.shape[0], G.shape[1]
    K = np.zeros((nu + m, nu + m))
    rhs = np.zeros(nu + m)
    for i in range(nu):
        for k in range(nu):
            K[i, k] = M[i, k]
        rhs[i] = 0.0
    for j in range(m):
        for i in range(nu):
            K[nu + j, i] = G[j, i]
            K[i, nu + j] = G[j, i]
        rhs[nu + j] = gamma[j]
    x, _, rank, sv = np.linalg.lstsq(K, np.concatenate((ud, rhs[nu:])), RANK_TOLERANCE)
    # rank of [M; G] decides whether u' is unique: u' has nu unknowns
    MG = np.zeros((nu + m, nu))
    for i in range(nu):
        for k in range(nu):
            MG[i, k] = M[i, k]
    for j in range(m):
        for k in range(nu):
            MG[nu + j, k] = G[j, k]
    svm = np.linalg.svd(MG)[1]
    ok = True
    if nu and svm.shape[0] and svm[nu - 1] <= RANK_TOLERANCE * svm[0]:
        ok = False
    for i in range(nu):
        ud[i] = x[i]
    for j in range(m):
        lam[j] = -x[nu + j]
    info[0] = np.linalg.matrix_rank(G, RANK_TOLERANCE * max(1.0, np.abs(G).max())) if m else 0
    info[1] = 1.0
    return ok



@internal(cache=True, _nrt=True)   # allocates: counted even under an uncounted caller
def rank_of(G):
    """``(rank, conditioning)``: the singular values of ``G`` above ``RANK_TOLERANCE`` of
    the largest, and the smallest of them over the largest."""
    if G.shape[0] == 0 or G.shape[1] == 0:
        return 0, 1.0
    sv = np.linalg.svd(G)[1]
    if sv[0] <= 0.0:
        return 0, 1.0
    rank = 0
    for k in range(sv.shape[0]):
        if sv[k] > RANK_TOLERANCE * sv[0]:
            rank += 1
    return rank, sv[rank - 1] / sv[0]



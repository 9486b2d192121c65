"""The projection's minimum-norm steps: ``du`` with ``G du = rhs`` of least norm, which
puts a closed mechanism's positions and speeds back on its constraints
(``kernels.constrained``, docs/constraints.md).  During a run the rank is known, and the
step is taken on that many independent rows of ``G``: the rows the last pivoted
factorisation chose while they stay well conditioned, else chosen again.
"""
import numpy as np
from numba import njit

from .loop_solve import RANK_TOLERANCE, ROWS, _pivoted_cholesky
from .rank_qr import pivoted_back
from .views import CACHED, UNCOUNTED, c_view
from .internal import internal

#: a projection's minimum-norm steps reuse the rows the last pivoted factorisation chose
#: while their conditioning stays above this fraction of what it was then; below it (the
#: mechanism moved where other rows are stronger, or towards a singular configuration)
#: the rows are chosen again
CHOSEN_DECAY = 0.5


def min_norm_work(m):
    """Floats of scratch ``min_norm_step`` takes (``m`` rows)."""
    return m * m + 3 * m


@njit(_nrt=True, **CACHED)   # allocates: counted under any caller
def min_norm_step(G, rhs, keep, du, info, work):
    """``du``: the minimum-norm solution of ``G du = rhs`` -- during a run (``keep`` >= 0,
    the rank it holds) by ``G_r^T (G_r G_r^T)^-1 rhs_r`` on ``r`` independent rows ``G_r``:
    the rows the last pivoted factorisation chose while they stay well conditioned
    (``_min_norm_chosen``), else chosen again by a Cholesky of ``G G^T`` with complete
    pivoting (``_min_norm_pivoted``, which records them in ``info[ROWS:]`` for the
    projections and evaluations that follow); the other rows are combinations of these, so
    the step is the same.  By least squares (SVD) when the rank is not known (``keep <
    0``).  Returns the conditioning of the rows used (the last pivot's singular value over
    the first's; 1.0 by least squares).  ``work``: ``min_norm_work(m)`` floats."""
    m, nu = G.shape[0], G.shape[1]
    if keep < 0:
        x = np.linalg.lstsq(G, rhs, RANK_TOLERANCE)[0]
        for k in range(nu):
            du[k] = x[k]
        return 1.0
    if keep > 0 and info[ROWS] == keep:
        ratio = _min_norm_chosen(G, rhs, keep, du, info, work)
        if ratio > 0.0:
            return ratio
    return _min_norm_pivoted(G, rhs, keep, du, info, work)


@internal(**UNCOUNTED)
def _min_norm_chosen(G, rhs, r, du, info, work):
    """``min_norm_step`` on the ``r`` rows the last pivoted factorisation chose
    (``info[ROWS + 1:]``, in its pivot order): ``G_r G_r^T`` (``r x r`` instead of ``m x
    m``) by Cholesky without pivoting.  Returns the rows' conditioning (the smallest
    diagonal entry of the factor over the largest), or -1.0, having changed only
    ``work``, when it fell below ``CHOSEN_DECAY`` of what it was when they were chosen
    (the caller chooses again)."""
    m, nu = G.shape[0], G.shape[1]
    rows = info[ROWS + 1:ROWS + 1 + r]
    A = c_view(work, 0, (r, r))
    z, x = c_view(work, r * r, (r,)), c_view(work, r * r + r, (r,))
    for i in range(r):
        gi = int(rows[i])
        for j in range(i + 1):
            gj = int(rows[j])
            acc = 0.0
            for k in range(nu):
                acc += G[gi, k] * G[gj, k]
            A[i, j] = acc
    lo, hi = np.inf, 0.0
    for k in range(r):                              # Cholesky, lower triangle
        d = A[k, k]
        for j in range(k):
            d -= A[k, j] * A[k, j]
        if not d > 0.0:
            return -1.0
        A[k, k] = np.sqrt(d)
        lo, hi = min(lo, A[k, k]), max(hi, A[k, k])
        for i in range(k + 1, r):
            s = A[i, k]
            for j in range(k):
                s -= A[i, j] * A[k, j]
            A[i, k] = s / A[k, k]
    ratio = lo / hi
    if not ratio >= CHOSEN_DECAY * info[ROWS + 1 + m]:
        return -1.0
    for i in range(r):                              # L L^T x = rhs_r
        s = rhs[int(rows[i])]
        for k in range(i):
            s -= A[i, k] * x[k]
        x[i] = s / A[i, i]
    for i in range(r - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, r):
            s -= A[k, i] * z[k]
        z[i] = s / A[i, i]
    for k in range(nu):
        acc = 0.0
        for i in range(r):
            acc += G[int(rows[i]), k] * z[i]
        du[k] = acc
    return ratio


@internal(**UNCOUNTED)
def _min_norm_pivoted(G, rhs, keep, du, info, work):
    """``min_norm_step`` with the rank known, the rows chosen by a Cholesky of ``G G^T``
    with complete pivoting, in ``work`` (``m^2 + 3 m`` floats); the rows and the
    factorisation's conditioning recorded in ``info`` (``ROWS``)."""
    m, nu = G.shape[0], G.shape[1]
    A = c_view(work, 0, (m, m))
    perm, z, x = (c_view(work, m * m, (m,)), c_view(work, m * m + m, (m,)),
                  c_view(work, m * m + 2 * m, (m,)))
    for i in range(m):
        for j in range(i + 1):
            acc = 0.0
            for k in range(nu):
                acc += G[i, k] * G[j, k]
            A[i, j] = acc
            A[j, i] = acc
    rank = _pivoted_cholesky(A, keep, perm)
    info[ROWS] = rank
    for i in range(rank):
        info[ROWS + 1 + i] = perm[i]
    pivoted_back(A, perm, rank, rhs, z, x)
    for k in range(nu):
        acc = 0.0
        for i in range(m):
            acc += G[i, k] * z[i]
        du[k] = acc
    ratio = A[rank - 1, rank - 1] / A[0, 0] if rank else 1.0
    info[ROWS + 1 + m] = ratio
    return ratio

"""The constrained accelerations and minimum-norm multipliers by a rank-revealing QR.

With ``L`` the Cholesky factor of ``M`` and ``Y = L^-1 G^T`` (free speeds x rows), the
equations ``M u' = f + G^T lam``, ``G u' = gamma`` become ``Y^T Y lam = res`` (``res =
gamma - G M^-1 f``) and ``u' = M^-1 f + L^-T (Y lam)``.  Householder's QR with column
pivoting, ``Y P = Q [[R11, R12], [0, 0]]``, stops where the next column's remaining norm
falls below ``tolerance`` of the first (that is the rank ``r``: the pivoted diagonal follows
the singular values, the first equal to the largest column norm).  Then

* ``Y lam = Q1 w`` with ``R11^T w = (P^T res)[:r]``: the correction ``z = Y lam`` is unique
  (it is ``u'`` that is unique), whatever the rows left out;
* the minimum-norm multipliers solve ``[R11 R12] mu = w`` (``mu = P^T lam``): by a second
  QR, of ``[R11 R12]^T``, when rows were left out (redundant constraints); ``R11^-1 w``
  when none was.

When the rows that are not all zero are independent and well conditioned (the common
case: a mechanism away from its singular configurations), the pivoted QR is not needed:
the Cholesky factor of ``Y^T Y`` with diagonal pivoting -- the same pivots in the same
order, ``R``'s diagonal squared -- shows it (its last pivot above ``WELL_CONDITIONED``
of its first, in ``Y``'s terms), and solves for the multipliers, which are then unique
(``_gram_solve``; the normal equations lose at most ``1 / WELL_CONDITIONED^2`` times the
rounding, four digits fewer than that of double precision).  Otherwise the QR decides.

No LAPACK call, no allocation: a four-bar's five rows cost a fraction of an SVD, which
allocated its three factors and its work arrays at every call.
"""
import numpy as np
from numba import njit

from .views import UNCOUNTED, c_view
from .internal import internal

#: the non-zero rows are solved by the normal equations (``_gram_solve``) when the last
#: pivot of ``Y``'s pivoted factor stays above this fraction of the first (the smallest
#: singular value over the largest, closely); below it, by the pivoted QR
WELL_CONDITIONED = 1e-2


@njit(cache=True, inline="always")
def work_size(nu, m):
    """Floats of scratch ``qr_solve`` takes."""
    return nu * m + m * m + 8 * m + 2 * nu


@internal(forceinline=True, **UNCOUNTED)
def _reflect(A, k, rows, cols, col0):
    """Householder reflector of ``A[k:rows, k]`` (kept there, the vector ``v``), applied to
    ``A[k:rows, col0:cols]``; returns ``(R_kk, beta)`` with ``H = I - beta v v^T``."""
    norm = 0.0
    for i in range(k, rows):
        norm += A[i, k] * A[i, k]
    norm = np.sqrt(norm)
    if norm == 0.0:
        return 0.0, 0.0
    alpha = -norm if A[k, k] >= 0.0 else norm
    A[k, k] -= alpha
    vv = 0.0
    for i in range(k, rows):
        vv += A[i, k] * A[i, k]
    beta = 2.0 / vv
    for j in range(col0, cols):
        s = 0.0
        for i in range(k, rows):
            s += A[i, k] * A[i, j]
        s *= beta
        for i in range(k, rows):
            A[i, j] -= s * A[i, k]
    return alpha, beta


@internal(forceinline=True, **UNCOUNTED)
def _apply_reflectors(A, beta, r, x, rows):
    """``x = H_0 H_1 ... H_(r-1) x`` for the reflectors kept in ``A``'s columns."""
    for k in range(r - 1, -1, -1):
        if beta[k] == 0.0:
            continue
        s = 0.0
        for i in range(k, rows):
            s += A[i, k] * x[i]
        s *= beta[k]
        for i in range(k, rows):
            x[i] -= s * A[i, k]


@njit(forceinline=True, **UNCOUNTED)   # the tests call it from Python too
def pivoted_qr(A, tolerance, perm, Rd, beta):
    """Householder QR with column pivoting of ``A`` (rows x cols) in place: ``perm`` the
    column order, ``Rd`` the diagonal of ``R``, ``R``'s strict upper part in ``A``, the
    reflectors below it.  Stops at the first column whose remaining norm is at most
    ``tolerance`` times the first column's; returns that rank and the first norm."""
    rows, cols = A.shape[0], A.shape[1]
    for j in range(cols):
        perm[j] = j
    first = 0.0
    for k in range(min(rows, cols)):
        best, at = -1.0, k
        for j in range(k, cols):
            s = 0.0
            for i in range(k, rows):
                s += A[i, j] * A[i, j]
            if s > best:
                best, at = s, j
        if k == 0:
            first = np.sqrt(best)
        if not np.sqrt(best) > tolerance * first or first == 0.0:
            return k, first
        if at != k:
            for i in range(rows):
                A[i, k], A[i, at] = A[i, at], A[i, k]
            perm[k], perm[at] = perm[at], perm[k]
        Rd[k], beta[k] = _reflect(A, k, rows, cols, k + 1)
    return min(rows, cols), first


@internal(forceinline=True, **UNCOUNTED)
def residual_rows(G, gamma, ud, res, index):
    """``res = gamma - G ud``, and in ``index`` the rows of ``G`` that are not all zero
    (row numbers, as floats); returns how many.  A row of zeros (a planar mechanism's
    out-of-plane rows, at every state) is a zero column of ``Y``: never pivoted in, its
    multiplier 0 in the minimum-norm solution, and it adds exact zeros to every other
    sum, so the solves leave it out."""
    m, nu = G.shape[0], G.shape[1]
    mc = 0
    for i in range(m):
        s = gamma[i]
        nonzero = False
        for k in range(nu):
            s -= G[i, k] * ud[k]
            nonzero = nonzero or G[i, k] != 0.0
        res[i] = s
        if nonzero:
            index[mc] = i
            mc += 1
    return mc


@njit(**UNCOUNTED)
def qr_solve(L, ud, G, gamma, lam, info, tolerance, work):
    """``ud`` (``M^-1 f`` on entry) corrected to the constrained ``u'``, ``lam`` the
    minimum-norm multipliers, ``info[0]`` the rank, ``info[1]`` the last kept pivot over
    the first (how far from a singular configuration).  ``work``: ``work_size`` floats."""
    m, nu = G.shape[0], G.shape[1]
    at = nu * m + m * m
    res, perm, Rd, beta = (c_view(work, at, (m,)), c_view(work, at + m, (m,)),
                           c_view(work, at + 2 * m, (m,)), c_view(work, at + 3 * m, (m,)))
    mu, Ud, beta2, index = (c_view(work, at + 4 * m, (m,)), c_view(work, at + 5 * m, (m,)),
                            c_view(work, at + 6 * m, (m,)), c_view(work, at + 7 * m, (m,)))
    w, z = c_view(work, at + 8 * m, (nu,)), c_view(work, at + 8 * m + nu, (nu,))
    for i in range(m):
        lam[i] = 0.0
    # the rows of zeros left out: the same solution (to rounding: with no other row left
    # out, the multipliers come by back substitution)
    mc = residual_rows(G, gamma, ud, res, index)
    A, B = c_view(work, 0, (nu, mc)), c_view(work, nu * m, (mc, mc))
    for j in range(mc):                             # L A = G^T, column by column
        g = int(index[j])
        for i in range(nu):
            s = G[g, i]
            for k in range(i):
                s -= L[i, k] * A[k, j]
            A[i, j] = s / L[i, i]
    if _gram_solve(A, mc, res, index, L, ud, lam, info, B, perm, mu, w, z):
        return
    r, first = pivoted_qr(A, tolerance, perm, Rd, beta)
    info[0] = r
    info[1] = abs(Rd[r - 1]) / first if r else 1.0
    if r == 0:
        return
    for i in range(r):                              # R11^T w = (P^T res)[:r]
        s = res[int(index[int(perm[i])])]
        for k in range(i):
            s -= A[k, i] * w[k]
        w[i] = s / Rd[i]
    for i in range(r, nu):
        w[i] = 0.0
    for i in range(nu):
        z[i] = w[i]
    _apply_reflectors(A, beta, r, z, nu)            # z = Q1 w = Y lam
    add_back_solved(L, z, ud)
    _min_norm_multipliers(A, Rd, r, mc, w, B, Ud, beta2, mu)
    for i in range(mc):
        lam[int(index[int(perm[i])])] = mu[i]


@internal(forceinline=True, **UNCOUNTED)
def add_back_solved(L, z, ud):
    """``ud += L^-T z`` (``z`` overwritten by ``L^-T z``): a correction ``z = Y lam`` of
    the accelerations, ``M^-1 G^T lam`` with ``M = L L^T``."""
    nu = L.shape[0]
    for i in range(nu - 1, -1, -1):
        s = z[i]
        for k in range(i + 1, nu):
            s -= L[k, i] * z[k]
        z[i] = s / L[i, i]
    for i in range(nu):
        ud[i] += z[i]


@internal(forceinline=True, **UNCOUNTED)
def pivoted_back(A, perm, rank, rhs, out, x):
    """``out`` (all rows): the solution of the pivoted rows' system ``C C^T x =
    rhs[perm[:rank]]`` at those rows, zero elsewhere (``C`` in ``A``'s lower triangle;
    ``perm``: row numbers, as floats; ``x``: at least ``rank`` floats of scratch, left
    holding the solution in pivot order)."""
    for i in range(rank):
        s = rhs[int(perm[i])]
        for k in range(i):
            s -= A[i, k] * x[k]
        x[i] = s / A[i, i]
    for i in range(rank - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, rank):
            s -= A[k, i] * x[k]
        x[i] = s / A[i, i]
    for j in range(out.shape[0]):
        out[j] = 0.0
    for i in range(rank):
        out[int(perm[i])] = x[i]


@internal(forceinline=True, **UNCOUNTED)
def _pivoted_cholesky(B, mc, perm):
    """``B[perm][:, perm] = C C^T`` in place (``C`` in ``B``'s lower triangle), by
    Cholesky with diagonal pivoting; returns the first pivot, or 0 when a pivot falls
    below ``WELL_CONDITIONED^2`` of it (``B`` then left half factored)."""
    first = 0.0
    for k in range(mc):
        at = k
        for j in range(k + 1, mc):
            if B[j, j] > B[at, at]:
                at = j
        if at != k:                                 # symmetric swap of k and at
            for j in range(mc):
                B[k, j], B[at, j] = B[at, j], B[k, j]
            for j in range(mc):
                B[j, k], B[j, at] = B[j, at], B[j, k]
            perm[k], perm[at] = perm[at], perm[k]
        d = B[k, k]
        if k == 0:
            first = d
        if not d > WELL_CONDITIONED * WELL_CONDITIONED * first:
            return 0.0
        c = np.sqrt(d)
        B[k, k] = c
        for i in range(k + 1, mc):
            B[i, k] /= c
        for i in range(k + 1, mc):                  # the complement, both triangles
            for j in range(k + 1, i + 1):
                B[i, j] -= B[i, k] * B[j, k]
                B[j, i] = B[i, j]
    return first


@njit(forceinline=True, **UNCOUNTED)   # the tests call it from Python too
def _gram_solve(A, mc, res, index, L, ud, lam, info, B, perm, rows, w, z):
    """The constrained ``u'`` and the multipliers when the ``mc`` columns of ``A = Y`` (the
    rows ``index[:mc]`` of ``G``) are independent and well conditioned: ``B = A^T A``
    factored by Cholesky with diagonal pivoting, ``B[perm][:, perm] = C C^T`` (``C`` in
    ``B``'s lower triangle); then ``B lam = res`` and ``u' += L^-T A lam``.  Returns False,
    with ``ud``, ``lam`` and ``info`` untouched, when a pivot falls below
    ``WELL_CONDITIONED^2`` of the first (dependent or nearly dependent rows: the pivoted QR
    decides) or there are more rows than speeds.  ``rows``: scratch of ``mc``; ``w``,
    ``z``: scratch of ``nu``."""
    nu = A.shape[0]
    if mc > nu:
        return False
    for i in range(mc):
        perm[i] = i
        for j in range(i + 1):
            s = 0.0
            for k in range(nu):
                s += A[k, i] * A[k, j]
            B[i, j] = s
            B[j, i] = s
    first = _pivoted_cholesky(B, mc, perm)
    if first == 0.0:
        return False
    for i in range(mc):                             # the pivots' row numbers in G
        rows[i] = index[int(perm[i])]
    pivoted_back(B, rows, mc, res, lam, w)          # C C^T x = P^T res, lam = P x
    for i in range(nu):
        z[i] = 0.0
    for j in range(mc):                             # z = A lam
        x = w[j]
        col = int(perm[j])
        for i in range(nu):
            z[i] += A[i, col] * x
    add_back_solved(L, z, ud)
    info[0] = mc
    info[1] = B[mc - 1, mc - 1] / np.sqrt(first)
    return True


@internal(forceinline=True, **UNCOUNTED)
def _min_norm_multipliers(A, Rd, r, m, w, B, Ud, beta2, mu):
    """``mu``: the minimum-norm solution of ``[R11 R12] mu = w`` (``R`` as ``pivoted_qr``
    left it); ``B`` (m x m), ``Ud``, ``beta2``: scratch."""
    if r == m:                                      # R11 mu = w, back substitution
        for i in range(r - 1, -1, -1):
            s = w[i]
            for k in range(i + 1, r):
                s -= A[i, k] * mu[k]
            mu[i] = s / Rd[i]
        return
    for j in range(m):                              # B = [R11 R12]^T (m x r)
        for i in range(r):
            B[j, i] = Rd[i] if j == i else (A[i, j] if j > i else 0.0)
    for k in range(r):
        Ud[k], beta2[k] = _reflect(B, k, m, r, k + 1)
    for i in range(r):                              # U^T s = w, s into mu[:r]
        s = w[i]
        for k in range(i):
            s -= B[k, i] * mu[k]
        mu[i] = s / Ud[i]
    for i in range(r, m):
        mu[i] = 0.0
    _apply_reflectors(B, beta2, r, mu, m)           # mu = Z [s; 0]

"""Closed loops through flexible bodies in compiled code: the constrained accelerations and
the projection onto the constraints, as ``algorithms.flexible_loops`` computes them.

The loop joints' rows come from the tree's kernel (``constraints._constraint_rows``:
``phi``, ``psi``, ``G_x``, ``gamma`` over the tree's speeds, the node frames being frames
of the tree), and the model's are ``G = G_x P``, ``gamma = gamma_x``.  The rank of ``G``
is decided by its singular values (``svd_rows``: one-sided Jacobi, no allocation) at
``RANK_TOLERANCE`` of the largest, during a run at most the rank it holds (``info[2]``)
and without directions below ``PASSAGE_TOLERANCE``; with the kept directions
``G_r = S_r V_r^T`` the system ``[[A, -G_r^T], [G_r, 0]] [u'; mu] = [f; U_r^T gamma]``
gives ``u'``, and ``lam = U_r mu`` are the minimum-norm multipliers.

``con`` is the tree's ``(con_int, con_data, phi, psi, G_x, gamma, lam, info)``; ``lw`` the
loops' own arrays: the model's ``G`` (rows x model speeds), then a float scratch.
"""
import numpy as np
from numba import njit

from .constrained import PROJECTION_ITERATIONS, PROJECTION_TOLERANCE, con_views
from .constraints import _constraint_rows
from .flexible import MAPPED, NUT, QM0, UM0, chain_state, lu_solve
from .flexible_views import (AA, CF, CHAIN, CON_INT, DMAP, FF, FLAGS, FREE_Q, FREE_U, GM,
                             LW, NQ, PIDX, PPTR, PVAL, QFULL, QUATS, SCRATCH, SLOTS,
                             UDFULL, UFULL, buffers, motion_views, one, tree_views, two)
from .flexible_views import NUT as H_NUT
from .joints import coordinate_rates
from .kinematics import walk
from .loop_solve import PASSAGE_TOLERANCE, RANK_TOLERANCE
from .views import UNCOUNTED, c_view
from .internal import internal

#: a projection whose residual stops falling (by half a step) below this is done
#: (``algorithms.flexible_loops.STALLED``)
STALLED = 1e-10


def loops_work(nq, nu, m):
    """Floats of the loops' scratch ``lw`` for ``nq`` model coordinates, ``nu`` speeds and
    ``m`` rows: the singular value decomposition, the solve, the projection's steps."""
    k = max(m, 1)
    return k * k + k + 2 * nu * k + 2 * (nu + k) ** 2 + 2 * (nu + k) + nu + nq


@njit(inline="always", **UNCOUNTED)
def svd_rows(G, U, s, V, X):
    """The singular values ``s`` (m, descending) of ``G`` (m x nu), its left vectors
    ``U`` (m x m, columns) and right vectors ``V`` (nu x m, columns; those of zero singular
    values left as they come), by one-sided Jacobi rotations of the columns of ``G^T``
    (``X``: nu x m scratch; ``G^T W = X S`` ...)."""
    m, nu = G.shape[0], G.shape[1]
    for k in range(nu):
        for j in range(m):
            X[k, j] = G[j, k]
    Wj = U                               # the rotations accumulate in U (m x m)
    for i in range(m):
        for j in range(m):
            Wj[i, j] = 1.0 if i == j else 0.0
    for _ in range(60):
        rotated = False
        for p in range(m - 1):
            for q in range(p + 1, m):
                al = 0.0
                be = 0.0
                ga = 0.0
                for k in range(nu):
                    al += X[k, p] * X[k, p]
                    be += X[k, q] * X[k, q]
                    ga += X[k, p] * X[k, q]
                if ga == 0.0 or abs(ga) <= 1e-15 * np.sqrt(al * be):
                    continue
                rotated = True
                zeta = (be - al) / (2.0 * ga)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
                c = 1.0 / np.sqrt(1.0 + t * t)
                sn = c * t
                for k in range(nu):
                    xp, xq = X[k, p], X[k, q]
                    X[k, p] = c * xp - sn * xq
                    X[k, q] = sn * xp + c * xq
                for k in range(m):
                    xp, xq = Wj[k, p], Wj[k, q]
                    Wj[k, p] = c * xp - sn * xq
                    Wj[k, q] = sn * xp + c * xq
        if not rotated:
            break
    for j in range(m):
        acc = 0.0
        for k in range(nu):
            acc += X[k, j] * X[k, j]
        s[j] = np.sqrt(acc)
    # sort by descending singular value (insertion sort: a few rows), columns with them
    for j in range(1, m):
        k = j
        while k > 0 and s[k - 1] < s[k]:
            s[k - 1], s[k] = s[k], s[k - 1]
            for i in range(nu):
                X[i, k - 1], X[i, k] = X[i, k], X[i, k - 1]
            for i in range(m):
                Wj[i, k - 1], Wj[i, k] = Wj[i, k], Wj[i, k - 1]
            k -= 1
    for j in range(m):
        inv = 1.0 / s[j] if s[j] > 0.0 else 0.0
        for k in range(nu):
            V[k, j] = X[k, j] * inv


@njit(inline="always", **UNCOUNTED)
def kept_rank(s, held):
    """``(r, ratio)``: the directions kept (module docstring) and the weakest kept
    singular value over the largest (1 when none)."""
    m = s.shape[0]
    if m == 0 or s[0] == 0.0:
        return 0, 1.0
    r = 0
    weak = 0
    for j in range(m):
        if s[j] > RANK_TOLERANCE * s[0]:
            r += 1
        if s[j] > PASSAGE_TOLERANCE * s[0]:
            weak += 1
    if held >= 0:
        r = min(r, held, weak)
    return r, (s[r - 1] / s[0] if r else 1.0)


@njit(inline="always", **UNCOUNTED)
def model_rows(Gx, G, pptr, pidx, pval, nut, mapped):
    """The model's ``G = G_x P`` (``P``'s tree rows; the modal columns of a model without
    node frames zero)."""
    m, nu = G.shape[0], G.shape[1]
    for i in range(m):
        for j in range(nu):
            G[i, j] = Gx[i, j] if (not mapped and j < nut) else 0.0
        if mapped:
            for e in range(nut):
                x = Gx[i, e]
                if x != 0.0:
                    for z in range(pptr[e], pptr[e + 1]):
                        G[i, pidx[z]] += x * pval[z]


@njit(inline="always", **UNCOUNTED)
def _svd_views(lw, m, nu):
    k = max(m, 1)
    at = 0
    U = c_view(lw, at, (k, k))
    s = lw[at + k * k:at + k * k + k]
    V = c_view(lw, at + k * k + k, (nu, k))
    X = c_view(lw, at + k * k + k + nu * k, (nu, k))
    return U, s, V, X, at + k * k + k + 2 * nu * k


@internal(**UNCOUNTED)
def constrained_solve(A, f, G, gamma, lam, held, ud, lw):
    """``ud``, ``lam`` of ``A u' = f + G^T lam``, ``G u' = gamma`` (module docstring);
    returns -1, or the column where the system is singular."""
    m, nu = G.shape[0], G.shape[1]
    U, s, V, X, at = _svd_views(lw, m, nu)
    r = 0
    if m:
        svd_rows(G, U, s, V, X)
        r = kept_rank(s[:m], held)[0]
    n = nu + r
    K = c_view(lw, at, (n, n))
    rhs = lw[at + n * n:at + n * n + n]
    x = lw[at + n * n + n:at + n * n + 2 * n]
    LU = c_view(lw, at + n * n + 2 * n, (n, n))
    for i in range(n):
        for j in range(n):
            K[i, j] = 0.0
    for i in range(nu):
        rhs[i] = f[i]
        for j in range(nu):
            K[i, j] = A[i, j]
    for k in range(r):
        acc = 0.0
        for i in range(m):
            acc += U[i, k] * gamma[i]
        rhs[nu + k] = acc
        for j in range(nu):
            g = s[k] * V[j, k]
            K[nu + k, j] = g
            K[j, nu + k] = -g
    pivot = lu_solve(K, rhs, x, LU)
    if pivot >= 0:
        return pivot
    for i in range(nu):
        ud[i] = x[i]
    for i in range(m):
        acc = 0.0
        for k in range(r):
            acc += U[i, k] * x[nu + k]
        lam[i] = acc
    return -1


@internal(**UNCOUNTED)
def min_norm(G, rhs, held, x, lw):
    """``x``: the minimum-norm solution of ``G x = rhs`` over the kept directions of
    ``G``; returns ``(kept, ratio)`` (``kept_rank``)."""
    m, nu = G.shape[0], G.shape[1]
    U, s, V, X, _ = _svd_views(lw, m, nu)
    for j in range(nu):
        x[j] = 0.0
    if m == 0:
        return 0, 1.0
    svd_rows(G, U, s, V, X)
    r, ratio = kept_rank(s[:m], held)
    for k in range(r):
        acc = 0.0
        for i in range(m):
            acc += U[i, k] * rhs[i]
        acc /= s[k]
        for j in range(nu):
            x[j] += V[j, k] * acc
    return r, ratio


@njit(inline="always", **UNCOUNTED)
def _constraints(h, x):
    """The tree's constraints ``(con_int, con_data, phi, psi, G_x, gamma, lam, info)``."""
    return con_views(two(h, CON_INT, h), one(h, CF, x), h[H_NUT])


@internal(**UNCOUNTED)
def rows_step(h, x, walk_first):
    """The constraint rows at the extended joint-space state (a walk first when
    ``walk_first``: the kinematics there are not the true ones), and the model's
    ``G = G_x P``."""
    fb, ib = buffers(h, x)
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx = tree_views(fb, ib)
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion_views(fb, ib)
    qfull, ufull, udfull = one(h, QFULL, x), one(h, UFULL, x), one(h, UDFULL, x)
    scratch = one(h, SCRATCH, x)
    con_int, con_data, phi, psi, Gx, gamma, lam, info = _constraints(h, x)
    if walk_first:
        walk(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx, qfull,
             ufull, udfull, R, r, w, v, alpha, a, JR, JT, S, scratch)
    _constraint_rows(con_int, con_data, ucol, qoff, uoff, qfull, ufull, udfull, R, r, w,
                     v, alpha, a, JR, JT, phi, psi, Gx, gamma, scratch, phi[:0], -1, False)
    flags = one(h, FLAGS, h)
    model_rows(Gx, two(h, GM, x), one(h, PPTR, h), one(h, PIDX, h), one(h, PVAL, x),
               flags[NUT], flags[MAPPED] != 0)


@internal(**UNCOUNTED)
def constrained_step(h, x):
    """``x = u'`` of the constrained system at the rows of ``rows_step`` (``lam`` in the
    constraints' workspace); returns as ``constrained_solve``."""
    con = _constraints(h, x)
    return constrained_solve(two(h, AA, x), one(h, FF, x), two(h, GM, x), con[5], con[6],
                             int(con[7][2]), x, one(h, LW, x))


@njit(inline="always", **UNCOUNTED)
def _place(h, y, nq):
    """``y = [q, u]`` into the extended joint space, the chains from ``eta``."""
    qfull, ufull, udfull = one(h, QFULL, y), one(h, UFULL, y), one(h, UDFULL, y)
    free_q, free_u = one(h, FREE_Q, h), one(h, FREE_U, h)
    for k in range(nq):
        qfull[free_q[k]] = y[k]
    for k in range(y.shape[0] - nq):
        ufull[free_u[k]] = y[nq + k]
    flags = one(h, FLAGS, h)
    chain_state(qfull, ufull, udfull, two(h, CHAIN, h), two(h, DMAP, y), flags[QM0],
                flags[UM0])


@internal(**UNCOUNTED)
def project_step(h, y):
    """Move ``y = [q, u]`` onto the constraints (``algorithms.flexible_loops.project``):
    Newton on the positions with minimum-norm steps through ``q' = N(q) u``, until every
    residual is below ``PROJECTION_TOLERANCE`` or stalls below ``STALLED``, then
    ``u -= G^+ psi``.  The drives must be in the joint space already.  Returns the
    Newton steps, -1 when the positions did not converge, -2 when the speeds cannot
    satisfy the constraints."""
    nq = h[NQ]
    nu = y.shape[0] - nq
    con_int, con_data, phi, psi, Gx, gamma, lam, info = _constraints(h, y)
    G, lw = two(h, GM, y), one(h, LW, y)
    slots, quats = two(h, SLOTS, h), one(h, QUATS, h)
    held = int(info[2])
    du = lw[lw.shape[0] - nu - nq:lw.shape[0] - nq]
    dq = lw[lw.shape[0] - nq:]
    work = lw[:lw.shape[0] - nu - nq]
    before = np.inf
    steps = 0
    while True:
        _place(h, y, nq)
        rows_step(h, y, True)
        size = 0.0
        for k in range(phi.shape[0]):
            size = max(size, abs(phi[k]))
        if size <= PROJECTION_TOLERANCE or (size <= STALLED and size > 0.5 * before):
            break
        if steps >= PROJECTION_ITERATIONS:
            return -1
        before = size
        min_norm(G, phi, held, du, work)
        coordinate_rates(y[:nq], du, slots, dq)
        for k in range(nq):
            y[k] -= dq[k]
        for s_ in range(quats.shape[0]):
            i = quats[s_]
            nrm = np.sqrt(y[i] ** 2 + y[i + 1] ** 2 + y[i + 2] ** 2 + y[i + 3] ** 2)
            for k in range(4):
                y[i + k] /= nrm
        steps += 1
    r, ratio = min_norm(G, psi, held, du, work)
    big = 0.0
    for k in range(nu):
        y[nq + k] -= du[k]
        big = max(big, abs(y[nq + k]))
    _place(h, y, nq)
    rows_step(h, y, True)
    for k in range(psi.shape[0]):
        if abs(psi[k]) > 1e-8 * (1.0 + big):
            return -2
    if held >= 0:                       # a run: the lowest rank and conditioning met
        info[3] = min(info[3], r)
        info[4] = min(info[4], ratio)
    return steps

"""Forward dynamics of a tree closed by loop constraints, and the projection of a state
back onto the constraint manifold.

The equations (Jourdain with multipliers): ``M u' = f + G^T lam``, ``G u' = gamma``.
They are solved by the range-space (Schur complement) method: with ``M = L L^T``
(Cholesky, as for trees) and ``u0 = M^-1 f``,

    ``S lam = gamma - G u0``,  ``S = G M^-1 G^T = Y^T Y``,  ``Y = L^-1 G^T``,
    ``u' = u0 + M^-1 G^T lam``.

``S`` is singular when constraints are redundant (a planar loop closed by a spatial
revolute: five equations of rank two).  ``Y``'s singular value decomposition gives the
rank -- singular values above ``RANK_TOLERANCE`` times the largest count -- and the
minimum-norm ``lam`` over the rest: ``u'`` is unique whenever the motion is, ``lam`` is
the smallest multiplier vector that produces it.  The SVD is of ``Y`` (not of ``S``,
whose singular values are squared) so that the rank decision keeps the digits.  When
``M`` is singular (a massless link whose motion the constraints fix) the augmented system
``[[M, G^T], [G, 0]]`` is solved by least squares instead.
"""
import numpy as np
from numba import njit

from .constraints import constraint_rows
from .evaluate import jourdain_accelerations
from .joints import coordinate_rates
from .kinematics import walk

#: singular values of ``Y = L^-1 G^T`` below this fraction of the largest are taken as
#: zero (redundant constraints, or a singular configuration)
RANK_TOLERANCE = 1e-9
#: during a run, a singular value of ``Y`` below this fraction of the largest is dropped
#: although the mechanism's rank counts it: the configuration is (nearly) singular, where
#: the stages of a step, off the manifold, would divide a residual by its square; the
#: motion then follows its inertia along that direction for the step, and the projection
#: puts it back on the constraints (a smooth passage, docs/constraints.md)
PASSAGE_TOLERANCE = 1e-6
#: the projection stops when every position residual is below this (metres for points,
#: dimensionless for directions)
PROJECTION_TOLERANCE = 1e-13
PROJECTION_ITERATIONS = 12


@njit(cache=True, _nrt=True)
def constrained_solve(M, L, ud, G, gamma, lam, info):
    """``ud`` (holding ``M^-1 f`` on entry, ``L`` the Cholesky factor of ``M``) corrected
    to the constrained accelerations; ``lam`` the minimum-norm multipliers.  ``info[0]``:
    the rank of ``G``, ``info[1]``: the smallest singular value kept over the largest
    (how far from a singular configuration)."""
    m, nu = G.shape[0], G.shape[1]
    if m == 0:
        info[0], info[1] = 0.0, 1.0
        return
    res = gamma.copy()
    for i in range(m):
        for k in range(nu):
            res[i] -= G[i, k] * ud[k]
    Y = np.empty((nu, m))
    for j in range(m):                              # L Y = G^T, column by column
        for i in range(nu):
            s = G[j, i]
            for k in range(i):
                s -= L[i, k] * Y[k, j]
            Y[i, j] = s / L[i, i]
    keep = info[2]               # during a run: the rank at the last projected state
    if keep >= 0:
        _pivoted_solve(L, ud, Y, res, lam, info, int(keep))
        return
    U, sv, Vt = np.linalg.svd(Y, full_matrices=False)
    top = sv[0] if sv.shape[0] else 0.0
    rank = 0
    smallest = 1.0
    c = np.zeros(sv.shape[0])
    for k in range(sv.shape[0]):
        if sv[k] > RANK_TOLERANCE * top and top > 0.0:
            rank += 1
            smallest = sv[k] / top
            acc = 0.0
            for i in range(m):
                acc += Vt[k, i] * res[i]
            c[k] = acc / (sv[k] * sv[k])
    for i in range(m):
        acc = 0.0
        for k in range(sv.shape[0]):
            acc += Vt[k, i] * c[k]
        lam[i] = acc
    _add_correction(L, ud, Y, lam)
    info[0] = rank
    info[1] = smallest


@njit(cache=True, inline="always")
def _add_correction(L, ud, Y, lam):
    """``ud += M^-1 G^T lam = L^-T (Y lam)``."""
    nu, m = Y.shape[0], Y.shape[1]
    z = np.empty(nu)
    for i in range(nu):
        acc = 0.0
        for j in range(m):
            acc += Y[i, j] * lam[j]
        z[i] = acc
    for i in range(nu - 1, -1, -1):
        s = z[i]
        for k in range(i + 1, nu):
            s -= L[k, i] * z[k]
        z[i] = s / L[i, i]
    for i in range(nu):
        ud[i] += z[i]


@njit(cache=True, inline="always")
def _pivoted_cholesky(A, keep, perm):
    """``A`` (symmetric, positive semi-definite) factored in place by Cholesky with
    complete pivoting: at most ``keep`` pivots, none below ``PASSAGE_TOLERANCE^2`` of the
    first (a nearly singular direction).  ``perm`` the chosen order; returns the number
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


@njit(cache=True, inline="always")
def _pivoted_back(A, perm, rank, rhs, out):
    """``out`` (all rows): the solution of the pivoted rows' system ``L_r L_r^T x =
    rhs[perm[:rank]]`` at those rows, zero elsewhere."""
    x = np.empty(rank)
    for i in range(rank):
        s = rhs[perm[i]]
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
        out[perm[i]] = x[i]


@njit(cache=True)
def _pivoted_solve(L, ud, Y, res, lam, info, keep):
    """The constrained ``ud`` during a run, whose rank ``keep`` is known: ``S = Y^T Y``
    factored by Cholesky with complete pivoting (``_pivoted_cholesky``), and the
    multipliers of the rows it chose solved for, the others zero.  The rows left out are
    combinations of the rows kept, so ``u'`` is the same as by the SVD (it is unique);
    ``lam`` is a basic solution, not the minimum-norm one (reactions are computed by
    ``constrained_solve`` outside runs).  An SVD costs more than a small tree's whole
    evaluation; this, a fraction of it."""
    m = Y.shape[1]
    A = np.empty((m, m))
    for i in range(m):
        for j in range(i + 1):
            acc = 0.0
            for k in range(Y.shape[0]):
                acc += Y[k, i] * Y[k, j]
            A[i, j] = acc
            A[j, i] = acc
    perm = np.empty(m, np.int64)
    first = 0.0
    for i in range(m):
        first = max(first, A[i, i])
    rank = _pivoted_cholesky(A, keep, perm)
    _pivoted_back(A, perm, rank, res, lam)
    _add_correction(L, ud, Y, lam)
    info[0] = rank
    info[1] = A[rank - 1, rank - 1] / np.sqrt(first) if rank and first > 0 else 1.0


@njit(cache=True)
def min_norm_step(G, rhs, keep, du):
    """``du``: the minimum-norm solution of ``G du = rhs`` -- by ``G^T (G G^T)^+ rhs`` on
    the rows a pivoted Cholesky of ``G G^T`` keeps (``keep`` at most) during a run, by
    least squares (SVD) when the rank is not known (``keep < 0``).  Returns the last
    pivot's singular value over the first's (an estimate of ``G``'s conditioning; 1.0
    by least squares)."""
    m, nu = G.shape[0], G.shape[1]
    if keep < 0:
        x = np.linalg.lstsq(G, rhs, RANK_TOLERANCE)[0]
        for k in range(nu):
            du[k] = x[k]
        return 1.0
    A = np.empty((m, m))
    for i in range(m):
        for j in range(i + 1):
            acc = 0.0
            for k in range(nu):
                acc += G[i, k] * G[j, k]
            A[i, j] = acc
            A[j, i] = acc
    perm = np.empty(m, np.int64)
    z = np.empty(m)
    rank = _pivoted_cholesky(A, keep, perm)
    _pivoted_back(A, perm, rank, rhs, z)
    for k in range(nu):
        acc = 0.0
        for i in range(m):
            acc += G[i, k] * z[i]
        du[k] = acc
    return A[rank - 1, rank - 1] / A[0, 0] if rank else 1.0


@njit(cache=True, _nrt=True)
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


@njit(inline="always")
def constrained_accelerations(tree, body, state, loads, motion, jourdain, con, scratch):
    """Jourdain's ``M``, ``f`` (``evaluate.jourdain_accelerations``), the constraint rows at
    the same state, then the constrained ``u'`` into ``jourdain[3]``.  ``con``:
    ``(con_int, con_data, phi, psi, G, gamma, lam, info)``.  Returns as
    ``jourdain_accelerations`` (-1 done; a pivot where neither ``M`` nor the augmented
    system determines ``u'``; -2 non-finite)."""
    M, f, L, ud = jourdain
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion
    qfull, ufull, udfull = state
    con_int, con_data, phi, psi, G, gamma, lam, info = con
    pivot = jourdain_accelerations(tree, body, state, loads, motion, jourdain, scratch)
    constraint_rows(con_int, con_data, tree[8], tree[6], tree[7], qfull, ufull, udfull,
                    R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma)
    if pivot >= 0:
        for k in range(ud.shape[0]):
            ud[k] = f[k]
        if not augmented_solve(M, f, G, gamma, ud, lam, info):
            return pivot
    elif pivot == -1:
        constrained_solve(M, L, ud, G, gamma, lam, info)
    for k in range(ud.shape[0]):
        if not np.isfinite(ud[k]):
            return -2
    return -1


@njit(cache=True)
def residual_norm(phi):
    out = 0.0
    for k in range(phi.shape[0]):
        out = max(out, abs(phi[k]))
    return out


@njit(inline="always")
def project_state(y, nq, slots, quats, free_q, free_u, tree, state, motion, con, scratch):
    """Move ``y = [q, u]`` onto the constraint manifold: Newton-Raphson on the positions
    (minimum-norm steps ``du = -G^+ phi``, applied through ``q' = N(q) u``), then the
    velocities by the minimum-norm correction ``u -= G^+ psi``.  The drives must be in
    ``state`` already.  Returns the number of Newton steps, or -1 when the positions did
    not converge."""
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx = tree
    qfull, ufull, udfull = state
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion
    con_int, con_data, phi, psi, G, gamma, lam, info = con
    nu = y.shape[0] - nq
    dq = np.empty(nq)
    du = np.empty(nu)
    steps = 0
    while True:
        for k in range(nq):
            qfull[free_q[k]] = y[k]
        for k in range(nu):
            ufull[free_u[k]] = y[nq + k]
        walk(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx, qfull,
             ufull, udfull, R, r, w, v, alpha, a, JR, JT, S, scratch)
        constraint_rows(con_int, con_data, ucol, qoff, uoff, qfull, ufull, udfull,
                        R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma)
        if residual_norm(phi) <= PROJECTION_TOLERANCE:
            break
        if steps == PROJECTION_ITERATIONS:
            return -1
        min_norm_step(G, phi, int(info[2]), du)
        coordinate_rates(y[:nq], du, slots, dq)
        for k in range(nq):
            y[k] -= dq[k]
        for s in range(quats.shape[0]):
            i = quats[s]
            nrm = np.sqrt(y[i] ** 2 + y[i + 1] ** 2 + y[i + 2] ** 2 + y[i + 3] ** 2)
            for k in range(4):
                y[i + k] /= nrm
        steps += 1
    ratio = min_norm_step(G, psi, int(info[2]), du)
    for k in range(nu):
        y[nq + k] -= du[k]
    if info[2] >= 0:                 # a run: the rank here, for the next step's stages
        if ratio < 1e-3:             # near a singular configuration: decide it exactly
            rank, ratio = rank_of(G)
            info[2] = rank
            info[3] = min(info[3], rank)
        info[4] = min(info[4], ratio)
    return steps


@njit(cache=True)
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


@njit(cache=True, _nrt=True)
def project_state_call(y, nq, slots, quats, free_q, free_u, tree, state, motion, con, scratch):
    """``project_state`` as a compiled entry point, for Python (one state) and the compiled
    loops (``routes.finish_step``).  Counted, explicitly: it allocates, and a callee
    inherits an uncounted caller's mode."""
    return project_state(y, nq, slots, quats, free_q, free_u, tree, state, motion, con,
                         scratch)


@njit(cache=True)
def constraint_state(tree, state, motion, con, scratch):
    """The kinematics at the joint-space state, then the constraint rows (Python's view
    of ``phi``, ``psi``, ``G``, ``gamma``)."""
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx = tree
    qfull, ufull, udfull = state
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion
    con_int, con_data, phi, psi, G, gamma, lam, info = con
    walk(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx, qfull, ufull,
         udfull, R, r, w, v, alpha, a, JR, JT, S, scratch)
    constraint_rows(con_int, con_data, ucol, qoff, uoff, qfull, ufull, udfull,
                    R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma)


@njit(cache=True)
def constrained_call(tree, body, state, loads, motion, jourdain, con, scratch):
    """``constrained_accelerations`` as a compiled entry point for Python."""
    return constrained_accelerations(tree, body, state, loads, motion, jourdain, con,
                                     scratch)


"""A closed mechanism's forward dynamics by the articulated-body algorithm: O(n) per
independent constraint row, for large trees closed by a few loops.

``M u' = f + G^T lam``, ``G u' = gamma`` without forming ``M`` (O(n nu^2)) or factoring it
(O(nu^3)): the tree's ``u0 = M^-1 f`` by the articulated-body algorithm
(``evaluate.articulated_accelerations``), which leaves its factors -- per joint ``U = IA S``
and the Cholesky factor of ``D = S^T IA S`` -- so that ``M^-1 tau`` for another
generalized force ``tau`` costs two light sweeps (``unit_solve``: no velocities, no
gravity, no inertia updates).  Then, on ``r`` independent rows ``c`` of ``G``:

    ``X = M^-1 G_c^T`` (r sweeps),  ``(G_c X) lam_c = gamma_c - G_c u0``,  ``u' = u0 + X lam_c``.

The rows: during a run, those the last projection chose (its rank known); else a
column-pivoted QR of ``G^T`` (``rank_qr.pivoted_qr``, the same tolerance as the mass-matrix
route's).  ``u'`` is unique; ``lam`` is a basic solution (zero on the rows left out), not
the minimum-norm one -- reactions take the mass-matrix route (``constrained``).

``G`` needs the Jacobians of the frames the loop joints join, which the articulated-body
kinematics do not make (they skip the full Jacobians):
``loop_jacobians.constrained_jacobians`` builds those frames' rows from their ancestors'
motion subspaces ``S``, O(depth) each.
"""
import numpy as np
from numba import njit

from .articulated import articulated_body
from .constrained import con_views
from .constraints import _constraint_rows
from .evaluate import articulated_accelerations, motion_and_loads, outcome
from .joints import NU
from .loop_jacobians import constrained_jacobians
from .loop_solve import PASSAGE_TOLERANCE, RANK_TOLERANCE, ROWS
from .packed import WRONG_SIZE, _scatter, _views, contiguous
from .rank_qr import pivoted_qr, residual_rows
from .views import UNCOUNTED, c_view

#: what ``constrained_articulated`` returns outside a run when the rows it chose are
#: nearly dependent: the caller decides the accelerations with the mass matrix instead
DEPENDENT_ROWS = -4


@njit(cache=True, inline="always")
def _joint_solve(Dl, rec, i, k, x):
    """``x <- D_i^-1 x``, ``D_i = L L^T`` with ``L`` in ``Dl[i, :k, :k]``; ``rec[i]`` holds
    ``1 / D_i`` of a one-speed joint (``reciprocals``)."""
    if k == 1:                                      # most joints: one product
        x[0] *= rec[i]
        return
    for a_ in range(k):
        s = x[a_]
        for b_ in range(a_):
            s -= Dl[i, a_, b_] * x[b_]
        x[a_] = s / Dl[i, a_, a_]
    for a_ in range(k - 1, -1, -1):
        s = x[a_]
        for b_ in range(a_ + 1, k):
            s -= Dl[i, b_, a_] * x[b_]
        x[a_] = s / Dl[i, a_, a_]


@njit(cache=True, inline="always")
def reciprocals(kind, ucol, Dl, rec):
    """``rec[i] = 1 / D_i`` for every joint of one speed (``D_i = Dl[i, 0, 0]^2``): the
    unit solves multiply by it, so that no division lies on their sweeps' chain of
    dependent operations (independent divisions here, pipelined)."""
    for i in range(kind.shape[0]):
        if ucol[i] >= 0 and NU[kind[i]] == 1:
            rec[i] = 1.0 / (Dl[i, 0, 0] * Dl[i, 0, 0])


@njit(cache=True, inline="always")
def _dot6(A, i, j, x, b):
    """``sum_a A[i, a, j] x[b, a]``, summed in pairs (a shorter chain of dependent adds
    than one running sum)."""
    return ((A[i, 0, j] * x[b, 0] + A[i, 1, j] * x[b, 1])
            + (A[i, 2, j] * x[b, 2] + A[i, 3, j] * x[b, 3])
            + (A[i, 4, j] * x[b, 4] + A[i, 5, j] * x[b, 5]))


@njit(cache=True, inline="always")
def unit_solve(parent, kind, ucol, r, S, U, Dl, rec, tau, x, p, acc, v6):
    """``x = M^-1 tau`` by the articulated-body factors ``U``, ``Dl`` of the last
    ``articulated_body`` call (and ``rec``, ``reciprocals``): the algorithm's two sweeps
    for the generalized force ``tau`` alone (no velocities, no gravity, no applied
    loads).  ``p``, ``acc`` (n x 6) and ``v6`` (6): scratch."""
    n = parent.shape[0]
    for i in range(n):
        for a_ in range(6):
            p[i, a_] = 0.0
    for i in range(n - 1, -1, -1):                  # leaves to root: the bias forces
        col0 = ucol[i]
        k = NU[kind[i]] if col0 >= 0 else 0
        if k:
            for j in range(k):
                v6[j] = tau[col0 + j] - _dot6(S, i, j, p, i)
            _joint_solve(Dl, rec, i, k, v6)
            for j in range(k):
                x[col0 + j] = v6[j]                  # D^-1 (tau - S^T p), kept for below
                for a_ in range(6):
                    p[i, a_] += U[i, a_, j] * v6[j]
        q = parent[i]
        if q >= 0:
            d0, d1, d2 = r[i, 0] - r[q, 0], r[i, 1] - r[q, 1], r[i, 2] - r[q, 2]
            f0, f1, f2 = p[i, 3], p[i, 4], p[i, 5]
            p[q, 0] += p[i, 0] + d1 * f2 - d2 * f1
            p[q, 1] += p[i, 1] + d2 * f0 - d0 * f2
            p[q, 2] += p[i, 2] + d0 * f1 - d1 * f0
            p[q, 3] += f0
            p[q, 4] += f1
            p[q, 5] += f2
    for i in range(n):                              # root to leaves: the accelerations
        q = parent[i]
        if q >= 0:
            d0, d1, d2 = r[i, 0] - r[q, 0], r[i, 1] - r[q, 1], r[i, 2] - r[q, 2]
            acc[i, 0], acc[i, 1], acc[i, 2] = acc[q, 0], acc[q, 1], acc[q, 2]
            acc[i, 3] = acc[q, 3] + acc[q, 1] * d2 - acc[q, 2] * d1
            acc[i, 4] = acc[q, 4] + acc[q, 2] * d0 - acc[q, 0] * d2
            acc[i, 5] = acc[q, 5] + acc[q, 0] * d1 - acc[q, 1] * d0
        else:
            for a_ in range(6):
                acc[i, a_] = 0.0
        col0 = ucol[i]
        if col0 >= 0:
            k = NU[kind[i]]
            for j in range(k):
                v6[j] = _dot6(U, i, j, acc, i)
            _joint_solve(Dl, rec, i, k, v6)
            for j in range(k):
                x[col0 + j] -= v6[j]
                for a_ in range(6):
                    acc[i, a_] += S[i, a_, j] * x[col0 + j]


@njit(cache=True, inline="always")
def _schur_cholesky(G, X, rows, nr, A):
    """``A = G_c X^T`` (``G_c M^-1 G_c^T`` on the rows ``rows[:nr]``), its Cholesky factor
    in the lower triangle.  Returns the largest diagonal entry and how many pivots stayed
    above ``PASSAGE_TOLERANCE^2`` of it (``nr`` when all did)."""
    nu = G.shape[1]
    first = 0.0
    for i in range(nr):
        gi = G[int(rows[i])]
        for j in range(i + 1):
            s = 0.0
            for k in range(nu):
                s += gi[k] * X[j, k]
            A[i, j] = s
        first = max(first, A[i, i])
    for k in range(nr):
        d = A[k, k]
        for j in range(k):
            d -= A[k, j] * A[k, j]
        if not d > PASSAGE_TOLERANCE * PASSAGE_TOLERANCE * first:
            return first, k
        A[k, k] = np.sqrt(d)
        for i in range(k + 1, nr):
            s = A[i, k]
            for j in range(k):
                s -= A[i, j] * A[k, j]
            A[i, k] = s / A[k, k]
    return first, nr


@njit(**UNCOUNTED)
def constrained_articulated(tree, body, state, loads, motion, work, ud, con, scratch):
    """``ud``: the closed mechanism's ``u'`` by the articulated-body algorithm (the module
    docstring); the groups as ``evaluate.articulated_accelerations`` takes them, ``con``
    the constraints' workspace, ``scratch`` sized by ``constrained.loop_work``.  Returns
    -1, the speed where a degree of freedom has no inertia, -2 when ``ud`` holds NaN or
    Inf, or ``DEPENDENT_ROWS`` outside a run when the independent rows are nearly
    dependent (a singular configuration, which the mass-matrix route decides).  During a
    run (``info[2]``, the rank it holds), rows that no longer span are chosen again, and
    near a singular configuration the weakest are dropped for the evaluation: the motion
    follows its inertia there and the projection after the step puts it back on the
    constraints, as the mass-matrix route does (``loop_solve.PASSAGE_TOLERANCE``)."""
    pivot = articulated_accelerations(tree, body, state, loads, motion, work, ud, scratch)
    if pivot != -1:
        return pivot
    return close_loops(tree, state, motion, work, ud, con, scratch, False)


@njit(cache=True, inline="always")
def close_loops(tree, state, motion, work, ud, con, scratch, live):
    """``ud``, the tree's ``M^-1 f`` left by the articulated-body algorithm (whose
    factors ``work`` holds), corrected to the closed mechanism's ``u'``: the rows of the
    constraints (with ``live``, not those zero at every state:
    ``constraints._constraint_rows``), then the unit solves and the small solve on
    independent rows.  Returns as ``constrained_articulated``."""
    # long: the rows, the unit solves and the small solve share one scratch layout
    parent, kind, _, _, _, _, qoff, uoff, ucol = tree[:9]
    qfull, ufull, udfull = state
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion
    U, Dl = work[3], work[4]
    con_int, con_data, phi, psi, G, gamma, lam, info = con
    constrained_jacobians(con_int, parent, kind, ucol, r, S, JR, JT)
    _constraint_rows(con_int, con_data, ucol, qoff, uoff, qfull, ufull, udfull,
                     R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma, scratch, phi[:0], -1, live)
    m, nu, n = G.shape[0], G.shape[1], parent.shape[0]
    for i in range(m):
        lam[i] = 0.0
    if m == 0:
        info[0], info[1] = 0.0, 1.0
        return -1
    p, acc2 = c_view(scratch, 0, (n, 6)), c_view(scratch, 6 * n, (n, 6))
    at = 12 * n
    X, A = c_view(scratch, at, (m, nu)), c_view(scratch, at + m * nu, (m, m))
    at += m * nu + m * m
    res, rows, Rd = (c_view(scratch, at, (m,)), c_view(scratch, at + m, (m,)),
                     c_view(scratch, at + 2 * m, (m,)))
    beta, v6 = c_view(scratch, at + 3 * m, (m,)), c_view(scratch, at + 4 * m, (6,))
    index = c_view(scratch, at + 4 * m + 6 + nu * m, (m,))
    rec = c_view(scratch, at + 5 * m + 6 + nu * m, (n,))
    reciprocals(kind, ucol, Dl, rec)
    mc = residual_rows(G, gamma, ud, res, index)    # rows of zeros are never chosen
    GT = c_view(scratch, at + 4 * m + 6, (nu, mc))
    keep = int(info[2])
    chosen = keep >= 0 and info[ROWS] == keep
    for attempt in range(2):
        if attempt == 0 and chosen:                 # a run: the projection's rows
            nr = keep
            for j in range(nr):
                rows[j] = info[ROWS + 1 + j]
        else:                                       # the independent rows by QR
            for i in range(nu):
                for j in range(mc):
                    GT[i, j] = G[int(index[j]), i]
            nr = pivoted_qr(GT, RANK_TOLERANCE, rows, Rd, beta)[0]
            for j in range(nr):
                rows[j] = index[int(rows[j])]
            if keep >= 0:
                nr = min(nr, keep)
        for j in range(nr):                         # X_j = M^-1 G_cj^T
            unit_solve(parent, kind, ucol, r, S, U, Dl, rec, G[int(rows[j])], X[j], p,
                       acc2, v6)
        first, good = _schur_cholesky(G, X, rows, nr, A)
        if good == nr:
            break
        if attempt == 0 and chosen:
            continue                                # those rows no longer span: choose
        if keep < 0:
            return DEPENDENT_ROWS                   # outside a run: M decides
        nr = good       # a run near a singular configuration: inertia decides the rest
        break
    for i in range(nr):                             # A y = res_c, y into Rd
        s = res[int(rows[i])]
        for j in range(i):
            s -= A[i, j] * Rd[j]
        Rd[i] = s / A[i, i]
    for i in range(nr - 1, -1, -1):
        s = Rd[i]
        for j in range(i + 1, nr):
            s -= A[j, i] * Rd[j]
        Rd[i] = s / A[i, i]
    for j in range(nr):
        lam[int(rows[j])] = Rd[j]
        for k in range(nu):
            ud[k] += X[j, k] * Rd[j]
    info[0] = nr
    info[1] = A[nr - 1, nr - 1] / np.sqrt(first) if nr and first > 0 else 1.0
    for k in range(nu):
        if not np.isfinite(ud[k]):
            return -2
    return -1


@njit(**UNCOUNTED)
def constrained_articulated_packed(fb, ib, forces, con_int, cf, q, u):
    """Scatter ``q``, ``u``, then ``constrained_articulated`` on the packed arrays (the
    integer buffer stands for the offset table) and the constraints' buffer (the Python
    entry point of a large closed mechanism; ``u'`` in the ``ud`` view), its kinematics
    those of the tree's entry (``evaluate.motion_and_loads``); ``WRONG_SIZE`` for ``q`` or
    ``u`` of another size."""
    t = ib
    if not (contiguous(q, t[7]) and contiguous(u, t[1])):
        return WRONG_SIZE
    _scatter(fb, ib, t, q, u)
    tree, body, state, loads, _, kin, jourdain, art, scratch = _views(fb, ib, t, forces)
    mass, com, inertia, _, gravity = body
    motion_and_loads(tree, body, state, loads, kin, scratch)
    R, r, w, v, alpha, a, _, _, S, F, N = kin
    IA, pA, cb, U, Dl, acc = art[2:8]
    ud = jourdain[3]
    pivot = outcome(articulated_body(mass, com, inertia, tree[0], tree[1], tree[8], R, r, w,
                                     alpha, a, S, F, N, IA, pA, cb, U, Dl, acc, ud, scratch),
                    ud)
    if pivot != -1:
        return pivot
    return close_loops(tree, state, kin, art[2:8], ud, con_views(con_int, cf, t[1]), scratch,
                       True)

"""Forward dynamics of a tree closed by loop constraints, and the projection of a state
back onto the constraint manifold.

The equations (Jourdain with multipliers): ``M u' = f + G^T lam``, ``G u' = gamma``.
They are solved by the range-space (Schur complement) method: with ``M = L L^T``
(Cholesky, as for trees) and ``u0 = M^-1 f``,

    ``S lam = gamma - G u0``,  ``S = G M^-1 G^T = Y^T Y``,  ``Y = L^-1 G^T``,
    ``u' = u0 + M^-1 G^T lam``.

``S`` is singular when constraints are redundant (a planar loop closed by a spatial
revolute: five equations of rank two).  A rank-revealing (column-pivoted) QR of ``Y``
(``rank_qr``) gives the rank -- pivots above ``loop_solve.RANK_TOLERANCE`` times the first
count -- and the minimum-norm ``lam`` over the rest: ``u'`` is unique whenever the motion
is, ``lam`` is the smallest multiplier vector that produces it.  The QR is of ``Y`` (not
of ``S``, whose singular values are squared) so that the rank decision keeps the digits;
runs, whose rank is known, solve on rows instead (``loop_solve``).  When ``M`` is singular
(a massless link whose motion the constraints fix) the augmented system ``[[M, G^T], [G,
0]]`` is solved by least squares instead.
"""
import numpy as np
from numba import njit

from .constraints import DATA, POINT, ROW_WORK, _constraint_rows, constraint_rows
from .evaluate import jourdain_accelerations
from .inverse import jourdain_by_subspaces
from .joints import coordinate_rates
from .kinematics import walk
from .loop_jacobians import constrained_jacobians
from .loop_solve import (ROWS, augmented_solve, chosen_solve, constrained_solve, rank_of,
                         solve_work)
from .min_norm import min_norm_step
from .packed import WRONG_SIZE, _scatter, _views, contiguous
from .views import CACHED, UNCOUNTED, c_view, untracked
from .internal import internal

#: the projection stops when every position residual is below this (metres for points,
#: dimensionless for directions)
PROJECTION_TOLERANCE = 1e-13
PROJECTION_ITERATIONS = 12


@njit(inline="always")
def constrained_accelerations(tree, body, state, loads, motion, jourdain, con, scratch):
    """Jourdain's ``M``, ``f`` (``evaluate.jourdain_accelerations``), the constraint rows at
    the same state, then the constrained ``u'`` into ``jourdain[3]``.  ``con``:
    ``(con_int, con_data, phi, psi, G, gamma, lam, info)``.  Returns as
    ``jourdain_accelerations`` (-1 done; a pivot where neither ``M`` nor the augmented
    system determines ``u'``; -2 non-finite)."""
    pivot = jourdain_accelerations(tree, body, state, loads, motion, jourdain, scratch)
    return close_by_mass_matrix(pivot, tree, state, motion, jourdain, con, scratch, False)


@njit(inline="always")
def close_by_mass_matrix(pivot, tree, state, motion, jourdain, con, scratch, live):
    """The tree's ``M``, ``f``, ``L`` and ``ud = M^-1 f`` (``pivot``, as
    ``jourdain_accelerations`` returned it) corrected to the closed mechanism's ``u'``:
    the constraint rows at the state (the Jacobians of the frames they join already in
    ``JR``, ``JT``), then the rank-tolerant solve; with ``live``, the rows that are zero
    at every state are not evaluated (``constraints._constraint_rows``).  Returns as
    ``constrained_accelerations``."""
    M, f, L, ud = jourdain
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion
    qfull, ufull, udfull = state
    con_int, con_data, phi, psi, G, gamma, lam, info = con
    # the scratch is free once M and f are made (loop_work: sized for the rows and solves)
    if pivot == -1 and info[2] > 0 and info[ROWS] == info[2]:
        # a run: only the rows its last projection chose, and the solve on them
        _constraint_rows(con_int, con_data, tree[8], tree[6], tree[7], qfull, ufull,
                         udfull, R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma, scratch,
                         info[ROWS + 1:], int(info[ROWS]), False)
        if chosen_solve(L, ud, G, gamma, lam, info, scratch):
            return _finite(ud)
        info[ROWS] = -1.0            # no longer independent: every row, pivoted, until the
                                     # next projection chooses again
    _constraint_rows(con_int, con_data, tree[8], tree[6], tree[7], qfull, ufull, udfull,
                     R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma, scratch, phi[:0], -1, live)
    if pivot >= 0:
        for k in range(ud.shape[0]):
            ud[k] = f[k]
        if not augmented_solve(M, f, G, gamma, ud, lam, info):
            return pivot
    elif pivot == -1:
        constrained_solve(M, L, ud, G, gamma, lam, info, scratch)
    return _finite(ud)


@njit(cache=True, inline="always")
def _finite(ud):
    """-1 (done) when every entry of ``ud`` is finite, else -2."""
    for k in range(ud.shape[0]):
        if not np.isfinite(ud[k]):
            return -2
    return -1


@internal(cache=True)
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
        if anc_ptr.shape[0] == 0:        # the articulated-body layout: no full Jacobians
            constrained_jacobians(con_int, parent, kind, ucol, r, S, JR, JT)
        _constraint_rows(con_int, con_data, ucol, qoff, uoff, qfull, ufull, udfull,
                         R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma, scratch, phi[:0],
                         -1, False)
        if residual_norm(phi) <= PROJECTION_TOLERANCE:
            break
        if steps == PROJECTION_ITERATIONS:
            return -1
        min_norm_step(G, phi, int(info[2]), du, info, scratch)
        coordinate_rates(y[:nq], du, slots, dq)
        for k in range(nq):
            y[k] -= dq[k]
        for s in range(quats.shape[0]):
            i = quats[s]
            nrm = np.sqrt(y[i] ** 2 + y[i + 1] ** 2 + y[i + 2] ** 2 + y[i + 3] ** 2)
            for k in range(4):
                y[i + k] /= nrm
        steps += 1
    ratio = min_norm_step(G, psi, int(info[2]), du, info, scratch)
    for k in range(nu):
        y[nq + k] -= du[k]
    if info[2] >= 0:                 # a run: the rank here, for the next step's stages
        if ratio < 1e-3:             # near a singular configuration: decide it exactly
            rank, ratio = rank_of(G)
            info[2] = rank
            info[3] = min(info[3], rank)
        info[4] = min(info[4], ratio)
    return steps


@njit(_nrt=True, **CACHED)
def project_state_call(y, nq, slots, quats, free_q, free_u, tree, state, motion, con, scratch):
    """``project_state`` as a compiled entry point, for Python (one state) and the compiled
    loops (``routes.finish_step``).  Counted, explicitly: it allocates, and a callee
    inherits an uncounted caller's mode."""
    return project_state(y, nq, slots, quats, free_q, free_u, tree, state, motion, con,
                         scratch)


@njit(**CACHED)
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


def loop_work(n, nu, m):
    """Floats of the model's scratch a closed mechanism's evaluation and projection take
    after the tree's kernels (``n`` frames, ``nu`` free speeds, at most ``m`` constraint
    rows), by either route (``loop_articulated.articulated_work``)."""
    return max(ROW_WORK + m * nu, solve_work(nu, m),
               13 * n + 2 * nu * m + m * m + 6 * m + 6)


def con_floats(nprim, m, nu):
    """Floats of the constraints' buffer (``con_views``)."""
    return nprim * DATA + 4 * m + m * nu + 7 + m


@njit(inline="always", **UNCOUNTED)
def con_views(con_int, cf, nu):
    """The constraints' workspace ``(con_int, con_data, phi, psi, G, gamma, lam, info)``
    with its float arrays as views of the one buffer ``cf``, in that order."""
    nprim = con_int.shape[0]
    m = 0
    for k in range(nprim):
        m += 3 if con_int[k, 0] == POINT else 1
    cf = untracked(cf)
    at = nprim * DATA
    return (con_int, c_view(cf, 0, (nprim, DATA)), cf[at:at + m], cf[at + m:at + 2 * m],
            c_view(cf, at + 2 * m, (m, nu)), cf[at + 2 * m + m * nu:at + 3 * m + m * nu],
            cf[at + 3 * m + m * nu:at + 4 * m + m * nu],
            cf[at + 4 * m + m * nu:at + 5 * m + m * nu + 7])


@njit(**UNCOUNTED)
def constrained_accelerations_packed(fb, ib, forces, con_int, cf, q, u):
    """Scatter ``q``, ``u``, then ``constrained_accelerations`` on the packed arrays
    (``kernels.packed``; the integer buffer stands for the offset table) and the
    constraints' buffer (``con_views``), ``M`` and ``f`` by the motion subspaces as the
    tree's per-call entries make them (``inverse.jourdain_by_subspaces``, which leaves
    the full Jacobians out: those of the frames the loops join are made here): the
    Python entry point of a closed mechanism's
    forward dynamics and multipliers (same return value, or ``WRONG_SIZE`` for ``q`` or
    ``u`` of another size; ``u'`` in the ``ud`` view, ``lam`` in the constraints'
    workspace)."""
    t = ib
    if not (contiguous(q, t[7]) and contiguous(u, t[1])):
        return WRONG_SIZE
    _scatter(fb, ib, t, q, u)
    tree, body, state, loads, _, motion, jourdain, art, scratch = _views(fb, ib, t, forces)
    pivot = jourdain_by_subspaces(tree, body, state, loads, motion, jourdain, art[8], art[2],
                                  scratch)
    constrained_jacobians(con_int, tree[0], tree[1], tree[8], motion[1], motion[8],
                          motion[6], motion[7])
    return close_by_mass_matrix(pivot, tree, state, motion, jourdain,
                                con_views(con_int, cf, t[1]), scratch, True)

"""The Jourdain form of a tree with flexible bodies in compiled code: the tree's kernels
with the flexible bodies massless, then each body's floating-frame terms
(``kernels.flexible_body``) and the elements at its nodes (``kernels.flexible_forces``),
over the *extended* speeds (the tree's, then the modal ones), projected on the model's
speeds by the constant map ``P`` and solved; the same equations as
``algorithms.flexible_dynamics`` (its docstring has them).

The model's state sits in joint space extended by the modal coordinates: ``qfull``,
``ufull``, ``udfull`` hold the tree's entries, then (from ``qm0``, ``um0``) each flexible
body's ``eta``, ``eta'``.  A node frame's chain coordinates are rows of ``D`` times
``eta`` (and ``eta'``), written first.  Each step below takes the hook ``h`` and a float
array ``x`` (for the element type of its views) and reads its arrays from the hook
(``kernels.flexible_views``): ``fint`` a row per body (``flexible_forces.FROW``
columns), ``fdata`` its numbers (``flexible_body.body_layout``), ``chain`` (the tree's
``q`` and ``u`` entries of each chain coordinate), ``P`` as compressed rows (``pptr``,
``pidx``, ``pval``; extended x model), ``flags`` (``FLAGS``), the extended ``M_x``,
``A_x``, ``f_x``, the model's ``M``, ``A``, ``f``, and scratch.  The steps are functions
of their own, called one after another by the model's C function
(``kernels.flexible_entry``): numba compiles each once and the function links them.
"""
import numpy as np
from numba import njit

from .dynamics import jourdain_terms
from .evaluate import drop_velocity_products, kinematics_and_loads
from .flexible_body import axial_row, body_equations
from .flexible_forces import FRAME, MODES, OFF, Q0, QE, U0, X0, element_forces
from .flexible_views import (AA, AX, CHAIN, DMAP, EDATA, EINT, FDATA, FF, FINT, FLAGS,
                             FWORK, FX, MM, MX, PIDX, PPTR, PVAL, QFULL, SCRATCH, SWITCH,
                             UDFULL, UFULL,
                             body_views, buffers, jourdain_views, loads_views, motion_views,
                             one, tree_views, two)
from .views import UNCOUNTED, c_view
from .internal import internal

#: ``flags`` entries: the stiffening on, tree speeds, first modal entry of ``qfull`` and
#: ``ufull``, any body's axial stiffness coupled, the map ``P`` not the identity, modal
#: coordinates; then offsets into ``fwork``: body matrix, body forces, body scratch,
#: element forces on bodies (``qe``), true angular velocities, element forces on the
#: tree's speeds (``fe``), element scratch, the LU copy, the B block and its product,
#: ``K_a eta``, small vectors
(STIFF, NUT, QM0, UM0, COUPLED, MAPPED, NMODAL, W_MB, W_Q, W_BODY, W_QE, W_OM, W_FE, W_EL,
 W_LU, W_BC, W_AX, W_VEC) = range(18)
FLAGS_SIZE = 18


@njit(inline="always", **UNCOUNTED)
def chain_state(qfull, ufull, udfull, chain, D, qm0, um0):
    """Each node frame's chain coordinate and speed from ``eta``, ``eta'`` (rows of
    ``D``); its rate zero (the Jourdain terms are at ``u' = 0``)."""
    for c in range(chain.shape[0]):
        aq = 0.0
        au = 0.0
        for k in range(D.shape[1]):
            d = D[c, k]
            if d != 0.0:
                aq += d * qfull[qm0 + k]
                au += d * ufull[um0 + k]
        qfull[chain[c, 0]] = aq
        ufull[chain[c, 1]] = au
        udfull[chain[c, 1]] = 0.0


@internal(**UNCOUNTED)
def kinematics_step(h, x, forces):
    """The chains from ``eta``, then the tree's kinematics and loads at the true speeds;
    each body's true angular velocity (body components) kept, the element forces
    zeroed.  ``forces``: None or True (the tree's force elements)."""
    fb, ib = buffers(h, x)
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx = tree_views(fb, ib)
    mass, com, inertia, has_inertia, gravity = body_views(fb, ib)
    (load_body, load_point, load_force, load_moment, load_in_body, tforces, force_data,
     switches) = loads_views(fb, ib, forces)
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion_views(fb, ib)
    qfull, ufull, udfull = one(h, QFULL, x), one(h, UFULL, x), one(h, UDFULL, x)
    flags, fint, fwork = one(h, FLAGS, h), two(h, FINT, h), one(h, FWORK, x)
    chain_state(qfull, ufull, udfull, two(h, CHAIN, h), two(h, DMAP, x), flags[QM0],
                flags[UM0])
    kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr,
                         anc_idx, mass, com, gravity, qfull, ufull, udfull, load_body,
                         load_point, load_force, load_moment, load_in_body, tforces,
                         force_data, switches, R, r, w, v, alpha, a, JR, JT, S, F, N,
                         one(h, SCRATCH, x))
    at = flags[W_OM]
    for b in range(fint.shape[0]):
        i = fint[b, FRAME]
        for k in range(3):
            fwork[at + 3 * b + k] = (R[i, 0, k] * w[i, 0] + R[i, 1, k] * w[i, 1]
                                     + R[i, 2, k] * w[i, 2])
    for k in range(flags[W_QE], flags[W_OM]):
        fwork[k] = 0.0
    for k in range(flags[W_FE], flags[W_EL]):
        fwork[k] = 0.0


@internal(**UNCOUNTED)
def element_step(h, x):
    """The loads and force elements at the flexible bodies' points (true speeds)."""
    fb, ib = buffers(h, x)
    tree = tree_views(fb, ib)
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion_views(fb, ib)
    flags, fwork = one(h, FLAGS, h), one(h, FWORK, x)
    element_forces(two(h, EINT, h), one(h, EDATA, x), two(h, FINT, h), one(h, QFULL, x),
                   one(h, UFULL, x), R, r, w, v, JR, JT, tree[9], tree[10],
                   fwork[flags[W_FE]:flags[W_EL]], fwork[flags[W_QE]:flags[W_OM]],
                   fwork[flags[W_EL]:flags[W_LU]])


@internal(**UNCOUNTED)
def bias_step(h, x):
    """The bias accelerations (without velocity products when the gyroscopic effect is
    off) and the tree's Jourdain terms; ``M_x``, ``f_x`` start from them (and the
    element forces on the tree's speeds)."""
    fb, ib = buffers(h, x)
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx = tree_views(fb, ib)
    mass, com, inertia, has_inertia, gravity = body_views(fb, ib)
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion_views(fb, ib)
    Mt, ft, Lt = jourdain_views(fb, ib)
    qfull, ufull, udfull = one(h, QFULL, x), one(h, UFULL, x), one(h, UDFULL, x)
    scratch = one(h, SCRATCH, x)
    if h[SWITCH] == 0:                     # the gyroscopic effect off
        drop_velocity_products(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr,
                               anc_idx, qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT,
                               S, scratch)
    jourdain_terms(mass, com, inertia, has_inertia, R, r, w, alpha, a, JR, JT, anc_ptr,
                   anc_idx, parent, F, N, Mt, ft, scratch)
    flags, fwork = one(h, FLAGS, h), one(h, FWORK, x)
    Mx, fx = two(h, MX, x), one(h, FX, x)
    nut, nux, fe = flags[NUT], fx.shape[0], flags[W_FE]
    for i in range(nux):
        fx[i] = ft[i] + fwork[fe + i] if i < nut else fwork[fe + i]
        for j in range(nux):
            Mx[i, j] = Mt[i, j] if i < nut and j < nut else 0.0


@internal(**UNCOUNTED)
def bodies_step(h, x):
    """Each body's ``B^T M_b B`` and ``B^T (Q + element forces)`` into ``M_x``, ``f_x``
    (``B`` only on the frame's ancestor columns and the body's modal ones), then
    ``A_x = M_x`` plus the geometric stiffness's part in ``u'`` (``K_a eta`` times the
    frame's ``a_x`` row)."""
    # long: each body's terms, its B map on the ancestors' columns and the stiffening row
    # in one pass over the bodies (one kernel: see body_equations)
    fb, ib = buffers(h, x)
    tree = tree_views(fb, ib)
    anc_ptr, anc_idx = tree[9], tree[10]
    gravity = body_views(fb, ib)[4]
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion_views(fb, ib)
    qfull, ufull = one(h, QFULL, x), one(h, UFULL, x)
    fint, fdata, flags, fwork = two(h, FINT, h), one(h, FDATA, x), one(h, FLAGS, h), \
        one(h, FWORK, x)
    Mx, Ax, fx = two(h, MX, x), two(h, AX, x), one(h, FX, x)
    for b in range(fint.shape[0]):
        i, n, q0, u0, x0 = fint[b, FRAME], fint[b, MODES], fint[b, Q0], fint[b, U0], \
            fint[b, X0]
        nb6 = 6 + n
        na = anc_ptr[i + 1] - anc_ptr[i]
        Mb = c_view(fwork, flags[W_MB], (nb6, nb6))
        Q = fwork[flags[W_Q]:flags[W_Q] + nb6]
        vec = fwork[flags[W_VEC]:flags[W_VEC] + 12]
        g, bias, omega = vec[0:3], vec[3:9], vec[9:12]
        Ri = R[i]
        for k in range(3):
            g[k] = Ri[0, k] * gravity[0] + Ri[1, k] * gravity[1] + Ri[2, k] * gravity[2]
            bias[k] = Ri[0, k] * a[i, 0] + Ri[1, k] * a[i, 1] + Ri[2, k] * a[i, 2]
            bias[3 + k] = (Ri[0, k] * alpha[i, 0] + Ri[1, k] * alpha[i, 1]
                           + Ri[2, k] * alpha[i, 2])
            omega[k] = Ri[0, k] * w[i, 0] + Ri[1, k] * w[i, 1] + Ri[2, k] * w[i, 2]
        om = flags[W_OM] + 3 * b
        body_equations(fdata, fint[b, OFF], n, qfull[q0:q0 + n], ufull[u0:u0 + n], omega,
                       g, bias, fwork[om:om + 3], h[SWITCH] != 0, flags[STIFF] != 0, Mb, Q,
                       fwork[flags[W_BODY]:flags[W_QE]])
        at = flags[W_QE] + fint[b, QE]
        for k in range(nb6):
            Q[k] += fwork[at + k]
        # Bc: the rigid rows of B on the ancestor columns (R^T JT, R^T JR); H = Mb6 Bc
        Bc = c_view(fwork, flags[W_BC], (6, na))
        H = c_view(fwork, flags[W_BC] + 6 * na, (nb6, na))
        for c in range(na):
            col = anc_idx[anc_ptr[i] + c]
            for k in range(3):
                Bc[k, c] = (Ri[0, k] * JT[i, 0, col] + Ri[1, k] * JT[i, 1, col]
                            + Ri[2, k] * JT[i, 2, col])
                Bc[3 + k, c] = (Ri[0, k] * JR[i, 0, col] + Ri[1, k] * JR[i, 1, col]
                                + Ri[2, k] * JR[i, 2, col])
            for rr in range(nb6):
                acc = 0.0
                for k in range(6):
                    acc += Mb[rr, k] * Bc[k, c]
                H[rr, c] = acc
        # M_x += B^T Mb B over the columns (ancestors, then modal), f_x += B^T Q
        for c in range(na + n):
            ec = anc_idx[anc_ptr[i] + c] if c < na else x0 + c - na
            acc = 0.0
            if c < na:
                for k in range(6):
                    acc += Bc[k, c] * Q[k]
            else:
                acc = Q[6 + c - na]
            fx[ec] += acc
            for d in range(na + n):
                ed = anc_idx[anc_ptr[i] + d] if d < na else x0 + d - na
                acc = 0.0
                if c < na:
                    for k in range(6):
                        acc += Bc[k, c] * (H[k, d] if d < na else Mb[k, 6 + d - na])
                else:
                    acc = H[6 + c - na, d] if d < na else Mb[6 + c - na, 6 + d - na]
                Mx[ec, ed] += acc
    for i in range(Mx.shape[0]):
        for j in range(Mx.shape[0]):
            Ax[i, j] = Mx[i, j]
    if flags[COUPLED]:
        for b in range(fint.shape[0]):
            i, n, q0, x0 = fint[b, FRAME], fint[b, MODES], fint[b, Q0], fint[b, X0]
            ka = fwork[flags[W_AX]:flags[W_AX] + n]
            axial_row(fdata, fint[b, OFF], n, qfull[q0:q0 + n], ka)
            Ri = R[i]
            for m in range(anc_ptr[i], anc_ptr[i + 1]):
                col = anc_idx[m]
                b0 = Ri[0, 0] * JT[i, 0, col] + Ri[1, 0] * JT[i, 1, col] \
                    + Ri[2, 0] * JT[i, 2, col]
                for k in range(n):
                    Ax[x0 + k, col] += ka[k] * b0


@internal(**UNCOUNTED)
def model_step(h, x, with_mass):
    """The model's ``A = P^T A_x P``, ``f = P^T f_x`` (and ``M = P^T M_x P`` when
    ``with_mass``): copies when ``P`` is the identity."""
    flags = one(h, FLAGS, h)
    Mx, Ax, fx = two(h, MX, x), two(h, AX, x), one(h, FX, x)
    M, A, f = two(h, MM, x), two(h, AA, x), one(h, FF, x)
    nux, nu = fx.shape[0], f.shape[0]
    if not flags[MAPPED]:
        for i in range(nu):
            f[i] = fx[i]
            for j in range(nu):
                A[i, j] = Ax[i, j]
                if with_mass:
                    M[i, j] = Mx[i, j]
        return
    pptr, pidx, pval = one(h, PPTR, h), one(h, PIDX, h), one(h, PVAL, x)
    for i in range(nu):
        f[i] = 0.0
    for e in range(nux):
        for z in range(pptr[e], pptr[e + 1]):
            f[pidx[z]] += pval[z] * fx[e]
    T = c_view(one(h, FWORK, x), flags[W_LU], (nux, nu))
    for which in range(2 if with_mass else 1):
        X, Y = (Ax, A) if which == 0 else (Mx, M)
        for e in range(nux):                   # T = X P
            for j in range(nu):
                T[e, j] = 0.0
            for e2 in range(nux):
                xe = X[e, e2]
                if xe != 0.0:
                    for z in range(pptr[e2], pptr[e2 + 1]):
                        T[e, pidx[z]] += xe * pval[z]
        for i in range(nu):                    # Y = P^T T
            for j in range(nu):
                Y[i, j] = 0.0
        for e in range(nux):
            for z in range(pptr[e], pptr[e + 1]):
                p, val = pidx[z], pval[z]
                for j in range(nu):
                    Y[p, j] += val * T[e, j]


@internal(**UNCOUNTED)
def lu_solve(A, b, x, LU):
    """``x = A^-1 b`` by LU with partial pivoting (``LU``: scratch of ``A``'s size).
    Returns -1, or the column where the pivot is exactly zero (a singular matrix, as
    LAPACK's ``getrf`` reports it)."""
    n = b.shape[0]
    for i in range(n):
        x[i] = b[i]
        for j in range(n):
            LU[i, j] = A[i, j]
    for k in range(n):
        p = k
        big = abs(LU[k, k])
        for i in range(k + 1, n):
            if abs(LU[i, k]) > big:
                big = abs(LU[i, k])
                p = i
        if big == 0.0:
            return k
        if p != k:
            for j in range(n):
                LU[k, j], LU[p, j] = LU[p, j], LU[k, j]
            x[k], x[p] = x[p], x[k]
        inv = 1.0 / LU[k, k]
        for i in range(k + 1, n):
            l_ = LU[i, k] * inv
            if l_ != 0.0:
                LU[i, k] = l_
                for j in range(k + 1, n):
                    LU[i, j] -= l_ * LU[k, j]
                x[i] -= l_ * x[k]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for j in range(i + 1, n):
            s -= LU[i, j] * x[j]
        x[i] = s / LU[i, i]
    return -1


@internal(**UNCOUNTED)
def solve_step(h, x):
    """``x = A^-1 f`` (the model's ``u'``); returns as ``lu_solve``."""
    nu = x.shape[0]
    flags = one(h, FLAGS, h)
    return lu_solve(two(h, AA, x), one(h, FF, x), x,
                    c_view(one(h, FWORK, x), flags[W_LU], (nu, nu)))

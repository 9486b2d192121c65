"""Constraint equations of closed loops: residuals ``Phi``, their rates, the Jacobian ``G``
and the acceleration term ``gamma`` (step 3 of the textbook: "position vectors and
constraint equations").

Every loop joint is written as a few *primitive* constraints between a point or vector of
a parent frame ``p`` and one of a child frame ``c`` (frame -1 is the ground):

=========  ====  ==============================================================
``POINT``  3     ``P_c - P_p = 0``: the two points coincide (world components)
``PERP``   1     ``a . b = 0``: vector ``a`` of p stays perpendicular to ``b`` of c
``SLIDE``  1     ``(P_c - P_p) . n = 0``: P_c stays in the plane through P_p normal to ``n`` of p
``DIST``   1     ``(|P_c - P_p|^2 - L^2) / 2 = 0``: a massless rod of length L
``COUPLE`` 1     ``q_a - ratio q_b - offset = 0``: two 1-DoF coordinates geared together
=========  ====  ==============================================================

Each residual's time derivative is exactly ``G u`` (plus the drives' part), with ``G``
built from the frames' Jacobians (``kernels.kinematics``): the Newton-Raphson of the
assembly and of the projection uses the true derivative.  ``gamma = -Phi''`` at ``u' = 0``
(from the bias accelerations the kinematics leave in ``alpha``, ``a``), so that the
accelerations satisfy ``G u' = gamma``.  All in world components.

``con_int[k]``: kind, parent frame, child frame, then (``COUPLE``) the follower's and the
leader's frame.  ``con_data[k]``: ``s_p`` (3, point in p's body axes), ``s_c`` (3),
vector ``A`` (3, body axes of p), vector ``B`` (3, body axes of c), then the length or the
ratio, then the offset.
"""
import numpy as np
from numba import njit

from .joints import REVOLUTE
from .linalg3 import cross_to
from .views import UNCOUNTED, c_view
from .internal import internal

POINT, PERP, SLIDE, DIST, COUPLE = 0, 1, 2, 3, 4
#: rows each primitive contributes
ROWS = np.array((3, 1, 1, 1, 1), np.int64)
#: floats of ``con_data`` per primitive
DATA = 14


@internal(forceinline=True, **UNCOUNTED)
def _point(i, s, R, r, w, v, alpha, a, rho, P, vP, aP, t1, t2):
    """World offset ``rho = R s``, position, velocity and bias acceleration of the point
    ``s`` (body axes) of frame ``i`` (-1: the ground, at rest)."""
    if i < 0:
        for k in range(3):
            rho[k] = s[k]
            P[k] = s[k]
            vP[k] = 0.0
            aP[k] = 0.0
        return
    for k in range(3):
        rho[k] = R[i, k, 0] * s[0] + R[i, k, 1] * s[1] + R[i, k, 2] * s[2]
        P[k] = r[i, k] + rho[k]
    cross_to(w[i], rho, t1)
    cross_to(w[i], t1, t2)
    for k in range(3):
        vP[k] = v[i, k] + t1[k]
    cross_to(alpha[i], rho, t1)
    for k in range(3):
        aP[k] = a[i, k] + t1[k] + t2[k]


@internal(forceinline=True, **UNCOUNTED)
def _vector(i, s, R, out):
    if i < 0:
        for k in range(3):
            out[k] = s[k]
        return
    for k in range(3):
        out[k] = R[i, k, 0] * s[0] + R[i, k, 1] * s[1] + R[i, k, 2] * s[2]


@internal(forceinline=True, **UNCOUNTED)
def _add_point_row(G, Gabs, row, i, rho, e, sign, JT, JR):
    """``G[row] += sign * e^T J_P`` for the point at world offset ``rho`` of frame i:
    ``J_P = JT - [rho]x JR`` (a point's velocity ``v + w x rho``); ``Gabs`` sums the
    terms' sizes (``_clean``)."""
    if i < 0:
        return
    for col in range(G.shape[1]):
        jr0, jr1, jr2 = JR[i, 0, col], JR[i, 1, col], JR[i, 2, col]
        j0 = JT[i, 0, col] + jr1 * rho[2] - jr2 * rho[1]
        j1 = JT[i, 1, col] + jr2 * rho[0] - jr0 * rho[2]
        j2 = JT[i, 2, col] + jr0 * rho[1] - jr1 * rho[0]
        term = e[0] * j0 + e[1] * j1 + e[2] * j2
        G[row, col] += sign * term
        Gabs[row, col] += abs(term)


@internal(forceinline=True, **UNCOUNTED)
def _add_point_rows(G, Gabs, row, i, rho, sign, JT, JR):
    """``G[row:row + 3] += sign * J_P``: ``_add_point_row`` for the three world axes at
    once (the point's Jacobian column computed once, not once per axis)."""
    if i < 0:
        return
    for col in range(G.shape[1]):
        jr0, jr1, jr2 = JR[i, 0, col], JR[i, 1, col], JR[i, 2, col]
        j0 = JT[i, 0, col] + jr1 * rho[2] - jr2 * rho[1]
        j1 = JT[i, 1, col] + jr2 * rho[0] - jr0 * rho[2]
        j2 = JT[i, 2, col] + jr0 * rho[1] - jr1 * rho[0]
        G[row, col] += sign * j0
        G[row + 1, col] += sign * j1
        G[row + 2, col] += sign * j2
        Gabs[row, col] += abs(j0)
        Gabs[row + 1, col] += abs(j1)
        Gabs[row + 2, col] += abs(j2)


@internal(forceinline=True, **UNCOUNTED)
def _add_rotation_row(G, Gabs, row, i, e, sign, JR):
    """``G[row] += sign * e^T JR_i``."""
    if i < 0:
        return
    for col in range(G.shape[1]):
        term = e[0] * JR[i, 0, col] + e[1] * JR[i, 1, col] + e[2] * JR[i, 2, col]
        G[row, col] += sign * term
        Gabs[row, col] += abs(term)


@njit(cache=True, inline="always")
def _clean(G, Gabs):
    """Entries of ``G`` that are differences of equal terms (a loop joint between two
    frames that a speed moves alike) are set to exactly zero: the round-off left there
    would otherwise count as a constraint when no free speed moves the joint."""
    for row in range(G.shape[0]):
        for col in range(G.shape[1]):
            if abs(G[row, col]) <= 64 * 2.220446049250313e-16 * Gabs[row, col]:
                G[row, col] = 0.0


@njit(cache=True, inline="always")
def _holds_chosen(row, count, chosen, nchosen):
    """Whether one of the rows ``chosen[:nchosen]`` lies in ``row .. row + count - 1``."""
    for j in range(nchosen):
        if row <= chosen[j] < row + count:
            return True
    return False


def constraint_count(con_int):
    """Rows of ``G`` the primitives ``con_int`` give."""
    return int(sum(ROWS[k] for k in con_int[:, 0])) if len(con_int) else 0


@internal(cache=True, _nrt=True)   # allocates: counted even under an uncounted caller
def constraint_rows(con_int, con_data, ucol, qoff, uoff, qfull, ufull, udfull,
                    R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma):
    """Fill the residuals ``phi`` (positions), ``psi`` (their rates), the Jacobian ``G``
    (rows x free speeds) and ``gamma``, after a kinematic walk at the state (bias
    accelerations in ``alpha``, ``a``: free speed rates zero, drives' rates given)."""
    _constraint_rows(con_int, con_data, ucol, qoff, uoff, qfull, ufull, udfull, R, r, w, v,
                     alpha, a, JR, JT, phi, psi, G, gamma,
                     np.empty(ROW_WORK + G.shape[0] * G.shape[1]), phi[:0], -1, False)


#: floats of scratch ``_constraint_rows`` takes besides ``G``'s size
ROW_WORK = 57


@internal(**UNCOUNTED)
def _constraint_rows(con_int, con_data, ucol, qoff, uoff, qfull, ufull, udfull,
                     R, r, w, v, alpha, a, JR, JT, phi, psi, G, gamma, work, chosen, nchosen,
                     live):
    """``constraint_rows`` in the scratch ``work`` (one allocation by the caller: the
    vectors below are views of it, which cost no allocation each).  With ``nchosen`` >= 0,
    only the primitives holding one of the rows ``chosen[:nchosen]`` (row numbers, as
    floats) are evaluated, the other rows left zero (a run solves on the rows it last
    chose); with ``nchosen`` -1, every row (``chosen`` unread: ``phi[:0]`` will do).
    With ``live``, the primitives whose rows are zero at every state (``con_int[:, 5]``
    0: ``compiled.constraint_packing.moves``) are not evaluated: their ``G`` rows and
    ``gamma`` are zero, their ``phi`` and ``psi`` set to zero too (the accelerations'
    entries do not read them)."""
    # long: one loop over the primitives, each kind's rows written where they are derived
    # (a reader checks a kind's residual, rate, Jacobian and gamma side by side).
    w0, rp, Pp, vp = (c_view(work, 0, (3,)), c_view(work, 3, (3,)), c_view(work, 6, (3,)),
                      c_view(work, 9, (3,)))
    ap, rc, Pc, vc = (c_view(work, 12, (3,)), c_view(work, 15, (3,)), c_view(work, 18, (3,)),
                      c_view(work, 21, (3,)))
    ac, va, vb, axb = (c_view(work, 24, (3,)), c_view(work, 27, (3,)),
                       c_view(work, 30, (3,)), c_view(work, 33, (3,)))
    t1, t2, t3, d = (c_view(work, 36, (3,)), c_view(work, 39, (3,)), c_view(work, 42, (3,)),
                     c_view(work, 45, (3,)))
    dv = c_view(work, 48, (3,))
    Gabs = c_view(work, ROW_WORK, (G.shape[0], G.shape[1]))
    for k in range(3):
        w0[k] = 0.0
    for k in range(G.shape[0]):
        for col in range(G.shape[1]):
            G[k, col] = 0.0
            Gabs[k, col] = 0.0
    row = 0
    for m in range(con_int.shape[0]):
        kind, ip, ic = con_int[m, 0], con_int[m, 1], con_int[m, 2]
        if nchosen >= 0 and not _holds_chosen(row, ROWS[kind], chosen, nchosen):
            row += ROWS[kind]
            continue
        if live and con_int[m, 5] == 0:
            for k in range(ROWS[kind]):
                phi[row + k] = psi[row + k] = gamma[row + k] = 0.0
            row += ROWS[kind]
            continue
        sp, sc = con_data[m, 0:3], con_data[m, 3:6]
        A, B = con_data[m, 6:9], con_data[m, 9:12]
        wp = w[ip] if ip >= 0 else w0
        wc = w[ic] if ic >= 0 else w0
        alp = alpha[ip] if ip >= 0 else w0
        alc = alpha[ic] if ic >= 0 else w0
        if kind == COUPLE:
            fa, fb = con_int[m, 3], con_int[m, 4]
            ratio, offset = con_data[m, 12], con_data[m, 13]
            phi[row] = qfull[qoff[fa]] - ratio * qfull[qoff[fb]] - offset
            psi[row] = ufull[uoff[fa]] - ratio * ufull[uoff[fb]]
            g = 0.0
            if ucol[fa] >= 0:
                G[row, ucol[fa]] += 1.0
            else:
                g -= udfull[uoff[fa]]
            if ucol[fb] >= 0:
                G[row, ucol[fb]] -= ratio
            else:
                g += ratio * udfull[uoff[fb]]
            gamma[row] = g
            row += 1
            continue
        if kind == PERP:
            _vector(ip, A, R, va)
            _vector(ic, B, R, vb)
            # Phi' = (w_p x a).b + a.(w_c x b) = e.(w_c - w_p) with e = b x a
            cross_to(vb, va, axb)
            phi[row] = va[0] * vb[0] + va[1] * vb[1] + va[2] * vb[2]
            rate = 0.0
            for k in range(3):
                rate += axb[k] * (wc[k] - wp[k])
            psi[row] = rate
            _add_rotation_row(G, Gabs, row, ic, axb, 1.0, JR)
            _add_rotation_row(G, Gabs, row, ip, axb, -1.0, JR)
            # Phi'' at u' = 0: e.(alpha_c - alpha_p) + e'.(w_c - w_p), with
            # e' = (w_c x b) x a + b x (w_p x a)
            cross_to(wc, vb, t1)
            cross_to(t1, va, t2)
            cross_to(wp, va, t1)
            cross_to(vb, t1, t3)
            acc = 0.0
            for k in range(3):
                acc += axb[k] * (alc[k] - alp[k]) + (t2[k] + t3[k]) * (wc[k] - wp[k])
            gamma[row] = -acc
            row += 1
            continue
        _point(ip, sp, R, r, w, v, alpha, a, rp, Pp, vp, ap, t1, t2)
        _point(ic, sc, R, r, w, v, alpha, a, rc, Pc, vc, ac, t1, t2)
        for k in range(3):
            d[k] = Pc[k] - Pp[k]
            dv[k] = vc[k] - vp[k]
        if kind == POINT:
            for k in range(3):
                phi[row + k] = d[k]
                psi[row + k] = dv[k]
                gamma[row + k] = -(ac[k] - ap[k])
            _add_point_rows(G, Gabs, row, ic, rc, 1.0, JT, JR)
            _add_point_rows(G, Gabs, row, ip, rp, -1.0, JT, JR)
            row += 3
        elif kind == SLIDE:
            _vector(ip, A, R, va)                          # n, fixed in p
            cross_to(wp, va, t1)                             # n'
            phi[row] = d[0] * va[0] + d[1] * va[1] + d[2] * va[2]
            psi[row] = (dv[0] * va[0] + dv[1] * va[1] + dv[2] * va[2]
                        + d[0] * t1[0] + d[1] * t1[1] + d[2] * t1[2])
            _add_point_row(G, Gabs, row, ic, rc, va, 1.0, JT, JR)
            _add_point_row(G, Gabs, row, ip, rp, va, -1.0, JT, JR)
            cross_to(va, d, t2)                              # d . (w_p x n) = w_p . (n x d)
            _add_rotation_row(G, Gabs, row, ip, t2, 1.0, JR)
            # Phi'' at u' = 0: d''.n + 2 d'.n' + d.(alpha_p x n + w_p x n')
            cross_to(alp, va, t2)
            cross_to(wp, t1, t3)
            acc = 0.0
            for k in range(3):
                acc += (ac[k] - ap[k]) * va[k] + 2.0 * dv[k] * t1[k] + d[k] * (t2[k] + t3[k])
            gamma[row] = -acc
            row += 1
        else:                                              # DIST
            length = con_data[m, 12]
            dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
            phi[row] = 0.5 * (dd - length * length)
            psi[row] = d[0] * dv[0] + d[1] * dv[1] + d[2] * dv[2]
            _add_point_row(G, Gabs, row, ic, rc, d, 1.0, JT, JR)
            _add_point_row(G, Gabs, row, ip, rp, d, -1.0, JT, JR)
            acc = 0.0
            for k in range(3):
                acc += dv[k] * dv[k] + d[k] * (ac[k] - ap[k])
            gamma[row] = -acc
            row += 1
    _clean(G, Gabs)


@internal(forceinline=True, **UNCOUNTED)
def _world(i, A, m, o, R):
    """The vector ``A[m, o:o + 3]``, in frame ``i``'s body axes, in world components
    (``R_i`` times it; itself for the ground, ``i`` -1), as a 3-tuple (registers)."""
    s0, s1, s2 = A[m, o], A[m, o + 1], A[m, o + 2]
    if i < 0:
        return (s0, s1, s2)
    return (R[i, 0, 0] * s0 + R[i, 0, 1] * s1 + R[i, 0, 2] * s2,
            R[i, 1, 0] * s0 + R[i, 1, 1] * s1 + R[i, 1, 2] * s2,
            R[i, 2, 0] * s0 + R[i, 2, 1] * s1 + R[i, 2, 2] * s2)


@internal(forceinline=True, **UNCOUNTED)
def _cross(a, b):
    """``a x b`` of 3-tuples (any frame, both in the same), without ``motion.cross``'s fused
    multiply-adds: the wrenches keep the rounding of the products written out."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@internal(forceinline=True, **UNCOUNTED)
def _apply(i, sign, P, f, mo, R, r, com, F, N):
    """``sign`` times the force ``f`` at the world point ``P`` and the moment ``mo`` (world
    3-tuples), reduced to frame ``i``'s centre of mass and added to its loads ``F[i]``,
    ``N[i]`` (world); nothing for the ground (``i`` -1)."""
    if i < 0:
        return
    c0, c1, c2 = com[i, 0], com[i, 1], com[i, 2]
    t = _cross((P[0] - r[i, 0] - (c0 * R[i, 0, 0] + c1 * R[i, 0, 1] + c2 * R[i, 0, 2]),
                P[1] - r[i, 1] - (c0 * R[i, 1, 0] + c1 * R[i, 1, 1] + c2 * R[i, 1, 2]),
                P[2] - r[i, 2] - (c0 * R[i, 2, 0] + c1 * R[i, 2, 1] + c2 * R[i, 2, 2])), f)
    F[i, 0] += sign * f[0]                              # t: (centre of mass -> P) x f
    F[i, 1] += sign * f[1]
    F[i, 2] += sign * f[2]
    N[i, 0] += sign * (mo[0] + t[0])
    N[i, 1] += sign * (mo[1] + t[1])
    N[i, 2] += sign * (mo[2] + t[2])


@njit(**UNCOUNTED)
def constraint_wrenches(con_int, con_data, parent, kind_of, axis, R, r, lam, F, N, com, out):
    """The loads the multipliers ``lam`` stand for: each primitive's force and moment on
    its child (at the child's point) and the opposite on its parent, added to the
    applied loads ``F``, ``N`` at the centres of mass (world).  ``out[m]``: the force and
    moment on the child of primitive ``m`` at its child point (6, world), for the reactions.
    A ``COUPLE`` row's multiplier is a torque (force) along the follower joint's axis
    between its parent and child, and ``-ratio`` times it along the leader's -- the
    gear mesh's efforts (``parent``, ``kind_of``, ``axis``: the tree's joints; ``out[m]``
    zero).  The 3-vectors are tuples (registers), not arrays: no allocation to compile."""
    row = 0
    zero = (0.0, 0.0, 0.0)
    for m in range(con_int.shape[0]):
        kind, ip, ic = con_int[m, 0], con_int[m, 1], con_int[m, 2]
        lr = lam[row]
        if kind == COUPLE:
            for k in range(6):
                out[m, k] = 0.0
            for side in range(2):
                j = con_int[m, 3 + side]
                e = (1.0 if side == 0 else -con_data[m, 12]) * lr
                va = _world(j, axis, j, 0, R)           # the joint's axis, world
                f, mo = zero, (e * va[0], e * va[1], e * va[2])
                if kind_of[j] != REVOLUTE:
                    f, mo = mo, zero
                P = (r[j, 0], r[j, 1], r[j, 2])
                _apply(j, 1.0, P, f, mo, R, r, com, F, N)
                _apply(parent[j], -1.0, P, f, mo, R, r, com, F, N)
            row += 1
            continue
        x = _world(ic, con_data, m, 3, R)              # the child's point, world
        P = ((r[ic, 0] if ic >= 0 else 0.0) + x[0], (r[ic, 1] if ic >= 0 else 0.0) + x[1],
             (r[ic, 2] if ic >= 0 else 0.0) + x[2])
        f, mo = zero, zero
        if kind == POINT:
            f = (lr, lam[row + 1], lam[row + 2])
            row += 2
        elif kind == PERP:
            mo = _cross(_world(ic, con_data, m, 9, R), _world(ip, con_data, m, 6, R))
            mo = (lr * mo[0], lr * mo[1], lr * mo[2])   # about b x a (see PERP's rows)
        elif kind == SLIDE:
            f = _world(ip, con_data, m, 6, R)
            f = (lr * f[0], lr * f[1], lr * f[2])
        else:                                           # DIST: along P - P_p
            x = _world(ip, con_data, m, 0, R)
            f = (lr * (P[0] - ((r[ip, 0] if ip >= 0 else 0.0) + x[0])),
                 lr * (P[1] - ((r[ip, 1] if ip >= 0 else 0.0) + x[1])),
                 lr * (P[2] - ((r[ip, 2] if ip >= 0 else 0.0) + x[2])))
        row += 1
        out[m, 0], out[m, 1], out[m, 2] = f
        out[m, 3], out[m, 4], out[m, 5] = mo
        _apply(ic, 1.0, P, f, mo, R, r, com, F, N)      # the parent at the same P
        _apply(ip, -1.0, P, f, mo, R, r, com, F, N)

"""Inverse dynamics and the mass matrix in O(n) and O(n d), from each joint's motion
subspace ``S`` alone (no full Jacobians): the recursive Newton-Euler algorithm and the
composite-rigid-body algorithm.

Spatial quantities as in ``articulated``: at each frame's own origin ``O_i``, world axes,
ordered (angular, linear); a wrench ``(n, f)`` is a moment about ``O_i`` and a force.

* ``recursive_newton_euler``: given every frame's full accelerations (the kinematics
  evaluated with the given ``u'``), the wrench each joint's parent exerts on its child,
  from the leaves to the root, and the generalized force on each free speed,
  ``tau_k = S_k . W_i`` -- the same ``Q = M u' - f`` as the Jourdain form, without ``M``.
* ``composite_mass_matrix_s``: ``M`` by composite rigid bodies (Featherstone's CRBA): the
  inertia of each subtree about its joint's origin, ``F = IC_i S_i`` carried up the
  ancestors, ``M[k, l] = S_k . F``.
"""
from numba import njit

import numpy as np

from .articulated import _add_shifted_inertia, _spatial_inertia, world_inertia
from .evaluate import drop_velocity_products, kinematics_and_loads
from .joints import NU
from .kinematics import walk
from .packed import FREE_Q, FREE_U, UDFULL, UFULL, WRONG_SIZE, _scatter, _views
from .views import UNCOUNTED, c_view

#: floats of scratch the two kernels need
INVERSE_WORK = 48


@njit(**UNCOUNTED)
def recursive_newton_euler(mass, com, inertia, parent, kind, ucol, R, r, w, alpha, a, S, F, N,
                           wrench, tau, work):
    """Inverse dynamics from the leaves to the root.  ``alpha``, ``a``: each frame's angular
    acceleration and its origin's acceleration (world), the given speed rates included;
    ``F``, ``N``: the applied force and the moment about the centre of mass.  Writes
    ``wrench[i] = (force, moment)``, what the parent exerts on the child about ``O_i``
    (world components), and ``tau`` (free speeds): ``S_k`` of the speed's own joint
    dotted with that wrench.  ``work``: ``INVERSE_WORK`` floats."""
    n = mass.shape[0]
    Iw, Y = c_view(work, 0, (3, 3)), c_view(work, 9, (3, 3))
    c, aG, t1, t2 = (c_view(work, 18, (3,)), c_view(work, 21, (3,)), c_view(work, 24, (3,)),
                     c_view(work, 27, (3,)))
    for i in range(n):               # each body's own wrench: m aG - F, about O_i
        world_inertia(R, com, inertia, i, c, Iw, Y)
        w0, w1, w2 = w[i, 0], w[i, 1], w[i, 2]
        al0, al1, al2 = alpha[i, 0], alpha[i, 1], alpha[i, 2]
        # aG = a + alpha x c + w x (w x c)
        t1[0], t1[1], t1[2] = w1 * c[2] - w2 * c[1], w2 * c[0] - w0 * c[2], w0 * c[1] - w1 * c[0]
        aG[0] = a[i, 0] + al1 * c[2] - al2 * c[1] + w1 * t1[2] - w2 * t1[1]
        aG[1] = a[i, 1] + al2 * c[0] - al0 * c[2] + w2 * t1[0] - w0 * t1[2]
        aG[2] = a[i, 2] + al0 * c[1] - al1 * c[0] + w0 * t1[1] - w1 * t1[0]
        m = mass[i]
        for k in range(3):
            wrench[i, k] = m * aG[k] - F[i, k]
            t2[k] = Iw[k, 0] * w0 + Iw[k, 1] * w1 + Iw[k, 2] * w2
        # about the centre of mass: Iw alpha + w x Iw w - N; then about O_i: + c x f
        f0, f1, f2 = wrench[i, 0], wrench[i, 1], wrench[i, 2]
        for k in range(3):
            t1[k] = Iw[k, 0] * al0 + Iw[k, 1] * al1 + Iw[k, 2] * al2 - N[i, k]
        wrench[i, 3] = t1[0] + w1 * t2[2] - w2 * t2[1] + c[1] * f2 - c[2] * f1
        wrench[i, 4] = t1[1] + w2 * t2[0] - w0 * t2[2] + c[2] * f0 - c[0] * f2
        wrench[i, 5] = t1[2] + w0 * t2[1] - w1 * t2[0] + c[0] * f1 - c[1] * f0
    for i in range(n - 1, -1, -1):   # children come after their parents: leaves first
        f0, f1, f2 = wrench[i, 0], wrench[i, 1], wrench[i, 2]
        m0, m1, m2 = wrench[i, 3], wrench[i, 4], wrench[i, 5]
        col0 = ucol[i]
        if col0 >= 0:
            for j in range(NU[kind[i]]):
                tau[col0 + j] = (S[i, 0, j] * m0 + S[i, 1, j] * m1 + S[i, 2, j] * m2
                                 + S[i, 3, j] * f0 + S[i, 4, j] * f1 + S[i, 5, j] * f2)
        p = parent[i]
        if p >= 0:
            x, y, z = r[i, 0] - r[p, 0], r[i, 1] - r[p, 1], r[i, 2] - r[p, 2]
            wrench[p, 0] += f0
            wrench[p, 1] += f1
            wrench[p, 2] += f2
            wrench[p, 3] += m0 + y * f2 - z * f1
            wrench[p, 4] += m1 + z * f0 - x * f2
            wrench[p, 5] += m2 + x * f1 - y * f0


@njit(**UNCOUNTED)
def composite_mass_matrix_s(mass, com, inertia, parent, kind, ucol, R, r, S, IC, M, work):
    """The mass matrix ``M`` (free speeds) by composite rigid bodies: ``IC[i]`` (6x6, a
    workspace) the spatial inertia of the subtree of frame ``i`` about ``O_i``; for each
    free speed ``k`` of frame ``i``, the wrench ``IC_i S_k`` moved up to every ancestor
    ``j`` gives the row ``M[l, k] = S_l . W`` of ``j``'s speeds ``l``.  ``work``:
    ``INVERSE_WORK`` floats."""
    n = mass.shape[0]
    Iw, Y = c_view(work, 0, (3, 3)), c_view(work, 9, (3, 3))
    c, rho, Fw = c_view(work, 18, (3,)), c_view(work, 21, (3,)), c_view(work, 24, (6,))
    Y6 = c_view(work, 30, (6, 3))
    for i in range(n):
        world_inertia(R, com, inertia, i, c, Iw, Y)
        _spatial_inertia(mass[i], c, Iw, IC, i)
    for i in range(n - 1, -1, -1):
        p = parent[i]
        if p >= 0:
            for a_ in range(3):
                rho[a_] = r[i, a_] - r[p, a_]
            _add_shifted_inertia(IC, i, p, rho, Y6)
    for k in range(M.shape[0]):          # speeds on different branches do not couple
        for j in range(M.shape[1]):
            M[k, j] = 0.0
    for i in range(n):
        col0 = ucol[i]
        if col0 < 0:
            continue
        for j in range(NU[kind[i]]):
            for a_ in range(6):
                s = 0.0
                for b_ in range(6):
                    s += IC[i, a_, b_] * S[i, b_, j]
                Fw[a_] = s
            k = i
            while k >= 0:
                ck = ucol[k]
                if ck >= 0:
                    for l_ in range(NU[kind[k]]):
                        s = 0.0
                        for a_ in range(6):
                            s += S[k, a_, l_] * Fw[a_]
                        M[ck + l_, col0 + j] = s
                        M[col0 + j, ck + l_] = s
                p = parent[k]
                if p >= 0:           # the wrench about O_p: moment + (O_k - O_p) x force
                    x, y, z = r[k, 0] - r[p, 0], r[k, 1] - r[p, 1], r[k, 2] - r[p, 2]
                    Fw[0] += y * Fw[5] - z * Fw[4]
                    Fw[1] += z * Fw[3] - x * Fw[5]
                    Fw[2] += x * Fw[4] - y * Fw[3]
                k = p


# The entries on the packed buffers (``packed``): one compiled call each.

@njit(**UNCOUNTED)
def inverse_dynamics_packed(fb, ib, t, forces, q, u, ud, tau):
    """Scatter ``q``, ``u``, ``u'``; the kinematics with those rates and the applied loads;
    then ``recursive_newton_euler``: ``tau`` (free speeds) and the joint wrenches in the
    ``W`` view.  ``forces``: the force table or None (``packed``).  Returns -1, or -2 when
    ``tau`` holds NaN or Inf, or ``WRONG_SIZE`` for an argument of another size."""
    nu = t[1]
    if q.shape[0] != t[7] or u.shape[0] != nu or ud.shape[0] != nu or tau.shape[0] != nu:
        return WRONG_SIZE
    _scatter(fb, ib, t, q, u)
    udfull, free_u = fb[t[UDFULL]:], ib[t[FREE_U]:]
    for k in range(ud.shape[0]):
        udfull[free_u[k]] = ud[k]
    tree, body, state, loads, _, motion, _, art, scratch = _views(fb, ib, t, forces)
    mass, com, inertia, _, gravity = body
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol = tree[:9]
    anc_ptr, anc_idx = art[0], art[1]            # empty: the kinematics fill S only
    qfull, ufull, udf = state
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion
    kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                         mass, com, gravity, qfull, ufull, udf, *loads, R, r, w, v, alpha, a,
                         JR, JT, S, F, N, scratch)
    if loads[7][0] == 0:                         # the gyroscopic effect switched off
        drop_velocity_products(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr,
                               anc_idx, qfull, ufull, udf, R, r, w, v, alpha, a, JR, JT, S,
                               scratch)
    recursive_newton_euler(mass, com, inertia, parent, kind, ucol, R, r, w, alpha, a, S, F, N,
                           art[8], tau, scratch)
    for k in range(tau.shape[0]):
        if not np.isfinite(tau[k]):
            return -2
    return -1


@njit(**UNCOUNTED)
def mass_matrix_packed(fb, ib, t, forces, q, M):
    """Scatter ``q`` (speeds zero), the kinematics, then ``composite_mass_matrix_s`` into
    ``M`` (nu x nu); ``forces`` is not read (the packed kernels' arguments).  Returns -1,
    or -2 when ``M`` holds NaN or Inf, or ``WRONG_SIZE`` for an argument of another size."""
    ufull, free_u = fb[t[UFULL]:], ib[t[FREE_U]:]
    nu = t[1]
    if q.shape[0] != t[7] or M.shape[0] != nu or M.shape[1] != nu:
        return WRONG_SIZE
    tree, body, state, _, _, motion, _, art, scratch = _views(fb, ib, t, None)
    qfull = state[0]
    free_q = ib[t[FREE_Q]:]
    for k in range(q.shape[0]):
        qfull[free_q[k]] = q[k]
    for k in range(nu):
        ufull[free_u[k]] = 0.0
    mass, com, inertia, _, _ = body
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol = tree[:9]
    R, r, w, v, alpha, a, JR, JT, S, _, _ = motion
    walk(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, art[0], art[1], qfull, state[1],
         state[2], R, r, w, v, alpha, a, JR, JT, S, scratch)
    composite_mass_matrix_s(mass, com, inertia, parent, kind, ucol, R, r, S, art[2], M,
                            scratch)
    for k in range(nu):
        for j in range(nu):
            if not np.isfinite(M[k, j]):
                return -2
    return -1

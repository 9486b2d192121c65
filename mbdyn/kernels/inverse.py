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
* ``jourdain_by_subspaces``: the Jourdain form's ``M`` and ``f`` by the two, for the
  per-call entry of a closed mechanism (``f = -tau`` at ``u' = 0``).
"""
from numba import njit

import numpy as np

from .dynamics import cholesky_solve
from .evaluate import motion_and_loads, outcome
from .joints import NU, REVOLUTE
from .motion import cross, motion, row3
from .packed import FREE_Q, FREE_U, UDFULL, WRONG_SIZE, _scatter, _views, contiguous
from .spatial import body_inertia
from .views import FUSED, UNCOUNTED
from .internal import internal

#: floats of scratch the two kernels need
INVERSE_WORK = 48


@internal(**FUSED)
def recursive_newton_euler(mass, com, inertia, parent, kind, ucol, R, r, w, alpha, a, S, F, N,
                           wrench, tau, work):
    """Inverse dynamics from the leaves to the root.  ``alpha``, ``a``: each frame's angular
    acceleration and its origin's acceleration (world), the given speed rates included;
    ``F``, ``N``: the applied force and the moment about the centre of mass.  Writes
    ``wrench[i] = (force, moment)``, what the parent exerts on the child about ``O_i``
    (world components), and ``tau`` (free speeds): ``S_k`` of the speed's own joint
    dotted with that wrench.  ``work``: ``INVERSE_WORK`` floats (not read: the frame's
    quantities are local tuples, ``spatial``)."""
    n = mass.shape[0]
    for i in range(n):               # each body's own wrench: m aG - F, about O_i
        c, Iw = body_inertia(R, com, inertia, i)
        wi, al = row3(w, i), row3(alpha, i)
        t1 = cross(al, c)
        t2 = cross(wi, cross(wi, c))
        m = mass[i]
        # aG = a + alpha x c + w x (w x c)
        f = (m * (a[i, 0] + t1[0] + t2[0]) - F[i, 0], m * (a[i, 1] + t1[1] + t2[1]) - F[i, 1],
             m * (a[i, 2] + t1[2] + t2[2]) - F[i, 2])
        # about the centre of mass: Iw alpha + w x Iw w - N; then about O_i: + c x f
        t3 = cross(wi, (Iw[0] * wi[0] + Iw[1] * wi[1] + Iw[2] * wi[2],
                        Iw[1] * wi[0] + Iw[3] * wi[1] + Iw[4] * wi[2],
                        Iw[2] * wi[0] + Iw[4] * wi[1] + Iw[5] * wi[2]))
        t4 = cross(c, f)
        wrench[i, 0], wrench[i, 1], wrench[i, 2] = f
        wrench[i, 3] = Iw[0] * al[0] + Iw[1] * al[1] + Iw[2] * al[2] - N[i, 0] + t3[0] + t4[0]
        wrench[i, 4] = Iw[1] * al[0] + Iw[3] * al[1] + Iw[4] * al[2] - N[i, 1] + t3[1] + t4[1]
        wrench[i, 5] = Iw[2] * al[0] + Iw[4] * al[1] + Iw[5] * al[2] - N[i, 2] + t3[2] + t4[2]
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


@internal(forceinline=True, **FUSED)
def _ancestor_rows(parent, kind, ucol, r, S, M, i, col, f0, f1, f2, n0, n1, n2):
    """Row ``col`` of ``M`` left of the diagonal (an ancestor's speeds come first), on
    frame ``i`` and its ancestors: the wrench ``(n, f)`` = ``IC_i s`` about ``O_i``, carried
    up the tree, dotted with each ancestor's motion subspace (frame ``i``'s own speeds
    after ``col`` too: the mirror overwrites them)."""
    k = i
    while k >= 0:
        ck = ucol[k]
        if ck >= 0 and kind[k] == REVOLUTE:      # S = (e, 0) about O_k: half the products
            M[col, ck] = S[k, 0, 0] * n0 + S[k, 1, 0] * n1 + S[k, 2, 0] * n2
        elif ck >= 0:
            for l_ in range(NU[kind[k]]):
                M[col, ck + l_] = (S[k, 0, l_] * n0 + S[k, 1, l_] * n1 + S[k, 2, l_] * n2
                                   + S[k, 3, l_] * f0 + S[k, 4, l_] * f1 + S[k, 5, l_] * f2)
        p = parent[k]
        if p >= 0:                   # the wrench about O_p: moment + (O_k - O_p) x force
            x, y, z = r[k, 0] - r[p, 0], r[k, 1] - r[p, 1], r[k, 2] - r[p, 2]
            n0, n1, n2 = n0 + y * f2 - z * f1, n1 + z * f0 - x * f2, n2 + x * f1 - y * f0
        k = p


@internal(**FUSED)
def composite_mass_matrix_s(mass, com, inertia, parent, kind, ucol, R, r, S, IC, M, work):
    """The mass matrix ``M`` (free speeds) by composite rigid bodies: the inertia of the
    subtree of frame ``i`` about ``O_i`` (world axes), a rigid body's, held as its mass
    ``m``, first moment ``h = m c`` and inertia about ``O_i`` (``IC[i, 0, :4]``: ``m, h``;
    ``IC[i, 1]``: ``xx, xy, xz, yy, yz, zz``; ``IC`` a workspace); for each free speed
    ``k`` of frame ``i``, the wrench ``IC_i S_k`` moved up to every ancestor ``j`` gives
    the row ``M[l, k] = S_l . W`` of ``j``'s speeds ``l``; the lower triangle, mirrored.
    A NaN or Inf anywhere in ``M`` shows on its diagonal: ``IC_i``, ``S_k`` and the
    transports that make ``M[l, k]`` make ``M[k, k]`` and ``M[l, l]`` too (and a NaN times
    zero is NaN), and ``|M[l, k]| <= sqrt(M[l, l] M[k, k])`` for the rest, ``M`` being
    positive semi-definite.  ``work``: ``INVERSE_WORK`` floats (not read)."""
    n = mass.shape[0]
    for i in range(n):               # each body about its own origin
        c, Iw = body_inertia(R, com, inertia, i)
        m = mass[i]
        cx, cy, cz = c
        IC[i, 0, 0], IC[i, 0, 1], IC[i, 0, 2], IC[i, 0, 3] = m, m * cx, m * cy, m * cz
        IC[i, 1, 0] = Iw[0] + m * (cy * cy + cz * cz)
        IC[i, 1, 1] = Iw[1] - m * cx * cy
        IC[i, 1, 2] = Iw[2] - m * cx * cz
        IC[i, 1, 3] = Iw[3] + m * (cx * cx + cz * cz)
        IC[i, 1, 4] = Iw[4] - m * cy * cz
        IC[i, 1, 5] = Iw[5] + m * (cx * cx + cy * cy)
    for i in range(n - 1, -1, -1):   # the subtrees, about their parents' origins
        p = parent[i]
        if p >= 0:
            _add_about_parent(IC, i, p, r[i, 0] - r[p, 0], r[i, 1] - r[p, 1],
                              r[i, 2] - r[p, 2])
    nu = M.shape[0]
    for k in range(nu):                  # speeds on different branches do not couple
        for j in range(k + 1):
            M[k, j] = 0.0
    for i in range(n):
        col0 = ucol[i]
        if col0 < 0:
            continue
        m, hx, hy, hz = IC[i, 0, 0], IC[i, 0, 1], IC[i, 0, 2], IC[i, 0, 3]
        ixx, ixy, ixz, iyy, iyz, izz = (IC[i, 1, 0], IC[i, 1, 1], IC[i, 1, 2], IC[i, 1, 3],
                                        IC[i, 1, 4], IC[i, 1, 5])
        if kind[i] == REVOLUTE:              # s = (a, 0): IC s = (I a, -h x a)
            a0, a1, a2 = S[i, 0, 0], S[i, 1, 0], S[i, 2, 0]
            _ancestor_rows(parent, kind, ucol, r, S, M, i, col0, hz * a1 - hy * a2,
                           hx * a2 - hz * a0, hy * a0 - hx * a1,
                           ixx * a0 + ixy * a1 + ixz * a2, ixy * a0 + iyy * a1 + iyz * a2,
                           ixz * a0 + iyz * a1 + izz * a2)
            continue
        for j in range(NU[kind[i]]):
            a0, a1, a2, l0, l1, l2 = (S[i, 0, j], S[i, 1, j], S[i, 2, j], S[i, 3, j],
                                      S[i, 4, j], S[i, 5, j])
            # IC s = (I a + h x l, m l - h x a) for s = (a, l)
            _ancestor_rows(parent, kind, ucol, r, S, M, i, col0 + j,
                           m * l0 - (hy * a2 - hz * a1), m * l1 - (hz * a0 - hx * a2),
                           m * l2 - (hx * a1 - hy * a0),
                           ixx * a0 + ixy * a1 + ixz * a2 + hy * l2 - hz * l1,
                           ixy * a0 + iyy * a1 + iyz * a2 + hz * l0 - hx * l2,
                           ixz * a0 + iyz * a1 + izz * a2 + hx * l1 - hy * l0)
    for k in range(nu):                  # the lower triangle mirrored: M exactly symmetric
        for j in range(k):
            M[j, k] = M[k, j]


@internal(forceinline=True, **FUSED)
def _add_about_parent(IC, i, p, x, y, z):
    """Add the rigid inertia ``IC[i]`` (``composite_mass_matrix_s``'s layout), moved from
    ``O_i`` to ``O_p`` (``rho = (x, y, z) = O_i - O_p``), to ``IC[p]``: the mass, ``h +
    m rho``, and ``I - rho h^T - h rho^T + 2 (h . rho) E + m (|rho|^2 E - rho rho^T)``."""
    m, hx, hy, hz = IC[i, 0, 0], IC[i, 0, 1], IC[i, 0, 2], IC[i, 0, 3]
    d = 2.0 * (hx * x + hy * y + hz * z) + m * (x * x + y * y + z * z)
    IC[p, 0, 0] += m
    IC[p, 0, 1] += hx + m * x
    IC[p, 0, 2] += hy + m * y
    IC[p, 0, 3] += hz + m * z
    IC[p, 1, 0] += IC[i, 1, 0] + d - 2.0 * x * hx - m * x * x
    IC[p, 1, 1] += IC[i, 1, 1] - x * hy - hx * y - m * x * y
    IC[p, 1, 2] += IC[i, 1, 2] - x * hz - hx * z - m * x * z
    IC[p, 1, 3] += IC[i, 1, 3] + d - 2.0 * y * hy - m * y * y
    IC[p, 1, 4] += IC[i, 1, 4] - y * hz - hy * z - m * y * z
    IC[p, 1, 5] += IC[i, 1, 5] + d - 2.0 * z * hz - m * z * z


@njit(cache=True, inline="always")
def jourdain_by_subspaces(tree, body, state, loads, kin, jourdain, wrench, IC, scratch):
    """``M u' = f`` by the motion subspaces ``S`` (no full Jacobians): the kinematics and
    loads of the per-call entries (``evaluate.motion_and_loads``, the free speeds' rates
    zero), ``f = -tau`` by ``recursive_newton_euler`` there (the generalized force that
    would hold the mechanism at ``u' = 0``: gravity, loads, velocity products) and ``M`` by
    ``composite_mass_matrix_s``; then ``ud = M^-1 f`` by Cholesky.  The groups as
    ``evaluate.jourdain_accelerations`` takes them (``jourdain``: ``M, f, L, ud``), with
    ``wrench`` (n x 6) and ``IC`` (n x 6 x 6) for workspace.  Returns as it does."""
    motion_and_loads(tree, body, state, loads, kin, scratch)
    mass, com, inertia = body[0], body[1], body[2]
    parent, kind, ucol = tree[0], tree[1], tree[8]
    R, r, w, v, alpha, a, _, _, S, F, N = kin
    M, f, L, ud = jourdain
    recursive_newton_euler(mass, com, inertia, parent, kind, ucol, R, r, w, alpha, a, S, F, N,
                           wrench, f, scratch)
    for k in range(f.shape[0]):
        f[k] = -f[k]
    composite_mass_matrix_s(mass, com, inertia, parent, kind, ucol, R, r, S, IC, M, scratch)
    return outcome(cholesky_solve(M, f, L, ud), ud)


# The entries on the packed buffers (``packed``): one compiled call each.

@njit(**UNCOUNTED)
def inverse_dynamics_packed(fb, ib, forces, q, u, ud, tau):
    """Scatter ``q``, ``u``, ``u'``; the kinematics with those rates and the applied loads;
    then ``recursive_newton_euler``: ``tau`` (free speeds) and the joint wrenches in the
    ``W`` view.  ``forces``: the force elements (``packed``).  Returns -1, or -2 when
    ``tau`` holds NaN or Inf, or ``WRONG_SIZE`` for an argument of another size.  The
    integer buffer stands for the offset table (``packed.articulated_accelerations_packed``)."""
    t = ib
    nu = t[1]
    if not (contiguous(q, t[7]) and contiguous(u, nu) and contiguous(ud, nu)
            and contiguous(tau, nu)):
        return WRONG_SIZE
    _scatter(fb, ib, t, q, u)
    udfull, free_u = fb[t[UDFULL]:], ib[t[FREE_U]:]
    for k in range(ud.shape[0]):
        udfull[free_u[k]] = ud[k]
    tree, body, state, loads, _, kin, _, art, scratch = _views(fb, ib, t, forces)
    motion_and_loads(tree, body, state, loads, kin, scratch)
    mass, com, inertia = body[0], body[1], body[2]
    parent, kind, ucol = tree[0], tree[1], tree[8]
    R, r, w, v, alpha, a, _, _, S, F, N = kin
    recursive_newton_euler(mass, com, inertia, parent, kind, ucol, R, r, w, alpha, a, S, F, N,
                           art[8], tau, scratch)
    for k in range(tau.shape[0]):
        if not np.isfinite(tau[k]):
            return -2
    return -1


@njit(**UNCOUNTED)
def mass_matrix_packed(fb, ib, forces, q, M):
    """Scatter ``q``, the kinematics (positions only), then ``composite_mass_matrix_s`` into
    ``M`` (nu x nu); ``forces`` is not read (the packed kernels' arguments).  Returns -1,
    or -2 when ``M`` holds NaN or Inf, or ``WRONG_SIZE`` for an argument of another size
    (the integer buffer standing for the table)."""
    t = ib
    nu = t[1]
    if not (contiguous(q, t[7]) and M.shape[0] == nu and M.shape[1] == nu
            and (nu < 2 or (M.strides[0] == 8 * nu and M.strides[1] == 8))):
        return WRONG_SIZE
    tree, body, state, _, _, kin, _, art, scratch = _views(fb, ib, t, None)
    qfull = state[0]
    free_q = ib[t[FREE_Q]:]
    for k in range(q.shape[0]):
        qfull[free_q[k]] = q[k]
    mass, com, inertia, _, _ = body
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol = tree[:9]
    R, r, w, v, alpha, a, JR, JT, S, _, _ = kin
    motion(parent, kind, axis, seq, pos, C, qoff, uoff, qfull, state[1], state[2], R, r, w, v,
           alpha, a, S, scratch, 0)
    composite_mass_matrix_s(mass, com, inertia, parent, kind, ucol, R, r, S, art[2], M,
                            scratch)
    for k in range(nu):              # the diagonal suffices (composite_mass_matrix_s)
        if not np.isfinite(M[k, k]):
            return -2
    return -1

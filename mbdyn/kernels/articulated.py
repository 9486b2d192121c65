"""O(n) forward dynamics: the articulated-body algorithm, and the joint reactions with it.

The same equations as the Newton-Euler system with reaction unknowns (``dynamics.
newton_euler_system``), eliminated in tree order instead of by a dense solve: from the
leaves to the root, each body's six equations are solved for its joint's reaction in
terms of its parent's acceleration (the *articulated* inertia ``IA`` and bias ``pA`` of
the subtree it carries); from the root to the leaves, each joint's speed rates follow from
the parent's now known acceleration.  Cost O(n) in the number of frames, against
O(n nu^2 + nu^3) for ``M u' = f`` and O(n^3) for the dense system.

Spatial quantities are taken at each frame's own origin ``O_i`` with world axes (never at
the world origin: a far-away body would lose digits to ``m |r|^2``), ordered
(angular, linear):

* motion: ``A_i = (alpha_i, a_i)``, the angular acceleration and the acceleration of the
  origin ``O_i``;
* force: ``W = (n, f)``, a moment about ``O_i`` and a force;
* a joint's motion subspace ``S_i``: its own columns of ``JR`` and ``JT`` (the frame's
  angular velocity and origin velocity per unit speed of its own joint), which the
  kinematics write compactly into ``S[i]`` (6 x 6: rows angular then linear, a column per
  speed of the joint): the full Jacobians, n x 3 x nu, are not needed.

Moving from a parent's origin to the child's (``rho = O_i - O_p``):
``X A_p = (alpha_p, a_p + alpha_p x rho)`` for motion, ``X^T W = (n + rho x f, f)`` brings
a child's wrench back to the parent.  The velocity-product and drive parts of the
accelerations enter through the kinematics' bias accelerations (computed with free
``u' = 0``): ``A_i = X A_p + S_i u'_i + c_i`` with ``c_i = A_bias_i - X A_bias_p``.
"""
# long: the articulated-body algorithm and the joint wrenches computed with it share their
# inlined helpers, which must sit in the same file as the kernels (numba's on-disk cache is
# invalidated per source file, docs/architecture.md).
import math

from numba import njit

from .joints import EULER, NU, REVOLUTE, SPHERICAL
from .motion import cross, row3
from .spatial import body_inertia, mirror, rigid_upper, shift_upper
from .views import FUSED, c_view
from .internal import internal

#: floats of scratch ``articulated_body`` needs: ``ARTICULATED_WORK + 6 n`` for n frames
#: (``joint_wrenches_tree`` needs 6)
ARTICULATED_WORK = 87


@njit(cache=True, inline="always")
def _spatial_inertia(m, c, Iw, IA, i):
    """Spatial inertia at the frame origin (world axes) of a body of mass ``m``, centre of
    mass at ``c`` from the origin and inertia ``Iw`` about the centre of mass, into
    ``IA[i]``: ``[[Iw - m [c]x [c]x, m [c]x], [-m [c]x, m E]]``.  (Arrays are indexed
    with the frame number rather than passed as ``IA[i]`` views: a view costs two
    reference-count calls, which dominated the cost of a small model.)"""
    cx, cy, cz = c[0], c[1], c[2]
    cc = cx * cx + cy * cy + cz * cz
    IA[i, 0, 0] = Iw[0, 0] + m * (cc - cx * cx)
    IA[i, 1, 1] = Iw[1, 1] + m * (cc - cy * cy)
    IA[i, 2, 2] = Iw[2, 2] + m * (cc - cz * cz)
    IA[i, 0, 1] = IA[i, 1, 0] = Iw[0, 1] - m * cx * cy
    IA[i, 0, 2] = IA[i, 2, 0] = Iw[0, 2] - m * cx * cz
    IA[i, 1, 2] = IA[i, 2, 1] = Iw[1, 2] - m * cy * cz
    for a_ in range(3):
        for b_ in range(3):
            IA[i, 3 + a_, 3 + b_] = m if a_ == b_ else 0.0
    IA[i, 0, 3], IA[i, 0, 4], IA[i, 0, 5] = 0.0, -m * cz, m * cy
    IA[i, 1, 3], IA[i, 1, 4], IA[i, 1, 5] = m * cz, 0.0, -m * cx
    IA[i, 2, 3], IA[i, 2, 4], IA[i, 2, 5] = -m * cy, m * cx, 0.0
    for a_ in range(3):
        for b_ in range(3):
            IA[i, 3 + b_, a_] = IA[i, a_, 3 + b_]


@njit(cache=True, inline="always")
def world_inertia(R, com, inertia, i, c, Iw, Y):
    """The centre of mass ``c = R com`` from the origin and the inertia about it in world
    axes ``Iw = R I R^T`` of frame ``i`` (``Y``, at least 3x3, is scratch: ``R I``)."""
    for a_ in range(3):
        c[a_] = R[i, a_, 0] * com[i, 0] + R[i, a_, 1] * com[i, 1] + R[i, a_, 2] * com[i, 2]
        for b_ in range(3):
            Y[a_, b_] = (R[i, a_, 0] * inertia[i, 0, b_] + R[i, a_, 1] * inertia[i, 1, b_]
                         + R[i, a_, 2] * inertia[i, 2, b_])
    for a_ in range(3):
        for b_ in range(a_, 3):
            Iw[a_, b_] = Iw[b_, a_] = (Y[a_, 0] * R[i, b_, 0] + Y[a_, 1] * R[i, b_, 1]
                                       + Y[a_, 2] * R[i, b_, 2])


@njit(cache=True, inline="always")
def _add_shifted_inertia(IA, i, p, rho, Y):
    """``IA[p] += X^T IA[i] X``: a child's articulated inertia moved from its origin to its
    parent's, ``rho`` being the child's origin from the parent's.  With
    ``IA[i] = [[A, B], [B^T, C]]`` and ``P = [rho]x``: ``[[A - B P + P B^T - P C P, B + P C],
    [B^T - C P, C]]``.  ``Y`` (6x3) is scratch."""
    x, y, z = rho[0], rho[1], rho[2]
    # Y = Ia X: the first three columns are Ia[:, 0:3] - Ia[:, 3:6] P, the rest Ia[:, 3:6]
    for r_ in range(6):
        b0, b1, b2 = IA[i, r_, 3], IA[i, r_, 4], IA[i, r_, 5]
        # (row of Ia[:, 3:6]) P, with P = [[0, -z, y], [z, 0, -x], [-y, x, 0]]
        Y[r_, 0] = IA[i, r_, 0] - (b1 * z - b2 * y)
        Y[r_, 1] = IA[i, r_, 1] - (-b0 * z + b2 * x)
        Y[r_, 2] = IA[i, r_, 2] - (b0 * y - b1 * x)
    # X^T Y: rows 0..2 gain P times rows 3..5
    for col in range(6):
        if col < 3:
            l0, l1, l2 = Y[3, col], Y[4, col], Y[5, col]
            u0, u1, u2 = Y[0, col], Y[1, col], Y[2, col]
        else:
            l0, l1, l2 = IA[i, 3, col], IA[i, 4, col], IA[i, 5, col]
            u0, u1, u2 = IA[i, 0, col], IA[i, 1, col], IA[i, 2, col]
        IA[p, 0, col] += u0 + (y * l2 - z * l1)
        IA[p, 1, col] += u1 + (z * l0 - x * l2)
        IA[p, 2, col] += u2 + (x * l1 - y * l0)
        IA[p, 3, col] += l0
        IA[p, 4, col] += l1
        IA[p, 5, col] += l2


@njit(cache=True, inline="always")
def _ball_joint_inertia(IA, pA, U, Dl, inv, cb, i, V):
    """``Ia`` into ``IA[i]`` and ``pa`` into ``pA[i]`` behind a ball joint (three speeds,
    ``U = IA S`` and ``D``'s factor and ``D^-1 (-S^T pA)`` in ``U[i]``, ``Dl[i]``): its
    ``S`` spans every rotation and no translation, so ``Ia`` has no rotational rows or
    columns and ``pa`` no moment (a ball joint passes none about its centre) -- zero
    exactly rather than to rounding; the translational rows as the general case's.  ``V``
    (6x3) is scratch."""
    for a_ in range(3, 6):
        for j in range(3):
            s = U[i, a_, j]
            for l_ in range(j):
                s -= Dl[i, j, l_] * V[a_, l_]
            V[a_, j] = s * inv[i, j]
    for a_ in range(3, 6):
        for b_ in range(a_, 6):
            IA[i, a_, b_] -= V[a_, 0] * V[b_, 0] + V[a_, 1] * V[b_, 1] + V[a_, 2] * V[b_, 2]
            IA[i, b_, a_] = IA[i, a_, b_]
    for a_ in range(3):
        pA[i, a_] = 0.0
        for b_ in range(6):
            IA[i, a_, b_] = 0.0
            IA[i, b_, a_] = 0.0
    for a_ in range(3, 6):
        pA[i, a_] += (U[i, a_, 0] * Dl[i, 0, 6] + U[i, a_, 1] * Dl[i, 1, 6]
                      + U[i, a_, 2] * Dl[i, 2, 6]
                      + IA[i, a_, 3] * cb[i, 3] + IA[i, a_, 4] * cb[i, 4]
                      + IA[i, a_, 5] * cb[i, 5])


@njit(cache=True, inline="always")
def _add_shifted_translational_inertia(IA, i, p, rho, T):
    """``_add_shifted_inertia`` for an articulated inertia that has only its translational
    block ``C`` (behind a ball joint): ``X^T IA[i] X = [[-P T, -T^T], [-T, C]]`` with
    ``P = [rho]x`` and ``T = C P`` (``P C = -T^T``: ``C`` symmetric, ``P`` skew).  ``T``
    (3x3) is scratch."""
    x, y, z = rho[0], rho[1], rho[2]
    for a_ in range(3):
        # row a_ of T = C P, with P = [[0, -z, y], [z, 0, -x], [-y, x, 0]]
        c0, c1, c2 = IA[i, 3 + a_, 3], IA[i, 3 + a_, 4], IA[i, 3 + a_, 5]
        T[a_, 0] = c1 * z - c2 * y
        T[a_, 1] = c2 * x - c0 * z
        T[a_, 2] = c0 * y - c1 * x
    for b_ in range(3):
        IA[p, 0, b_] += z * T[1, b_] - y * T[2, b_]
        IA[p, 1, b_] += x * T[2, b_] - z * T[0, b_]
        IA[p, 2, b_] += y * T[0, b_] - x * T[1, b_]
        for a_ in range(3):
            IA[p, 3 + a_, b_] -= T[a_, b_]
            IA[p, b_, 3 + a_] -= T[a_, b_]
            IA[p, 3 + a_, 3 + b_] += IA[i, 3 + a_, 3 + b_]


@internal(**FUSED)
def _bodies(mass, com, inertia, parent, R, r, w, alpha_b, a_b, F, N, IA, pA, cb):
    """The first sweep of ``articulated_body``: every body on its own -- the upper
    triangle of its spatial inertia (``spatial``), its bias force (velocity products and
    applied loads) and its joint's bias acceleration ``c_i = A_bias_i - X A_bias_p``."""
    for i in range(mass.shape[0]):
        c, Iw = body_inertia(R, com, inertia, i)
        m_i = mass[i]
        rigid_upper(IA, i, m_i, c, Iw)
        wi = row3(w, i)
        t1 = cross(wi, cross(wi, c))     # w x (w x c), the centre of mass relative to O_i
        f = (m_i * t1[0] - F[i, 0], m_i * t1[1] - F[i, 1], m_i * t1[2] - F[i, 2])
        # about O_i: w x Iw w - N + c x (m w x (w x c) - F)
        t2 = cross(wi, (Iw[0] * wi[0] + Iw[1] * wi[1] + Iw[2] * wi[2],
                        Iw[1] * wi[0] + Iw[3] * wi[1] + Iw[4] * wi[2],
                        Iw[2] * wi[0] + Iw[4] * wi[1] + Iw[5] * wi[2]))
        t3 = cross(c, f)
        for a_ in range(3):
            pA[i, a_] = t2[a_] - N[i, a_] + t3[a_]
            pA[i, 3 + a_] = f[a_]
        p = parent[i]
        if p >= 0:
            ap = row3(alpha_b, p)
            t4 = cross(ap, (r[i, 0] - r[p, 0], r[i, 1] - r[p, 1], r[i, 2] - r[p, 2]))
            for a_ in range(3):
                cb[i, a_] = alpha_b[i, a_] - ap[a_]
                cb[i, 3 + a_] = a_b[i, a_] - a_b[p, a_] - t4[a_]
        else:
            for a_ in range(3):
                cb[i, a_] = alpha_b[i, a_]
                cb[i, 3 + a_] = a_b[i, a_]


@internal(**FUSED)
def _one_speed(IA, pA, cb, U, Dl, S, i, turns):
    """The joint of frame ``i`` with one speed (motion subspace ``s``, ``S[i, :, 0]``; no
    translation part when it ``turns``), the upper triangle of its articulated inertia
    complete: ``U = IA s``, ``D = s^T U`` (its square root in ``Dl[i, 0, 0]``),
    ``z = -s^T pA / D`` in ``Dl[i, 0, 6]``; then ``IA[i]`` becomes ``Ia = IA - U U^T / D``
    (whole) and ``pA[i]`` ``pa = pA + Ia c + U z``.  Returns ``D`` (not positive: no
    inertia on this speed, nothing written after it)."""
    s0, s1, s2 = S[i, 0, 0], S[i, 1, 0], S[i, 2, 0]
    # U = IA s from the upper triangle (IA[b, a] = IA[a, b])
    u0 = IA[i, 0, 0] * s0 + IA[i, 0, 1] * s1 + IA[i, 0, 2] * s2
    u1 = IA[i, 0, 1] * s0 + IA[i, 1, 1] * s1 + IA[i, 1, 2] * s2
    u2 = IA[i, 0, 2] * s0 + IA[i, 1, 2] * s1 + IA[i, 2, 2] * s2
    u3 = IA[i, 0, 3] * s0 + IA[i, 1, 3] * s1 + IA[i, 2, 3] * s2
    u4 = IA[i, 0, 4] * s0 + IA[i, 1, 4] * s1 + IA[i, 2, 4] * s2
    u5 = IA[i, 0, 5] * s0 + IA[i, 1, 5] * s1 + IA[i, 2, 5] * s2
    D = s0 * u0 + s1 * u1 + s2 * u2
    sb = -(s0 * pA[i, 0] + s1 * pA[i, 1] + s2 * pA[i, 2])
    if not turns:
        s3, s4, s5 = S[i, 3, 0], S[i, 4, 0], S[i, 5, 0]
        u0 += IA[i, 0, 3] * s3 + IA[i, 0, 4] * s4 + IA[i, 0, 5] * s5
        u1 += IA[i, 1, 3] * s3 + IA[i, 1, 4] * s4 + IA[i, 1, 5] * s5
        u2 += IA[i, 2, 3] * s3 + IA[i, 2, 4] * s4 + IA[i, 2, 5] * s5
        u3 += IA[i, 3, 3] * s3 + IA[i, 3, 4] * s4 + IA[i, 3, 5] * s5
        u4 += IA[i, 3, 4] * s3 + IA[i, 4, 4] * s4 + IA[i, 4, 5] * s5
        u5 += IA[i, 3, 5] * s3 + IA[i, 4, 5] * s4 + IA[i, 5, 5] * s5
        D = s0 * u0 + s1 * u1 + s2 * u2 + s3 * u3 + s4 * u4 + s5 * u5
        sb -= s3 * pA[i, 3] + s4 * pA[i, 4] + s5 * pA[i, 5]
    if not D > 0.0:
        return D
    Dl[i, 0, 0] = math.sqrt(D)
    z = sb / D
    Dl[i, 0, 6] = z
    u = (u0, u1, u2, u3, u4, u5)
    g = 1.0 / D
    for a_ in range(6):
        U[i, a_, 0] = u[a_]
        ga = u[a_] * g
        for b_ in range(a_, 6):
            IA[i, a_, b_] -= ga * u[b_]
            IA[i, b_, a_] = IA[i, a_, b_]
    for a_ in range(6):
        pA[i, a_] += (IA[i, a_, 0] * cb[i, 0] + IA[i, a_, 1] * cb[i, 1] + IA[i, a_, 2] * cb[i, 2]
                      + IA[i, a_, 3] * cb[i, 3] + IA[i, a_, 4] * cb[i, 4]
                      + IA[i, a_, 5] * cb[i, 5] + u[a_] * z)
    return D


@internal(**FUSED)
def articulated_body(mass, com, inertia, parent, kind, ucol, R, r, w, alpha_b, a_b, S, F, N,
                     IA, pA, cb, U, Dl, acc, ud, work):
    """Forward dynamics ``ud`` by the articulated-body algorithm (see the module
    docstring), from the kinematics of ``forward_kinematics`` evaluated with ``u' = 0`` for
    the free speeds (bias accelerations ``alpha_b``, ``a_b``; the joints' motion subspaces
    ``S``) and the applied loads ``F``, ``N`` at the centres of mass.

    Workspace, per frame: ``IA`` (6x6) articulated inertia, then ``Ia``, the part the
    parent sees; ``pA`` (6) bias force, then ``pa``; ``cb`` (6) the joint's bias
    acceleration; ``U`` (6 x nu_i) ``= IA S``; ``Dl`` (6 x 7) the Cholesky factor
    of ``D = S^T IA S`` (in ``Dl[i, :, :6]``), and ``Dl[i, :, 6]`` holds ``D^-1 (-S^T pA)``; ``acc`` (6) the
    frame's acceleration.  After the call ``acc`` holds every frame's (angular, linear)
    acceleration and ``IA[i]``, ``pA[i]`` give the joint's wrench on the child,
    ``W_i = Ia_i X_i A_p + pa_i`` (``joint_reactions``).

    Returns -1, or the first speed column where ``D`` is not positive definite (a degree
    of freedom without inertia).  ``work``: ``ARTICULATED_WORK + 6 n`` floats of scratch
    (the last ``6 n``: each joint's ``1 / L_jj``, so that its solves multiply).
    """
    # long: the articulated-body algorithm's sweeps over the tree (bodies, leaves to root,
    # root to leaves); a joint of one speed by ``_one_speed``, the others written out here
    # on the whole 6x6 blocks (the leaves-to-root sweep adds only upper triangles,
    # ``spatial``, and a frame's block is made whole before it is read).
    n = mass.shape[0]
    Iw, Y, Vbig = c_view(work, 0, (3, 3)), c_view(work, 9, (6, 3)), c_view(work, 51, (6, 6))
    inv = c_view(work, ARTICULATED_WORK, (n, 6))
    rho, v6 = c_view(work, 39, (3,)), c_view(work, 42, (6,))
    _bodies(mass, com, inertia, parent, R, r, w, alpha_b, a_b, F, N, IA, pA, cb)
    # -- leaves to root: articulated inertias and biases
    largest = 0.0
    for i in range(n - 1, -1, -1):
        col0 = ucol[i]
        kd = kind[i]
        k = NU[kd] if col0 >= 0 else 0
        ball = k > 0 and kd == SPHERICAL
        if k == 1:
            D = _one_speed(IA, pA, cb, U, Dl, S, i, kd == REVOLUTE)
            if not D > 0.0:
                return col0
            largest = max(largest, D)
            inv[i, 0] = 1.0 / Dl[i, 0, 0]
        else:
            mirror(IA, i)
        if k > 1:
            # U = IA S, D = S^T U, and D's Cholesky factor in Dl[i, :k, :k].  A joint that
            # only turns about the frame's origin (Euler angles, spherical) has zero
            # translation columns: their terms, which come last, are skipped.
            turns = kd == EULER or kd == SPHERICAL
            for j in range(k):
                s0, s1, s2 = S[i, 0, j], S[i, 1, j], S[i, 2, j]
                for a_ in range(6):
                    s = IA[i, a_, 0] * s0 + IA[i, a_, 1] * s1 + IA[i, a_, 2] * s2
                    if not turns:
                        s += (IA[i, a_, 3] * S[i, 3, j] + IA[i, a_, 4] * S[i, 4, j]
                              + IA[i, a_, 5] * S[i, 5, j])
                    U[i, a_, j] = s
            for j in range(k):
                for m in range(j + 1):
                    s = (S[i, 0, m] * U[i, 0, j] + S[i, 1, m] * U[i, 1, j]
                         + S[i, 2, m] * U[i, 2, j])
                    if not turns:
                        s += (S[i, 3, m] * U[i, 3, j] + S[i, 4, m] * U[i, 4, j]
                              + S[i, 5, m] * U[i, 5, j])
                    for l_ in range(m):
                        s -= Dl[i, j, l_] * Dl[i, m, l_]
                    if m == j:
                        if not s > 0.0:
                            return col0 + j
                        largest = max(largest, s)
                        Dl[i, j, j] = math.sqrt(s)
                        inv[i, j] = 1.0 / Dl[i, j, j]
                    else:
                        Dl[i, j, m] = s * inv[i, m]
            # the joint's own equations: S^T (IA A + pA) = 0  ->  u' = D^-1 (uv - U^T X A_p)
            # keep z = D^-1 (-S^T pA) in Dl[i, :k, 6]
            for j in range(k):
                v6[j] = -(S[i, 0, j] * pA[i, 0] + S[i, 1, j] * pA[i, 1]
                          + S[i, 2, j] * pA[i, 2] + S[i, 3, j] * pA[i, 3]
                          + S[i, 4, j] * pA[i, 4] + S[i, 5, j] * pA[i, 5])
            _cholesky_solve_small(Dl, inv, i, k, v6)
            for j in range(k):
                Dl[i, j, 6] = v6[j]
            # Ia = IA - U D^-1 U^T = IA - V^T V with V = L^-1 U^T (one triangular solve
            # per row of U, not two); pa = pA + Ia c + U D^-1 (-S^T pA)
            if ball:
                _ball_joint_inertia(IA, pA, U, Dl, inv, cb, i, Y)
            else:
                V = Y                                        # (6 x 3 scratch: k <= 3 here)
                if k > 3:
                    V = Vbig
                for a_ in range(6):
                    for j in range(k):
                        s = U[i, a_, j]
                        for l_ in range(j):
                            s -= Dl[i, j, l_] * V[a_, l_]
                        V[a_, j] = s * inv[i, j]
                for a_ in range(6):
                    for b_ in range(a_, 6):
                        s = 0.0
                        for j in range(k):
                            s += V[a_, j] * V[b_, j]
                        IA[i, a_, b_] -= s
                        if b_ != a_:
                            IA[i, b_, a_] = IA[i, a_, b_]
                for a_ in range(6):
                    s = 0.0
                    for j in range(k):
                        s += U[i, a_, j] * Dl[i, j, 6]
                    pA[i, a_] += s
        if k != 1 and not ball:
            for a_ in range(6):
                s = 0.0
                for b_ in range(6):
                    s += IA[i, a_, b_] * cb[i, b_]
                pA[i, a_] += s
        p = parent[i]
        if p >= 0:
            x, y, z = r[i, 0] - r[p, 0], r[i, 1] - r[p, 1], r[i, 2] - r[p, 2]
            if ball:
                rho[0], rho[1], rho[2] = x, y, z
                _add_shifted_translational_inertia(IA, i, p, rho, Iw)     # Iw: 3x3 scratch
            else:
                shift_upper(IA, i, p, x, y, z)
            f0, f1, f2 = pA[i, 3], pA[i, 4], pA[i, 5]
            pA[p, 0] += pA[i, 0] + y * f2 - z * f1
            pA[p, 1] += pA[i, 1] + z * f0 - x * f2
            pA[p, 2] += pA[i, 2] + x * f1 - y * f0
            pA[p, 3] += f0
            pA[p, 4] += f1
            pA[p, 5] += f2
    # a pivot far below the largest: no inertia on that degree of freedom (as Cholesky)
    tiny = 1e-14 * largest
    for i in range(n):
        if ucol[i] >= 0:
            for j in range(NU[kind[i]]):
                if not Dl[i, j, j] * Dl[i, j, j] > tiny:
                    return ucol[i] + j
    # -- root to leaves: accelerations and speed rates
    for i in range(n):
        p = parent[i]
        if p >= 0:
            x, y, z = r[i, 0] - r[p, 0], r[i, 1] - r[p, 1], r[i, 2] - r[p, 2]
            a0, a1, a2 = acc[p, 0], acc[p, 1], acc[p, 2]
            acc[i, 0] = a0 + cb[i, 0]
            acc[i, 1] = a1 + cb[i, 1]
            acc[i, 2] = a2 + cb[i, 2]
            acc[i, 3] = acc[p, 3] + a1 * z - a2 * y + cb[i, 3]
            acc[i, 4] = acc[p, 4] + a2 * x - a0 * z + cb[i, 4]
            acc[i, 5] = acc[p, 5] + a0 * y - a1 * x + cb[i, 5]
        else:
            for a_ in range(6):
                acc[i, a_] = cb[i, a_]
        col0 = ucol[i]
        if col0 < 0:
            continue
        k = NU[kind[i]]
        if k == 1:
            s = (U[i, 0, 0] * acc[i, 0] + U[i, 1, 0] * acc[i, 1] + U[i, 2, 0] * acc[i, 2]
                 + U[i, 3, 0] * acc[i, 3] + U[i, 4, 0] * acc[i, 4] + U[i, 5, 0] * acc[i, 5])
            udj = Dl[i, 0, 6] - s * inv[i, 0] * inv[i, 0]
            ud[col0] = udj
            for a_ in range(6):
                acc[i, a_] += S[i, a_, 0] * udj
            continue
        # u' = D^-1 (-S^T pA) - D^-1 U^T (X A_p + c)
        for j in range(k):
            s = 0.0
            for a_ in range(6):
                s += U[i, a_, j] * acc[i, a_]
            v6[j] = s
        _cholesky_solve_small(Dl, inv, i, k, v6)
        for j in range(k):
            udj = Dl[i, j, 6] - v6[j]
            ud[col0 + j] = udj
            for a_ in range(6):
                acc[i, a_] += S[i, a_, j] * udj
    return -1


@njit(cache=True, inline="always")
def _cholesky_solve_small(Dl, inv, f, k, x):
    """``x <- D^-1 x`` for ``D = L L^T``, ``L`` lower triangular in ``Dl[f, :k, :k]``,
    ``inv[f, :k]`` the inverses of its diagonal."""
    for i in range(k):
        s = x[i]
        for j in range(i):
            s -= Dl[f, i, j] * x[j]
        x[i] = s * inv[f, i]
    for i in range(k - 1, -1, -1):
        s = x[i]
        for j in range(i + 1, k):
            s -= Dl[f, j, i] * x[j]
        x[i] = s * inv[f, i]

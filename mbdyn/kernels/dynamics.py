"""Applied loads, the Newton-Euler-Jourdain form and the Newton-Euler system with reactions.

Everything in inertial (world) components.  Per body: mass ``m``, centre of mass ``com``
(body components, from the frame origin) and inertia tensor ``inertia`` about the centre
of mass in body axes.  Applied loads are reduced to each body's centre of mass:
force ``F[i]`` and moment ``N[i]``.
"""
# long: Jourdain's M and f, the dense Newton-Euler system and the Cholesky solves share
# inlined helpers, which must sit in the same file as the kernels that inline them (numba's
# on-disk cache is invalidated per source file, docs/architecture.md).
import numpy as np
from numba import njit
from numba.extending import register_jitable

from .linalg3 import cross_to, mat_vec, rotate_tensor
from .motion import cross, row3
from .spatial import body_inertia
from .views import CACHED, UNCOUNTED, c_view
from .internal import internal


@njit(cache=True, inline="always")
def applied_loads(mass, com, gravity, R, r, load_body, load_point, load_force, load_moment,
                  load_in_body, F, N, work):
    """Gravity and point loads reduced to each centre of mass (world components).

    A load's force acts at ``load_point`` (body components); ``load_in_body`` says whether
    its force and moment are given in body (1) or world (0) components.  ``work``: at
    least 15 floats of scratch.
    """
    n = mass.shape[0]
    f, mo, arm = c_view(work, 0, (3,)), c_view(work, 3, (3,)), c_view(work, 6, (3,))
    lever, t = c_view(work, 9, (3,)), c_view(work, 12, (3,))
    for i in range(n):
        for k in range(3):
            F[i, k] = mass[i] * gravity[k]
            N[i, k] = 0.0
    for m in range(load_body.shape[0]):
        i = load_body[m]
        if load_in_body[m]:
            mat_vec(R[i], load_force[m], f)
            mat_vec(R[i], load_moment[m], mo)
        else:
            for k in range(3):                       # (an array assignment would compile
                f[k] = load_force[m, k]              # numba's shape-mismatch message)
                mo[k] = load_moment[m, k]
        for k in range(3):
            arm[k] = load_point[m, k] - com[i, k]
        mat_vec(R[i], arm, lever)                    # centre of mass -> point of action
        cross_to(lever, f, t)
        for k in range(3):
            F[i, k] += f[k]
            N[i, k] += mo[k] + t[k]


@internal(**UNCOUNTED, forceinline=True)
def body_terms(i, com, inertia, R, w, alpha_b, a_b, c, Iw, aG_b, gyro, S3, t1, t2):
    """Per body i, into the given arrays: lever ``c`` (origin -> centre of mass), world
    inertia ``Iw``, bias acceleration of the centre of mass ``aG_b`` and the inertia
    moment ``gyro = Iw alpha_b + w x Iw w``.  ``S3``, ``t1``, ``t2`` are scratch."""
    mat_vec(R[i], com[i], c)
    rotate_tensor(R[i], inertia[i], S3, Iw)
    wi = w[i]
    cross_to(alpha_b[i], c, t1)
    for k in range(3):
        aG_b[k] = a_b[i, k] + t1[k]
    cross_to(wi, c, t1)
    cross_to(wi, t1, t2)
    for k in range(3):
        aG_b[k] += t2[k]
    mat_vec(Iw, wi, t1)
    cross_to(wi, t1, t2)
    mat_vec(Iw, alpha_b[i], t1)
    for k in range(3):
        gyro[k] = t1[k] + t2[k]


@internal(**UNCOUNTED, forceinline=True)
def com_jacobian(i, c, JT, JR, anc_ptr, anc_idx, out):
    """Translation Jacobian of body i's centre of mass over its ancestor columns."""
    for m in range(anc_ptr[i], anc_ptr[i + 1]):
        col = anc_idx[m]
        out[0, col] = JT[i, 0, col] + JR[i, 1, col] * c[2] - JR[i, 2, col] * c[1]
        out[1, col] = JT[i, 1, col] + JR[i, 2, col] * c[0] - JR[i, 0, col] * c[2]
        out[2, col] = JT[i, 2, col] + JR[i, 0, col] * c[1] - JR[i, 1, col] * c[0]


@njit(**CACHED)
def jourdain(mass, com, inertia, has_inertia, R, r, w, alpha_b, a_b, JR, JT, anc_ptr, anc_idx,
             parent, F, N, M, f):
    """Newton-Euler-Jourdain: ``M = sum JT^T m JT + JR^T I JR`` (assembled by the
    composite-rigid-body algorithm, ``composite_mass_matrix``) and
    ``f = sum JT^T (F - m a_bias) + JR^T (N - I alpha_bias - w x I w)``."""
    n, nu = mass.shape[0], M.shape[0]
    jourdain_terms(mass, com, inertia, has_inertia, R, r, w, alpha_b, a_b, JR, JT, anc_ptr,
                   anc_idx, parent, F, N, M, f, np.empty(jourdain_work(n, nu)))


@register_jitable
def jourdain_work(n, nu):
    """Floats of scratch ``jourdain_terms`` needs for ``n`` frames and ``nu`` speeds."""
    return 39 * n + 9 * nu + 60


@njit(**UNCOUNTED)
def jourdain_terms(mass, com, inertia, has_inertia, R, r, w, alpha_b, a_b, JR, JT, anc_ptr,
                   anc_idx, parent, F, N, M, f, work):
    """``jourdain`` in the scratch ``work`` (``jourdain_work(n, nu)`` floats): it
    allocates nothing, so that it can run uncounted (``views.UNCOUNTED``)."""
    n, nu = mass.shape[0], M.shape[0]
    composite_mass_matrix(mass, com, inertia, parent, R, r, JR, JT, anc_ptr, anc_idx, M,
                          c_view(work, 0, (nu, 6)), c_view(work, 6 * nu, (n, 6, 6)),
                          c_view(work, 6 * nu + 36 * n, (3 * n + 60,)))
    at = 6 * nu + 39 * n + 60          # the mass matrix's scratch ends here
    for k in range(nu):
        f[k] = 0.0
    JG = c_view(work, at, (3, nu))
    for k in range(3 * nu):
        work[at + k] = 0.0
    Iw, S3 = c_view(work, 0, (3, 3)), c_view(work, 9, (3, 3))   # reuse: M is done
    c, aG_b, gyro, t1 = (c_view(work, 18, (3,)), c_view(work, 21, (3,)),
                         c_view(work, 24, (3,)), c_view(work, 27, (3,)))
    t2, fT, fR = c_view(work, 30, (3,)), c_view(work, 33, (3,)), c_view(work, 36, (3,))
    for i in range(mass.shape[0]):
        if not has_inertia[i]:
            loaded = False
            for k in range(3):
                loaded = loaded or F[i, k] != 0.0 or N[i, k] != 0.0
            if not loaded:               # a massless frame without loads adds nothing
                continue
        m_i = mass[i]
        body_terms(i, com, inertia, R, w, alpha_b, a_b, c, Iw, aG_b, gyro, S3, t1, t2)
        com_jacobian(i, c, JT, JR, anc_ptr, anc_idx, JG)
        for k in range(3):
            fT[k] = F[i, k] - m_i * aG_b[k]
            fR[k] = N[i, k] - gyro[k]
        for m in range(anc_ptr[i], anc_ptr[i + 1]):
            a_ = anc_idx[m]
            f[a_] += (JG[0, a_] * fT[0] + JG[1, a_] * fT[1] + JG[2, a_] * fT[2]
                      + JR[i, 0, a_] * fR[0] + JR[i, 1, a_] * fR[1] + JR[i, 2, a_] * fR[2])


@internal(**UNCOUNTED, forceinline=True)
def composite_mass_matrix(mass, com, inertia, parent, R, r, JR, JT, anc_ptr, anc_idx, M, S, IC,
                          scratch):
    """``M`` by the composite-rigid-body algorithm, in world Pluecker coordinates.

    A speed's column is a twist ``S = (w, v0)``: angular velocity and the velocity of the
    material point at a reference point ``o`` (the first frame's origin: about the world
    origin, a model far from it would lose digits to ``m |r|^2``).  Each body's spatial
    inertia about ``o`` is ``[[I_G - m [c]x[c]x, m [c]x], [-m [c]x, m E]]``; summed over subtrees into
    composite inertias ``IC``, they give ``M[a, b] = S_a . IC_k S_b`` for every column b of
    frame k's joint and every column a of k's joint or an ancestor's -- O(n d^2) instead of
    the O(n nu^2) of summing ``J^T m J`` body by body.

    Scratch: ``S`` (nu x 6), ``IC`` (n x 6 x 6) and ``scratch`` (at least 33 floats).
    """
    # long: the composite-rigid-body sweep and its projection on the joints' columns in one
    # loop, so the spatial inertia of each subtree never leaves the scratch.
    n = mass.shape[0]
    nu = M.shape[0]
    for i in range(n):
        for a_ in range(6):
            for b_ in range(6):
                IC[i, a_, b_] = 0.0
    Iw, S3 = c_view(scratch, 0, (3, 3)), c_view(scratch, 9, (3, 3))
    c, Fc, o = c_view(scratch, 18, (3,)), c_view(scratch, 21, (6,)), c_view(scratch, 27, (3,))
    for a_ in range(nu):
        for b_ in range(nu):
            M[a_, b_] = 0.0
    for k in range(3):
        o[k] = r[0, k] if n else 0.0
    for i in range(n):
        # this frame's own columns come last in its (sorted) column list: columns are
        # numbered in topological order, after every ancestor's
        p = parent[i]
        inherited = anc_ptr[p + 1] - anc_ptr[p] if p >= 0 else 0
        # twists of this frame's own columns
        for m in range(anc_ptr[i] + inherited, anc_ptr[i + 1]):
            col = anc_idx[m]
            wx, wy, wz = JR[i, 0, col], JR[i, 1, col], JR[i, 2, col]
            S[col, 0], S[col, 1], S[col, 2] = wx, wy, wz
            # v0 = v_origin_i - w x (r_i - o)
            dx, dy, dz = r[i, 0] - o[0], r[i, 1] - o[1], r[i, 2] - o[2]
            S[col, 3] = JT[i, 0, col] - (wy * dz - wz * dy)
            S[col, 4] = JT[i, 1, col] - (wz * dx - wx * dz)
            S[col, 5] = JT[i, 2, col] - (wx * dy - wy * dx)
        # this body's spatial inertia about the world origin
        m_i = mass[i]
        rotate_tensor(R[i], inertia[i], S3, Iw)
        mat_vec(R[i], com[i], c)
        cx, cy, cz = c[0] + r[i, 0] - o[0], c[1] + r[i, 1] - o[1], c[2] + r[i, 2] - o[2]
        cc = cx * cx + cy * cy + cz * cz
        G = IC[i]
        G[0, 0] = Iw[0, 0] + m_i * (cc - cx * cx)
        G[1, 1] = Iw[1, 1] + m_i * (cc - cy * cy)
        G[2, 2] = Iw[2, 2] + m_i * (cc - cz * cz)
        G[0, 1] = G[1, 0] = Iw[0, 1] - m_i * cx * cy
        G[0, 2] = G[2, 0] = Iw[0, 2] - m_i * cx * cz
        G[1, 2] = G[2, 1] = Iw[1, 2] - m_i * cy * cz
        # m [c]x (upper right) and its transpose (lower left)
        G[0, 4], G[0, 5] = -m_i * cz, m_i * cy
        G[1, 3], G[1, 5] = m_i * cz, -m_i * cx
        G[2, 3], G[2, 4] = -m_i * cy, m_i * cx
        for a_ in range(3):
            for b_ in range(3):
                G[3 + b_, a_] = G[a_, 3 + b_]
        G[3, 3] = G[4, 4] = G[5, 5] = m_i
    # composite inertias, leaves to root
    for i in range(n - 1, -1, -1):
        p = parent[i]
        if p >= 0:
            for a_ in range(6):
                for b_ in range(6):
                    IC[p, a_, b_] += IC[i, a_, b_]
    for i in range(n):
        p = parent[i]
        inherited = anc_ptr[p + 1] - anc_ptr[p] if p >= 0 else 0
        first_own = anc_ptr[i] + inherited
        for m in range(first_own, anc_ptr[i + 1]):
            b_ = anc_idx[m]
            for a_ in range(6):
                acc = 0.0
                for k in range(6):
                    acc += IC[i, a_, k] * S[b_, k]
                Fc[a_] = acc
            for mm in range(anc_ptr[i], m + 1):
                a_ = anc_idx[mm]
                val = 0.0
                for k in range(6):
                    val += S[a_, k] * Fc[k]
                M[a_, b_] = val
                M[b_, a_] = val


#: from this size on the factorization is LAPACK's (faster for large matrices, measured
#: crossover about 30); a failure is then located by the written-out loop below
LAPACK_CHOLESKY_FROM = 40


@internal(cache=True, _nrt=True)
def _lapack_cholesky(M, L, tiny):
    """``L`` from LAPACK's Cholesky; False if it fails or a pivot is below ``tiny``.
    Counted, explicitly (a callee inherits an uncounted caller's mode): LAPACK's factor
    is allocated and freed in here."""
    try:
        Lf = np.linalg.cholesky(M)
    except Exception:
        return False
    for j in range(M.shape[0]):
        if not (Lf[j, j] * Lf[j, j] > tiny):
            return False
    for i in range(M.shape[0]):                 # element-wise: see kinematics.forward_kinematics
        for j in range(M.shape[0]):
            L[i, j] = Lf[i, j]
    return True


@njit(**UNCOUNTED)
def cholesky_solve(M, f, L, x):
    """Solve ``M x = f`` by Cholesky.  Returns -1, or the index of the first pivot that is
    not positive (the coordinate where positive definiteness fails); ``L`` is workspace."""
    n = M.shape[0]
    scale = 0.0
    for j in range(n):
        scale = max(scale, abs(M[j, j]))
    tiny = 1e-14 * scale if scale > 0.0 else 1e-300
    if n >= LAPACK_CHOLESKY_FROM and _lapack_cholesky(M, L, tiny):
        return _triangular_solves(L, f, x)
    for j in range(n):
        s = M[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not (s > tiny):
            return j
        L[j, j] = np.sqrt(s)
        for i in range(j + 1, n):
            s = M[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / L[j, j]
    return _triangular_solves(L, f, x)


@internal(cache=True, _nrt=False, forceinline=True)
def _triangular_solves(L, f, x):
    """``x`` from ``L L^T x = f`` (``L`` lower triangular); returns -1."""
    n = L.shape[0]
    for i in range(n):                  # forward: L y = f
        s = f[i]
        for k in range(i):
            s -= L[i, k] * x[k]
        x[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):      # backward: L^T x = y
        s = x[i]
        for k in range(i + 1, n):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]
    return -1


#: floats of ``work`` ``newton_euler_system`` needs beyond ``3 nu``
NEWTON_EULER_WORK = 45


@njit(**UNCOUNTED)
def newton_euler_system(mass, com, inertia, parent, R, r, w, alpha_b, a_b, JR, JT,
                        anc_ptr, anc_idx, F, N, react_joint, react_force, react_moment, A, b,
                        work):
    """Assemble the Newton-Euler equations with reaction unknowns, ``A x = b``.

    Rows ``6i..6i+2``: Newton for body i at its centre of mass; rows ``6i+3..6i+5``: Euler
    about its centre of mass.  Unknowns: the free speed rates ``ud`` (columns ``0..nu-1``)
    and the reaction components ``lambda_k`` (column ``nu + k``).  Reaction component k
    belongs to the joint whose child is frame ``react_joint[k]`` and acts on that child at
    its origin with force ``R react_force[k]`` and moment ``R react_moment[k]`` (child
    components); the parent receives the opposite.  ``work``: ``3 nu +
    NEWTON_EULER_WORK`` floats of scratch (the kernel allocates nothing).
    """
    n = mass.shape[0]
    nu = JR.shape[2]
    if work.shape[0] < 3 * nu + NEWTON_EULER_WORK:
        raise ValueError("newton_euler_system: work holds fewer than 3 nu + NEWTON_EULER_WORK "
                         "floats")
    A[:, :] = 0.0
    JG = c_view(work, 0, (3, nu))
    for k in range(3 * nu):
        work[k] = 0.0
    at = 3 * nu
    Iw, S3 = c_view(work, at, (3, 3)), c_view(work, at + 9, (3, 3))
    c, cp, aG_b, gyro = (c_view(work, at + 18, (3,)), c_view(work, at + 21, (3,)),
                         c_view(work, at + 24, (3,)), c_view(work, at + 27, (3,)))
    t1, t2, Fk, Nk = (c_view(work, at + 30, (3,)), c_view(work, at + 33, (3,)),
                      c_view(work, at + 36, (3,)), c_view(work, at + 39, (3,)))
    lever = c_view(work, at + 42, (3,))
    for i in range(n):
        body_terms(i, com, inertia, R, w, alpha_b, a_b, c, Iw, aG_b, gyro, S3, t1, t2)
        com_jacobian(i, c, JT, JR, anc_ptr, anc_idx, JG)
        m_i = mass[i]
        for m in range(anc_ptr[i], anc_ptr[i + 1]):
            col = anc_idx[m]
            for k in range(3):
                A[6 * i + k, col] = m_i * JG[k, col]
                A[6 * i + 3 + k, col] = (Iw[k, 0] * JR[i, 0, col] + Iw[k, 1] * JR[i, 1, col]
                                         + Iw[k, 2] * JR[i, 2, col])
        for k in range(3):
            b[6 * i + k] = F[i, k] - m_i * aG_b[k]
            b[6 * i + 3 + k] = N[i, k] - gyro[k]
    for k in range(react_joint.shape[0]):
        i = react_joint[k]
        col = nu + k
        mat_vec(R[i], react_force[k], Fk)
        mat_vec(R[i], react_moment[k], Nk)
        mat_vec(R[i], com[i], c)                     # child's centre of mass -> joint is -c
        cross_to(c, Fk, t1)
        for q in range(3):
            A[6 * i + q, col] -= Fk[q]
            A[6 * i + 3 + q, col] -= Nk[q] - t1[q]
        p = parent[i]
        if p >= 0:
            mat_vec(R[p], com[p], cp)
            for q in range(3):
                lever[q] = r[i, q] - r[p, q] - cp[q]  # parent's centre of mass -> joint
            cross_to(lever, Fk, t1)
            for q in range(3):
                A[6 * p + q, col] += Fk[q]
                A[6 * p + 3 + q, col] += Nk[q] + t1[q]


@njit(**CACHED)
def joint_wrenches(mass, com, inertia, parent, R, r, w, alpha, a, F, N, out):
    """Inverse dynamics, leaves to root: the force and moment (about the joint origin)
    each parent exerts on its child, given the full accelerations; ``out[i] = (F, N)``.

    An independent route to the reactions: it uses no reaction basis and no linear solve.
    Each frame's terms in registers (``spatial.body_inertia``, ``motion``'s tuple
    products), so that it compiles in a fraction of a second (numpy's products took 2.8 s).
    """
    n = mass.shape[0]
    for i in range(n):
        for k in range(6):
            out[i, k] = 0.0
    # accumulate, per frame, the wrench its children draw (about each frame's own origin)
    for i in range(n - 1, -1, -1):
        c, Iw = body_inertia(R, com, inertia, i)
        wi, al = row3(w, i), row3(alpha, i)
        wc = cross(wi, c)
        t1, t2 = cross(al, c), cross(wi, wc)
        m = mass[i]
        # wrench needed at the origin from the parent, beyond what children take (already
        # in out[i]): f = m a_G - F, and the moment about G, then about the origin
        f = (m * (a[i, 0] + t1[0] + t2[0]) - F[i, 0], m * (a[i, 1] + t1[1] + t2[1]) - F[i, 1],
             m * (a[i, 2] + t1[2] + t2[2]) - F[i, 2])
        Ia, Iw_w = _sym_times(Iw, al), _sym_times(Iw, wi)
        gyro, lever_f = cross(wi, Iw_w), cross(c, f)
        for k in range(3):
            out[i, k] += f[k]
            out[i, 3 + k] += Ia[k] + gyro[k] - N[i, k] + lever_f[k]
        p = parent[i]
        if p >= 0:
            fi = row3(out, i)
            mp = cross((r[i, 0] - r[p, 0], r[i, 1] - r[p, 1], r[i, 2] - r[p, 2]), fi)
            for k in range(3):
                out[p, k] += fi[k]
                out[p, 3 + k] += out[i, 3 + k] + mp[k]


@register_jitable(inline="always")
def _sym_times(I6, x):
    """A symmetric 3x3 held as ``(xx, xy, xz, yy, yz, zz)`` times the 3-tuple ``x``."""
    return (I6[0] * x[0] + I6[1] * x[1] + I6[2] * x[2], I6[1] * x[0] + I6[3] * x[1] + I6[4] * x[2],
            I6[2] * x[0] + I6[4] * x[1] + I6[5] * x[2])


@njit(**CACHED)
def energies(mass, com, inertia, gravity, R, r, w, v):
    """Kinetic energy ``T = sum 1/2 m |v_G|^2 + 1/2 w . I w`` and gravitational potential
    ``V = -sum m g . r_G`` of the whole system."""
    T = 0.0
    V = 0.0
    c = np.empty(3)
    vG = np.empty(3)
    Iw = np.empty((3, 3))
    S3 = np.empty((3, 3))
    Iww = np.empty(3)
    for i in range(mass.shape[0]):
        mat_vec(R[i], com[i], c)
        cross_to(w[i], c, vG)
        rotate_tensor(R[i], inertia[i], S3, Iw)
        mat_vec(Iw, w[i], Iww)
        for k in range(3):
            vG[k] += v[i, k]
            T += 0.5 * (mass[i] * vG[k] * vG[k] + w[i, k] * Iww[k])
            V -= mass[i] * gravity[k] * (r[i, k] + c[k])
    return T, V

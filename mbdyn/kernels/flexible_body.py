"""A flexible body's floating-frame equations in compiled code, from its inertia invariants
packed in a flat float array (``compiled.flexible_packing``).

The same formulas as ``mbdyn.flexible.invariants`` (``floating_frame_mass_matrix``,
``quadratic_velocity_vector``) and ``algorithms.flexible_dynamics.body_forces``, written as
matrix-vector products over the packed numbers (``mv``): with ``w = (v_0, omega, eta')``
in body components,

    M_b(eta) [a_0; alpha; eta''] = Q_v + Q_g - [0; 0; K eta + D eta' + spin G eta' + K_G eta]

``body_layout(n)`` gives where each invariant of a body with ``n`` modes sits from its
offset, all row-major: ``m``, ``c`` (3), ``C`` (3 x n), ``J0`` (9), ``J1`` (n x 9), ``J2s``
(n x n x 9, ``J2_kl + J2_lk``: then ``dJ/deta_k = J1_k + eta_l J2s_kl`` and ``J(eta) = J0 +
(eta_k J1_k + eta_k dJ/deta_k) / 2``), ``Cr0`` (3 x n), ``Cr1`` (n x 3n), the modal mass
``M_ee`` (as the reduced body gives it), stiffness ``K``, damping ``D``, the geometric
stiffness per unit ``omega_y^2 + omega_z^2`` (``K_c``) and per unit ``a_x - g_x``
(``K_a``), and a rotor's ``spin G_ee`` (n x n each).
"""
from numba import njit
from numba.extending import register_jitable

from .views import UNCOUNTED
from .internal import internal


@register_jitable
def body_layout(n):
    """Offsets (from the body's first number) of ``(m, c, C, J0, J1, J2s, Cr0, Cr1, M_ee,
    K, D, K_c, K_a, spin G, end)`` for a body of ``n`` modes (module docstring)."""
    c = 1
    Cm = 4
    J0 = Cm + 3 * n
    J1 = J0 + 9
    J2 = J1 + 9 * n
    Cr0 = J2 + 9 * n * n
    Cr1 = Cr0 + 3 * n
    Mee = Cr1 + 3 * n * n
    K = Mee + n * n
    D = K + n * n
    Kc = D + n * n
    Ka = Kc + n * n
    Gs = Ka + n * n
    return 0, c, Cm, J0, J1, J2, Cr0, Cr1, Mee, K, D, Kc, Ka, Gs, Gs + n * n


@register_jitable
def body_work(n):
    """Floats of scratch ``body_equations`` takes for ``n`` modes (besides ``Mb``, ``Q``)."""
    return 45 + 18 * n


@internal(**UNCOUNTED)
def mv(A, off, rows, cols, x, xo, out, oo, scale, transpose):
    """``out[oo:] += scale A x[xo:]`` (``A^T`` when ``transpose``) for the row-major
    ``rows x cols`` matrix at ``A[off]``: every product of the body's terms."""
    if transpose:
        for i in range(rows):
            s = scale * x[xo + i]
            if s != 0.0:
                for j in range(cols):
                    out[oo + j] += s * A[off + i * cols + j]
    else:
        for i in range(rows):
            acc = 0.0
            for j in range(cols):
                acc += A[off + i * cols + j] * x[xo + j]
            out[oo + i] += scale * acc


@njit(inline="always", **UNCOUNTED)
def _cross_add(a, ao, b, bo, out, oo, scale):
    """``out[oo:oo+3] += scale (a x b)`` of the 3-vectors at ``a[ao]``, ``b[bo]``."""
    out[oo] += scale * (a[ao + 1] * b[bo + 2] - a[ao + 2] * b[bo + 1])
    out[oo + 1] += scale * (a[ao + 2] * b[bo] - a[ao] * b[bo + 2])
    out[oo + 2] += scale * (a[ao] * b[bo + 1] - a[ao + 1] * b[bo])


@internal(**UNCOUNTED)
def body_equations(fd, off, n, eta, ed, omega, g, bias, omega_k, gyroscopic, stiffening,
                   Mb, Q, w):
    """The body's ``Mb`` ((6 + n) x (6 + n)) and generalized forces ``Q`` (6 + n) at
    ``eta``, ``eta'`` (``ed``): the quadratic velocity vector at the angular velocity
    ``omega`` (when ``gyroscopic``), gravity ``g``, the elastic, damping and spin forces,
    the geometric stiffness (when ``stiffening``: ``omega_k`` the true angular velocity,
    ``a_x = bias[0]``) and ``-Mb[:, :6] bias`` (``bias``: the frame's acceleration and
    angular acceleration at ``u' = 0``); all body components.  ``w``: ``body_work(n)``
    floats of scratch."""
    # long: the body's mass matrix and forces term by term in one compiled loop (calls between
    # kernels are optimised again in every caller: docs/performance.md, cold start)
    o_m, o_c, o_C, o_J0, o_J1, o_J2, o_Cr0, o_Cr1, o_Mee, o_K, o_D, o_Kc, o_Ka, o_G, _ = \
        body_layout(n)
    # scratch: c (3), J (9), dJ (9n), Cr (3n), Jdot (9), C eta' (3), Cr eta' (3), J w (3),
    # Jdot w (3), w w^T (9), Cr_dot (3n), w eta'^T (3n), a 3-vector
    for k in range(body_work(n)):
        w[k] = 0.0
    m = fd[off + o_m]
    # integers and flags as values, not literals: numba would compile ``mv`` once per
    # combination of literal arguments
    i0 = n - n
    i3, i6, i9 = i0 + 3, i0 + 6, i0 + 9
    yes, no = i0 == 0, i0 != 0
    C_, J_, dJ, Cr, Jd = i0, i3, i0 + 12, 12 + 9 * n, 12 + 12 * n
    Ce, Cre, Jw, Jdw, ww = Jd + 9, Jd + 12, Jd + 15, Jd + 18, Jd + 21
    Crd, we, v = ww + 9, ww + 9 + 3 * n, ww + 9 + 6 * n
    for i in range(3):
        w[C_ + i] = fd[off + o_c + i]
    mv(fd, off + o_C, i3, n, eta, i0, w, C_, 1.0, no)             # c(eta) = c + C eta
    for k in range(n):                                              # dJ_k = J1_k + J2s_kl eta_l
        for j in range(9):
            w[dJ + 9 * k + j] = fd[off + o_J1 + 9 * k + j]
        mv(fd, off + o_J2 + 9 * n * k, n, i9, eta, i0, w, dJ + 9 * k, 1.0, yes)
    for j in range(9):
        w[J_ + j] = fd[off + o_J0 + j]
    mv(fd, off + o_J1, n, i9, eta, i0, w, J_, 0.5, yes)              # J(eta)
    mv(w, dJ, n, i9, eta, i0, w, J_, 0.5, yes)
    for i in range(3 * n):
        w[Cr + i] = fd[off + o_Cr0 + i]
    mv(fd, off + o_Cr1, n, 3 * n, eta, i0, w, Cr, 1.0, yes)         # Cr(eta) = Cr0 + Cr1 eta
    # the mass matrix
    nb = 6 + n
    for i in range(nb):
        for j in range(nb):
            Mb[i, j] = 0.0
    for i in range(3):
        Mb[i, i] = m
        for j in range(3):
            Mb[3 + i, 3 + j] = w[J_ + 3 * i + j]
        for k in range(n):
            Mb[i, 6 + k] = Mb[6 + k, i] = fd[off + o_C + n * i + k]
            Mb[3 + i, 6 + k] = Mb[6 + k, 3 + i] = w[Cr + n * i + k]
    c0, c1, c2 = w[C_], w[C_ + 1], w[C_ + 2]
    Mb[0, 4], Mb[0, 5], Mb[1, 5] = c2, -c1, c0                      # -c~ and c~
    Mb[1, 3], Mb[2, 3], Mb[2, 4] = -c2, c1, -c0
    Mb[4, 0], Mb[5, 0], Mb[5, 1] = c2, -c1, c0
    Mb[3, 1], Mb[3, 2], Mb[4, 2] = -c2, c1, -c0
    for k in range(n):
        for l_ in range(n):
            Mb[6 + k, 6 + l_] = fd[off + o_Mee + n * k + l_]
    for r in range(nb):
        Q[r] = 0.0
    if gyroscopic:
        mv(w, dJ, n, i9, ed, i0, w, Jd, 1.0, yes)                    # J' = dJ_k eta'_k
        mv(fd, off + o_C, i3, n, ed, i0, w, Ce, 1.0, no)           # C eta'
        mv(w, Cr, i3, n, ed, i0, w, Cre, 1.0, no)                  # Cr eta'
        mv(w, J_, i3, i3, omega, i0, w, Jw, 1.0, no)                # J w
        mv(w, Jd, i3, i3, omega, i0, w, Jdw, 1.0, no)               # J' w
        mv(fd, off + o_Cr1, n, 3 * n, ed, i0, w, Crd, 1.0, yes)     # Cr_dot = Cr1 eta'
        for i in range(3):
            for j in range(3):
                w[ww + 3 * i + j] = omega[i] * omega[j]
            for k in range(n):
                w[we + n * i + k] = omega[i] * ed[k]
        # Q_t = -w x (w x c) - 2 w x (C eta'); Q_r = -w x (J w) - J' w - w x (Cr eta')
        _cross_add(omega, i0, w, C_, w, v, 1.0)
        _cross_add(omega, i0, w, v, Q, i0, -1.0)
        _cross_add(omega, i0, w, Ce, Q, i0, -2.0)
        _cross_add(omega, i0, w, Jw, Q, i3, -1.0)
        _cross_add(omega, i0, w, Cre, Q, i3, -1.0)
        for i in range(3):
            Q[3 + i] -= w[Jdw + i]
        # Q_e,k = 1/2 w^T dJ_k w + w^T Cr1_k eta' - w^T Cr_dot[:, k]
        mv(w, dJ, n, i9, w, ww, Q, i6, 0.5, no)
        mv(fd, off + o_Cr1, n, 3 * n, w, we, Q, i6, 1.0, no)
        mv(w, Crd, i3, n, omega, i0, Q, i6, -1.0, yes)
    # gravity: m g, c(eta) x g, C^T g
    for i in range(3):
        Q[i] += m * g[i]
    _cross_add(w, C_, g, i0, Q, i3, 1.0)
    mv(fd, off + o_C, i3, n, g, i0, Q, i6, 1.0, yes)
    # elastic, damping, spin and geometric stiffness forces on the modal rows
    mv(fd, off + o_K, n, n, eta, i0, Q, i6, -1.0, no)
    mv(fd, off + o_D, n, n, ed, i0, Q, i6, -1.0, no)
    mv(fd, off + o_G, n, n, ed, i0, Q, i6, -1.0, no)
    if stiffening:
        mv(fd, off + o_Kc, n, n, eta, i0, Q, i6,
           -(omega_k[1] * omega_k[1] + omega_k[2] * omega_k[2]), False)
        mv(fd, off + o_Ka, n, n, eta, i0, Q, i6, -(bias[0] - g[0]), no)
    # the frame's bias accelerations to the right: Q -= Mb[:, :6] bias
    for r in range(nb):
        acc = 0.0
        for j in range(6):
            acc += Mb[r, j] * bias[j]
        Q[r] -= acc


@internal(**UNCOUNTED)
def axial_row(fd, off, n, eta, out):
    """``out = K_a eta`` (n): the modal rows' coefficient of the frame's ``a_x`` that the
    geometric stiffness moves to the left-hand side."""
    for k in range(n):
        out[k] = 0.0
    i0 = n - n
    mv(fd, off + body_layout(n)[12], n, n, eta, i0, out, i0, 1.0, i0 != 0)

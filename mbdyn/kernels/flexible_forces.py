"""Loads and force elements at points of flexible bodies, in compiled code: the laws of
``algorithms.flexible_forces`` (and of ``kernels.forces``) on the points' motion, their
generalized forces on the extended speeds (the tree's, then the modal ones).

A *side* of an element is the ground, a point of a rigid frame of the tree, or a point of a
flexible body tied to its node: ``r_0 + R (x_p + Phi_p eta)``, turned by the node's small
rotation ``Psi_p eta`` (Rodrigues), its velocity ``v_0 + omega x R x_p' + R Phi_p eta'`` and
angular velocity ``omega + R Psi_p eta'`` (world components).  A force ``F`` and a moment
``N`` at a world point ``p`` act on a rigid frame ``i`` through ``JT_i^T F + JR_i^T (N +
(p - r_i) x F)``; on a flexible body they add ``[F_b; x_p' x F_b + N_b; Phi_p^T F_b +
Psi_p^T N_b]`` to its generalized forces (body components; ``N_b`` about its point), which
its ``B^T`` maps to the speeds (``kernels.flexible``).

Layout (``compiled.flexible_packing``): ``eint[e] = [kind, frame_a, body_a, point_a,
frame_b, body_b, point_b, data, table mode, spin slot, in body]`` (frame -1: the ground;
body -1: a rigid frame, else the flexible body's row of ``fint``; ``point_*``: the offset of
the point's numbers in ``edata``: ``s`` (3) on a rigid frame, ``x_p, Phi_p (3 x n), Psi_p
(3 x n)`` on a flexible body).  Numbers at ``data``: a load's ``F, N``; a spring-damper's
``k, c, L0, F0, eps``; a bushing's ``K, C`` (6 x 6 each, frame a's axes); a bearing's
``e1, e2`` (housing axes), eight coefficients and eight table offsets (-1: constant), its
spin the ``ufull`` entry ``spin slot``.
"""
import math

from numba import njit

from .tables import table_eval
from .views import UNCOUNTED, c_view
from .internal import internal

LOAD, SPRING_DAMPER, BUSHING, BEARING = 0, 1, 2, 3
EROW = 11          # entries of an eint row
#: fint columns: tree frame, modes, eta in qfull, eta' in ufull, first extended speed,
#: offset of its numbers in fdata, offset of its element forces in ``qe``
FRAME, MODES, Q0, U0, X0, OFF, QE = 0, 1, 2, 3, 4, 5, 6
FROW = 7
#: floats of scratch ``element_forces`` takes
ELEMENT_WORK = 2 * 24 + 80


@njit(inline="always", **UNCOUNTED)
def side_state(frame, b, off, fint, edata, qfull, ufull, R, r, w, v, out):
    """The side's world point ``out[0:3]``, velocity ``[3:6]``, orientation ``[6:15]``
    (row-major: the frame's, a node's turned by its small rotation) and angular velocity
    ``[15:18]``; ``[18:21]`` the point in body axes ``x_p + Phi_p eta`` (flexible sides);
    ``out[21:24]`` scratch."""
    # long: a rigid side's and a node's point, velocity and frame, written where derived
    if frame < 0:
        for k in range(3):
            out[k] = edata[off + k]
            out[3 + k] = 0.0
            out[15 + k] = 0.0
        for k in range(9):
            out[6 + k] = 1.0 if k % 4 == 0 else 0.0
        return
    Ri = R[frame]
    xb, th, tmp = out[18:21], out[21:24], out[3:6]
    for k in range(3):
        xb[k] = edata[off + k]
        th[k] = 0.0
        tmp[k] = 0.0
        out[15 + k] = 0.0
    if b >= 0:
        n, q0, u0 = fint[b, MODES], fint[b, Q0], fint[b, U0]
        Phi = c_view(edata, off + 3, (3, n))
        Psi = c_view(edata, off + 3 + 3 * n, (3, n))
        for k in range(3):
            a1 = 0.0
            a2 = 0.0
            a3 = 0.0
            a4 = 0.0
            for j in range(n):
                a1 += Phi[k, j] * qfull[q0 + j]
                a2 += Psi[k, j] * qfull[q0 + j]
                a3 += Phi[k, j] * ufull[u0 + j]
                a4 += Psi[k, j] * ufull[u0 + j]
            xb[k] += a1
            th[k] = a2
            tmp[k] = a3          # Phi eta' (body), then R of it below
            out[15 + k] = a4     # Psi eta' (body)
    p, vel, Rn, wn = out[0:3], out[3:6], c_view(out, 6, (3, 3)), out[15:18]
    lever = out[6:9]             # (Rn is written last)
    for k in range(3):
        lever[k] = Ri[k, 0] * xb[0] + Ri[k, 1] * xb[1] + Ri[k, 2] * xb[2]
        p[k] = r[frame, k] + lever[k]
    e0 = Ri[0, 0] * tmp[0] + Ri[0, 1] * tmp[1] + Ri[0, 2] * tmp[2]
    e1 = Ri[1, 0] * tmp[0] + Ri[1, 1] * tmp[1] + Ri[1, 2] * tmp[2]
    e2 = Ri[2, 0] * tmp[0] + Ri[2, 1] * tmp[1] + Ri[2, 2] * tmp[2]
    c0 = w[frame, 1] * lever[2] - w[frame, 2] * lever[1]
    c1 = w[frame, 2] * lever[0] - w[frame, 0] * lever[2]
    c2 = w[frame, 0] * lever[1] - w[frame, 1] * lever[0]
    vel[0] = v[frame, 0] + c0 + e0
    vel[1] = v[frame, 1] + c1 + e1
    vel[2] = v[frame, 2] + c2 + e2
    s0, s1, s2 = wn[0], wn[1], wn[2]
    for k in range(3):
        wn[k] = w[frame, k] + Ri[k, 0] * s0 + Ri[k, 1] * s1 + Ri[k, 2] * s2
    # Rn = R Rot(theta), Rot by Rodrigues (I + K to first order at |theta| < 1e-12)
    t0, t1_, t2 = th[0], th[1], th[2]
    a = math.sqrt(t0 * t0 + t1_ * t1_ + t2 * t2)
    if a < 1e-12:
        s, cc = 1.0, 0.0
    else:
        s, cc = math.sin(a) / a, (1.0 - math.cos(a)) / (a * a)
    K00, K01, K02 = 0.0, -t2, t1_
    K10, K11, K12 = t2, 0.0, -t0
    K20, K21, K22 = -t1_, t0, 0.0
    rot = (1.0 + cc * (K00 * K00 + K01 * K10 + K02 * K20),
           s * K01 + cc * (K00 * K01 + K01 * K11 + K02 * K21),
           s * K02 + cc * (K00 * K02 + K01 * K12 + K02 * K22),
           s * K10 + cc * (K10 * K00 + K11 * K10 + K12 * K20),
           1.0 + cc * (K10 * K01 + K11 * K11 + K12 * K21),
           s * K12 + cc * (K10 * K02 + K11 * K12 + K12 * K22),
           s * K20 + cc * (K20 * K00 + K21 * K10 + K22 * K20),
           s * K21 + cc * (K20 * K01 + K21 * K11 + K22 * K21),
           1.0 + cc * (K20 * K02 + K21 * K12 + K22 * K22))
    for i in range(3):
        for j in range(3):
            Rn[i, j] = Ri[i, 0] * rot[j] + Ri[i, 1] * rot[3 + j] + Ri[i, 2] * rot[6 + j]


@internal(**UNCOUNTED)
def apply(frame, b, off, st, F, N, p, fint, edata, R, r, JR, JT, anc_ptr, anc_idx, fe, qe,
          tmp):
    """Add the force ``F`` and moment ``N`` (world) acting at the world point ``p`` on a
    side (state ``st`` from ``side_state``): to ``fe`` (extended speeds) for a rigid frame,
    to the flexible body's generalized forces in ``qe`` otherwise (``tmp``: 6 floats)."""
    if frame < 0:
        return
    if b < 0:
        for k in range(3):
            tmp[k] = p[k] - r[frame, k]
        n0 = N[0] + tmp[1] * F[2] - tmp[2] * F[1]
        n1 = N[1] + tmp[2] * F[0] - tmp[0] * F[2]
        n2 = N[2] + tmp[0] * F[1] - tmp[1] * F[0]
        for m in range(anc_ptr[frame], anc_ptr[frame + 1]):
            col = anc_idx[m]
            fe[col] += (JT[frame, 0, col] * F[0] + JT[frame, 1, col] * F[1]
                        + JT[frame, 2, col] * F[2] + JR[frame, 0, col] * n0
                        + JR[frame, 1, col] * n1 + JR[frame, 2, col] * n2)
        return
    Ri = R[frame]
    n, at = fint[b, MODES], fint[b, QE]
    for k in range(3):                         # the moment about the side's point
        tmp[k] = p[k] - st[k]
    m0 = N[0] + tmp[1] * F[2] - tmp[2] * F[1]
    m1 = N[1] + tmp[2] * F[0] - tmp[0] * F[2]
    m2 = N[2] + tmp[0] * F[1] - tmp[1] * F[0]
    for k in range(3):                         # body components
        tmp[k] = Ri[0, k] * F[0] + Ri[1, k] * F[1] + Ri[2, k] * F[2]
        tmp[3 + k] = Ri[0, k] * m0 + Ri[1, k] * m1 + Ri[2, k] * m2
    xb = st[18:21]
    qe[at] += tmp[0]
    qe[at + 1] += tmp[1]
    qe[at + 2] += tmp[2]
    qe[at + 3] += xb[1] * tmp[2] - xb[2] * tmp[1] + tmp[3]
    qe[at + 4] += xb[2] * tmp[0] - xb[0] * tmp[2] + tmp[4]
    qe[at + 5] += xb[0] * tmp[1] - xb[1] * tmp[0] + tmp[5]
    Phi = c_view(edata, off + 3, (3, n))
    Psi = c_view(edata, off + 3 + 3 * n, (3, n))
    for j in range(n):
        qe[at + 6 + j] += (Phi[0, j] * tmp[0] + Phi[1, j] * tmp[1] + Phi[2, j] * tmp[2]
                           + Psi[0, j] * tmp[3] + Psi[1, j] * tmp[4] + Psi[2, j] * tmp[5])


@internal(**UNCOUNTED)
def element_forces(eint, edata, fint, qfull, ufull, R, r, w, v, JR, JT, anc_ptr, anc_idx, fe,
                   qe, work):
    """Add every element's generalized forces: rigid frames' to ``fe`` (extended speeds),
    flexible bodies' to ``qe`` (body components, at each body's ``fint[b, QE]``), with the
    true velocities (before the gyroscopic switch drops them).  ``work``: ``ELEMENT_WORK``
    floats."""
    # long: one branch per kind in one loop, as kernels.forces.force_elements
    sa, sb = work[0:24], work[24:48]
    F, N, Fm, Nm, d, tmp = (work[48:51], work[51:54], work[54:57], work[57:60], work[60:63],
                            work[63:69])
    x6, xd6, e1, e2, ks = work[69:75], work[75:81], work[81:84], work[84:87], work[87:95]
    tab = work[95:98]
    for e in range(eint.shape[0]):
        kind, fa, ba, pa_, fb_, bb, pb_, off = (eint[e, 0], eint[e, 1], eint[e, 2],
                                                eint[e, 3], eint[e, 4], eint[e, 5],
                                                eint[e, 6], eint[e, 7])
        side_state(fa, ba, pa_, fint, edata, qfull, ufull, R, r, w, v, sa)
        if kind == LOAD:
            for k in range(3):
                F[k] = edata[off + k]
                N[k] = edata[off + 3 + k]
            if eint[e, 10] and fa >= 0:               # body components: the frame's axes
                for k in range(3):
                    Fm[k] = R[fa, k, 0] * F[0] + R[fa, k, 1] * F[1] + R[fa, k, 2] * F[2]
                    Nm[k] = R[fa, k, 0] * N[0] + R[fa, k, 1] * N[1] + R[fa, k, 2] * N[2]
                for k in range(3):
                    F[k] = Fm[k]
                    N[k] = Nm[k]
            apply(fa, ba, pa_, sa, F, N, sa, fint, edata, R, r, JR, JT, anc_ptr, anc_idx,
                  fe, qe, tmp)
            continue
        side_state(fb_, bb, pb_, fint, edata, qfull, ufull, R, r, w, v, sb)
        if kind == SPRING_DAMPER:
            L2 = 0.0
            for k in range(3):
                d[k] = sb[k] - sa[k]
                L2 += d[k] * d[k]
            L = math.sqrt(L2)
            eps = edata[off + 4]
            scale = 1.0 / math.sqrt(L2 + eps * eps)
            xd = 0.0
            for k in range(3):
                d[k] *= scale
                xd += d[k] * (sb[3 + k] - sa[3 + k])
            T = edata[off + 3] + edata[off] * (L - edata[off + 2]) + edata[off + 1] * xd
            for k in range(3):
                F[k] = T * d[k]
                Fm[k] = -F[k]
                N[k] = 0.0
            apply(fa, ba, pa_, sa, F, N, sa, fint, edata, R, r, JR, JT, anc_ptr, anc_idx,
                  fe, qe, tmp)
            apply(fb_, bb, pb_, sb, Fm, N, sb, fint, edata, R, r, JR, JT, anc_ptr, anc_idx,
                  fe, qe, tmp)
        elif kind == BUSHING:
            _bushing(off, sa, sb, edata, d, x6, xd6, F, N, e1)
            for k in range(3):
                Fm[k] = -F[k]
                Nm[k] = -N[k]
            apply(fb_, bb, pb_, sb, F, N, sb, fint, edata, R, r, JR, JT, anc_ptr, anc_idx,
                  fe, qe, tmp)
            apply(fa, ba, pa_, sa, Fm, Nm, sb, fint, edata, R, r, JR, JT, anc_ptr,
                  anc_idx, fe, qe, tmp)
        else:
            _bearing(e, off, eint, sa, sb, edata, ufull, d, e1, e2, ks, tab, F, Fm, N)
            apply(fa, ba, pa_, sa, F, N, sa, fint, edata, R, r, JR, JT, anc_ptr, anc_idx,
                  fe, qe, tmp)
            apply(fb_, bb, pb_, sb, Fm, N, sa, fint, edata, R, r, JR, JT, anc_ptr, anc_idx,
                  fe, qe, tmp)


@njit(inline="always", **UNCOUNTED)
def _bushing(off, sa, sb, edata, d, x6, xd6, F, N, t):
    """A bushing's force ``F`` and moment ``N`` on side b (world components):
    ``-(K x6 + C xd6)`` in side a's axes, ``x6`` b's offset and small rotation from a."""
    Ra, Rb = c_view(sa, 6, (3, 3)), c_view(sb, 6, (3, 3))
    wa, wb = sa[15:18], sb[15:18]
    for k in range(3):
        d[k] = sb[k] - sa[k]
    for k in range(3):
        x6[k] = Ra[0, k] * d[0] + Ra[1, k] * d[1] + Ra[2, k] * d[2]
        t[k] = Ra[0, k] * wa[0] + Ra[1, k] * wa[1] + Ra[2, k] * wa[2]      # Ra^T wa
        xd6[k] = (Ra[0, k] * (sb[3] - sa[3]) + Ra[1, k] * (sb[4] - sa[4])
                  + Ra[2, k] * (sb[5] - sa[5]))
        xd6[3 + k] = (Ra[0, k] * (wb[0] - wa[0]) + Ra[1, k] * (wb[1] - wa[1])
                      + Ra[2, k] * (wb[2] - wa[2]))
    xd6[0] -= t[1] * x6[2] - t[2] * x6[1]
    xd6[1] -= t[2] * x6[0] - t[0] * x6[2]
    xd6[2] -= t[0] * x6[1] - t[1] * x6[0]
    for a_ in range(3):                 # the axial vector of Ra^T Rb's skew part
        b_, c_ = (a_ + 1) % 3, (a_ + 2) % 3
        s_ = 0.0
        for q in range(3):
            s_ += Ra[q, c_] * Rb[q, b_] - Ra[q, b_] * Rb[q, c_]
        x6[3 + a_] = 0.5 * s_
    for row in range(3):
        f_ = 0.0
        m_ = 0.0
        for col in range(6):
            f_ += edata[off + 6 * row + col] * x6[col] \
                + edata[off + 36 + 6 * row + col] * xd6[col]
            m_ += edata[off + 6 * (row + 3) + col] * x6[col] \
                + edata[off + 36 + 6 * (row + 3) + col] * xd6[col]
        t[row] = -f_
        d[row] = -m_
    for k in range(3):
        F[k] = Ra[k, 0] * t[0] + Ra[k, 1] * t[1] + Ra[k, 2] * t[2]
        N[k] = Ra[k, 0] * d[0] + Ra[k, 1] * d[1] + Ra[k, 2] * d[2]


@njit(inline="always", **UNCOUNTED)
def _bearing(e, off, eint, sa, sb, edata, ufull, d, e1, e2, ks, tab, F, Fm, N):
    """A bearing's force ``F`` on the shaft's side a at its point (``Fm = -F`` on the
    housing's material point there; ``N = 0``)."""
    Rh, wh = c_view(sb, 6, (3, 3)), sb[15:18]
    for k in range(3):
        e1[k] = Rh[k, 0] * edata[off] + Rh[k, 1] * edata[off + 1] + Rh[k, 2] * edata[off + 2]
        e2[k] = (Rh[k, 0] * edata[off + 3] + Rh[k, 1] * edata[off + 4]
                 + Rh[k, 2] * edata[off + 5])
        d[k] = sa[k] - sb[k]
    slot = eint[e, 9]
    spin = ufull[slot] if slot >= 0 else 0.0
    for c8 in range(8):
        toff = int(edata[off + 14 + c8])
        if toff < 0:
            ks[c8] = edata[off + 6 + c8]
        else:
            table_eval(edata, toff, eint[e, 8], spin, tab)
            ks[c8] = tab[0]
    x = y = xd = yd = 0.0
    for k in range(3):
        # the housing's material velocity at the shaft's point: vb + wh x (pa - pb)
        vh = sb[3 + k] + (wh[(k + 1) % 3] * d[(k + 2) % 3] - wh[(k + 2) % 3] * d[(k + 1) % 3])
        x += e1[k] * d[k]
        y += e2[k] * d[k]
        xd += e1[k] * (sa[3 + k] - vh)
        yd += e2[k] * (sa[3 + k] - vh)
    fx = -(ks[0] * x + ks[1] * y + ks[4] * xd + ks[5] * yd)
    fy = -(ks[2] * x + ks[3] * y + ks[6] * xd + ks[7] * yd)
    for k in range(3):
        F[k] = fx * e1[k] + fy * e2[k]
        Fm[k] = -F[k]
        N[k] = 0.0

"""The kinematics of the per-call dynamics: every frame's orientation, origin and motion
subspace ``S``, and (``rates``) its velocities and accelerations -- ``kinematics.walk``
without the full Jacobians, the quantities held in local scalars instead of scratch rows.

The per-call entries (forward dynamics by articulated bodies, inverse dynamics, the mass
matrix: ``packed``, ``inverse``) spend half their time in the kinematics.  ``walk`` passes
each frame's rows through a scratch buffer, whose every write the compiler must assume
may change any other array of the packed buffers (they are views of one buffer); here a
frame's 3x3 products and cross products are tuples (registers), and the three joint kinds
of a robot -- revolute, prismatic, fixed -- have their relative motion written out; the
others (Euler angles, spherical, free) take ``joints.joint_motion`` as ``walk`` does.  The
same quantities in the same frames as ``walk`` (``kinematics``'s docstring), to rounding.
"""
import math


from .joints import (FIXED, FREE, MAX_NU, NQ, NU, PRISMATIC, REVOLUTE, joint_motion,
                     quaternion_matrix)
from .views import FUSED, c_view
from .internal import internal

#: floats of scratch ``motion`` needs (the general joints' relative motion)
MOTION_WORK = 12 + 6 * MAX_NU + 82


@internal(**FUSED)
def mm(a, b):
    """``a b`` of 3x3 matrices held row by row in 9-tuples."""
    return (a[0] * b[0] + a[1] * b[3] + a[2] * b[6], a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
            a[0] * b[2] + a[1] * b[5] + a[2] * b[8], a[3] * b[0] + a[4] * b[3] + a[5] * b[6],
            a[3] * b[1] + a[4] * b[4] + a[5] * b[7], a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[3] + a[8] * b[6], a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
            a[6] * b[2] + a[7] * b[5] + a[8] * b[8])


@internal(**FUSED)
def mv(a, x, y, z):
    """``a (x, y, z)`` of a 3x3 matrix held in a 9-tuple."""
    return (a[0] * x + a[1] * y + a[2] * z, a[3] * x + a[4] * y + a[5] * z,
            a[6] * x + a[7] * y + a[8] * z)


@internal(**FUSED)
def cross(a, b):
    """``a x b`` of 3-tuples."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@internal(**FUSED)
def row3(A, i):
    """``A[i]`` of an (n, 3) array as a 3-tuple."""
    return (A[i, 0], A[i, 1], A[i, 2])


@internal(**FUSED)
def mat9(A, i):
    """``A[i]`` of an (n, 3, 3) array as a 9-tuple, row by row."""
    return (A[i, 0, 0], A[i, 0, 1], A[i, 0, 2], A[i, 1, 0], A[i, 1, 1], A[i, 1, 2],
            A[i, 2, 0], A[i, 2, 1], A[i, 2, 2])


@internal(**FUSED)
def rodrigues(x, y, z, angle):
    """The rotation by ``angle`` about the unit axis ``(x, y, z)``, as ``joints.
    rotation_about_axis`` writes it, in a 9-tuple."""
    c, s = math.cos(angle), math.sin(angle)
    k = 1.0 - c
    return (c + x * x * k, x * y * k - z * s, x * z * k + y * s,
            y * x * k + z * s, c + y * y * k, y * z * k - x * s,
            z * x * k - y * s, z * y * k + x * s, c + z * z * k)


@internal(forceinline=True, **FUSED)
def turned(J, x, y, z, angle):
    """``J Rot(a, angle)`` and the axis ``J a`` in world axes, for the unit axis ``a = (x, y,
    z)`` in the joint frame ``J`` (9-tuple).  An axis along ``x``, ``y`` or ``z`` (as URDF
    files mostly give them) turns two columns of ``J``: a third of the products of
    ``mm(J, rodrigues(...))``, whose exact zeros they leave out."""
    c, s = math.cos(angle), math.sin(angle)
    if x == 0.0 and y == 0.0 and abs(z) == 1.0:
        s *= z
        return ((c * J[0] + s * J[1], c * J[1] - s * J[0], J[2],
                 c * J[3] + s * J[4], c * J[4] - s * J[3], J[5],
                 c * J[6] + s * J[7], c * J[7] - s * J[6], J[8]),
                (z * J[2], z * J[5], z * J[8]))
    if x == 0.0 and z == 0.0 and abs(y) == 1.0:
        s *= y
        return ((c * J[0] - s * J[2], J[1], c * J[2] + s * J[0],
                 c * J[3] - s * J[5], J[4], c * J[5] + s * J[3],
                 c * J[6] - s * J[8], J[7], c * J[8] + s * J[6]),
                (y * J[1], y * J[4], y * J[7]))
    if y == 0.0 and z == 0.0 and abs(x) == 1.0:
        s *= x
        return ((J[0], c * J[1] + s * J[2], c * J[2] - s * J[1],
                 J[3], c * J[4] + s * J[5], c * J[5] - s * J[4],
                 J[6], c * J[7] + s * J[8], c * J[8] - s * J[7]),
                (x * J[0], x * J[3], x * J[6]))
    return mm(J, rodrigues(x, y, z, angle)), mv(J, x, y, z)


@internal(forceinline=True, **FUSED)
def _free(i, qfull, ufull, udfull, k0, j0, J, rates, S):
    """A free joint (a floating base) written out, as ``joints.joint_motion`` defines it:
    ``q = (x, y, z, w, qx, qy, qz)``, the origin's offset ``(x, y, z)`` in the joint frame
    ``J`` and the unit quaternion (``joints.quaternion_matrix``, normalised first);
    the speeds: the origin's velocity along ``J``'s axes, then the angular velocity in the
    body's axes.  Returns as ``_general``, the joint's six columns of ``S`` written."""
    Ri = mm(J, quaternion_matrix(qfull[k0 + 3], qfull[k0 + 4], qfull[k0 + 5], qfull[k0 + 6]))
    for c in range(3):
        for k in range(3):
            S[i, k, c] = 0.0
            S[i, 3 + k, c] = J[3 * k + c]            # translation along J's axis c
            S[i, k, 3 + c] = Ri[3 * k + c]           # rotation about the body's axis c
            S[i, 3 + k, 3 + c] = 0.0
    off = mv(J, qfull[k0], qfull[k0 + 1], qfull[k0 + 2])
    zero = (0.0, 0.0, 0.0)
    if not rates:
        return Ri, off, zero, zero, zero, zero
    u, ud = ufull, udfull
    return (Ri, off, mv(Ri, u[j0 + 3], u[j0 + 4], u[j0 + 5]),
            mv(Ri, ud[j0 + 3], ud[j0 + 4], ud[j0 + 5]), mv(J, u[j0], u[j0 + 1], u[j0 + 2]),
            mv(J, ud[j0], ud[j0 + 1], ud[j0 + 2]))


@internal(**FUSED)
def _general(i, kd, seq, axis, qfull, ufull, udfull, k0, j0, J, rates, S, work):
    """A joint of any kind by ``joints.joint_motion``: ``Ri`` (9-tuple), the origin's
    offset ``J d`` and, in world axes, the relative angular velocity and acceleration and
    the relative velocity and acceleration of the origin (3-tuples), the joint's columns
    of ``S`` written.  ``work``: ``MOTION_WORK`` floats."""
    nq, nu = NQ[kd], NU[kd]
    Rrel, d = c_view(work, 0, (3, 3)), c_view(work, 9, (3,))
    Hw, Hv = c_view(work, 12, (3, MAX_NU)), c_view(work, 12 + 3 * MAX_NU, (3, MAX_NU))
    at = 12 + 6 * MAX_NU
    Sm, Sv = c_view(work, at, (4, 3, 3)), c_view(work, at + 36, (8, 3))
    hw, hv = c_view(work, at + 60, (3,)), c_view(work, at + 63, (3,))
    qj, uj = c_view(work, at + 66, (7,)), c_view(work, at + 73, (6,))
    axi = c_view(work, at + 79, (3,))
    for k in range(nq):
        qj[k] = qfull[k0 + k]
    for k in range(nu):
        uj[k] = ufull[j0 + k]
    for k in range(3):
        axi[k] = axis[i, k]
    joint_motion(kd, axi, seq[i], qj[:nq], uj[:nu], Rrel, d, Hw, Hv, hw, hv, Sm, Sv)
    Ri = mm(J, (Rrel[0, 0], Rrel[0, 1], Rrel[0, 2], Rrel[1, 0], Rrel[1, 1], Rrel[1, 2],
                Rrel[2, 0], Rrel[2, 1], Rrel[2, 2]))
    w0 = w1 = w2 = v0 = v1 = v2 = 0.0
    dw0, dw1, dw2, dv0, dv1, dv2 = hw[0], hw[1], hw[2], hv[0], hv[1], hv[2]
    for c in range(nu):
        uc, udc = uj[c], (udfull[j0 + c] if rates else 0.0)
        w0, w1, w2 = w0 + Hw[0, c] * uc, w1 + Hw[1, c] * uc, w2 + Hw[2, c] * uc
        v0, v1, v2 = v0 + Hv[0, c] * uc, v1 + Hv[1, c] * uc, v2 + Hv[2, c] * uc
        dw0, dw1, dw2 = dw0 + Hw[0, c] * udc, dw1 + Hw[1, c] * udc, dw2 + Hw[2, c] * udc
        dv0, dv1, dv2 = dv0 + Hv[0, c] * udc, dv1 + Hv[1, c] * udc, dv2 + Hv[2, c] * udc
        sr = mv(Ri, Hw[0, c], Hw[1, c], Hw[2, c])
        st = mv(J, Hv[0, c], Hv[1, c], Hv[2, c])
        for k in range(3):
            S[i, k, c] = sr[k]
            S[i, 3 + k, c] = st[k]
    return (Ri, mv(J, d[0], d[1], d[2]), mv(Ri, w0, w1, w2), mv(Ri, dw0, dw1, dw2),
            mv(J, v0, v1, v2), mv(J, dv0, dv1, dv2))


@internal(constants=True, **FUSED)   # rates 0 (the mass matrix): no velocity terms
def motion(parent, kind, axis, seq, pos, C, qoff, uoff, qfull, ufull, udfull, R, r, w, v,
           alpha, a, S, work, rates):
    """Every frame's ``R``, ``r`` and its joint's columns of ``S`` (world axes, parents
    first), and with ``rates`` its ``w``, ``v``, ``alpha``, ``a`` at the speed rates
    ``udfull`` (zeros for the bias accelerations).  ``work``: ``MOTION_WORK`` floats."""
    # long: one frame after another in one loop, the parent's rows read once into
    # registers (see the module docstring); the three common joint kinds written out.
    zero = (0.0, 0.0, 0.0)
    for i in range(parent.shape[0]):
        p, kd, k0, j0 = parent[i], kind[i], qoff[i], uoff[i]
        Ci = mat9(C, i)
        if p >= 0:
            Rp = mat9(R, p)
            J = mm(Rp, Ci)                       # the joint frame's axes
            rho = mv(Rp, pos[i, 0], pos[i, 1], pos[i, 2])
        else:
            J, rho = Ci, row3(pos, i)
        wrel = dwrel = vrel = dvrel = zero      # relative motion, world axes
        if kd == REVOLUTE or kd == PRISMATIC:
            x, y, z = axis[i, 0], axis[i, 1], axis[i, 2]
            uc = ufull[j0] if rates else 0.0
            udc = udfull[j0] if rates else 0.0
            if kd == REVOLUTE:
                Ri, e = turned(J, x, y, z, qfull[k0])
                S[i, 0, 0], S[i, 1, 0], S[i, 2, 0] = e
                S[i, 3, 0] = S[i, 4, 0] = S[i, 5, 0] = 0.0
                wrel = (e[0] * uc, e[1] * uc, e[2] * uc)
                dwrel = (e[0] * udc, e[1] * udc, e[2] * udc)
            else:
                e = mv(J, x, y, z)               # the joint's axis
                Ri, qc = J, qfull[k0]
                rho = (rho[0] + e[0] * qc, rho[1] + e[1] * qc, rho[2] + e[2] * qc)
                S[i, 0, 0] = S[i, 1, 0] = S[i, 2, 0] = 0.0
                S[i, 3, 0], S[i, 4, 0], S[i, 5, 0] = e
                vrel = (e[0] * uc, e[1] * uc, e[2] * uc)
                dvrel = (e[0] * udc, e[1] * udc, e[2] * udc)
        elif kd == FIXED:
            Ri = J
        elif kd == FREE:
            Ri, off, wrel, dwrel, vrel, dvrel = _free(i, qfull, ufull, udfull, k0, j0, J, rates,
                                                      S)
            rho = (rho[0] + off[0], rho[1] + off[1], rho[2] + off[2])
        else:
            Ri, off, wrel, dwrel, vrel, dvrel = _general(i, kd, seq, axis, qfull, ufull,
                                                         udfull, k0, j0, J, rates, S, work)
            rho = (rho[0] + off[0], rho[1] + off[1], rho[2] + off[2])
        R[i, 0, 0], R[i, 0, 1], R[i, 0, 2] = Ri[0], Ri[1], Ri[2]
        R[i, 1, 0], R[i, 1, 1], R[i, 1, 2] = Ri[3], Ri[4], Ri[5]
        R[i, 2, 0], R[i, 2, 1], R[i, 2, 2] = Ri[6], Ri[7], Ri[8]
        rp = row3(r, p) if p >= 0 else zero
        r[i, 0], r[i, 1], r[i, 2] = rp[0] + rho[0], rp[1] + rho[1], rp[2] + rho[2]
        if not rates:
            continue
        if p >= 0:
            wp, vp, alp, ap = row3(w, p), row3(v, p), row3(alpha, p), row3(a, p)
        else:
            wp = vp = alp = ap = zero
        t1 = cross(wp, rho)
        t2 = cross(wp, wrel)
        t3 = cross(wp, t1)
        t4 = cross(alp, rho)
        t5 = cross(wp, vrel)
        for k in range(3):
            w[i, k] = wp[k] + wrel[k]
            v[i, k] = vp[k] + t1[k] + vrel[k]
            alpha[i, k] = alp[k] + t2[k] + dwrel[k]
            a[i, k] = ap[k] + t4[k] + t3[k] + 2.0 * t5[k] + dvrel[k]

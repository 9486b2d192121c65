"""Forward kinematics of the tree and the Jacobians of translation and rotation.

Steps 1-6 of the textbook, done for every frame in topological order (parents first).
All outputs are in inertial (world) components unless a name says otherwise:

* ``R[i]``  -- orientation of frame i: ``I s = R[i] . B_i s`` (the textbook's ``T`` is ``R^T``);
* ``r, v, a`` -- position, velocity, acceleration of frame i's origin;
* ``w, alpha`` -- absolute angular velocity and acceleration of frame i;
* ``JR[i]``, ``JT[i]`` -- Jacobians of rotation ``dw_i/du`` and of translation of the
  origin ``dv_i/du``, over the free speeds ``u`` (driven joints have no column);
* ``S[i]`` -- the same Jacobians' columns of frame i's own joint only, compactly: its
  motion subspace, ``S[i, :3, c]`` of rotation and ``S[i, 3:, c]`` of translation for the
  joint's ``c``-th free speed (all the articulated-body route reads: n x 6 x 6 floats,
  where ``JR`` and ``JT`` are n x 3 x nu each); written in their place when the walk is
  given no ancestor lists.

The accelerations use the speed rates passed in ``udfull``: with zeros for the free
speeds they are the velocity-product ("bias") accelerations, so that
``a = JT ud + a_bias`` and ``alpha = JR ud + alpha_bias``.
"""
import numpy as np
from numba import njit

from .joints import EULER, MAX_NU, REVOLUTE, SPHERICAL, joint_motion
from .linalg3 import cross_to, mat_mat, mat_vec
from .views import CACHED, UNCOUNTED, c_view
from .internal import internal


@internal(cache=True)
def cross(a, b):
    """``a x b`` as a new array (for code off the hot path)."""
    return np.array((a[1] * b[2] - a[2] * b[1],
                     a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]))


#: floats of scratch ``forward_kinematics`` needs (see ``walk``)
KINEMATICS_WORK = 5 * 9 + 2 * 3 * MAX_NU + 4 * 9 + 8 * 3 + 25 * 3 + 1


@njit(**CACHED)
def forward_kinematics(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                       qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S):
    """Motion of every frame and the Jacobians at frame origins (see module docstring).

    ``anc_idx[anc_ptr[i]:anc_ptr[i+1]]`` lists the free-speed columns on which frame i
    depends (its own joint's and its ancestors'); the other columns of ``JR[i]`` and
    ``JT[i]`` are zero and are never written, so the caller zeroes them once.  ``S`` is
    written instead of them when ``anc_ptr`` is empty (the full Jacobians may then be
    empty too): the articulated-body route's kinematics.
    """
    walk(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx, qfull, ufull,
         udfull, R, r, w, v, alpha, a, JR, JT, S, np.empty(KINEMATICS_WORK))


@internal(**UNCOUNTED)
def walk(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx, qfull, ufull,
         udfull, R, r, w, v, alpha, a, JR, JT, S, work):
    """``forward_kinematics`` in the scratch ``work`` (at least ``KINEMATICS_WORK``
    floats): it allocates nothing, so that it can run uncounted (``views.UNCOUNTED``)."""
    # long: steps 1-6 of the textbook for one frame after another in one loop (rotation,
    # position, velocities, accelerations, Jacobian columns): numba passes rows of the
    # parent's results through the scratch, not as arguments of helper calls.
    n = parent.shape[0]
    full = anc_ptr.shape[0] > 0
    # Per-frame rows are copied into this scratch, element by element, rather than passed
    # on as views (R[p], w[p], ...): each view costs reference-count calls, which cost
    # more than the arithmetic of a small model; the scratch views (c_view) cost none.
    Rrel, RJ0, Rp = c_view(work, 0, (3, 3)), c_view(work, 9, (3, 3)), c_view(work, 18, (3, 3))
    Ri, Ci = c_view(work, 27, (3, 3)), c_view(work, 36, (3, 3))
    Hw, Hv = c_view(work, 45, (3, MAX_NU)), c_view(work, 45 + 3 * MAX_NU, (3, MAX_NU))
    at = 45 + 6 * MAX_NU
    Sm, Sv = c_view(work, at, (4, 3, 3)), c_view(work, at + 36, (8, 3))
    at += 60
    d, hw, hv, rho = (c_view(work, at, (3,)), c_view(work, at + 3, (3,)),
                      c_view(work, at + 6, (3,)), c_view(work, at + 9, (3,)))
    wrel_b, dwrel_b, vrel_j, dvrel_j = (c_view(work, at + 12, (3,)), c_view(work, at + 15, (3,)),
                                        c_view(work, at + 18, (3,)), c_view(work, at + 21, (3,)))
    wrel, vrel, t1, t2 = (c_view(work, at + 24, (3,)), c_view(work, at + 27, (3,)),
                          c_view(work, at + 30, (3,)), c_view(work, at + 33, (3,)))
    t3, t4, axi, posi = (c_view(work, at + 36, (3,)), c_view(work, at + 39, (3,)),
                         c_view(work, at + 42, (3,)), c_view(work, at + 45, (3,)))
    wp, alp = c_view(work, at + 48, (3,)), c_view(work, at + 51, (3,))
    qj, uj, udj = c_view(work, at + 54, (7,)), c_view(work, at + 61, (6,)), c_view(work, at + 67, (6,))
    for i in range(n):
        p = parent[i]
        k0 = qoff[i]
        j0 = uoff[i]
        kd = kind[i]
        nu = 0 if kd == 0 else (1 if kd <= 2 else (3 if kd <= 4 else 6))
        nq = 0 if kd == 0 else (1 if kd <= 2 else (3 if kd == 3 else (4 if kd == 4 else 7)))
        for k in range(nq):
            qj[k] = qfull[k0 + k]
        for k in range(nu):
            uj[k] = ufull[j0 + k]
            udj[k] = udfull[j0 + k]
        for k in range(3):
            axi[k] = axis[i, k]
            posi[k] = pos[i, k]
            for m in range(3):
                Ci[k, m] = C[i, k, m]
        joint_motion(kd, axi, seq[i], qj[:nq], uj[:nu], Rrel, d, Hw, Hv, hw, hv, Sm, Sv)

        # orientation and position: J0 = parent (x) placement, child = J0 (x) joint
        if p >= 0:
            for k in range(3):
                wp[k] = w[p, k]
                alp[k] = alpha[p, k]
                for m in range(3):
                    Rp[k, m] = R[p, k, m]
            mat_mat(Rp, Ci, RJ0)
            mat_vec(Rp, posi, rho)
        else:                                 # (element by element: an array assignment
            for k in range(3):                # makes numba compile its error message)
                rho[k] = posi[k]
                for m in range(3):
                    RJ0[k, m] = Ci[k, m]
        mat_mat(RJ0, Rrel, Ri)
        for k in range(3):
            for m in range(3):
                R[i, k, m] = Ri[k, m]
        mat_vec(RJ0, d, t1)
        for k in range(3):
            rho[k] += t1[k]                   # parent origin -> child origin
        # relative velocities and accelerations of the joint (child / J0 components); a
        # joint that only turns about the child's origin has none of translation
        turns = kd == REVOLUTE or kd == EULER or kd == SPHERICAL
        for k in range(3):
            wrel_b[k] = 0.0
            dwrel_b[k] = hw[k]
        for c in range(nu):
            for k in range(3):
                wrel_b[k] += Hw[k, c] * uj[c]
                dwrel_b[k] += Hw[k, c] * udj[c]
        mat_vec(Ri, wrel_b, wrel)
        mat_vec(Ri, dwrel_b, t3)              # relative angular acceleration, world
        if turns:
            for k in range(3):
                vrel[k] = 0.0
                t4[k] = 0.0
        else:
            for k in range(3):
                vrel_j[k] = 0.0
                dvrel_j[k] = hv[k]
            for c in range(nu):
                for k in range(3):
                    vrel_j[k] += Hv[k, c] * uj[c]
                    dvrel_j[k] += Hv[k, c] * udj[c]
            mat_vec(RJ0, vrel_j, vrel)
            mat_vec(RJ0, dvrel_j, t4)         # relative acceleration, world
        if p >= 0:
            cross_to(wp, rho, t1)
            for k in range(3):
                r[i, k] = r[p, k] + rho[k]
                w[i, k] = wp[k] + wrel[k]
                v[i, k] = v[p, k] + t1[k] + vrel[k]
            # alpha = alpha_p + w_p x w_rel + R dw_rel
            cross_to(wp, wrel, t2)
            for k in range(3):
                alpha[i, k] = alp[k] + t2[k] + t3[k]
            # a = a_p + alpha_p x rho + w_p x (w_p x rho) + 2 w_p x v_rel + RJ0 d''
            cross_to(wp, t1, t2)              # w_p x (w_p x rho)
            for k in range(3):
                t4[k] += t2[k]
            cross_to(alp, rho, t2)
            for k in range(3):
                t4[k] += t2[k]
            cross_to(wp, vrel, t2)
            for k in range(3):
                a[i, k] = a[p, k] + t4[k] + 2.0 * t2[k]
        else:
            for k in range(3):
                r[i, k] = rho[k]
                w[i, k] = wrel[k]
                v[i, k] = vrel[k]
                alpha[i, k] = t3[k]
                a[i, k] = t4[k]

        # Jacobians: inherit the parent's columns, then add this joint's own (into the full
        # Jacobians when they are wanted, else into S)
        if full and p >= 0:
            for m in range(anc_ptr[p], anc_ptr[p + 1]):
                col = anc_idx[m]
                jr0, jr1, jr2 = JR[p, 0, col], JR[p, 1, col], JR[p, 2, col]
                JR[i, 0, col] = jr0
                JR[i, 1, col] = jr1
                JR[i, 2, col] = jr2
                # v_i = v_p + w_p x rho  ->  JT_i = JT_p - [rho]x JR_p
                JT[i, 0, col] = JT[p, 0, col] + jr1 * rho[2] - jr2 * rho[1]
                JT[i, 1, col] = JT[p, 1, col] + jr2 * rho[0] - jr0 * rho[2]
                JT[i, 2, col] = JT[p, 2, col] + jr0 * rho[1] - jr1 * rho[0]
        if ucol[i] >= 0:
            for c in range(nu):
                col = ucol[i] + c
                for k in range(3):
                    sr = Ri[k, 0] * Hw[0, c] + Ri[k, 1] * Hw[1, c] + Ri[k, 2] * Hw[2, c]
                    st = 0.0 if turns else (RJ0[k, 0] * Hv[0, c] + RJ0[k, 1] * Hv[1, c]
                                            + RJ0[k, 2] * Hv[2, c])
                    if full:
                        JR[i, k, col] = sr
                        JT[i, k, col] = st
                    else:
                        S[i, k, c] = sr
                        S[i, 3 + k, c] = st


@njit(**UNCOUNTED)
def point_jacobian(JT_origin, JR, offset_world, out):
    """Translation Jacobian of a point fixed on a frame: ``JT_P = JT_O - [r_OP]x JR``."""
    ncol = JR.shape[1]
    x, y, z = offset_world[0], offset_world[1], offset_world[2]
    for c in range(ncol):
        out[0, c] = JT_origin[0, c] + JR[1, c] * z - JR[2, c] * y
        out[1, c] = JT_origin[1, c] + JR[2, c] * x - JR[0, c] * z
        out[2, c] = JT_origin[2, c] + JR[0, c] * y - JR[1, c] * x

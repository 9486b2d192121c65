"""Joint kinds: the few formulas each kind needs, dispatched by integer code.

A joint connects a parent frame P to a child frame B through a *joint frame* J0 that is
fixed in P (placed by the joint's position and orientation).  For every kind this module
gives, from the joint's own coordinates ``qj``, speeds ``uj`` and speed rates ``udj``:

* ``Rrel`` -- rotation of B relative to J0, mapping B components to J0 components
  (``J0 s = Rrel . B s``; the textbook's ``T`` is its transpose);
* ``d`` -- position of B's origin relative to J0's origin, J0 components;
* ``Hw`` -- relative angular velocity of B w.r.t. J0, **B components**: ``w_rel = Hw uj``;
* ``Hv`` -- relative velocity of B's origin, **J0 components**: ``d' = Hv uj``;
* ``hw``, ``hv`` -- the velocity-product parts ``Hw' uj`` and ``Hv' uj`` of the relative
  accelerations (zero for every kind but the Euler-angle joint).
"""
import numpy as np
from numba import njit

from .linalg3 import cross_to, mat_mat, mat_t_vec
from .views import UNCOUNTED
from .internal import internal

FIXED, REVOLUTE, PRISMATIC, EULER, SPHERICAL, FREE = 0, 1, 2, 3, 4, 5
KIND_CODES = {"fixed": FIXED, "revolute": REVOLUTE, "prismatic": PRISMATIC,
              "euler": EULER, "spherical": SPHERICAL, "free": FREE}
KIND_NAMES = {v: k for k, v in KIND_CODES.items()}
# Number of coordinates q and speeds u of each kind, indexed by code.
NQ = (0, 1, 1, 3, 4, 7)
NU = (0, 1, 1, 3, 3, 6)
MAX_NU = 6


@internal(**UNCOUNTED)
def rotation_about_axis(axis, angle, out):
    """Rodrigues: rotation by ``angle`` about the unit ``axis``; maps rotated to fixed comps."""
    c = np.cos(angle)
    s = np.sin(angle)
    k = 1.0 - c
    x, y, z = axis[0], axis[1], axis[2]
    out[0, 0] = c + x * x * k
    out[0, 1] = x * y * k - z * s
    out[0, 2] = x * z * k + y * s
    out[1, 0] = y * x * k + z * s
    out[1, 1] = c + y * y * k
    out[1, 2] = y * z * k - x * s
    out[2, 0] = z * x * k - y * s
    out[2, 1] = z * y * k + x * s
    out[2, 2] = c + z * z * k


@internal(**UNCOUNTED)
def rotation_about_coordinate_axis(k, angle, out):
    """Rotation by ``angle`` about coordinate axis ``k`` (0=x, 1=y, 2=z); = T_k(angle)^T."""
    c = np.cos(angle)
    s = np.sin(angle)
    out[:, :] = 0.0
    i = (k + 1) % 3
    j = (k + 2) % 3
    out[k, k] = 1.0
    out[i, i] = c
    out[j, j] = c
    out[i, j] = -s
    out[j, i] = s


@internal(forceinline=True, **UNCOUNTED)
def quaternion_matrix(qw, qx, qy, qz):
    """Rotation matrix of the quaternion ``(qw, qx, qy, qz)``, normalised first, as a
    9-tuple row by row (``quaternion_to_matrix``, and the per-call kinematics' free joint,
    ``motion._free``).

    Normalising here makes the dynamics independent of any drift of ``|q|`` that an
    integrator lets in; the drift itself is reported by the simulation.
    """
    n = np.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    w, x, y, z = qw / n, qx / n, qy / n, qz / n
    return (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),
            2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x),
            2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y))


@internal(**UNCOUNTED)
def quaternion_to_matrix(q, out):
    """``quaternion_matrix`` of ``q = (w, x, y, z)`` into the 3x3 array ``out``."""
    m = quaternion_matrix(q[0], q[1], q[2], q[3])
    for k in range(9):
        out[k // 3, k % 3] = m[k]


@internal(**UNCOUNTED)
def quaternion_rate(q, w, out):
    """``q' = 1/2 q (x) (0, w)`` with ``w`` in the rotated (child) frame.

    Uses the normalised ``q`` so that ``q . q' = 0``: the norm is an invariant of the
    exact flow whatever its current value.
    """
    n = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    a, b, c, d = q[0] / n, q[1] / n, q[2] / n, q[3] / n
    out[0] = 0.5 * (-b * w[0] - c * w[1] - d * w[2])
    out[1] = 0.5 * (a * w[0] - d * w[1] + c * w[2])
    out[2] = 0.5 * (d * w[0] + a * w[1] - b * w[2])
    out[3] = 0.5 * (-c * w[0] + b * w[1] + a * w[2])


@internal(**UNCOUNTED)
def euler_rate_matrix(seq, angles, rates, Hw, hw, Sm, Sv):
    """Relative angular velocity of an Euler-angle joint, child components.

    ``Rrel = R_{s0}(q0) R_{s1}(q1) R_{s2}(q2)`` (rotations about moving axes), so
    ``w = R2^T R1^T e_{s0} q0' + R2^T e_{s1} q1' + e_{s2} q2'``.  Fills the columns of
    ``Hw`` and the velocity product ``hw = Hw' q'``, using
    ``d/dt R^T(q) x = -q' e x (R^T x) + R^T x'``.  ``Sm`` (>= 2x3x3) and ``Sv`` (>= 8x3)
    are scratch.
    """
    R1 = Sm[0]
    R2 = Sm[1]
    rotation_about_coordinate_axis(seq[1], angles[1], R1)
    rotation_about_coordinate_axis(seq[2], angles[2], R2)
    y, c0, c1, e1, e2, t0, t1, t2 = Sv[0], Sv[1], Sv[2], Sv[3], Sv[4], Sv[5], Sv[6], Sv[7]
    for k in range(3):
        y[k] = R1[seq[0], k]               # R1^T e_{s0}
        c1[k] = R2[seq[1], k]              # R2^T e_{s1}
        e1[k] = 0.0
        e2[k] = 0.0
    e1[seq[1]] = 1.0
    e2[seq[2]] = 1.0
    mat_t_vec(R2, y, c0)                   # R2^T R1^T e_{s0}
    for k in range(3):
        Hw[k, 0] = c0[k]
        Hw[k, 1] = c1[k]
        Hw[k, 2] = e2[k]
    cross_to(e1, y, t1)
    mat_t_vec(R2, t1, t0)                  # R2^T (e1 x R1^T e0)
    cross_to(e2, c0, t1)
    cross_to(e2, c1, t2)
    for k in range(3):
        dc0 = -rates[2] * t1[k] - rates[1] * t0[k]
        dc1 = -rates[2] * t2[k]
        hw[k] = dc0 * rates[0] + dc1 * rates[1]


@internal(**UNCOUNTED)
def joint_motion(kind, axis, seq, qj, uj, Rrel, d, Hw, Hv, hw, hv, Sm, Sv):
    """Relative motion of one joint; see the module docstring for the outputs.
    ``Sm`` (4x3x3) and ``Sv`` (8x3) are scratch.  Only the joint's own ``NU[kind]``
    columns of ``Hw``, ``Hv`` are written."""
    nu = NU[kind]
    for k in range(3):
        d[k] = 0.0
        hw[k] = 0.0
        hv[k] = 0.0
        for c in range(nu):
            Hw[k, c] = 0.0
            Hv[k, c] = 0.0
    if kind == FIXED:
        for i in range(3):
            for j in range(3):
                Rrel[i, j] = 1.0 if i == j else 0.0
    elif kind == REVOLUTE:
        rotation_about_axis(axis, qj[0], Rrel)
        for k in range(3):
            Hw[k, 0] = axis[k]
    elif kind == PRISMATIC:
        for i in range(3):
            for j in range(3):
                Rrel[i, j] = 1.0 if i == j else 0.0
        for k in range(3):
            d[k] = axis[k] * qj[0]
            Hv[k, 0] = axis[k]
    elif kind == EULER:
        rotation_about_coordinate_axis(seq[0], qj[0], Sm[2])
        rotation_about_coordinate_axis(seq[1], qj[1], Sm[0])
        rotation_about_coordinate_axis(seq[2], qj[2], Sm[1])
        mat_mat(Sm[2], Sm[0], Sm[3])
        mat_mat(Sm[3], Sm[1], Rrel)
        euler_rate_matrix(seq, qj, uj, Hw, hw, Sm, Sv)
    elif kind == SPHERICAL:
        quaternion_to_matrix(qj, Rrel)
        for k in range(3):
            Hw[k, k] = 1.0
    elif kind == FREE:
        quaternion_to_matrix(qj[3:7], Rrel)
        for k in range(3):
            d[k] = qj[k]
            Hv[k, k] = 1.0
            Hw[k, 3 + k] = 1.0


@internal(**UNCOUNTED)
def joint_coordinate_rates(kind, qj, uj, out):
    """Kinematic equations ``q' = N(q) u`` of one joint."""
    if kind == SPHERICAL:
        quaternion_rate(qj, uj, out)
    elif kind == FREE:
        for k in range(3):
            out[k] = uj[k]
        quaternion_rate(qj[3:7], uj[3:6], out[3:7])
    else:
        for k in range(uj.shape[0]):
            out[k] = uj[k]


@njit(**UNCOUNTED)
def coordinate_rates(q, u, slots, out):
    """``q' = N(q) u`` for every free joint; ``slots[s] = (kind, q start, nq, u start, nu)``."""
    for s in range(slots.shape[0]):
        code, qi, nqj, ui, nuj = slots[s, 0], slots[s, 1], slots[s, 2], slots[s, 3], slots[s, 4]
        joint_coordinate_rates(code, q[qi:qi + nqj], u[ui:ui + nuj], out[qi:qi + nqj])

"""Closed forms of the textbook's three examples, transcribed independently of mbdyn.

Sources: ``/work/shared/textbook/EXAMPLES.md`` (the cleaned-up examples) and the Pascal
listings of ``dynamics_of_machines_II.txt`` (``pend2`` for the double pendulum, ``top`` for
the heavy top).  Plain ``math``/``numpy`` only -- nothing here may call mbdyn, so that the
engine can be tested against it.

Conventions (the textbook's): ``T_z(a)``, ``T_x(a)`` map a vector's components from the
parent frame into the rotated frame, ``B s = T . I s``.
"""
import math

import numpy as np

from random_trees import quat_mul

G = 9.81


def T_z(a):
    """The text's transformation matrix for a rotation ``a`` about z (parent -> rotated)."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def T_x(a):
    """The text's transformation matrix for a rotation ``a`` about x (parent -> rotated)."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


# ---------------------------------------------------------------------------------------
# Example 1 (1.4.1): particle pendulum on a rotating disk on a rotating arm
# ---------------------------------------------------------------------------------------
def rotating_pendulum(beta, beta_dot, t, Omega, omega, b, r, l, m, g=G):
    """``(beta'', R, T)`` of EXAMPLES.md Example 1.

    ``beta'' + (g/l) sin b - (b Omega^2 cos(omega t) + r W^2)/l cos b - W^2 sin b cos b = 0``,
    ``R = -m (b Omega^2 sin(omega t) + 2 l W beta' cos b)``,
    ``T = m {g cos b + [b Omega^2 cos(omega t) + r W^2] sin b + l [beta'^2 + W^2 sin^2 b]}``
    with ``W = Omega + omega``.  ``R`` and ``T`` are the B3 x and z components of the force
    the rod/hinge exerts on the particle E (``[R, 0, T]`` in B3).
    """
    W = Omega + omega
    sb, cb = math.sin(beta), math.cos(beta)
    K = b * Omega**2 * math.cos(omega * t) + r * W**2
    beta_ddot = -(g / l) * sb + K / l * cb + W**2 * sb * cb
    R = -m * (b * Omega**2 * math.sin(omega * t) + 2.0 * l * W * beta_dot * cb)
    T = m * (g * cb + K * sb + l * (beta_dot**2 + W**2 * sb**2))
    return beta_ddot, R, T


def rotating_pendulum_kinematics(beta, beta_dot, beta_ddot, t, Omega, omega, b, r, l):
    """``(B3 w3, B3 alpha3, B3 a_E)`` of Example 1 (components in the pendulum frame B3)."""
    W = Omega + omega
    sb, cb = math.sin(beta), math.cos(beta)
    w3 = np.array([beta_dot, W * sb, W * cb])
    alpha3 = np.array([beta_ddot, W * beta_dot * cb, -W * beta_dot * sb])
    K = b * Omega**2 * math.cos(omega * t) + r * W**2
    a_E = np.array([
        -b * Omega**2 * math.sin(omega * t) - 2.0 * l * W * beta_dot * cb,
        -K * cb + l * beta_ddot - l * W**2 * sb * cb,
        K * sb + l * (beta_dot**2 + W**2 * sb**2),
    ])
    return w3, alpha3, a_E


def rotating_pendulum_transformations(beta, t, Omega, omega):
    """The text's transformation matrices from I of the arm B1, the disk B2 and the
    pendulum B3: ``B1 = T_z(Omega t)``, ``B2 = T_z(omega t) B1``, ``B3 = T_x(beta) B2``."""
    T1 = T_z(Omega * t)
    T2 = T_z(omega * t) @ T1
    T3 = T_x(beta) @ T2
    return T1, T2, T3


# ---------------------------------------------------------------------------------------
# Example 2 (1.4.2): planar double pendulum of two particles (Pascal program pend2)
# ---------------------------------------------------------------------------------------
def double_pendulum(t1, t2, dt1, dt2, m1, m2, l1, l2, g=G):
    """``(ddt1, ddt2, Tr1, Tr2)`` exactly as the Pascal listing ``pend2`` prints them
    (``Power(x, 2)`` is ``x**2``).  ``t1`` is rod 1's angle from the downward vertical,
    ``t2`` rod 2's angle relative to rod 1; ``Tr1``, ``Tr2`` are the rod forces (tension
    positive: at rest hanging, ``Tr1 = (m1 + m2) g`` and ``Tr2 = m2 g``)."""
    sin, cos = math.sin, math.cos

    def Power(x, n):
        return x**n

    Sin, Cos = sin, cos
    den = -(l1 * l2 * m1 * m2) - l1 * l2 * Power(m2, 2) * Power(Sin(t2), 2)
    ddt1 = (g * l2 * m1 * m2 * Sin(t1)
            - Power(dt1, 2) * Power(l2, 2) * Power(m2, 2) * Sin(t2)
            - 2 * dt1 * dt2 * Power(l2, 2) * Power(m2, 2) * Sin(t2)
            - Power(dt2, 2) * Power(l2, 2) * Power(m2, 2) * Sin(t2)
            - Power(dt1, 2) * l1 * l2 * Power(m2, 2) * Cos(t2) * Sin(t2)
            - g * l2 * Power(m2, 2) * Cos(t1 + t2) * Sin(t2)) / den
    ddt2 = (-(g * l2 * m1 * m2 * Sin(t1))
            - g * l1 * m1 * m2 * Cos(t2) * Sin(t1)
            + Power(dt1, 2) * Power(l1, 2) * m1 * m2 * Sin(t2)
            + Power(dt1, 2) * Power(l2, 2) * Power(m2, 2) * Sin(t2)
            + 2 * dt1 * dt2 * Power(l2, 2) * Power(m2, 2) * Sin(t2)
            + Power(dt2, 2) * Power(l2, 2) * Power(m2, 2) * Sin(t2)
            + 2 * Power(dt1, 2) * l1 * l2 * Power(m2, 2) * Cos(t2) * Sin(t2)
            + 2 * dt1 * dt2 * l1 * l2 * Power(m2, 2) * Cos(t2) * Sin(t2)
            + Power(dt2, 2) * l1 * l2 * Power(m2, 2) * Cos(t2) * Sin(t2)
            + Power(dt1, 2) * Power(l1, 2) * Power(m2, 2) * Power(Cos(t2), 2) * Sin(t2)
            + g * l2 * Power(m2, 2) * Cos(t1 + t2) * Sin(t2)
            + g * l1 * Power(m2, 2) * Cos(t2) * Cos(t1 + t2) * Sin(t2)
            + Power(dt1, 2) * Power(l1, 2) * Power(m2, 2) * Power(Sin(t2), 3)
            + g * l1 * m1 * m2 * Sin(t1 + t2)
            + g * l1 * Power(m2, 2) * Power(Sin(t2), 2) * Sin(t1 + t2)) / den
    Tr1 = (-(Power(dt1, 2) * Power(l1, 2) * l2 * Power(m1, 2) * m2)
           - g * l1 * l2 * Power(m1, 2) * m2 * Cos(t1)
           - Power(dt1, 2) * l1 * Power(l2, 2) * m1 * Power(m2, 2) * Cos(t2)
           - 2 * dt1 * dt2 * l1 * Power(l2, 2) * m1 * Power(m2, 2) * Cos(t2)
           - Power(dt2, 2) * l1 * Power(l2, 2) * m1 * Power(m2, 2) * Cos(t2)
           - Power(dt1, 2) * Power(l1, 2) * l2 * m1 * Power(m2, 2) * Power(Cos(t2), 2)
           - g * l1 * l2 * m1 * Power(m2, 2) * Cos(t2) * Cos(t1 + t2)
           - g * l1 * l2 * m1 * Power(m2, 2) * Cos(t2) * Sin(t1) * Sin(t2)
           - Power(dt1, 2) * Power(l1, 2) * l2 * m1 * Power(m2, 2) * Power(Sin(t2), 2)
           - g * l1 * l2 * m1 * Power(m2, 2) * Cos(t1) * Power(Sin(t2), 2)) / den
    Tr2 = (-(Power(dt1, 2) * l1 * Power(l2, 2) * m1 * Power(m2, 2))
           - 2 * dt1 * dt2 * l1 * Power(l2, 2) * m1 * Power(m2, 2)
           - Power(dt2, 2) * l1 * Power(l2, 2) * m1 * Power(m2, 2)
           - Power(dt1, 2) * Power(l1, 2) * l2 * m1 * Power(m2, 2) * Cos(t2)
           - g * l1 * l2 * m1 * Power(m2, 2) * Cos(t1 + t2)
           - g * l1 * l2 * m1 * Power(m2, 2) * Sin(t1) * Sin(t2)) / den
    return ddt1, ddt2, Tr1, Tr2


def double_pendulum_positions(t1, t2, l1, l2):
    """``(x1, y1, x2, y2)`` of the two particles as in the listing (gravity along -y)."""
    x1 = -l1 * math.sin(t1)
    y1 = -(l1 * math.cos(t1))
    x2 = -l1 * math.sin(t1) - l2 * math.sin(t1 + t2)
    y2 = -(l1 * math.cos(t1) + l2 * math.cos(t1 + t2))
    return x1, y1, x2, y2


# ---------------------------------------------------------------------------------------
# Example 3 (1.4.3): the heavy top with Euler angles psi (Z), theta (X1), phi (Z2)
# ---------------------------------------------------------------------------------------
def top(psi, theta, phi, dpsi, dtheta, dphi, m, h, A, C, Mz, g=G):
    """``(ddpsi, ddtheta, ddphi)`` as the Pascal listing ``top`` computes them, with
    ``Ixx = Iyy = A`` and ``Izz = C`` about the contact point O and ``Mz`` a moment about
    the spin axis.  (``psi`` and ``phi`` do not enter.)"""
    Ixx = Iyy = A
    Izz = C
    mp = m
    sin, cos = math.sin, math.cos

    def Sqr(x):
        return x * x

    teta, Dpsi, Dteta, Dphi = theta, dpsi, dtheta, dphi
    DDteta = (1 / Ixx) * (mp * g * h * sin(teta) + Sqr(Dpsi) * (-Izz + Iyy) * sin(teta) * cos(teta)
                          - Izz * Dphi * Dpsi * sin(teta))
    DDpsi = (1 / (Iyy * sin(teta))) * (Izz * Dpsi * Dteta * cos(teta)
                                       + Dpsi * Dteta * cos(teta) * (-Ixx - Iyy)
                                       + Izz * Dphi * Dteta)
    DDphi = (1 / Izz) * (-Izz * DDpsi * cos(teta) + Izz * Dpsi * Dteta * sin(teta)
                         + Dpsi * Dteta * (-Iyy + Ixx) * sin(teta) + Mz)
    return DDpsi, DDteta, DDphi


def top_B2(psi, theta):
    """Transformation matrix of the (non-spinning) frame B2 from I: ``T_x(theta) T_z(psi)``."""
    return T_x(theta) @ T_z(psi)


def top_body_T(psi, theta, phi):
    """Transformation matrix of the top itself (B3) from I: ``T_z(phi) T_x(theta) T_z(psi)``."""
    return T_z(phi) @ T_x(theta) @ T_z(psi)


def top_acceleration_G_B2(theta, dpsi, dtheta, ddpsi, ddtheta, h):
    """``B2 a_G = h [2 psi' theta' cos th + psi'' sin th, psi'^2 sin th cos th - theta'',
    -psi'^2 sin^2 th - theta'^2]``."""
    s, c = math.sin(theta), math.cos(theta)
    return h * np.array([2.0 * dpsi * dtheta * c + ddpsi * s,
                         dpsi**2 * s * c - ddtheta,
                         -dpsi**2 * s**2 - dtheta**2])


def top_contact_force_B2(theta, dpsi, dtheta, ddpsi, ddtheta, m, h, g=G):
    """Contact force the floor exerts on the top, B2 components: ``m B2 a_G - B2 P`` with
    ``B2 P = [0, -m g sin th, -m g cos th]``."""
    P = np.array([0.0, -m * g * math.sin(theta), -m * g * math.cos(theta)])
    return m * top_acceleration_G_B2(theta, dpsi, dtheta, ddpsi, ddtheta, h) - P


def top_angular_velocity_B2(theta, dpsi, dtheta, dphi):
    """``B2 omega = [theta', psi' sin th, psi' cos th + phi']`` (the top, in B2)."""
    return np.array([dtheta, dpsi * math.sin(theta), dpsi * math.cos(theta) + dphi])


def top_frame_angular_velocity_B2(theta, dpsi, dtheta):
    """``B2 Omega = [theta', psi' sin th, psi' cos th]`` (the frame B2 itself)."""
    return np.array([dtheta, dpsi * math.sin(theta), dpsi * math.cos(theta)])


def top_body_rates(psi, theta, phi, dpsi, dtheta, dphi, ddpsi, ddtheta, ddphi):
    """The top's angular velocity and angular acceleration in its own frame B3
    (``B3 = T_z(phi) B2``): what a quaternion (spherical) joint uses as speeds and their
    rates.  ``B2 alpha = d/dt(B2 omega components) + B2 Omega x B2 omega``."""
    s, c = math.sin(theta), math.cos(theta)
    w2 = top_angular_velocity_B2(theta, dpsi, dtheta, dphi)
    dw2 = np.array([ddtheta,
                    ddpsi * s + dpsi * dtheta * c,
                    ddpsi * c - dpsi * dtheta * s + ddphi])
    alpha2 = dw2 + np.cross(top_frame_angular_velocity_B2(theta, dpsi, dtheta), w2)
    Tphi = T_z(phi)
    return Tphi @ w2, Tphi @ alpha2


def quaternion_zxz(psi, theta, phi):
    """Unit quaternion ``(w, x, y, z)`` of ``Rot_z(psi) Rot_x(theta) Rot_z(phi)`` (the
    rotation mapping body components to inertial ones, ``I s = R B s``, ``R = T^T``)."""
    qz1 = np.array([math.cos(psi / 2), 0.0, 0.0, math.sin(psi / 2)])
    qx = np.array([math.cos(theta / 2), math.sin(theta / 2), 0.0, 0.0])
    qz2 = np.array([math.cos(phi / 2), 0.0, 0.0, math.sin(phi / 2)])
    return quat_mul(quat_mul(qz1, qx), qz2)


def quaternion_matrix(q):
    """``R`` (body -> inertial components) of a unit quaternion ``(w, x, y, z)``: the
    textbook's ``T`` is its transpose."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])

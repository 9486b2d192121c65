"""Inertia invariants of a flexible body in the floating frame of reference, and the
body's mass matrix and quadratic velocity vector from them.

The body is a set of *mass points* p (nodes of a lumped model, or the Gauss points of a
beam's elements, which makes the sums exact integrals of the consistent model), each with
mass ``m_p`` at ``x_p`` (body axes, from the frame origin), rotary inertia ``J_p`` about
itself, and mode shapes ``Phi_p`` (translation, 3 x n) and ``Psi_p`` (rotation, 3 x n).
With ``u_p = Phi_p eta`` the point moves as ``r_p = r_0 + R (x_p + u_p)`` and turns at
``omega + Psi_p eta'`` (body components, rotations linearised).  The kinetic energy is
``T = 1/2 w^T M(eta) w`` with ``w = (v_0, omega, eta')`` in body components and

    M(eta) = [[ m I,       -c(eta)~,  C        ],
              [ c(eta)~,    J(eta),   Cr(eta)  ],
              [ C^T,        Cr^T,     M_ee     ]]

    m      = sum m_p                               mass
    c(eta) = c + C eta,  c = sum m_p x_p,  C_k = sum m_p Phi_pk      first moments (S-bar)
    J(eta) = J0 + eta_k J1_k + eta_k eta_l J2_kl   inertia about the frame origin
             J0 = sum J_p - m_p x~_p x~_p,  J1_k = -sum m_p (x~_p Phi~_pk + Phi~_pk x~_p),
             J2_kl = -sum m_p Phi~_pk Phi~_pl
    Cr(eta) = Cr0 + eta_k Cr1_k,  Cr0 = sum m_p x~_p Phi_p + J_p Psi_p,
             Cr1_k = sum m_p Phi~_pk Phi_p         rotation-elastic coupling
    M_ee   = sum m_p Phi_p^T Phi_p + Psi_p^T J_p Psi_p

(``a~`` is the cross-product matrix, ``a~ b = a x b``; sums over repeated k, l.)  These
are the invariants of A. A. Shabana, *Dynamics of Multibody Systems*, 4th ed., Cambridge
2020, ch. 5 (eqs. 5.54-5.74, the lumped-mass form), and of R. Schwertassek and O.
Wallrapp, *Dynamik flexibler Mehrkoerpersysteme*, Vieweg 1999 (the SID data).

Equations of motion (Kirchhoff's form of Lagrange's equations for the frame's body-axis
speeds): with ``a_0`` the absolute acceleration of the frame origin and ``alpha`` the
angular acceleration, both in body components,

    M(eta) [a_0; alpha; eta''] = Q_v + Q_applied - [0; 0; K_ee eta + C_ee eta']

where ``quadratic_velocity_vector`` gives ``Q_v``; it does not depend on the origin's
velocity (written with ``a_0``, the velocity terms cancel).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError


def skew(a):
    """Cross-product matrices of the vectors ``a`` (..., 3): ``skew(a) @ b = a x b``."""
    a = np.asarray(a, dtype=float)
    out = np.zeros(a.shape + (3,))
    out[..., 0, 1], out[..., 0, 2] = -a[..., 2], a[..., 1]
    out[..., 1, 0], out[..., 1, 2] = a[..., 2], -a[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -a[..., 1], a[..., 0]
    return out


@dataclass(frozen=True, eq=False)
class MassPoints:
    """Mass points of a body: ``mass`` (P,), ``position`` (P, 3) in body axes,
    ``inertia`` (P, 3, 3) about each point, and mode shapes at each point, ``translation``
    (P, 3, n) and ``rotation`` (P, 3, n), in body axes relative to the floating frame."""
    mass: np.ndarray
    position: np.ndarray
    inertia: np.ndarray
    translation: np.ndarray
    rotation: np.ndarray


@dataclass(frozen=True, eq=False)
class Invariants:
    """The inertia invariants (see the module's docstring for each formula)."""
    mass: float                 # m
    first_moment: np.ndarray    # c (3,)
    modal_first_moment: np.ndarray   # C (3, n): column k is sum m_p Phi_pk
    inertia: np.ndarray         # J0 (3, 3), about the frame origin
    inertia_1: np.ndarray       # J1 (n, 3, 3)
    inertia_2: np.ndarray       # J2 (n, n, 3, 3)
    coupling: np.ndarray        # Cr0 (3, n)
    coupling_1: np.ndarray      # Cr1 (n, 3, n)
    modal_mass: np.ndarray      # M_ee (n, n)

    @property
    def n_modes(self):
        return self.modal_first_moment.shape[1]


def inertia_invariants(points):
    """The :class:`Invariants` of the :class:`MassPoints` ``points``."""
    m, x, J = points.mass, points.position, points.inertia
    Phi, Psi = points.translation, points.rotation
    X = skew(x)                                        # (P, 3, 3)
    Y = skew(np.moveaxis(Phi, 2, 1))                   # (P, n, 3, 3): Phi~_pk
    return Invariants(
        mass=float(m.sum()),
        first_moment=m @ x,
        modal_first_moment=np.einsum("p,pin->in", m, Phi),
        inertia=np.einsum("pij->ij", J) - np.einsum("p,pij,pjk->ik", m, X, X),
        inertia_1=-np.einsum("p,pij,pkjl->kil", m, X, Y) - np.einsum("p,pkij,pjl->kil", m, Y, X),
        inertia_2=-np.einsum("p,pkij,plja->klia", m, Y, Y, optimize=True),
        coupling=np.einsum("p,pij,pjn->in", m, X, Phi) + np.einsum("pij,pjn->in", J, Psi),
        coupling_1=np.einsum("p,pkij,pjn->kin", m, Y, Phi, optimize=True),
        modal_mass=np.einsum("p,pik,pil->kl", m, Phi, Phi)
        + np.einsum("pik,pij,pjl->kl", Psi, J, Psi, optimize=True))


def _state(inv, eta):
    eta = np.asarray(eta, dtype=float)
    n = inv.n_modes
    if eta.shape != (n,):
        raise ModelError(f"eta has shape {eta.shape}; the body has {inv.n_modes} modes")
    c = inv.first_moment + inv.modal_first_moment @ eta
    # J0 + eta_k J1_k + eta_k eta_l J2_kl and Cr0 + eta_k Cr1_k, as matrix products
    J = (inv.inertia + (eta @ inv.inertia_1.reshape(n, 9)).reshape(3, 3)
         + (np.outer(eta, eta).ravel() @ inv.inertia_2.reshape(n * n, 9)).reshape(3, 3))
    Cr = inv.coupling + (eta @ inv.coupling_1.reshape(n, 3 * n)).reshape(3, n)
    return eta, c, J, Cr


def _inertia_derivatives(inv, eta):
    """``dJ/deta_k`` (n, 3, 3) at ``eta``: ``J1_k + eta_l (J2_kl + J2_lk)``."""
    n = inv.n_modes
    J2 = inv.inertia_2.reshape(n, n, 9)
    return inv.inertia_1 + (J2.swapaxes(1, 2) @ eta
                            + (eta @ J2.reshape(n, 9 * n)).reshape(n, 9)).reshape(n, 3, 3)


def cross3(a, b):
    """``a x b`` of two 3-vectors (``np.cross`` costs ten times more on these)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def floating_frame_mass_matrix(inv, eta):
    """The body's (6 + n) x (6 + n) mass matrix ``M(eta)`` for ``(a_0, alpha, eta'')``,
    frame origin acceleration and angular acceleration in body components."""
    eta, c, J, Cr = _state(inv, eta)
    n = inv.n_modes
    M = np.zeros((6 + n, 6 + n))
    M[:3, :3] = inv.mass * np.eye(3)
    M[:3, 3:6], M[3:6, :3] = -skew(c), skew(c)
    M[:3, 6:], M[6:, :3] = inv.modal_first_moment, inv.modal_first_moment.T
    M[3:6, 3:6] = J
    M[3:6, 6:], M[6:, 3:6] = Cr, Cr.T
    M[6:, 6:] = inv.modal_mass
    return M


def quadratic_velocity_vector(inv, eta, eta_dot, omega):
    """The quadratic velocity vector ``Q_v`` (6 + n) at modal coordinates ``eta``, modal
    speeds ``eta_dot`` and angular velocity ``omega`` (body components):

        Q_t = -omega x (omega x c(eta)) - 2 omega x (C eta')
        Q_r = -omega x (J omega) - J' omega - omega x (Cr eta')
        Q_e,k = 1/2 omega^T dJ/deta_k omega + omega^T Cr1_k eta' - omega^T (eta'_l Cr1_l)[:, k]

    with ``J' = eta'_k dJ/deta_k`` (centrifugal, Coriolis and gyroscopic terms)."""
    eta, c, J, Cr = _state(inv, eta)
    ed = np.asarray(eta_dot, dtype=float)
    w = np.asarray(omega, dtype=float)
    n = inv.n_modes
    dJ = _inertia_derivatives(inv, eta)
    Jdot = (ed @ dJ.reshape(n, 9)).reshape(3, 3)
    Q_t = -cross3(w, cross3(w, c)) - 2.0 * cross3(w, inv.modal_first_moment @ ed)
    Q_r = -cross3(w, J @ w) - Jdot @ w - cross3(w, Cr @ ed)
    Cr1 = inv.coupling_1                               # (l, i, n)
    Cr_dot = (ed @ Cr1.reshape(n, 3 * n)).reshape(3, n)
    Q_e = (0.5 * (dJ @ w) @ w + (Cr1 @ ed) @ w - w @ Cr_dot)
    return np.concatenate([Q_t, Q_r, Q_e])


def lumped_mass_points(nodes, node_mass, modes):
    """Mass points of a lumped model: ``nodes`` (N, 3), ``node_mass`` (N,) masses or
    (N, 6, 6) rigid-body mass matrices about each node (translation first; the
    translation block ``m I``), ``modes`` (N, 6, n).  A 6 x 6 block whose centre of mass
    is off the node, ``[[m I, -m s~], [m s~, J_node]]``, becomes a point at ``x + s``
    moving with the node (``Phi + Psi x s``) with inertia ``J_node + m s~ s~``."""
    nodes, modes = np.asarray(nodes, float), np.asarray(modes, float)
    node_mass = np.asarray(node_mass, float)
    Phi, Psi = modes[:, :3, :], modes[:, 3:, :]
    if node_mass.ndim == 1:
        return MassPoints(node_mass, nodes, np.zeros((len(nodes), 3, 3)), Phi, Psi)
    m = node_mass[:, 0, 0]
    safe = np.where(m > 0, m, 1.0)
    s_skew = -node_mass[:, :3, 3:] / safe[:, None, None]
    s = np.stack([s_skew[:, 2, 1], s_skew[:, 0, 2], s_skew[:, 1, 0]], axis=1)
    J = node_mass[:, 3:, 3:] + m[:, None, None] * s_skew @ s_skew
    return MassPoints(m, nodes + s, J, Phi - s_skew @ Psi, Psi)

"""The interpolation of a 2-node, 12-DoF beam element along x, evaluated at Gauss points.

Each node carries ``(u, v, w, rx, ry, rz)``: displacements along x, y, z and small
rotations about x, y, z, body axes.  Axial displacement ``u`` and twist ``rx`` are
linear.  Bending uses the interpolation that solves the static Timoshenko beam exactly
(Z. Friedman and J. B. Kosmatka, "An improved two-node Timoshenko beam finite element",
Computers & Structures 47, 1993), with ``phi = 12 E I / (kappa G A L^2)``; ``phi = 0`` is the
cubic Hermite (Euler-Bernoulli) element, whose rotation is the slope.  In the x-y plane
the rotation is ``rz`` (``= dv/dx`` without shear); in the x-z plane it is ``ry``
(``= -dw/dx`` without shear), hence the sign pattern of the x-z plane below.

``element_rows`` returns, at each point, four 3 x 12 matrices acting on the element's
DoFs ``[node 1 (6), node 2 (6)]``: the translation ``(u, v, w)``, the rotation
``(rx, ry, rz)`` and their derivatives along x.
"""
from __future__ import annotations

import numpy as np

#: Gauss-Legendre points and weights on [0, 1]; four points integrate degree 7 exactly,
#: enough for every product below (mass: 6; stiffness: 4; geometric stiffness with a
#: quadratic axial force: 6; inertia invariants: 7)
_G, _W = np.polynomial.legendre.leggauss(4)
GAUSS_POINTS = 0.5 * (_G + 1.0)
GAUSS_WEIGHTS = 0.5 * _W

#: the element's DoFs of each bending plane: x-y (v, rz) and x-z (w, ry)
PLANE_XY = (1, 5, 7, 11)
PLANE_XZ = (2, 4, 8, 10)
_XZ_SIGN = np.array([1.0, -1.0, 1.0, -1.0])     # ry = -dw/dx


def bending_shapes(xi, length, phi):
    """Displacement and rotation shape functions of one bending plane at ``xi`` in [0, 1]
    for the plane DoFs ``(v1, theta1, v2, theta2)``, ``theta`` the section's rotation
    (the slope when ``phi = 0``): ``(N, dN/dx, Nth, dNth/dx)``, each (len(xi), 4)."""
    xi = np.asarray(xi, dtype=float)
    c, L = 1.0 / (1.0 + phi), length
    x2, x3 = xi * xi, xi ** 3
    N = c * np.stack([2 * x3 - 3 * x2 - phi * xi + 1 + phi,
                      L * (x3 - (2 + phi / 2) * x2 + (1 + phi / 2) * xi),
                      -(2 * x3 - 3 * x2 - phi * xi),
                      L * (x3 - (1 - phi / 2) * x2 - phi / 2 * xi)], axis=-1)
    dN = c / L * np.stack([6 * x2 - 6 * xi - phi,
                           L * (3 * x2 - (4 + phi) * xi + 1 + phi / 2),
                           -(6 * x2 - 6 * xi - phi),
                           L * (3 * x2 - (2 - phi) * xi - phi / 2)], axis=-1)
    Nth = c * np.stack([6 / L * (x2 - xi), 3 * x2 - (4 + phi) * xi + 1 + phi,
                        -6 / L * (x2 - xi), 3 * x2 - (2 - phi) * xi], axis=-1)
    dNth = c / L * np.stack([6 / L * (2 * xi - 1), 6 * xi - (4 + phi),
                             -6 / L * (2 * xi - 1), 6 * xi - (2 - phi)], axis=-1)
    return N, dN, Nth, dNth


def element_rows(xi, length, phi_xy, phi_xz):
    """Translation, rotation and their x-derivatives at the points ``xi`` of an element
    of ``length``: four arrays (len(xi), 3, 12).  ``phi_xy`` and ``phi_xz`` are the shear
    parameters of the x-y and x-z bending planes."""
    xi = np.asarray(xi, dtype=float)
    n = len(xi)
    T, R, dT, dR = (np.zeros((n, 3, 12)) for _ in range(4))
    lin, dlin = np.stack([1 - xi, xi], axis=-1), np.full((n, 2), [-1.0, 1.0]) / length
    T[:, 0, [0, 6]], dT[:, 0, [0, 6]] = lin, dlin          # axial u
    R[:, 0, [3, 9]], dR[:, 0, [3, 9]] = lin, dlin          # twist rx
    N, dN, Nth, dNth = bending_shapes(xi, length, phi_xy)
    T[:, 1, PLANE_XY], dT[:, 1, PLANE_XY] = N, dN          # v
    R[:, 2, PLANE_XY], dR[:, 2, PLANE_XY] = Nth, dNth      # rz
    N, dN, Nth, dNth = bending_shapes(xi, length, phi_xz)
    T[:, 2, PLANE_XZ], dT[:, 2, PLANE_XZ] = N * _XZ_SIGN, dN * _XZ_SIGN       # w
    R[:, 1, PLANE_XZ], dR[:, 1, PLANE_XZ] = -Nth * _XZ_SIGN, -dNth * _XZ_SIGN  # ry
    return T, R, dT, dR

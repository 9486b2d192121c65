"""Spatial inertias for the recursive algorithms (articulated bodies, composite rigid
bodies, inverse dynamics), with the frame's quantities in local tuples (registers).

A spatial inertia at a frame's origin ``O`` in world axes, ordered (angular, linear), is
``[[A, B], [B^T, C]]``: for a rigid body of mass ``m``, centre of mass ``c`` from ``O``
and inertia ``Iw`` about it, ``A = Iw - m [c]x [c]x``, ``B = m [c]x``, ``C = m E``
(``articulated._spatial_inertia``).  The sweeps from the leaves to the root read and write
only the upper triangle of such a 6x6 block (21 numbers), and a frame's block is
made whole (``mirror``) when it is complete, before anything reads its lower triangle.
"""

from .motion import mat9, mv
from .views import FUSED
from .internal import internal

@internal(forceinline=True, **FUSED)
def body_inertia(R, com, inertia, i):
    """Frame ``i``'s centre of mass ``c = R com`` from its origin (3-tuple) and its inertia
    about the centre of mass in world axes ``Iw = R I R^T`` as a 6-tuple ``(xx, xy, xz,
    yy, yz, zz)``."""
    Ri = mat9(R, i)
    c = mv(Ri, com[i, 0], com[i, 1], com[i, 2])
    I = mat9(inertia, i)
    y = (Ri[0] * I[0] + Ri[1] * I[3] + Ri[2] * I[6], Ri[0] * I[1] + Ri[1] * I[4] + Ri[2] * I[7],
         Ri[0] * I[2] + Ri[1] * I[5] + Ri[2] * I[8], Ri[3] * I[0] + Ri[4] * I[3] + Ri[5] * I[6],
         Ri[3] * I[1] + Ri[4] * I[4] + Ri[5] * I[7], Ri[3] * I[2] + Ri[4] * I[5] + Ri[5] * I[8],
         Ri[6] * I[0] + Ri[7] * I[3] + Ri[8] * I[6], Ri[6] * I[1] + Ri[7] * I[4] + Ri[8] * I[7],
         Ri[6] * I[2] + Ri[7] * I[5] + Ri[8] * I[8])           # R I
    return c, (y[0] * Ri[0] + y[1] * Ri[1] + y[2] * Ri[2],
               y[0] * Ri[3] + y[1] * Ri[4] + y[2] * Ri[5],
               y[0] * Ri[6] + y[1] * Ri[7] + y[2] * Ri[8],
               y[3] * Ri[3] + y[4] * Ri[4] + y[5] * Ri[5],
               y[3] * Ri[6] + y[4] * Ri[7] + y[5] * Ri[8],
               y[6] * Ri[6] + y[7] * Ri[7] + y[8] * Ri[8])


@internal(forceinline=True, **FUSED)
def rigid_upper(IA, i, m, c, Iw):
    """The upper triangle of a rigid body's spatial inertia at its frame's origin into
    ``IA[i]`` (the module docstring)."""
    cx, cy, cz = c
    IA[i, 0, 0] = Iw[0] + m * (cy * cy + cz * cz)
    IA[i, 0, 1] = Iw[1] - m * cx * cy
    IA[i, 0, 2] = Iw[2] - m * cx * cz
    IA[i, 1, 1] = Iw[3] + m * (cx * cx + cz * cz)
    IA[i, 1, 2] = Iw[4] - m * cy * cz
    IA[i, 2, 2] = Iw[5] + m * (cx * cx + cy * cy)
    IA[i, 0, 3], IA[i, 0, 4], IA[i, 0, 5] = 0.0, -m * cz, m * cy
    IA[i, 1, 3], IA[i, 1, 4], IA[i, 1, 5] = m * cz, 0.0, -m * cx
    IA[i, 2, 3], IA[i, 2, 4], IA[i, 2, 5] = -m * cy, m * cx, 0.0
    IA[i, 3, 3] = IA[i, 4, 4] = IA[i, 5, 5] = m
    IA[i, 3, 4] = IA[i, 3, 5] = IA[i, 4, 5] = 0.0


@internal(forceinline=True, **FUSED)
def mirror(IA, i):
    """``IA[i]``'s lower triangle from its upper one."""
    for a_ in range(1, 6):
        for b_ in range(a_):
            IA[i, a_, b_] = IA[i, b_, a_]


@internal(forceinline=True, **FUSED)
def shift_upper(IA, i, p, x, y, z):
    """``IA[p] += X^T IA[i] X`` on the upper triangles: the child's block moved from its
    origin to its parent's, ``(x, y, z)`` the child's origin from the parent's.  With
    ``P = [rho]x``, ``T = P C`` and ``W = P B^T``: ``A + W + W^T - T P``, ``B + T``,
    ``C`` (``articulated._add_shifted_inertia``)."""
    # C (symmetric) and the columns of B
    c00, c01, c02 = IA[i, 3, 3], IA[i, 3, 4], IA[i, 3, 5]
    c11, c12, c22 = IA[i, 4, 4], IA[i, 4, 5], IA[i, 5, 5]
    b00, b01, b02 = IA[i, 0, 3], IA[i, 0, 4], IA[i, 0, 5]
    b10, b11, b12 = IA[i, 1, 3], IA[i, 1, 4], IA[i, 1, 5]
    b20, b21, b22 = IA[i, 2, 3], IA[i, 2, 4], IA[i, 2, 5]
    # T = P C, row by row: (-z C1 + y C2, z C0 - x C2, -y C0 + x C1)
    t00, t01, t02 = -z * c01 + y * c02, -z * c11 + y * c12, -z * c12 + y * c22
    t10, t11, t12 = z * c00 - x * c02, z * c01 - x * c12, z * c02 - x * c22
    t20, t21, t22 = -y * c00 + x * c01, -y * c01 + x * c11, -y * c02 + x * c12
    # W = P B^T: the rows of B^T are B's columns (b0k, b1k, b2k)
    w00, w01, w02 = -z * b01 + y * b02, -z * b11 + y * b12, -z * b21 + y * b22
    w10, w11, w12 = z * b00 - x * b02, z * b10 - x * b12, z * b20 - x * b22
    w20, w21, w22 = -y * b00 + x * b01, -y * b10 + x * b11, -y * b20 + x * b21
    # T P (symmetric), by columns: (z T1 - y T2, -z T0 + x T2, y T0 - x T1)
    IA[p, 0, 0] += IA[i, 0, 0] + 2.0 * w00 - (z * t01 - y * t02)
    IA[p, 0, 1] += IA[i, 0, 1] + w01 + w10 - (-z * t00 + x * t02)
    IA[p, 0, 2] += IA[i, 0, 2] + w02 + w20 - (y * t00 - x * t01)
    IA[p, 1, 1] += IA[i, 1, 1] + 2.0 * w11 - (-z * t10 + x * t12)
    IA[p, 1, 2] += IA[i, 1, 2] + w12 + w21 - (y * t10 - x * t11)
    IA[p, 2, 2] += IA[i, 2, 2] + 2.0 * w22 - (y * t20 - x * t21)
    IA[p, 0, 3] += b00 + t00
    IA[p, 0, 4] += b01 + t01
    IA[p, 0, 5] += b02 + t02
    IA[p, 1, 3] += b10 + t10
    IA[p, 1, 4] += b11 + t11
    IA[p, 1, 5] += b12 + t12
    IA[p, 2, 3] += b20 + t20
    IA[p, 2, 4] += b21 + t21
    IA[p, 2, 5] += b22 + t22
    IA[p, 3, 3] += c00
    IA[p, 3, 4] += c01
    IA[p, 3, 5] += c02
    IA[p, 4, 4] += c11
    IA[p, 4, 5] += c12
    IA[p, 5, 5] += c22

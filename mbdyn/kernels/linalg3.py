"""Small fixed-size linear algebra for the kernels, written out so that nothing allocates.

Inside compiled code, ``A @ x`` on 3x3 arrays calls BLAS and allocates its result; for
these sizes that costs more than the arithmetic.  Outputs must not alias inputs.
"""
from numba import njit

from .views import UNCOUNTED


@njit(**UNCOUNTED)
def mat_vec(A, x, out):
    """``out = A x``."""
    for i in range(3):
        out[i] = A[i, 0] * x[0] + A[i, 1] * x[1] + A[i, 2] * x[2]


@njit(**UNCOUNTED)
def mat_t_vec(A, x, out):
    """``out = A^T x``."""
    for i in range(3):
        out[i] = A[0, i] * x[0] + A[1, i] * x[1] + A[2, i] * x[2]


@njit(**UNCOUNTED)
def mat_mat(A, B, out):
    """``out = A B``."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@njit(**UNCOUNTED)
def rotate_tensor(R, I, tmp, out):
    """``out = R I R^T`` (a body-axes tensor in world axes); ``tmp`` is scratch."""
    for i in range(3):
        for j in range(3):
            tmp[i, j] = R[i, 0] * I[0, j] + R[i, 1] * I[1, j] + R[i, 2] * I[2, j]
    for i in range(3):
        for j in range(3):
            out[i, j] = tmp[i, 0] * R[j, 0] + tmp[i, 1] * R[j, 1] + tmp[i, 2] * R[j, 2]


@njit(**UNCOUNTED)
def cross_to(a, b, out):
    """``out = a x b``."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, inline="always")
def spatial_inertia(m, c, Iw, IA, i):
    """Spatial inertia about a reference point (world axes) of a body of mass ``m``,
    centre of mass at ``c`` from that point and inertia ``Iw`` about the centre of mass,
    into ``IA[i]``: ``[[Iw - m [c]x [c]x, m [c]x], [-m [c]x, m E]]``.  (Arrays are indexed
    with the frame number rather than passed as ``IA[i]`` views: a view costs two
    reference-count calls, which dominated the cost of a small model.)"""
    cx, cy, cz = c[0], c[1], c[2]
    cc = cx * cx + cy * cy + cz * cz
    IA[i, 0, 0] = Iw[0, 0] + m * (cc - cx * cx)
    IA[i, 1, 1] = Iw[1, 1] + m * (cc - cy * cy)
    IA[i, 2, 2] = Iw[2, 2] + m * (cc - cz * cz)
    IA[i, 0, 1] = IA[i, 1, 0] = Iw[0, 1] - m * cx * cy
    IA[i, 0, 2] = IA[i, 2, 0] = Iw[0, 2] - m * cx * cz
    IA[i, 1, 2] = IA[i, 2, 1] = Iw[1, 2] - m * cy * cz
    for a_ in range(3):
        for b_ in range(3):
            IA[i, 3 + a_, 3 + b_] = m if a_ == b_ else 0.0
    IA[i, 0, 3], IA[i, 0, 4], IA[i, 0, 5] = 0.0, -m * cz, m * cy
    IA[i, 1, 3], IA[i, 1, 4], IA[i, 1, 5] = m * cz, 0.0, -m * cx
    IA[i, 2, 3], IA[i, 2, 4], IA[i, 2, 5] = -m * cy, m * cx, 0.0
    for a_ in range(3):
        for b_ in range(3):
            IA[i, 3 + b_, a_] = IA[i, a_, 3 + b_]

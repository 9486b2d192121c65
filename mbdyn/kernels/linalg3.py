"""Small fixed-size linear algebra for the kernels, written out so that nothing allocates.

Inside compiled code, ``A @ x`` on 3x3 arrays calls BLAS and allocates its result; for
these sizes that costs more than the arithmetic.  Outputs must not alias inputs.
"""

from .views import UNCOUNTED
from .internal import internal


@internal(**UNCOUNTED)
def mat_vec(A, x, out):
    """``out = A x``."""
    for i in range(3):
        out[i] = A[i, 0] * x[0] + A[i, 1] * x[1] + A[i, 2] * x[2]


@internal(**UNCOUNTED)
def mat_t_vec(A, x, out):
    """``out = A^T x``."""
    for i in range(3):
        out[i] = A[0, i] * x[0] + A[1, i] * x[1] + A[2, i] * x[2]


@internal(**UNCOUNTED)
def mat_mat(A, B, out):
    """``out = A B``."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@internal(**UNCOUNTED)
def rotate_tensor(R, I, tmp, out):
    """``out = R I R^T`` (a body-axes tensor in world axes); ``tmp`` is scratch."""
    for i in range(3):
        for j in range(3):
            tmp[i, j] = R[i, 0] * I[0, j] + R[i, 1] * I[1, j] + R[i, 2] * I[2, j]
    for i in range(3):
        for j in range(3):
            out[i, j] = tmp[i, 0] * R[j, 0] + tmp[i, 1] * R[j, 1] + tmp[i, 2] * R[j, 2]


@internal(**UNCOUNTED)
def cross_to(a, b, out):
    """``out = a x b``."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]

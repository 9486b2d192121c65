"""Entry points compiled for one signature: the low-level calls from Python that must cost
little (``compiled.lowlevel``).

numba checks every argument of a compiled function at each call; a function compiled for
one explicit signature (contiguous, writable float64 arrays and the packed model's integer
buffer) does that fastest and refuses any other type at once (``TypeError``) instead of
compiling for it.  Each entry, or the kernel it calls, checks the sizes before it touches
the buffers (returns ``WRONG_SIZE``) and returns the kernel's status: -1 on success, a
speed's column where a degree of freedom has no inertia, -2 for a non-finite result.

The integer buffer ``ib`` starts with the offset table (``packed.pack``) and stands for it:
one array less to type and unbox at every call; the force table is its view
(``packed.force_table``), so the entries are compiled with the force kernel.  The ordinary
``Model`` methods call the packed kernels themselves, with the force elements' table and the
address of their compiled function (``force_function``: a first call compiles less).
"""
from numba import njit, typeof

from . import inverse as ki
from . import packed as kp
from .views import UNCOUNTED, c_view

#: a size that does not fit the model
WRONG_SIZE = kp.WRONG_SIZE

#: ``(fb, ib, q, u, out)``
FORWARD_SIGNATURE = "int64(float64[::1], int64[::1], float64[::1], float64[::1], float64[::1])"
#: ``(fb, ib, q, u, u_dot, tau)``
INVERSE_SIGNATURE = ("int64(float64[::1], int64[::1], float64[::1], float64[::1], "
                     "float64[::1], float64[::1])")
#: ``(fb, ib, q, M)``
MASS_MATRIX_SIGNATURE = "int64(float64[::1], int64[::1], float64[::1], float64[:, ::1])"

_COMPILED = {}


def entry(function, signature):
    """``function`` compiled for ``signature`` only, on first use (``import`` compiles
    nothing)."""
    if function not in _COMPILED:
        _COMPILED[function] = njit(signature, **UNCOUNTED)(function)
    return _COMPILED[function]


def direct(kernel, args):
    """The specialization ``kernel`` (a compiled dispatcher) already has for the types of
    ``args``, as numba's own wrapper of it (``entry_point``): a call with no dispatch --
    no typing of the arguments, no search among specializations, never a compile -- at
    half the cost of the dispatcher's (0.5 against 0.9-1.1 us for five to seven arrays).
    The wrapper unboxes each argument as the type it was compiled for *without checking
    it* (an int64 array would be read as float64, a 2-d one overrun), so the caller
    passes only arrays it has checked to be of those types (``algorithms.inputs.fits``)
    and its own buffers; a 1-d array's strides the packed kernels check
    (``packed.contiguous``).  ``None`` when ``kernel`` has no such specialization."""
    compiled = kernel.overloads.get(tuple(typeof(a) for a in args))
    return None if compiled is None else compiled.entry_point


def inverse_dynamics(fb, ib, q, u, ud, tau):
    """Generalized forces ``tau = M u' - f`` on the free speeds, and the joint wrenches in
    the packed ``W`` view (``inverse.inverse_dynamics_packed``, which checks the sizes)."""
    return ki.inverse_dynamics_packed(fb, ib, kp.force_table(ib, ib), q, u, ud, tau)


def mass_matrix(fb, ib, q, M):
    """The mass matrix at ``q`` into ``M`` (``inverse.mass_matrix_packed``, which checks
    the sizes)."""
    return ki.mass_matrix_packed(fb, ib, None, q, M)


@njit(inline="always", **UNCOUNTED)
def _forward(accelerations, fb, ib, q, u, out):
    """``accelerations`` (a packed kernel) at ``q``, ``u``, its ``u'`` copied into ``out``
    (which may be the workspace's own ``ud``) in compiled code."""
    nu = ib[1]
    if q.shape[0] != ib[7] or u.shape[0] != nu or out.shape[0] != nu:
        return WRONG_SIZE
    status = accelerations(fb, ib, ib, kp.force_table(ib, ib), q, u)
    ud = c_view(fb, ib[kp.UD], (nu,))
    for k in range(nu):
        out[k] = ud[k]
    return status


@njit(inline="always", **UNCOUNTED)
def _articulated(fb, ib, t, forces, q, u):
    """``packed.articulated_accelerations_packed`` in ``_forward``'s arguments (the table
    is the integer buffer's head)."""
    return kp.articulated_accelerations_packed(fb, ib, forces, q, u)


@njit(inline="always", **UNCOUNTED)
def _jourdain(fb, ib, t, forces, q, u):
    """``packed.jourdain_accelerations_packed`` in ``_forward``'s arguments."""
    return kp.jourdain_accelerations_packed(fb, ib, forces, q, u)


def jourdain_forward(fb, ib, q, u, out):
    """Forward dynamics ``u'`` into ``out`` by ``M u' = f`` (Cholesky)."""
    return _forward(_jourdain, fb, ib, q, u, out)


def articulated_forward(fb, ib, q, u, out):
    """Forward dynamics ``u'`` into ``out`` by the articulated-body algorithm."""
    return _forward(_articulated, fb, ib, q, u, out)

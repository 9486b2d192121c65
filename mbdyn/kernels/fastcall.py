"""The hottest per-call methods, ``Model.mass_matrix``, ``Model.effort_array`` and
``Model.forward_dynamics`` by articulated bodies, at the cost of one C call.

What a robot's mass matrix costs from Python is mostly not its arithmetic: on a 9-speed
Panda the kernel takes about half of the call, and the rest went to the Python checks of
the arguments (``inputs.fits``, 0.1-0.25 us), the recycling of the result (0.1 us) and
numba's wrapper, which unboxes each array argument (0.3-0.5 us for four to seven).  A small
C extension, ``_fastcall`` (``_fastcall.c``), does the three in one call: its ``Entry``
holds the model's buffers and the C address of the kernel below (a ``cfunc`` taking raw
pointers and sizes, which calls the same compiled kernel as the ordinary route), checks
each argument in C, takes back a result array nothing else refers to (an exact reference
count, ``1``) or makes one, and calls the kernel.  It returns ``None`` for any argument of
another kind or size and for any status but success: the method then takes its checked
route, as before.

The extension is optional: a machine without a C compiler installs mbdyn without it
(``setup.py``), and ``entry`` returns ``None``: the methods keep their Python fast path.
``MBDYN_FASTCALL=0`` switches it off (a comparison, or a suspicion).
"""
import os

import numpy as np
from numba import carray, types

from . import inverse as ki
from . import packed as kp
from .c_function import c_function
from .views import c_view

try:
    from ._fastcall import Entry
except ImportError:                     # built without the extension (no C compiler)
    Entry = None

_F64P, _I64P, _I64 = types.CPointer(types.float64), types.CPointer(types.int64), types.int64
#: ``(fb, nfb, ib, nib, q, nq, M, nu) -> status``
MASS_MATRIX = _I64(_F64P, _I64, _I64P, _I64, _F64P, _I64, _F64P, _I64)
#: ``(fb, nfb, ib, nib, forces, q, nq, u, u_dot, nu, tau) -> status``; ``forces``: the
#: address of the force elements' function (``force_function``)
EFFORTS = _I64(_F64P, _I64, _I64P, _I64, _I64, _F64P, _I64, _F64P, _F64P, _I64, _F64P)
#: ``(fb, nfb, ib, nib, forces, q, nq, u, nu, u_rate) -> status``
FORWARD = _I64(_F64P, _I64, _I64P, _I64, _I64, _F64P, _I64, _F64P, _I64, _F64P)
#: the ``Entry`` kinds
KINDS = {"mass matrix": 0, "efforts": 1, "articulated": 2}


#: what the C functions return where the kernel raised (a division by zero: a quaternion
#: of no length, say); caught here, since a ``cfunc`` would print it as unraisable
RAISED = -4


def _mass_matrix(fb, nfb, ib, nib, q, nq, M, nu):
    """``inverse.mass_matrix_packed`` on the buffers and arrays at these addresses."""
    try:
        return ki.mass_matrix_packed(carray(fb, (nfb,)), carray(ib, (nib,)), None,
                                     carray(q, (nq,)), carray(M, (nu, nu)))
    except Exception:                    # the caller's checked route says what it was
        return RAISED


def _efforts(fb, nfb, ib, nib, forces, q, nq, u, u_dot, nu, tau):
    """``inverse.inverse_dynamics_packed`` on the buffers and arrays at these addresses,
    the force table a view of the integer buffer (``packed.force_table``)."""
    ints = carray(ib, (nib,))
    table = kp.force_table(ints, ints)[0]
    try:
        return ki.inverse_dynamics_packed(carray(fb, (nfb,)), ints, (table, forces),
                                          carray(q, (nq,)), carray(u, (nu,)),
                                          carray(u_dot, (nu,)), carray(tau, (nu,)))
    except Exception:
        return RAISED


def _articulated(fb, nfb, ib, nib, forces, q, nq, u, nu, u_rate):
    """``packed.articulated_accelerations_packed`` on the buffers and arrays at these
    addresses, ``u'`` copied from the workspace into ``u_rate``."""
    ints, floats = carray(ib, (nib,)), carray(fb, (nfb,))
    table = kp.force_table(ints, ints)[0]
    try:
        status = kp.articulated_accelerations_packed(floats, ints, (table, forces),
                                                     carray(q, (nq,)), carray(u, (nu,)))
    except Exception:
        return RAISED
    if status == -1:
        out, ud = carray(u_rate, (nu,)), c_view(floats, ints[kp.UD], (nu,))
        for k in range(nu):
            out[k] = ud[k]
    return status


_FUNCTIONS = {"mass matrix": (MASS_MATRIX, _mass_matrix), "efforts": (EFFORTS, _efforts),
              "articulated": (FORWARD, _articulated)}
_COMPILED = {}


def enabled():
    """Whether the extension is there and not switched off (``MBDYN_FASTCALL=0``)."""
    return Entry is not None and os.environ.get("MBDYN_FASTCALL", "1").strip() not in (
        "0", "no", "off", "false")


def kernel(key):
    """The C function of ``key`` (``KINDS``), compiled on its first use (or loaded from
    numba's cache)."""
    if key not in _COMPILED:
        signature, function = _FUNCTIONS[key]
        _COMPILED[key] = c_function(signature, function, cache=True)
    return _COMPILED[key]


def entry(key, fb, ib, forces, nq, nu, recycle):
    """The ``Entry`` of ``key`` on the packed buffers ``fb``, ``ib`` (``forces``: the
    force function's address, for the efforts and the accelerations), or ``None`` without
    the extension.
    ``recycle``: whether reference counts are exact here (``algorithms.recycling``)."""
    if not enabled():
        return None
    if not (ib.dtype == np.int64 and ib.shape[0] > 7 and nq == ib[7] and nu == ib[1]):
        raise ValueError(f"fastcall.entry: nq={nq}, nu={nu} do not match the packed "
                         "buffers' table")
    return Entry(kernel(key).address, KINDS[key], fb, ib, int(forces), nq, nu, bool(recycle))

"""The result arrays of the hottest per-call methods (``mass_matrix``, ``effort_array``),
recycled once the caller has let go of them.  (Their C entries, ``kernels.fastcall``,
recycle the same way in C, where the count of a free spare is exactly 1; ``FREE != -1``
is their switch too.)

Each call returns a new array, which is what a caller may keep.  Allocating it
(``np.empty``) is an eighth of a 9-speed mass matrix's cost.  So the model keeps two arrays
it returned (``spares``) and takes back the first one nothing but the model refers to any
more; CPython's reference count says which.  Two, because a loop ``M = model.mass_matrix(q)``
still holds the last result under the name it is about to rebind.  When both are held, a
new array replaces the second, which moves to the first place: an array the caller keeps
leaves the spares at the next call that finds both held.

No array the caller can still reach is ever written: a name, a list, a view
(``M[0]``, ``M.T``), a memoryview or ``np.asarray`` all hold a reference (a weak
reference and a raw pointer, ``M.ctypes.data``, do not).  A spare is taken back only as the
model made it, float64 and writable: the caller may have set its ``dtype`` or made it
read-only before letting go.  Its shape and strides the kernels check (``WRONG_SIZE``:
the checked route, which makes new spares).

The two hot paths write the taking back inline, the same six lines each: a call of a
helper costs 40-50 ns, half of what the recycling saves (as ``inputs.fits``'s test is
written inline there too).  Where the count
is not exact, the arrays are never recycled (``FREE = -1``): on another interpreter, on a
free-threaded CPython, and from 3.14, whose interpreter may borrow a local's reference
without counting it.
"""
from __future__ import annotations

import sys
import sysconfig

import numpy as np

#: one name lookup for the hot paths
refcount = sys.getrefcount


def spares(shape):
    """The model's two recycled results of ``shape``."""
    return [np.empty(shape), np.empty(shape)]


def _count_when_free():
    """``refcount`` of a spare that only the model refers to, taken as the hot paths
    take it."""
    spare = spares(0)
    result = spare[0]
    return refcount(result)


def _exact_counts():
    """Whether this interpreter's reference counts are exact: CPython below 3.14 with the
    global interpreter lock."""
    return (sys.implementation.name == "cpython" and sys.version_info < (3, 14)
            and not sysconfig.get_config_var("Py_GIL_DISABLED"))


#: the count of a free spare in the hot paths: the list's reference, the local name's and
#: the argument's
EXPECTED = 3
#: ``refcount`` of a spare free to recycle (the hot paths compare ``!= FREE``; -1: never).
#: Measured, and kept only when it is ``EXPECTED``: a tracer that reads the frames' locals
#: (a debugger stepping through this import) adds one, and a count calibrated one too high
#: would take an array the caller still holds for free.  Under such a tracer later, a
#: count only errs towards allocating.
FREE = EXPECTED if _exact_counts() and _count_when_free() == EXPECTED else -1


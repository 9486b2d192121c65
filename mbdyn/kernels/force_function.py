"""The force elements as a C function called by address: one compiled route for every model.

The evaluations reach the force elements through the loads' ``forces``: ``(force_int,
address)``, the force table and the address of a C function of ``SIGNATURE``
(``numba.cfunc``) that adds the elements' wrenches (``forces.force_elements``), called
there (``apply_forces``).  An address is an integer to numba, of one type whatever the
function, so the kinematics, the routes, the compiled loops and the adaptive stretches are
compiled once for models with and without force elements: a model without any passes 0
(never called: its table is empty; no function is compiled for it), a model with force
elements the address of the function that applies them, compiled on its first use
(``address``).  The function object itself, numba's first-class function type, would do
as much in compiled code, but each call from Python unboxes it in about 30 us.  Before,
``forces`` was ``None`` or ``(force_int, shapes)``, whose types made numba compile every
one of those functions again for the first model with force elements (8-9 s of its first
run).

Each function is made on first use, not at import (a ``cfunc`` compiles when it is made:
``import mbdyn`` compiles nothing), and cached on disk like the kernels.  The arrays are
contiguous (``C``), as every caller's are (``forces.force_elements`` cuts views of them).
"""
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic, overload

from .c_function import c_function
from .forces import force_elements
from .views import UNCOUNTED

_F1, _F2, _F3 = (types.Array(types.float64, d, "C") for d in (1, 2, 3))
_I1, _I2 = types.Array(types.int64, 1, "C"), types.Array(types.int64, 2, "C")
#: ``(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N, acc,
#: work) -> 0``: ``forces.force_elements``'s arguments but ``shapes``
SIGNATURE = types.int64(_I2, _F1, _I1, _F2, _F2, _F1, _F1, _F3, _F2, _F2, _F2, _F2, _F2, _F1,
                        _F1)
#: the kinds: no force elements (no function), the elements without contacts between
#: shapes, and with them (``forces.force_elements``' ``shapes``: None or True)
NONE, PLAIN, SHAPES = "none", "plain", "shapes"
#: what a function returns when the kernel raised (``apply_forces`` raises it again)
FAILED = 1


@njit(**UNCOUNTED)
def _status(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N, acc, work,
            shapes):
    """``forces.force_elements`` with what it raises (a division by zero: numba's only
    exception there) turned into ``FAILED``: a C function cannot raise -- numba's wrapper
    would print the exception and return, and the caller go on with half the loads --, so
    ``apply_forces`` raises it again."""
    try:
        force_elements(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F,
                       N, acc, work, shapes)
    except Exception:
        return FAILED
    return 0


# One Python function per kind: numba's cache keys a cfunc by its function, so two cfuncs of
# one function with one signature would share a cache entry.

def _plain(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N, acc,
           work):
    return _status(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N,
                   acc, work, None)


def _shapes(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N, acc,
            work):
    return _status(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N,
                   acc, work, True)


_PYTHON = {PLAIN: _plain, SHAPES: _shapes}
_MADE = {}


def function(kind):
    """The compiled force function of ``kind`` (``PLAIN`` or ``SHAPES``), made on first use
    (and kept: its address stays valid for the process)."""
    if kind not in _MADE:
        _MADE[kind] = c_function(SIGNATURE, _PYTHON[kind], **UNCOUNTED)
    return _MADE[kind]


def address(kind):
    """The address of ``function(kind)``, as the loads carry it; 0 for ``NONE``."""
    return 0 if kind == NONE else function(kind).address


@intrinsic
def _call_at(typingctx, where, force_int, force_data, parent, axis, com, qfull, ufull, R, r,
             w, v, F, N, acc, work):
    """Call the C function of ``SIGNATURE`` at the address ``where`` (an integer) as numba
    calls a ``cfunc``: each array passed as its value (numba's array structure)."""
    given = (force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N, acc,
             work)
    if not isinstance(where, types.Integer) or given != SIGNATURE.args:
        return None

    def codegen(context, builder, sig, args):
        fnty = ir.FunctionType(context.get_value_type(SIGNATURE.return_type),
                               [context.get_value_type(t) for t in SIGNATURE.args])
        target = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(target, args[1:])
    return SIGNATURE.return_type(where, *given), codegen


def apply_forces(how, force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F,
                 N, acc, work):
    """Add the force elements' wrenches to ``F``, ``N``: ``how`` is the address of the
    loads' function (a model's ``forces``), or None or True where the caller passes the
    table itself (the low-level entries and the flexible bodies' kernels:
    ``force_elements``' ``shapes``).  Compiled code only: numba compiles the
    implementation ``_apply_forces`` chooses by ``how``'s type (the idiom of
    ``routes.accelerations``); this body runs only if Python calls it."""
    raise NotImplementedError("apply_forces is compiled code only")


@overload(apply_forces, inline="always")
def _apply_forces(how, force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F,
                  N, acc, work):
    if isinstance(how, types.Integer):
        def by_address(how, force_int, force_data, parent, axis, com, qfull, ufull, R, r, w,
                       v, F, N, acc, work):
            if _call_at(how, force_int, force_data, parent, axis, com, qfull, ufull, R, r,
                        w, v, F, N, acc, work) == FAILED:
                raise ZeroDivisionError("division by zero in a force element")
        return by_address

    def in_place(how, force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F,
                 N, acc, work):
        force_elements(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F,
                       N, acc, work, how)
    return in_place

"""The compiled entry of a model with flexible bodies: one C-callable function per kind of
model, reached by its address, so that its code is compiled once and the integration
loops a rigid model compiled serve flexible models unchanged.

numba compiles a function together with everything it calls: every compiled caller
optimises and machine-codes its callees' code again (``docs/performance.md``, "Cold and
warm start").  Linked into the loops (the adaptive stretch, its stages, each fixed-step
scheme), the flexible bodies' terms were compiled once per loop, 30 to 55 s each on the
shared machine.  Here they are compiled once, as a ``cfunc`` (cached like the other
kernels), and the loops call it through its address: a model with flexible bodies passes
the Jourdain layout of a rigid model (``Model.loop_arguments``) whose ``switches`` (the
loads' last array, ``[gyroscopic]`` for a rigid model) is the *hook*: ``[gyroscopic,
the function's address, ...]`` followed by the addresses and shapes of every array the
evaluation reads (``HOOK``).  ``routes.accelerations`` tests the hook's length (one
comparison) and calls the address (``call_address``); ``routes.finish_step`` projects
through it when the hook's last entry says so (a model with loop joints).

Modes: ``ACCEL`` (``io``: ``u'``, nu), ``TERMS`` (the model's ``M``, ``A``, ``f`` into the
flexible arrays), ``PROJECT`` (``io``: ``y = [q, u]``, moved onto the loop constraints).
Returns as ``kernels.flexible`` and ``kernels.flexible_loops`` do (-1 done, a singular
column, -2 non-finite; the projection's steps, -1 or -2), or ``FAILED`` where a kernel
raised (a C function cannot raise: ``call`` and the loops raise again).

One function per kind: without or with the tree's force elements, loads or force
elements at flexible bodies' points, loop joints (``entry``), each compiled on its first
use; a model with contacts between shapes keeps the Python route.
"""
import numpy as np
from numba import njit, types

from .c_function import c_function
from .flexible import bias_step, bodies_step, element_step, kinematics_step, model_step, \
    solve_step
from .flexible_loops import constrained_step, project_step, rows_step
from .flexible_views import (FAILED, FUNCTION, HOOK, NQ, NU, SWITCH, call_address,
                             pointer_view)
from .views import CACHED, UNCOUNTED

ACCEL, TERMS, PROJECT = 0, 1, 2
SIGNATURE = types.int64(types.CPointer(types.int64), types.CPointer(types.float64),
                        types.int64)


@njit(**CACHED)
def call(hook, io, mode):
    """The hook's function on ``io`` in ``mode``, from Python (this module's functions and
    ``route_entry``'s): its status, or ``ZeroDivisionError`` where its kernels raised."""
    status = call_address(hook[FUNCTION], hook, io, mode)
    if status == FAILED:
        raise ZeroDivisionError("division by zero in a compiled evaluation")
    return status


@njit(inline="always", **UNCOUNTED)
def _run(hook_ptr, io_ptr, mode, forces, elements, loops):
    """``_evaluate`` with what its kernels raise turned into ``FAILED``."""
    try:
        return _evaluate(hook_ptr, io_ptr, mode, forces, elements, loops)
    except Exception:
        return FAILED


@njit(inline="always", **UNCOUNTED)
def _evaluate(hook_ptr, io_ptr, mode, forces, elements, loops):
    """The evaluation in ``mode`` (module docstring); ``forces``, ``elements``,
    ``loops``: None or True (types: the kind's function compiles only what it has)."""
    h = pointer_view(hook_ptr, HOOK)
    nq, nu = h[NQ], h[NU]
    x = pointer_view(io_ptr, nq + nu if mode == PROJECT else nu)
    if loops is not None and mode == PROJECT:
        return project_step(h, x)
    kinematics_step(h, x, forces)
    if elements is not None:
        element_step(h, x)
    bias_step(h, x)
    bodies_step(h, x)
    model_step(h, x, mode == TERMS)
    if mode == TERMS:
        return -1
    if loops is not None:
        rows_step(h, x, h[SWITCH] == 0)        # gyroscopic off: walk with the speeds
        pivot = constrained_step(h, x)
    else:
        pivot = solve_step(h, x)
    if pivot >= 0:
        return pivot
    for k in range(nu):
        if not np.isfinite(x[k]):
            return -2
    return -1


# one function per kind (forces, elements, loops): None or True each
def _plain(hook, io, mode):
    return _run(hook, io, mode, None, None, None)


def _forces(hook, io, mode):
    return _run(hook, io, mode, True, None, None)


def _elements(hook, io, mode):
    return _run(hook, io, mode, None, True, None)


def _forces_elements(hook, io, mode):
    return _run(hook, io, mode, True, True, None)


def _loops(hook, io, mode):
    return _run(hook, io, mode, None, None, True)


def _loops_forces(hook, io, mode):
    return _run(hook, io, mode, True, None, True)


def _loops_elements(hook, io, mode):
    return _run(hook, io, mode, None, True, True)


def _loops_forces_elements(hook, io, mode):
    return _run(hook, io, mode, True, True, True)


_KINDS = {(False, False, False): _plain, (True, False, False): _forces,
          (False, True, False): _elements, (True, True, False): _forces_elements,
          (False, False, True): _loops, (True, False, True): _loops_forces,
          (False, True, True): _loops_elements, (True, True, True): _loops_forces_elements}
_COMPILED = {}


def entry(forces, elements, loops):
    """The C function (``numba.cfunc``) of a model with (or without) the tree's force
    elements, elements at flexible bodies' points and loop joints: compiled on first use
    (or loaded from numba's cache), kept for the process."""
    key = (bool(forces), bool(elements), bool(loops))
    if key not in _COMPILED:
        _COMPILED[key] = c_function(SIGNATURE, _KINDS[key], cache=True, _nrt=False)
    return _COMPILED[key]

"""The routes of a rigid model that the compiled loops reach by address: the
articulated-body algorithm and a closed mechanism's accelerations and projection, each one
C-callable function (``numba.cfunc``) whose code is compiled once, so that the loops (the
adaptive stretch, its stages, each fixed-step scheme) compiled for a tree by Jourdain's
``M u' = f`` serve these routes unchanged, as they serve flexible bodies
(``kernels.flexible_entry``; why: ``docs/performance.md``, "Cold and warm start").

A model on such a route passes the Jourdain layout of the workspace
(``Model.loop_arguments``) with a *hook* for the loads' ``switches``: ``[gyroscopic, the
function's address, the force function's address, nq, nu]``, then ``(address, d0, d1,
d2)`` for every array of ``ARRAYS`` (``hook``), and last a flag, 1 when the route
projects the state onto loop constraints after a step (``routes.finish_step``, as in a
flexible model's hook).  ``routes.accelerations`` tests the hook's length and calls the
address (``flexible_views.call_address``) with ``u'`` (``ACCEL``) or the state ``y =
[q, u]`` (``PROJECT``); Python calls a closed mechanism's function for its multipliers
too (``algorithms.route_hook``), so that a run's outputs compile no entry of their own.
The function builds its views of the arrays from the hook and calls the kernels the
loops inlined before (``docs/performance.md``, "Seventh round"): the same arithmetic.
"""
import ctypes

import numpy as np
from numba import njit, types

from .c_function import c_function
from .constrained import constrained_accelerations, project_state_call
from .evaluate import articulated_accelerations
from .flexible_entry import ACCEL, PROJECT
from .flexible_views import FAILED, pointer_view
from .loop_articulated import constrained_articulated
from .views import UNCOUNTED, far_view

SWITCH, FUNCTION, FORCES, NQ, NU = range(5)
HEAD = 5
#: the arrays a route reads and writes, in order: (name, integer?, dimensions, written?)
ARRAYS = (
    ("parent", 1, 1, 0), ("kind", 1, 1, 0), ("axis", 0, 2, 0), ("seq", 1, 2, 0),
    ("pos", 0, 2, 0), ("C", 0, 3, 0), ("qoff", 1, 1, 0), ("uoff", 1, 1, 0),
    ("ucol", 1, 1, 0), ("anc_ptr", 1, 1, 0), ("anc_idx", 1, 1, 0),
    ("mass", 0, 1, 0), ("com", 0, 2, 0), ("inertia", 0, 3, 0), ("has_inertia", 1, 1, 0),
    ("gravity", 0, 1, 0),
    ("qfull", 0, 1, 1), ("ufull", 0, 1, 1), ("udfull", 0, 1, 1),
    ("R", 0, 3, 1), ("r", 0, 2, 1), ("w", 0, 2, 1), ("v", 0, 2, 1), ("alpha", 0, 2, 1),
    ("a", 0, 2, 1), ("JR", 0, 3, 1), ("JT", 0, 3, 1), ("S", 0, 3, 1), ("F", 0, 2, 1),
    ("N", 0, 2, 1), ("M", 0, 2, 1), ("f", 0, 1, 1), ("L", 0, 2, 1), ("scratch", 0, 1, 1),
    ("IA", 0, 3, 1), ("pA", 0, 2, 1), ("cb", 0, 2, 1), ("U", 0, 3, 1), ("Dl", 0, 3, 1),
    ("acc", 0, 2, 1),
    ("load_body", 1, 1, 0), ("load_point", 0, 2, 0), ("load_force", 0, 2, 0),
    ("load_moment", 0, 2, 0), ("load_in_body", 1, 1, 0), ("force_int", 1, 2, 0),
    ("force_data", 0, 1, 0), ("switches", 1, 1, 0),
    ("con_int", 1, 2, 0), ("con_data", 0, 2, 0), ("phi", 0, 1, 1), ("psi", 0, 1, 1),
    ("G", 0, 2, 1), ("gamma", 0, 1, 1), ("lam", 0, 1, 1), ("info", 0, 1, 1),
    ("slots", 1, 2, 0), ("quats", 1, 1, 0), ("free_q", 1, 1, 0), ("free_u", 1, 1, 0))
#: the hook's length: the head, four entries an array, the closing flag
HOOK = HEAD + 4 * len(ARRAYS) + 1
ARTICULATED, CLOSED, ARTICULATED_CLOSED = range(3)
SIGNATURE = types.int64(types.CPointer(types.int64), types.CPointer(types.float64),
                        types.int64)


def hook(arrays, switch, force_address, nq, nu, closed):
    """The hook (module docstring) of ``arrays`` (``{name: array}`` for every name of
    ``ARRAYS``, C-contiguous), its function's address left 0 (``ready``).  The arrays
    must outlive every call through it."""
    h = np.zeros(HOOK, np.int64)
    h[SWITCH], h[FORCES], h[NQ], h[NU], h[-1] = switch, force_address, nq, nu, int(closed)
    for k, (name, integer, ndim, _) in enumerate(ARRAYS):
        a = arrays[name]
        if a.ndim != ndim or a.dtype != (np.int64 if integer else np.float64) or \
                not a.flags.c_contiguous:
            raise TypeError(f"route hook: array {name!r} is {a.dtype}, {a.ndim}-d, "
                            f"{'' if a.flags.c_contiguous else 'not '}C-contiguous")
        h[HEAD + 4 * k] = a.ctypes.data
        h[HEAD + 4 * k + 1:HEAD + 4 * k + 1 + ndim] = a.shape
    return h


def private_hook(h, copies):
    """A copy of the hook ``h`` for one member of a batch (``kernels.batched``): every
    array a route writes at a private copy -- the one ``copies`` maps its address to
    (the member's workspace), else a new copy of its memory -- and the others shared.
    Returns the hook and the new arrays it points to (keep them alive)."""
    out, kept = h.copy(), []
    for k, (name, integer, ndim, written) in enumerate(ARRAYS):
        at = HEAD + 4 * k
        address, shape = int(h[at]), tuple(int(s) for s in h[at + 1:at + 1 + ndim])
        size = int(np.prod(shape))
        if not written or size == 0:
            continue
        if address in copies:
            out[at] = copies[address].ctypes.data
            continue
        kind = ctypes.c_int64 if integer else ctypes.c_double
        fresh = np.ctypeslib.as_array((kind * size).from_address(address)).reshape(shape)
        fresh = fresh.copy()
        kept.append(fresh)
        out[at] = fresh.ctypes.data
    return out, kept


@njit(inline="always", **UNCOUNTED)
def _one(h, name, like):
    at = HEAD + 4 * name
    return far_view(like, h[at], (h[at + 1],))


@njit(inline="always", **UNCOUNTED)
def _two(h, name, like):
    at = HEAD + 4 * name
    return far_view(like, h[at], (h[at + 1], h[at + 2]))


@njit(inline="always", **UNCOUNTED)
def _three(h, name, like):
    at = HEAD + 4 * name
    return far_view(like, h[at], (h[at + 1], h[at + 2], h[at + 3]))


#: where each group of ``ARRAYS`` begins
TREE, BODY, STATE, MOTION, JOURDAIN, SCRATCH, ART, LOADS, CON, PROJ = (
    0, 11, 16, 19, 30, 33, 34, 40, 48, 56)


@njit(inline="always", **UNCOUNTED)
def _groups(h, x):
    """``(tree, body, state, loads, motion, jourdain, art, con, scratch)`` as the loops'
    workspace holds them (``routes``), from the hook ``h``; ``x`` a float view (for the
    element type)."""
    t, b, m, c = TREE, BODY, MOTION, CON
    tree = (_one(h, t, h), _one(h, t + 1, h), _two(h, t + 2, x), _two(h, t + 3, h),
            _two(h, t + 4, x), _three(h, t + 5, x), _one(h, t + 6, h), _one(h, t + 7, h),
            _one(h, t + 8, h), _one(h, t + 9, h), _one(h, t + 10, h))
    body = (_one(h, b, x), _two(h, b + 1, x), _three(h, b + 2, x), _one(h, b + 3, h),
            _one(h, b + 4, x))
    state = (_one(h, STATE, x), _one(h, STATE + 1, x), _one(h, STATE + 2, x))
    loads = (_one(h, LOADS, h), _two(h, LOADS + 1, x), _two(h, LOADS + 2, x),
             _two(h, LOADS + 3, x), _one(h, LOADS + 4, h), (_two(h, LOADS + 5, h), h[FORCES]),
             _one(h, LOADS + 6, x), _one(h, LOADS + 7, h))
    motion = (_three(h, m, x), _two(h, m + 1, x), _two(h, m + 2, x), _two(h, m + 3, x),
              _two(h, m + 4, x), _two(h, m + 5, x), _three(h, m + 6, x), _three(h, m + 7, x),
              _three(h, m + 8, x), _two(h, m + 9, x), _two(h, m + 10, x))
    jourdain = (_two(h, JOURDAIN, x), _one(h, JOURDAIN + 1, x), _two(h, JOURDAIN + 2, x))
    art = (_three(h, ART, x), _two(h, ART + 1, x), _two(h, ART + 2, x), _three(h, ART + 3, x),
           _three(h, ART + 4, x), _two(h, ART + 5, x))
    con = (_two(h, c, h), _two(h, c + 1, x), _one(h, c + 2, x), _one(h, c + 3, x),
           _two(h, c + 4, x), _one(h, c + 5, x), _one(h, c + 6, x), _one(h, c + 7, x))
    return tree, body, state, loads, motion, jourdain, art, con, _one(h, SCRATCH, x)


@njit(inline="always", **UNCOUNTED)
def _run(hook_ptr, io_ptr, mode, articulated, closed):
    """``_route`` with what its kernels raise turned into ``FAILED`` (a C function cannot
    raise: its callers raise ``ZeroDivisionError`` again)."""
    try:
        return _route(hook_ptr, io_ptr, mode, articulated, closed)
    except Exception:
        return FAILED


@njit(inline="always", **UNCOUNTED)
def _route(hook_ptr, io_ptr, mode, articulated, closed):
    """The accelerations into ``io`` (``ACCEL``) or, for a closed mechanism, the
    projection of the state ``io`` (``PROJECT``), returning as the kernels called do
    (``evaluate.articulated_accelerations``, ``constrained.constrained_accelerations``,
    ``loop_articulated.constrained_articulated``, ``constrained.project_state_call``);
    ``articulated``, ``closed``: None or True (types: each kind's function compiles only
    its own route)."""
    h = pointer_view(hook_ptr, HOOK)
    nq, nu = h[NQ], h[NU]
    x = pointer_view(io_ptr, nq + nu if mode == PROJECT else nu)
    tree, body, state, loads, motion, jourdain, art, con, scratch = _groups(h, x)
    if closed is not None and mode == PROJECT:
        return project_state_call(x, nq, _two(h, PROJ, h), _one(h, PROJ + 1, h),
                                  _one(h, PROJ + 2, h), _one(h, PROJ + 3, h), tree, state,
                                  motion, con, scratch)
    if articulated is None:
        M, f, L = jourdain
        return constrained_accelerations(tree, body, state, loads, motion, (M, f, L, x),
                                         con, scratch)
    mass, com, inertia, _, gravity = body
    if closed is None:
        return articulated_accelerations(tree, (mass, com, inertia, gravity), state, loads,
                                         motion, art, x, scratch)
    return constrained_articulated(tree, (mass, com, inertia, gravity), state, loads, motion,
                                   art, x, con, scratch)


def _articulated(hook_ptr, io_ptr, mode):
    return _run(hook_ptr, io_ptr, mode, True, None)


def _closed(hook_ptr, io_ptr, mode):
    return _run(hook_ptr, io_ptr, mode, None, True)


def _articulated_closed(hook_ptr, io_ptr, mode):
    return _run(hook_ptr, io_ptr, mode, True, True)


_KINDS = {ARTICULATED: _articulated, CLOSED: _closed, ARTICULATED_CLOSED: _articulated_closed}
_COMPILED = {}


def entry(route):
    """The C function of ``route`` (``ARTICULATED``, ``CLOSED``, ``ARTICULATED_CLOSED``):
    compiled on first use (or loaded from numba's cache), kept for the process."""
    if route not in _COMPILED:
        _COMPILED[route] = c_function(SIGNATURE, _KINDS[route], cache=True, _nrt=False)
    return _COMPILED[route]


__all__ = ["ACCEL", "PROJECT", "FAILED", "hook", "private_hook", "entry"]

"""The hook of a model's route reached by address (``kernels.route_entry``): the addresses
and shapes of the arrays its C function reads and writes.  The compiled loops take it in
place of the loads' ``switches`` (``compiled.route_packing``); Python calls a closed
mechanism's function through it for the projection onto the constraints and for the
constraint rows (``algorithms.constrained``), so that a run and the checks around it
compile that code once, in the function, instead of again in entries of their own.
"""
from __future__ import annotations

import numpy as np

from ..kernels import route_entry as kre


#: a closed mechanism's forward dynamics take the articulated-body route (``"auto"``)
#: from this many free speeds on: below it the mass matrix and its factor cost less than
#: the unit solves (``kernels.loop_articulated``; docs/performance.md, "Closed loops")
LOOP_ARTICULATED_FROM = 16


def loop_route(model, method):
    """``"jourdain"`` or ``"articulated"``: the route ``method`` stands for on a closed
    mechanism (``"auto"``: by its number of free speeds)."""
    if method == "auto":
        return "articulated" if model.nu >= LOOP_ARTICULATED_FROM else "jourdain"
    return method


def route_hook(model, route, tree):
    """The hook of ``route`` (``kre.ARTICULATED``, ``CLOSED``, ``ARTICULATED_CLOSED``) on
    the model's current arrays, with ``tree`` the tree's arrays the route reads (without
    ancestor lists on the articulated routes), its function compiled (or loaded from
    numba's cache) on first use.  The model keeps the arrays it points to."""
    con = model._con if model._con is not None else _no_constraints(model.nu)
    quats = np.array([s.start for s in model._quaternions], np.int64)
    body = (model._mass, model._com, model._inertia, model._has_inertia, model.gravity)
    ws = (model._qfull, model._ufull, model._udfull, *model._kin_out, model._M, model._f,
          model._L, model._scratch)
    art = (model._IA, model._pA, model._cb, model._U, model._Dl, model._acc)
    loads = model._loads_arrays
    values = (*tree, *body, *ws, *art, *loads[:5], loads[5][0], *loads[6:8], *con,
              model._slots, quats, model._free_q, model._free_u)
    arrays = dict(zip([name for name, _, _, _ in kre.ARRAYS], values, strict=True))
    keep = getattr(model, "_route_arrays", None)
    if keep is None:
        keep = model._route_arrays = {}
    keep[route, tree is model._tree] = arrays     # the memory the hook points to, kept
    h = kre.hook(arrays, int(loads[7][0]), loads[5][1], model.nq, model.nu,
                 closed=model._con is not None)
    h[kre.FUNCTION] = kre.entry(route).address
    return h


def python_hook(model):
    """A closed mechanism's hook for the calls from Python (``RESIDUALS``, ``PROJECT``):
    the function of its own route (by the mass matrix or, from ``LOOP_ARTICULATED_FROM``
    free speeds, the articulated bodies: the one its runs compile) on the arrays Python's
    kernels see (``constrained.groups``: the tree as it is).  Made again when an array
    it points to was replaced (``Model._full_workspace``)."""
    key = (id(model._tree[9]), id(model._JR), id(model._JT), id(model._M), id(model._L))
    cached = getattr(model, "_python_hook", None)
    if cached is not None and cached[0] == key:
        return cached[1]
    route = (kre.ARTICULATED_CLOSED if loop_route(model, "auto") == "articulated"
             else kre.CLOSED)
    h = route_hook(model, route, model._tree)
    model._python_hook = (key, h)
    return h


def _no_constraints(nu):
    """A tree's stand-ins for the constraints' arrays (never read)."""
    return (np.zeros((0, 5), np.int64), np.zeros((0, 1)), np.zeros(0), np.zeros(0),
            np.zeros((0, nu)), np.zeros(0), np.zeros(0), np.zeros(0))

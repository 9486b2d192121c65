"""The hook of a model's route reached by address (``kernels.route_entry``): the addresses
and shapes of the arrays its C function reads and writes.  The compiled loops take it in
place of the loads' ``switches`` (``compiled.route_packing``); Python calls a closed
mechanism's function through it for the multipliers (``algorithms.constrained``), so
that a run's reactions and drive efforts compile no entry of their own.
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
    the model's current arrays (``route_arrays``), its function compiled (or loaded from
    numba's cache) on first use."""
    loads = model._loads_arrays
    h = kre.hook(route_arrays(model, tree), int(loads[7][0]), loads[5][1], model.nq,
                 model.nu, closed=model._con is not None)
    h[kre.FUNCTION] = kre.entry(route).address
    return h


def route_arrays(model, tree):
    """``{name: array}`` for every array of ``kre.ARRAYS``, with ``tree`` the tree's
    arrays the route reads (without ancestor lists on the articulated routes).  Each is
    the model's own, for the model's life (``model_quats``), except the stand-ins of a
    tree's constraints and the articulated routes' ancestor lists: empty, never read."""
    con = model._con if model._con is not None else _no_constraints(model.nu)
    body = (model._mass, model._com, model._inertia, model._has_inertia, model.gravity)
    ws = (model._qfull, model._ufull, model._udfull, *model._kin_out, model._M, model._f,
          model._L, model._scratch)
    art = (model._IA, model._pA, model._cb, model._U, model._Dl, model._acc)
    loads = model._loads_arrays
    values = (*tree, *body, *ws, *art, *loads[:5], loads[5][0], *loads[6:8], *con,
              model._slots, model_quats(model), model._free_q, model._free_u)
    return dict(zip([name for name, _, _, _ in kre.ARRAYS], values, strict=True))


def model_quats(model):
    """Where each unit quaternion begins in ``q`` (int64), one array for the model's life:
    the hooks point to it (``route_hook``)."""
    quats = model.__dict__.get("_quat_starts")
    if quats is None:
        quats = np.array([s.start for s in model._quaternions], np.int64)
        model._quat_starts = quats
    return quats


def python_hook(model):
    """A closed mechanism's hook for the multipliers from Python (``ACCEL``): the
    function of its own route (by the mass matrix or, from ``LOOP_ARTICULATED_FROM`` free
    speeds, the articulated bodies: the one its runs compile) on the arrays Python's
    kernels see (``constrained.groups``: the tree as it is).  Made again when one of the
    arrays ``Model._full_workspace`` allocates was replaced."""
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

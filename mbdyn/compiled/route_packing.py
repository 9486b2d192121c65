"""The arrays the compiled loops take (``Model.loop_arguments``): the Jourdain layout of
the workspace for every rigid model, and, for the routes reached by address (the
articulated-body algorithm, closed mechanisms: ``kernels.route_entry``), the hook that
stands for the loads' ``switches``.  A tree by Jourdain's ``M u' = f`` passes its own
``switches``, and the loops call its route compiled with them, as before.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..algorithms.route_hook import model_quats, route_hook
from ..kernels import route_entry as kre


def loop_arguments(model, method):
    """``(nq, slots, quats, free_q, free_u, drive_q, drive_u, tree, body, loads, ws)``
    laid out for ``method`` (``"jourdain"`` or ``"articulated"``)."""
    if method not in ("jourdain", "articulated"):
        raise ModelError(f"loop_arguments: no compiled loop for method {method!r}")
    closed = model._con is not None
    if method == "jourdain":
        model._full_workspace()
    tree = model._tree
    if method == "articulated":       # no ancestor lists: no full Jacobians computed
        none = np.zeros(0, np.int64)
        tree = tree[:9] + (none, none)
    slots = model._slots
    quats = model_quats(model)
    drive_q = np.array([d[1] for d in model._time_inputs], np.int64)
    drive_u = np.array([d[2] for d in model._time_inputs], np.int64)
    body = (model._mass, model._com, model._inertia, model._has_inertia, model.gravity)
    ws = (model._qfull, model._ufull, model._udfull, model._R, model._r, model._w, model._v,
          model._alpha, model._a, model._JR, model._JT, model._S, model._F, model._N,
          model._M, model._f, model._L, model._scratch)
    loads = model._loads_arrays
    if method == "articulated" or closed:
        route = (kre.CLOSED if method == "jourdain" else
                 kre.ARTICULATED_CLOSED if closed else kre.ARTICULATED)
        loads = loads[:7] + (route_hook(model, route, tree),)
    return (model.nq, slots, quats, model._free_q, model._free_u, drive_q, drive_u, tree,
            body, loads, ws)

"""The routes the compiled integrators take, chosen when a loop is compiled by the layout
of the model's workspace ``ws`` (``Model.loop_arguments``): the accelerations by
Jourdain's ``M u' = f``, by the articulated bodies, or of a closed mechanism (``M u' = f +
G^T lam``, ``G u' = gamma``), and what follows each step (unit quaternions; for a closed
mechanism, the projection onto its constraints).  A run compiles only its own route.

Each route is a function the loops call, compiled once (uncounted, as the kernels it
calls), not inlined: numba compiles the implementation of an inlined overload as a
function anyway, and then again inside every caller.
"""
import numpy as np
from numba import njit
from numba.extending import overload

from .constrained import constrained_accelerations, project_state_call
from .evaluate import articulated_accelerations, jourdain_accelerations
from .flexible_entry import ACCEL, PROJECT
from .flexible_views import FUNCTION, call_address
from .loop_articulated import constrained_articulated


@njit(cache=True, inline="always")
def _normalize(y, quats):
    for s in range(quats.shape[0]):
        i = quats[s]
        n = np.sqrt(y[i] ** 2 + y[i + 1] ** 2 + y[i + 2] ** 2 + y[i + 3] ** 2)
        for k in range(4):
            y[i + k] /= n


def accelerations(tree, body, loads, ws, ud):
    """``ud = u'`` by the route the workspace ``ws`` is laid out for (see
    ``_accelerations_route``); returns as ``evaluate.jourdain_accelerations``."""
    raise NotImplementedError("compiled code only")


@overload(accelerations, jit_options={"_nrt": False, "no_cfunc_wrapper": True})
def _accelerations_route(tree, body, loads, ws, ud):
    """The formulation is chosen when the loop is compiled, by the workspace's type: 18
    arrays (``M``, ``f``, ``L``, scratch last) for ``M u' = f``, 26 (the same and the
    eight arrays of the constraints, ``Model._con``) for a closed mechanism, 21 (the articulated-body
    workspace, then the scratch; ``tree`` then has empty ancestor lists) for the
    articulated-body algorithm, 29 (that and the constraints) for a closed mechanism by
    the articulated bodies (``loop_articulated``).  A run compiles only its own route.  A closed
    mechanism's accelerations are inlined here too (a call with their fifty arrays cost a
    tenth of a four-bar's evaluation); the kernels they call that allocate are counted
    explicitly (``constraint_rows``, the solves).  A model with flexible bodies takes the
    Jourdain layout (with loops, the closed mechanism's) and a *hook* for the loads'
    ``switches``: its evaluation's address and arrays (``kernels.flexible_entry``), called
    instead of the tree's."""
    if len(ws) == 29:
        def articulated_loop_route(tree, body, loads, ws, ud):
            (qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S, F, N, IA, pA, cb, U, Dl,
             acc, scratch) = ws[:21]
            mass, com, inertia, _, gravity = body
            return constrained_articulated(tree, (mass, com, inertia, gravity),
                                           (qfull, ufull, udfull), loads,
                                           (R, r, w, v, alpha, a, JR, JT, S, F, N),
                                           (IA, pA, cb, U, Dl, acc), ud, ws[21:], scratch)
        return articulated_loop_route
    if len(ws) == 26:
        def constrained_route(tree, body, loads, ws, ud):
            hook = loads[7]
            if hook.shape[0] > 1:          # flexible bodies (kernels.flexible_entry)
                return call_address(hook[FUNCTION], hook, ud, ACCEL)
            (qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S, F, N, M, f, L,
             scratch) = ws[:18]
            return constrained_accelerations(tree, body, (qfull, ufull, udfull), loads,
                                             (R, r, w, v, alpha, a, JR, JT, S, F, N),
                                             (M, f, L, ud), ws[18:], scratch)
        return constrained_route
    if len(ws) == 18:
        def jourdain_route(tree, body, loads, ws, ud):
            hook = loads[7]
            if hook.shape[0] > 1:          # flexible bodies (kernels.flexible_entry)
                return call_address(hook[FUNCTION], hook, ud, ACCEL)
            (qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S, F, N, M, f, L,
             scratch) = ws
            return jourdain_accelerations(tree, body, (qfull, ufull, udfull), loads,
                                          (R, r, w, v, alpha, a, JR, JT, S, F, N),
                                          (M, f, L, ud), scratch)
        return jourdain_route

    def articulated_route(tree, body, loads, ws, ud):
        (qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S, F, N, IA, pA, cb, U, Dl,
         acc, scratch) = ws
        mass, com, inertia, _, gravity = body
        return articulated_accelerations(tree, (mass, com, inertia, gravity),
                                         (qfull, ufull, udfull), loads,
                                         (R, r, w, v, alpha, a, JR, JT, S, F, N),
                                         (IA, pA, cb, U, Dl, acc), ud, scratch)
    return articulated_route


def _constraints_and_scratch(ws):
    """A closed mechanism's workspace: its constraints (the last eight arrays) and the
    scratch before them."""
    raise NotImplementedError("compiled code only")


@overload(_constraints_and_scratch, inline="always")
def _constraints_and_scratch_layout(ws):
    if len(ws) == 29:                    # articulated bodies: 21 arrays, then the eight
        return lambda ws: (ws[21:], ws[20])
    return lambda ws: (ws[18:], ws[17])  # the mass matrix: 18 arrays, then the eight


def finish_step(y, drive_vals, nq, slots, quats, free_q, free_u, drive_q, drive_u, tree, loads,
                ws):
    """After a step: unit quaternions and, for a closed mechanism, the state projected
    back onto the constraint manifold (``kernels.constrained.project_state``) with the
    drives at the step's end ``drive_vals``.  Returns 0, or 5 when the projection failed."""
    raise NotImplementedError("compiled code only")


@overload(finish_step, jit_options={"_nrt": False, "no_cfunc_wrapper": True})
def _finish_step_route(y, drive_vals, nq, slots, quats, free_q, free_u, drive_q, drive_u,
                       tree, loads, ws):
    """Chosen by the workspace's layout, as ``accelerations``: a tree only normalises; a
    closed mechanism's projection is the entry point Python calls
    (``constrained.project_state_call``, counted: it allocates), once a step; with
    flexible bodies (a hook, as in ``accelerations``) their projection
    (``flexible_loops.project_flexible``)."""
    if len(ws) == 26 or len(ws) == 29:
        def project_route(y, drive_vals, nq, slots, quats, free_q, free_u, drive_q, drive_u,
                          tree, loads, ws):
            qfull, ufull, udfull = ws[0], ws[1], ws[2]
            for d in range(drive_q.shape[0]):
                qfull[drive_q[d]] = drive_vals[d, 0]
                ufull[drive_u[d]] = drive_vals[d, 1]
                udfull[drive_u[d]] = drive_vals[d, 2]
            _normalize(y, quats)
            hook = loads[7]
            if hook.shape[0] > 1:
                return 5 if call_address(hook[FUNCTION], hook, y, PROJECT) < 0 else 0
            con, scratch = _constraints_and_scratch(ws)
            steps = project_state_call(y, nq, slots, quats, free_q, free_u, tree,
                                       (qfull, ufull, udfull), ws[3:14], con, scratch)
            return 5 if steps < 0 else 0
        return project_route

    def normalize_route(y, drive_vals, nq, slots, quats, free_q, free_u, drive_q, drive_u,
                        tree, loads, ws):
        _normalize(y, quats)
        return 0
    return normalize_route

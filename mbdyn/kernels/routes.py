"""The routes the compiled integrators take (``Model.loop_arguments``): the accelerations
by Jourdain's ``M u' = f``, or by a C function reached by address -- the
articulated-body algorithm, a closed mechanism (``M u' = f + G^T lam``, ``G u' =
gamma``; ``kernels.route_entry``), flexible bodies (``kernels.flexible_entry``) -- and
what follows each step (unit quaternions; for a closed mechanism, the projection onto its
constraints, by the same function).

Every model passes the workspace ``ws`` of ``M u' = f`` (18 arrays: the state, the frames'
motion, ``M``, ``f``, ``L``, scratch last); a route by address puts its *hook* in the
loads' ``switches`` (one entry, the gyroscopic switch, for a tree by the mass matrix).
The loops, compiled for those types once, serve every route: a route's own code is
compiled once, in its function, instead of again inside every loop and stage that calls
it (the articulated route's first run 8.5 s, a closed loop's 25-40 s of compiling,
docs/performance.md).  The tree's route is a function the loops call, compiled once
(uncounted, as the kernels it calls), not inlined: numba compiles the implementation of
an inlined overload as a function anyway, and then again inside every caller.
"""
import numpy as np
from numba import njit
from numba.extending import overload

from .evaluate import jourdain_accelerations
from .flexible_entry import ACCEL, PROJECT
from .flexible_views import FAILED, FUNCTION, call_address
from .views import UNCOUNTED


@njit(cache=True, inline="always")
def _normalize(y, quats):
    for s in range(quats.shape[0]):
        i = quats[s]
        n = np.sqrt(y[i] ** 2 + y[i + 1] ** 2 + y[i + 2] ** 2 + y[i + 3] ** 2)
        for k in range(4):
            y[i + k] /= n


def accelerations(tree, body, loads, ws, ud):
    """``ud = u'`` by the model's route (the module docstring); returns as
    ``evaluate.jourdain_accelerations``."""
    raise NotImplementedError("compiled code only")


@overload(accelerations, jit_options={"_nrt": False, "no_cfunc_wrapper": True})
def _accelerations_route(tree, body, loads, ws, ud):
    """The tree's ``M u' = f`` on the workspace, or the function of the hook (its length
    tells: one comparison, then an indirect call)."""
    def route(tree, body, loads, ws, ud):
        hook = loads[7]
        if hook.shape[0] > 1:          # articulated, closed or flexible: by address
            status = call_address(hook[FUNCTION], hook, ud, ACCEL)
            if status == FAILED:
                raise ZeroDivisionError("division by zero in the accelerations")
            return status
        (qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S, F, N, M, f, L,
         scratch) = ws
        return jourdain_accelerations(tree, body, (qfull, ufull, udfull), loads,
                                      (R, r, w, v, alpha, a, JR, JT, S, F, N),
                                      (M, f, L, ud), scratch)
    return route


@njit(inline="always", **UNCOUNTED)
def projects(hook):
    """Whether the loads' ``switches`` is the hook of a closed mechanism, whose function
    projects the state onto its constraints after each step (the hook's last entry)."""
    return hook.shape[0] > 1 and hook[hook.shape[0] - 1] != 0


@njit(inline="always", **UNCOUNTED)
def closed(loads):
    """Whether the loops run a closed mechanism (``projects``)."""
    return projects(loads[7])


def finish_step(y, drive_vals, nq, slots, quats, free_q, free_u, drive_q, drive_u, tree, loads,
                ws):
    """After a step: unit quaternions and, for a closed mechanism, the state projected
    back onto the constraint manifold with the drives at the step's end ``drive_vals``
    (``constrained.project_state``, or the flexible bodies' projection, by address).
    Returns 0, or 5 when the projection failed."""
    raise NotImplementedError("compiled code only")


@overload(finish_step, jit_options={"_nrt": False, "no_cfunc_wrapper": True})
def _finish_step_route(y, drive_vals, nq, slots, quats, free_q, free_u, drive_q, drive_u,
                       tree, loads, ws):
    """Normalise, then project by the hook's function when it ``projects``."""
    def normalize_route(y, drive_vals, nq, slots, quats, free_q, free_u, drive_q, drive_u,
                        tree, loads, ws):
        _normalize(y, quats)
        hook = loads[7]
        if not projects(hook):
            return 0
        qfull, ufull, udfull = ws[0], ws[1], ws[2]
        for d in range(drive_q.shape[0]):
            qfull[drive_q[d]] = drive_vals[d, 0]
            ufull[drive_u[d]] = drive_vals[d, 1]
            udfull[drive_u[d]] = drive_vals[d, 2]
        status = call_address(hook[FUNCTION], hook, y, PROJECT)
        if status == FAILED:
            raise ZeroDivisionError("division by zero in the projection")
        return 5 if status < 0 else 0
    return normalize_route

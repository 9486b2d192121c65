"""The state's rate ``y' = [N(q) u, M^-1 f]`` at one stage of a compiled step, with the
drives' values of that stage, for the fixed-step and adaptive loops."""
import numpy as np
from numba import njit
from .joints import coordinate_rates
from .routes import accelerations
from .internal import internal


@njit(cache=True, inline="always")
def coordinate_rates_into(y, nq, slots, out):
    """``q' = N(q) u`` into ``out[:nq]``."""
    coordinate_rates(y[:nq], y[nq:], slots, out[:nq])


@njit(cache=True, inline="always")
def state_rate(y, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
               ws, ydot, nfev):
    """``ydot = [N(q) u, M^-1 f]`` at the stage whose drive values are ``drive_vals``;
    counts the evaluation in ``nfev[0]``."""
    nfev[0] += 1
    qfull, ufull, udfull = ws[0], ws[1], ws[2]
    nu = y.shape[0] - nq
    for k in range(nq):
        qfull[free_q[k]] = y[k]
    for k in range(nu):
        ufull[free_u[k]] = y[nq + k]
        udfull[free_u[k]] = 0.0
    for d in range(drive_q.shape[0]):
        qfull[drive_q[d]] = drive_vals[d, 0]
        ufull[drive_u[d]] = drive_vals[d, 1]
        udfull[drive_u[d]] = drive_vals[d, 2]
    pivot = accelerations(tree, body, loads, ws, ydot[nq:])
    if pivot >= 0:
        return 2
    coordinate_rates_into(y, nq, slots, ydot)
    for k in range(ydot.shape[0]):
        if not np.isfinite(ydot[k]):
            return 1
    return 0


@njit(cache=True, inline="always")
def copy_into(src, dst):
    """``dst[:] = src`` element by element (an array assignment makes numba compile its
    shape-mismatch message: string formatting, seconds of a first run)."""
    for k in range(src.shape[0]):
        dst[k] = src[k]


@internal(cache=True, _nrt=False, forceinline=True)
def state_rate_call(y, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
                    loads, ws, ydot, nfev):
    """``state_rate`` compiled once, as a function of its own, for the steps that
    evaluate it at several places (RK4's four stages, the implicit midpoint rule's
    iteration): inlined by numba at each call site it was compiled at each (RK4's loop
    4.5 s to compile cold instead of 3.2).  ``forceinline``: LLVM inlines the compiled
    code at each site (a plain call made RK4 runs a fifth slower)."""
    return state_rate(y, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
                      loads, ws, ydot, nfev)

"""Batched ensembles: many members of one compiled model advanced in one compiled call.

Each member differs only in its initial state ``Y0[i] = [q, u]``; the model's arrays are
shared read-only, and each member gets its own copy of the workspace (laid out for
``M u' = f`` or for the articulated-body algorithm, as the model's route is).  Members run in
parallel over cores (numba ``prange``); each member runs the very same compiled fixed-step
loop as a single run (``kernels.integrators.fixed_step_loop``), so a member's final state
is bit-identical to ``simulate`` with the same scheme and step.
"""
import numpy as np
from numba import njit, prange
from numba.extending import overload

from .integrators import fixed_step_loop


def _own_workspace(ws):
    """A private copy of the workspace arrays of ``Model.loop_arguments`` (each layout:
    18 arrays for ``M u' = f``, 26 with a closed mechanism's constraints, 21 for the
    articulated-body algorithm)."""
    raise NotImplementedError("compiled code only")


@overload(_own_workspace, inline="always")
def _own_workspace_layout(ws):
    if len(ws) == 26:          # a closed mechanism: the Jourdain layout and its constraints
        def constrained_layout(ws):
            return (ws[0].copy(), ws[1].copy(), ws[2].copy(), ws[3].copy(), ws[4].copy(),
                    ws[5].copy(), ws[6].copy(), ws[7].copy(), ws[8].copy(), ws[9].copy(),
                    ws[10].copy(), ws[11].copy(), ws[12].copy(), ws[13].copy(),
                    ws[14].copy(), ws[15].copy(), ws[16].copy(), ws[17].copy(),
                    ws[18], ws[19], ws[20].copy(), ws[21].copy(), ws[22].copy(),
                    ws[23].copy(), ws[24].copy(), ws[25].copy())
        return constrained_layout
    if len(ws) == 18:
        def jourdain_layout(ws):
            return (ws[0].copy(), ws[1].copy(), ws[2].copy(), ws[3].copy(), ws[4].copy(),
                    ws[5].copy(), ws[6].copy(), ws[7].copy(), ws[8].copy(), ws[9].copy(),
                    ws[10].copy(), ws[11].copy(), ws[12].copy(), ws[13].copy(),
                    ws[14].copy(), ws[15].copy(), ws[16].copy(), ws[17].copy())
        return jourdain_layout

    def articulated_layout(ws):
        return (ws[0].copy(), ws[1].copy(), ws[2].copy(), ws[3].copy(), ws[4].copy(),
                ws[5].copy(), ws[6].copy(), ws[7].copy(), ws[8].copy(), ws[9].copy(),
                ws[10].copy(), ws[11].copy(), ws[12].copy(), ws[13].copy(), ws[14].copy(),
                ws[15].copy(), ws[16].copy(), ws[17].copy(), ws[18].copy(), ws[19].copy(),
                ws[20].copy())
    return articulated_layout


@njit(cache=True, parallel=True)
def batched_fixed_step(scheme, h, n_steps, h_last, Y0, table, table_last, nq, slots, quats,
                       free_q, free_u, drive_q, drive_u, tree, body, loads, ws, Yend, done,
                       status, nfev):
    """Advance every row of ``Y0`` by ``n_steps`` steps of size ``h`` and then, if
    ``h_last > 0``, one step of ``h_last`` (``simulate``'s shortened last step).

    ``table``/``table_last``: the drives' stage values (as ``fixed_step_loop`` takes them)
    for the ``n_steps`` steps and the last one.  Writes per member the final state
    ``Yend[i]``, the steps done ``done[i]``, the loop's status code ``status[i]`` (0 done)
    and the right-hand-side evaluations ``nfev[i]``."""
    m = Y0.shape[0]
    ny = Y0.shape[1]
    for i in prange(m):
        w = _own_workspace(ws)
        out = np.empty((n_steps + 1, ny))
        count = np.zeros(1, np.int64)
        d, st = fixed_step_loop(scheme, h, Y0[i], table, nq, slots, quats, free_q, free_u,
                                drive_q, drive_u, tree, body, loads, w, out, count)
        if st == 0 and h_last > 0.0:
            last = np.empty((2, ny))
            y = out[n_steps].copy()
            d2, st = fixed_step_loop(scheme, h_last, y, table_last, nq, slots, quats, free_q,
                                     free_u, drive_q, drive_u, tree, body, loads, w, last,
                                     count)
            d += d2
            Yend[i] = last[d2]
        else:
            Yend[i] = out[d]
        done[i] = d
        status[i] = st
        nfev[i] = count[0]

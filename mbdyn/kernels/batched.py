"""Batched ensembles: many members of one compiled model advanced together.

Each member differs only in its initial state ``Y0[i] = [q, u]``; the model's arrays are
shared read-only, and each member gets its own copy of the workspace and, on a route
reached by address (the articulated bodies, a closed mechanism:
``kernels.route_entry``), its own hook on its own copies of what that route writes.
Each member runs the very compiled loop of a
single run with the same scheme (``kernels.integrators.LOOPS``, with the same argument
types), so a member's final state is bit-identical to ``simulate`` with the same scheme and
step, and a sweep compiles nothing a single run has not: no loop over all four schemes, no
parallel kernel of its own (a ``prange`` kernel around the loop compiled 15 to 30 s).
Members run in parallel on threads, as many as numba's (``NUMBA_NUM_THREADS``: the
cores): the loops release the GIL (``nogil``).
"""
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import config

from .integrators import LOOPS, loop_scratch
from .route_entry import HOOK, private_hook

def own_workspace(ws, loads):
    """A private copy of the workspace arrays of ``Model.loop_arguments``, and the loads
    with, for a route reached by address (``kernels.route_entry``), a private hook on the
    copies and on copies of the other arrays its function writes (the third item, to be
    kept alive while the member runs)."""
    own = tuple(a.copy() for a in ws)
    hook = loads[7]
    if hook.shape[0] != HOOK:     # a tree's switches (a flexible model's hook: not batched)
        return own, loads, ()
    hook, kept = private_hook(hook, {a.ctypes.data: c for a, c in zip(ws, own) if a.size})
    return own, loads[:7] + (hook,), kept


def batched_fixed_step(scheme, h, n_steps, h_last, Y0, table, table_last, nq, slots, quats,
                       free_q, free_u, drive_q, drive_u, tree, body, loads, ws, Yend, done,
                       status, nfev, no_events):
    """Advance every row of ``Y0`` by ``n_steps`` steps of size ``h`` of the scheme code
    ``scheme`` and then, if ``h_last > 0``, one step of ``h_last`` (``simulate``'s shortened
    last step).

    ``table``/``table_last``: the drives' stage values (as the loops take them) for the
    ``n_steps`` steps and the last one; ``no_events``: ``EventPrograms.none()``.  Writes per
    member the final state ``Yend[i]``, the steps done ``done[i]``, the loop's status code
    ``status[i]`` (0 done) and the right-hand-side evaluations ``nfev[i]``."""
    loop = LOOPS[scheme]
    m, ny = Y0.shape
    no_rates, no_times = np.empty((0, ny)), np.empty(0)

    def member(i):
        w, member_loads, _kept = own_workspace(ws, loads)
        out = np.empty((n_steps + 1, ny))
        count = np.zeros(1, np.int64)
        d, st = loop(h, Y0[i], table, nq, slots, quats, free_q, free_u, drive_q, drive_u,
                     tree, body, member_loads, w, out, no_rates, count, no_times, no_events,
                     loop_scratch(ny, scheme))
        row = out[d]
        if st == 0 and h_last > 0.0:
            last = np.empty((2, ny))
            d2, st = loop(h_last, out[n_steps], table_last, nq, slots, quats, free_q,
                          free_u, drive_q, drive_u, tree, body, member_loads, w, last, no_rates,
                          count, no_times, no_events, loop_scratch(ny, scheme))
            d += d2
            row = last[d2]
        Yend[i] = row
        done[i] = d
        status[i] = st
        nfev[i] = count[0]

    threads = max(1, min(config.NUMBA_NUM_THREADS, m))

    def share(k):                 # every threads-th member, as a static schedule would
        for i in range(k, m, threads):
            member(i)
    if threads == 1:
        share(0)
        return
    with ThreadPoolExecutor(threads) as pool:
        for _ in pool.map(share, range(threads)):
            pass

"""Event conditions in the compiled loops: after each step, every condition ``g(t, q, u)``
(a program of ``kernels.programs``) at the new state, and whether the loop must hand over
to Python there.

A loop takes its events as one tuple ``(ops, consts, starts, direction, terminal, g_prev,
out_g, stack, any_crossing)``: condition ``k`` is the program ``starts[k] .. starts[k + 1]``,
``direction[k]`` +1 (rising), -1 (falling) or 0 (either) and ``terminal[k]`` 0/1 as in
``mbdyn.integrate.events.Event``; ``g_prev`` holds the conditions at the state before the step and is
updated; ``out_g[row]`` receives the conditions after step ``row``.  A loop stops after a
step where a condition is not finite, or where a terminal one crossed zero (any one with
``any_crossing``: the adaptive stretch keeps only its last step's stages, from which Python
locates the crossing on the dense output).  No conditions (``starts = [0]``): nothing is
evaluated.
"""
import numpy as np
from numba import njit

from .views import CACHED

from .internal import internal

from .programs import evaluate


@njit(cache=True, inline="always")
def crossed(direction, g_old, g_new):
    """Whether a condition going from ``g_old`` to ``g_new`` crosses zero in ``direction``
    (the same test as ``mbdyn.integrate.event_search.crossed``: reaching zero counts, leaving it not)."""
    up = g_old < 0.0 and g_new >= 0.0
    down = g_old > 0.0 and g_new <= 0.0
    if direction > 0:
        return up
    if direction < 0:
        return down
    return up or down


@internal(cache=True, _nrt=False, forceinline=True)
def step_ends_stretch(events, t, y, row):
    """The conditions at ``(t, y)`` into ``out_g[row]``; true when the loop must stop after
    this step (a condition not finite, or a crossing that Python must handle now)."""
    ops, consts, starts, direction, terminal, g_prev, out_g, stack, any_crossing = events
    stop = False
    for k in range(direction.shape[0]):
        g = evaluate(ops, consts, starts[k], starts[k + 1], t, y, stack)
        out_g[row, k] = g
        if not np.isfinite(g):
            stop = True
        elif crossed(direction[k], g_prev[k], g) and (any_crossing or terminal[k]):
            stop = True
        g_prev[k] = g
    return stop


@njit(**CACHED)
def condition_rows(ops, consts, first, last, ts, ys, stack, out):
    """One condition at every row: ``out[i] = g(ts[i], ys[i])``."""
    for i in range(ts.shape[0]):
        out[i] = evaluate(ops, consts, first, last, ts[i], ys[i], stack)

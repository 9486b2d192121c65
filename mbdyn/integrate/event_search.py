"""Event conditions along a motion: their values at a state or at the rows of a stretch,
and which rows cross zero in the event's direction.
"""
from __future__ import annotations


import numpy as np

from ..errors import (NonFiniteError)


def event_values(events, model, t, y):
    nq = model.nq
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        values = np.array([float(e.condition(t, y[:nq], y[nq:])) for e in events])
    if not np.all(np.isfinite(values)):
        bad = [e.name for e, v in zip(events, values) if not np.isfinite(v)]
        raise NonFiniteError(f"event {', '.join(map(repr, bad))}: the condition is not a "
                             f"finite number at t={t:.6g} (e.g. a square root or logarithm "
                             "of a negative value, a division by zero), so its crossing "
                             "cannot be found; write a condition defined over the whole motion")
    return values


def crossed(e, g_old, g_new):
    if e.direction > 0:
        return g_old < 0 <= g_new
    if e.direction < 0:
        return g_old > 0 >= g_new
    return (g_old < 0 <= g_new) or (g_old > 0 >= g_new)


def event_rows(events, model, ts, ys):
    """Every event's condition at the rows ``(ts, ys)``: ``(len(ts), len(events))``, NaN
    and Inf left in.  Conditions from text or sympy are evaluated on the whole columns."""
    from .events import CompiledCondition
    nq = model.nq
    out = np.empty((len(ts), len(events)))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for k, e in enumerate(events):
            g = e.condition
            v = g.rows(ts, ys) if isinstance(g, CompiledCondition) else None
            out[:, k] = v if v is not None else [float(g(t, y[:nq], y[nq:]))
                                                 for t, y in zip(ts, ys)]
    return out


def crossed_rows(e, g_old, g_new):
    """``crossed`` over arrays."""
    up = (g_old < 0) & (g_new >= 0)
    down = (g_old > 0) & (g_new <= 0)
    return up if e.direction > 0 else down if e.direction < 0 else up | down

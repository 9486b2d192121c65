"""The samples a fixed-step run keeps, gathered stretch by stretch: every ``decimate``-th
step and the last one, or the states at the output times, interpolated between the steps
by cubic Hermite polynomials on ``q`` and ``u`` from the states and their derivatives at
both ends of the step (the derivatives the steps computed anyway), so that the output
costs no accuracy: the interpolation error, O(h^4), stays below the scheme's own.
"""
from __future__ import annotations

import numpy as np


def hermite(s, h, y0, f0, y1, f1):
    """The cubic through ``y0`` and ``y1`` with slopes ``f0``, ``f1`` over a step ``h``,
    at the fractions ``s`` of the step (each argument a column or rows, broadcast)."""
    return ((1 + 2 * s) * (1 - s) ** 2 * y0 + s * (1 - s) ** 2 * h * f0
            + s * s * (3 - 2 * s) * y1 + s * s * (s - 1) * h * f1)


class Samples:
    """The samples a fixed-step run keeps, gathered stretch by stretch (arrays, not rows):
    every ``every``-th step and the last one, or the states interpolated at ``t_eval``
    (cubic Hermite between the steps that bracket each time; ``add`` is then given each
    step's ``y'`` at its start, and ``arrays`` a function for ``y'`` at the last state)."""

    def __init__(self, t0, y0, every=1, t_eval=None):
        self.every = every
        self.t_eval = None if t_eval is None else np.asarray(t_eval, dtype=float)
        self.next_eval = 0
        self.times, self.states = [], []
        self.count = 0                  # samples kept
        self.step = 0                   # steps seen
        self.last = (t0, y0)            # the newest state, kept or not
        self.last_kept = False
        # the dense output's nodes not yet passed: times, states, derivatives (the newest
        # node's derivative is the next step's, so not known yet)
        self.nodes = (np.array([t0], dtype=float), np.asarray(y0, dtype=float)[None, :],
                      None)
        if self.t_eval is not None:
            self._take(self.t_eval[self.t_eval <= t0], np.repeat(self.nodes[1], np.sum(
                self.t_eval <= t0), axis=0))
        else:
            self._keep([t0], y0[None, :], np.array([0]))
            self.last_kept = True

    def _take(self, sel, rows):
        if len(sel):
            self.times.append(np.asarray(sel, dtype=float))
            self.states.append(np.asarray(rows))
            self.next_eval += len(sel)
            self.count += len(sel)

    def _keep(self, ts, ys, keep):
        if keep.size:
            self.times.append(np.asarray(ts, dtype=float)[keep])
            self.states.append(np.asarray(ys)[keep])
            self.count += keep.size

    def _interpolate(self, T, Y, F, upto):
        """The output times up to ``upto`` (at most ``T[-1]``) between nodes ``T`` with
        states ``Y`` and derivatives ``F`` (``F[k]`` needed only inside a step)."""
        lo = self.t_eval[self.next_eval:]
        sel = lo[lo <= upto]
        if not sel.size:
            return
        i = np.clip(np.searchsorted(T, sel, side="left"), 1, len(T) - 1)   # T[i-1] < s <= T[i]
        out = np.empty((sel.size, Y.shape[1]))
        node = T[i] == sel
        out[node] = Y[i[node]]
        inner = np.flatnonzero(~node)
        if inner.size:
            a, b = i[inner] - 1, i[inner]
            h = (T[b] - T[a])[:, None]
            out[inner] = hermite((sel[inner] - T[a])[:, None] / h, h, Y[a], F[a], Y[b], F[b])
        self._take(sel, out)

    def add(self, ts, ys, fs=None):
        """The rows ``(ts, ys)`` of a stretch; ``fs[k]``: ``y'`` at the state before row
        ``k`` (the previous row, or the last one of the stretch before)."""
        if not len(ts):
            return
        ts = np.asarray(ts, dtype=float)
        if self.t_eval is not None:
            T0, Y0, F0 = self.nodes
            F0 = fs[:1] if F0 is None else np.vstack([F0, fs[:1]])
            T = np.concatenate([T0, ts])
            Y = np.vstack([Y0, ys])
            F = np.vstack([F0, fs[1:]])               # one row short: the newest is unknown
            self._interpolate(T, Y, F, T[-2])         # the steps whose both ends are known
            self.nodes = (T[-2:], Y[-2:], F[-1:])
        else:
            index = self.step + 1 + np.arange(len(ts))
            keep = np.flatnonzero(index % self.every == 0)
            self._keep(ts, ys, keep)
            self.last_kept = bool(keep.size and keep[-1] == len(ts) - 1)
        self.step += len(ts)
        self.last = (ts[-1], np.array(ys[-1], dtype=float))

    def arrays(self, derivative=None):
        """``(t, y)`` of the kept samples; the last state is always among them (without
        ``t_eval``).  With ``t_eval``, ``derivative(t, y)`` gives ``y'`` at the last state
        (``None``: not finite there; the last step is then interpolated linearly) for the
        output times in the last step; output times within rounding past the last state
        take it."""
        if self.t_eval is None and not self.last_kept:
            self._keep([self.last[0]], self.last[1][None, :], np.array([0]))
            self.last_kept = True
        elif self.t_eval is not None and self.next_eval < len(self.t_eval):
            T, Y, F = self.nodes
            lo = self.t_eval[self.next_eval:]
            if len(T) > 1:
                if np.any((lo > T[0]) & (lo < T[-1])):
                    f = derivative(T[-1], Y[-1])
                    if f is None:           # not finite there: linear (secant slopes)
                        f = (Y[-1] - Y[-2]) / (T[-1] - T[-2])
                        F = np.vstack([f, f])
                    else:
                        F = np.vstack([F, f])
                self._interpolate(T, Y, F, T[-1])
            lo = self.t_eval[self.next_eval:]
            tail = lo[lo <= T[-1] + 1e-12 * max(1.0, abs(T[-1]))]
            self._take(tail, np.repeat(Y[-1:], tail.size, axis=0))
            self.nodes = (T[-1:], Y[-1:], None)
        if not self.times:
            return np.empty(0), np.empty((0, self.last[1].size))
        return np.concatenate(self.times), np.vstack(self.states)

"""The samples a fixed-step run keeps, gathered stretch by stretch: every ``decimate``-th
step and the last one, or the states interpolated at the output times.
"""
from __future__ import annotations


import numpy as np



class Samples:
    """The samples a fixed-step run keeps, gathered stretch by stretch (arrays, not rows):
    every ``every``-th step and the last one, or the states interpolated at ``t_eval``
    (linearly between the steps that bracket each time)."""

    def __init__(self, t0, y0, every=1, t_eval=None):
        self.every = every
        self.t_eval = None if t_eval is None else np.asarray(t_eval, dtype=float)
        self.next_eval = 0
        self.times, self.states = [], []
        self.count = 0                  # samples kept
        self.step = 0                   # steps seen
        self.last = (t0, y0)            # the newest state, kept or not
        self.last_kept = False
        self._add([t0], y0[None, :], first=True)

    def _add(self, ts, ys, first=False):
        ts = np.asarray(ts, dtype=float)
        if self.t_eval is not None:
            t_prev, y_prev = self.last
            lo = self.t_eval[self.next_eval:]
            sel = lo[lo <= ts[-1]] if len(ts) else lo[:0]
            if first:
                sel = lo[lo <= ts[0]]
            if sel.size:
                tt = np.concatenate([[t_prev], ts]) if not first else ts
                yy = np.vstack([y_prev[None, :], ys]) if not first else ys
                self.times.append(sel)
                self.states.append(np.column_stack([np.interp(sel, tt, yy[:, c])
                                                    for c in range(yy.shape[1])]))
                self.next_eval += sel.size
                self.count += sel.size
        else:
            if first:
                keep = np.array([0])
            else:
                index = self.step + 1 + np.arange(len(ts))
                keep = np.flatnonzero(index % self.every == 0)
            if keep.size:
                self.times.append(ts[keep])
                self.states.append(np.asarray(ys)[keep])
                self.count += keep.size
            self.last_kept = bool(len(ts)) and (first or keep.size and keep[-1] == len(ts) - 1)
        if len(ts):
            if not first:
                self.step += len(ts)
            self.last = (ts[-1], np.array(ys[-1], dtype=float))

    def add(self, ts, ys):
        if len(ts):
            self._add(ts, ys)

    def arrays(self):
        """``(t, y)`` of the kept samples; the last state is always among them (without
        ``t_eval``)."""
        if self.t_eval is None and not self.last_kept:
            self.times.append(np.array([self.last[0]]))
            self.states.append(self.last[1][None, :])
            self.last_kept = True
        if not self.times:
            return np.empty(0), np.empty((0, self.last[1].size))
        return np.concatenate(self.times), np.vstack(self.states)

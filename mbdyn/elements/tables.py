"""Tables of force elements: ``y(x)`` through strictly increasing knots, interpolated
monotonically -- ``"pchip"`` (piecewise-cubic Hermite that keeps monotone data monotone;
the default) or ``"linear"``; never a smoothing spline.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

INTERPOLATIONS = ("pchip", "linear")


@dataclass(frozen=True)
class Table:
    """A monotone interpolation table ``y(x)``: strictly increasing knots ``x``."""
    x: np.ndarray
    y: np.ndarray
    interpolation: str = "pchip"
    clamp: bool = False           # hold the end values outside the knots (else extrapolate)

    def block(self):
        """The kernel's table block ``[n, clamp, x, y, slopes, integral]`` (see
        ``kernels.forces``)."""
        x, y = self.x, self.y
        n = len(x)
        h = np.diff(x)
        secant = np.diff(y) / h
        if self.interpolation == "pchip" and n > 2:
            from scipy.interpolate import PchipInterpolator
            d = PchipInterpolator(x, y).derivative()(x)
        else:
            d = np.empty(n)
            d[:-1] = secant
            d[-1] = secant[-1]
            if self.interpolation == "pchip":          # two knots: the line through them
                d[:] = secant[0]
        integral = np.zeros(n)
        for k in range(n - 1):                         # exact integral of each segment
            if self.interpolation == "linear":
                seg = h[k] * 0.5 * (y[k] + y[k + 1])
            else:
                seg = h[k] * (0.5 * (y[k] + y[k + 1]) + h[k] * (d[k] - d[k + 1]) / 12.0)
            integral[k + 1] = integral[k] + seg
        return np.concatenate([[n, 1.0 if self.clamp else 0.0], x, y, d, integral])

    @property
    def mode(self):
        return 1 if self.interpolation == "linear" else 2

    def __call__(self, x):
        """The interpolant at ``x`` (numpy; for reports and tests)."""
        from ..kernels.tables import table_eval
        blk = self.block()
        out = np.empty(3)
        table_eval(blk, 0, self.mode, float(x), out)
        return float(out[0])


def make_table(value, element, what, interpolation="pchip", clamp=False):
    """A ``Table`` from ``[[x0, y0], [x1, y1], ...]`` or ``{"x": [...], "y": [...]}`` or a
    pair of sequences ``(xs, ys)``; refuses unsorted or repeated knots, mismatched lengths,
    fewer than two points and non-finite values, naming the element and key."""
    if interpolation not in INTERPOLATIONS:
        raise ModelError(f"{element}: interpolation {interpolation!r} is not one of "
                         f"{', '.join(INTERPOLATIONS)} (tables are interpolated monotonically; "
                         "a smoothing spline would overshoot)")
    if isinstance(value, dict):
        if set(value) != {"x", "y"}:
            raise ModelError(f"{element}: {what} must have keys 'x' and 'y', got "
                             f"{sorted(value)}")
        xs, ys = value["x"], value["y"]
    elif (isinstance(value, (tuple, list)) and len(value) == 2
          and all(isinstance(v, (tuple, list, np.ndarray)) for v in value)
          and not all(len(v) == 2 for v in value)):
        xs, ys = value
    else:
        try:
            pairs = [tuple(p) for p in value]
        except TypeError:
            raise ModelError(f"{element}: {what} must be a list of [x, y] pairs") from None
        if any(len(p) != 2 for p in pairs):
            raise ModelError(f"{element}: {what} must be a list of [x, y] pairs")
        xs, ys = [p[0] for p in pairs], [p[1] for p in pairs]
    try:
        x = np.asarray(xs, dtype=float).reshape(-1)
        y = np.asarray(ys, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {what} must hold numbers") from None
    if x.size != y.size:
        raise ModelError(f"{element}: {what} has {x.size} abscissae but {y.size} values; "
                         "give one value per abscissa")
    if x.size < 2:
        raise ModelError(f"{element}: {what} needs at least two points")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ModelError(f"{element}: {what} holds non-finite numbers")
    if np.any(np.diff(x) <= 0):
        k = int(np.argmax(np.diff(x) <= 0))
        raise ModelError(f"{element}: {what} is not monotone: its abscissae must increase "
                         f"strictly, but {x[k]:g} is followed by {x[k + 1]:g}; sort the rows "
                         "and remove repeated abscissae")
    return Table(x, y, interpolation, clamp)

"""Monotone interpolation tables in compiled code: a force element's law, a bearing's
coefficients, an actuator's setpoint or torque-speed curve.

A table block in a float array is ``[n, clamp, x(n), y(n), d(n), integral(n)]``: knots,
values, slopes at the knots (piecewise-cubic Hermite, as PCHIP gives them; for linear
interpolation only the end slopes are used, for extrapolation) and the integral of the
interpolant from the first knot to each knot.  Outside the knots a table extrapolates
linearly with its end slope, or holds its end value (``clamp``).
"""
from numba import njit

from .views import UNCOUNTED

NO_TABLE, LINEAR, PCHIP = 0, 1, 2


@njit(**UNCOUNTED)
def table_eval(data, off, mode, x, out):
    """Interpolated value, slope and integral (from the first knot) at ``x`` into
    ``out[0:3]``."""
    n = int(data[off])
    clamp = data[off + 1] != 0.0
    X = off + 2
    Y = X + n
    D = Y + n
    I = D + n
    x0, xn = data[X], data[X + n - 1]
    if x <= x0 or x >= xn:
        k = 0 if x <= x0 else n - 1
        y, d = data[Y + k], data[D + k]
        if clamp:
            d = 0.0
        dx = x - data[X + k]
        out[0] = y + d * dx
        out[1] = d
        out[2] = data[I + k] + y * dx + 0.5 * d * dx * dx
        return
    lo, hi = 0, n - 1
    while hi - lo > 1:                  # bisection for x_lo <= x < x_hi
        mid = (lo + hi) // 2
        if data[X + mid] <= x:
            lo = mid
        else:
            hi = mid
    h = data[X + hi] - data[X + lo]
    s = (x - data[X + lo]) / h
    y0, y1 = data[Y + lo], data[Y + hi]
    if mode == LINEAR:
        out[0] = y0 + s * (y1 - y0)
        out[1] = (y1 - y0) / h
        out[2] = data[I + lo] + h * (y0 * s + 0.5 * (y1 - y0) * s * s)
        return
    d0, d1 = data[D + lo] * h, data[D + hi] * h
    s2, s3 = s * s, s * s * s
    out[0] = (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * d0 + (-2 * s3 + 3 * s2) * y1 \
        + (s3 - s2) * d1
    out[1] = ((6 * s2 - 6 * s) * y0 + (3 * s2 - 4 * s + 1) * d0 + (-6 * s2 + 6 * s) * y1
              + (3 * s2 - 2 * s) * d1) / h
    s4 = s2 * s2
    out[2] = data[I + lo] + h * ((0.5 * s4 - s3 + s) * y0 + (0.25 * s4 - 2 * s3 / 3 + 0.5 * s2) * d0
                                 + (-0.5 * s4 + s3) * y1 + (0.25 * s4 - s3 / 3) * d1)

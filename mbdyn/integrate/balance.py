"""The energy balance of a motion: what is stored, what was dissipated, what was put in.

``T + V + dissipated - work`` is constant along an exact motion, where ``V`` is the
gravitational potential plus the energy stored in springs and contacts, ``dissipated``
what dampers, friction, bushings and bearings took out (``-`` the time integral of their
non-conservative power) and ``work`` what loads, drives and actuators put in (the time
integral of their power).  The two integrals are taken over the stored samples by Simpson's rule, so
the balance's drift includes that quadrature error as well as the integrator's: store
samples densely (``t_eval``, ``output_dt``) for a tight check.
"""
from __future__ import annotations

import numpy as np


def _cumulative(t, p):
    """Running integral of the samples ``p(t)``: Simpson's rule for three samples or more
    at increasing times, else the trapezoidal rule."""
    if len(t) < 2:
        return np.zeros(len(t))
    if len(t) >= 3 and np.all(np.diff(t) > 0):
        return cumulative_simpson(np.asarray(p, dtype=float), np.asarray(t, dtype=float))
    from scipy.integrate import cumulative_trapezoid
    return cumulative_trapezoid(p, x=t, initial=0.0)


def _simpson_pieces(dx, y):
    """The integral over each first interval ``[x_k, x_k+1]`` of the parabola through the
    samples ``k, k+1, k+2`` (Cartwright's formula (8) for unequal intervals ``dx``)."""
    x21 = dx[:-1]
    x32 = dx[1:]
    x31 = x21 + x32
    x21_x31 = x21 / x31
    x21_x32 = x21 / x32
    x21x21_x31x32 = x21_x31 * x21_x32
    coeff1 = 3 - x21_x31
    coeff2 = 3 + x21x21_x31x32 + x21_x31
    coeff3 = -x21x21_x31x32
    return x21 / 6 * (coeff1 * y[:-2] + coeff2 * y[1:-1] + coeff3 * y[2:])


def cumulative_simpson(y, x):
    """``integral of y from x[0] to x[k]`` for every k (``len(x) >= 3``, increasing): each
    interval by the parabola through it and its right neighbour, the last one through
    its left neighbour.  The same operations as ``scipy.integrate.cumulative_simpson(y,
    x=x, initial=0)`` (the same numbers, bit for bit; tests/test_balance.py), without
    importing scipy.integrate (a fifth of a second of a run's start)."""
    dx = np.diff(x)
    first = _simpson_pieces(dx, y)                        # [x_k, x_k+1] from k, k+1, k+2
    second = _simpson_pieces(dx[::-1], y[::-1])[::-1]     # [x_k+1, x_k+2] from k, k+1, k+2
    pieces = np.empty(len(dx))
    pieces[:-1:2] = first[::2]
    pieces[1::2] = second[::2]
    pieces[-1] = second[-1]
    out = np.empty(len(y))
    out[0] = 0.0
    out[1:] = np.cumsum(pieces) + 0.0
    return out


def energy_balance(model, t, q, u):
    """``{"kinetic", "potential", "total", "dissipated", "work", "balance"}``, arrays over
    the samples ``t`` (states ``q``, ``u`` row by row)."""
    n = len(t)
    T = np.empty(n)
    V = np.empty(n)
    P_nc = np.zeros(n)
    P_in = np.zeros(n)
    drives = [(name, drive) for name, _, _, drive in model._driven]
    flexible = getattr(model, "flexible_bodies", ())   # modal damping, stiffening's power
    for k in range(n):
        T[k], V[k] = model.energy(q[k], u[k], t[k])
        if model.forces or flexible:
            v_el, P_nc[k], P_act = model.element_power(q[k], u[k], t[k])
            V[k] += v_el
            P_in[k] += P_act
        if model.loads:
            P_in[k] += model.load_power(q[k], u[k], t[k])
        if drives:
            efforts = model.drive_efforts(q[k], u[k], t[k])
            for name, drive in drives:
                P_in[k] += efforts[name] * drive.velocity(t[k])
    dissipated = -_cumulative(t, P_nc)
    work = _cumulative(t, P_in)
    total = T + V
    return {"kinetic": T, "potential": V, "total": total, "dissipated": dissipated,
            "work": work, "balance": total + dissipated - work}

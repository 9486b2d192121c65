"""The energy balance of a motion: what is stored, what was dissipated, what was put in.

``T + V + dissipated - work`` is constant along an exact motion, where ``V`` is the
gravitational potential plus the energy stored in springs and contacts, ``dissipated``
what dampers, friction, bushings and bearings took out (``-`` the time integral of their
non-conservative power) and ``work`` what loads and drives put in (the time integral of
their power).  The two integrals are taken over the stored samples by Simpson's rule, so
the balance's drift includes that quadrature error as well as the integrator's: store
samples densely (``t_eval``, ``output_dt``) for a tight check.
"""
from __future__ import annotations

import numpy as np


def _cumulative(t, p):
    """Running integral of the samples ``p(t)`` (Simpson where scipy has it)."""
    if len(t) < 2:
        return np.zeros(len(t))
    try:
        from scipy.integrate import cumulative_simpson
        if len(t) >= 3 and np.all(np.diff(t) > 0):
            return cumulative_simpson(p, x=t, initial=0.0)
    except ImportError:                  # scipy < 1.12
        pass
    from scipy.integrate import cumulative_trapezoid
    return cumulative_trapezoid(p, x=t, initial=0.0)


def energy_balance(model, t, q, u):
    """``{"kinetic", "potential", "total", "dissipated", "work", "balance"}``, arrays over
    the samples ``t`` (states ``q``, ``u`` row by row)."""
    n = len(t)
    T = np.empty(n)
    V = np.empty(n)
    P_nc = np.zeros(n)
    P_in = np.zeros(n)
    drives = [(name, drive) for name, _, _, drive in model._driven]
    for k in range(n):
        T[k], V[k] = model.energy(q[k], u[k], t[k])
        if model.forces:
            v_el, P_nc[k] = model.element_energy(q[k], u[k], t[k])
            V[k] += v_el
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

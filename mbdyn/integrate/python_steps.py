"""One step of a fixed-step scheme in Python (models whose loads are Python functions, or
``compiled_loop=False``): explicit and semi-implicit Euler, RK4, the implicit midpoint
rule by Newton with a finite-difference Jacobian.
"""
from __future__ import annotations


import numpy as np

from ..errors import (NonFiniteError)


def fixed_step(rhs, integrator, t, y, h, nq):
    """One step of a fixed-step scheme in Python (models with callable loads): ``(the
    state after it, y' at its start)`` (the latter for the dense output, ``samples``)."""
    model = rhs.model
    if integrator == "euler":
        f0 = rhs(t, y)
        return y + h * f0, f0
    if integrator == "semi-implicit-euler":
        q, u = y[:nq], y[nq:]
        rhs.evaluations += 1
        ud = rhs.accelerations(q, u, t)
        u_new = u + h * ud
        q_new = q + h * model.coordinate_rates(q, u_new)
        return np.concatenate([q_new, u_new]), np.concatenate([model.coordinate_rates(q, u),
                                                               ud])
    if integrator == "implicit-midpoint":
        f0 = rhs(t, y)
        return implicit_midpoint(rhs, t, y, h, f0), f0
    k1 = rhs(t, y)
    k2 = rhs(t + h / 2, y + h / 2 * k1)
    k3 = rhs(t + h / 2, y + h / 2 * k2)
    k4 = rhs(t + h, y + h * k3)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), k1


def implicit_midpoint(rhs, t, y, h, f0):
    """``y1 = y + h F(t + h/2, (y + y1)/2)`` by Newton with a finite-difference Jacobian
    (the same algorithm as the compiled ``implicit_midpoint_step``); ``f0 = F(t, y)``."""
    tm = t + h / 2
    ym = y + h / 2 * f0
    fm = rhs(tm, ym)
    y1 = y + h * fm
    n = y.size
    J = np.eye(n)
    for j in range(n):
        eps = 1.4901161193847656e-08 * max(1.0, abs(ym[j]))
        yp = ym.copy()
        yp[j] += eps
        J[:, j] -= 0.5 * h * (rhs(tm, yp) - fm) / eps
    for _ in range(30):
        G = y1 - y - h * rhs(tm, 0.5 * (y + y1))
        dy = np.linalg.solve(J, G)
        y1 = y1 - dy
        if np.abs(dy).max() <= 1e-14 * max(1.0, np.abs(y1).max()):
            return y1
    raise NonFiniteError("the implicit midpoint's Newton iteration did not converge; "
                         "reduce dt")

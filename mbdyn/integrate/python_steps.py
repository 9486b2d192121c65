"""One step of a fixed-step scheme in Python (models whose loads are Python functions, or
``compiled_loop=False``): explicit and semi-implicit Euler, RK4, the implicit midpoint
rule by the compiled loop's quasi-Newton iteration (``kernels.implicit_midpoint``).
"""
from __future__ import annotations


import numpy as np

from ..errors import (NonFiniteError)


def fixed_step(rhs, integrator, t, y, h, nq, memory=None):
    """One step of a fixed-step scheme in Python (models with callable loads): ``(the
    state after it, y' at its start)`` (the latter for the dense output, ``samples``).
    ``memory``: a dict the caller keeps over a run's steps of one size (the implicit
    midpoint rule's iteration matrix and last states; none kept when ``None``)."""
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
        return implicit_midpoint(rhs, t, y, h, f0, {} if memory is None else memory), f0
    k1 = rhs(t, y)
    k2 = rhs(t + h / 2, y + h / 2 * k1)
    k3 = rhs(t + h / 2, y + h / 2 * k2)
    k4 = rhs(t + h, y + h * k3)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), k1


def implicit_midpoint(rhs, t, y, h, f0, memory):
    """``y1 = y + h F(t + h/2, (y + y1)/2)`` by the quasi-Newton iteration of the compiled
    loop (``kernels.implicit_midpoint``: the same predictor, Broyden updates, refresh rule
    and tolerance); ``f0 = F(t, y)``; ``memory``: what the last step left (updated)."""
    from ..kernels.implicit_midpoint import (FRESH_ITERATIONS, NEWTON_TOL, REFRESH_RATE,
                                             STALE_ITERATIONS)
    tm = t + h / 2
    last = memory.setdefault("last", [])
    H = memory.get("H")
    if H is not None and len(last) == 2:
        pred = 3.0 * (y - last[1]) + last[0]
    else:
        pred = y + h * rhs(tm, y + h / 2 * f0)
    last[:] = [last[-1], y.copy()] if last else [y.copy()]
    y1, fresh, g_old, step = pred.copy(), H is None, None, None
    prev, left = -1.0, FRESH_ITERATIONS if fresh else STALE_ITERATIONS
    while left > 0:
        ym = 0.5 * (y + y1)
        fm = rhs(tm, ym)
        if H is None:
            H = memory["H"] = _midpoint_inverse(rhs, tm, ym, fm, h)
            fresh, g_old, prev, left = True, None, -1.0, FRESH_ITERATIONS
        g = y1 - y - h * fm
        if g_old is not None:
            a, b = H @ (g - g_old), H.T @ step
            den = step @ a
            if den != 0.0 and np.isfinite(den):
                H += np.outer((step - a) / den, b)
        step, g_old = -(H @ g), g
        y1 = y1 + step
        size = np.abs(step).max()
        if size <= NEWTON_TOL * max(1.0, np.abs(y1).max()):
            return y1
        if prev > 0.0 and size / prev > REFRESH_RATE and not fresh:
            H = None
            if size >= prev:
                y1 = pred.copy()
            continue
        prev, left = size, left - 1
        if left == 0 and not fresh:
            H, left = None, 1
    raise NonFiniteError("the implicit midpoint's Newton iteration did not converge; "
                         "reduce dt")


def _midpoint_inverse(rhs, tm, ym, fm, h):
    """``(I - h/2 dF/dy)^-1`` at ``ym`` (``fm = F(tm, ym)``), the derivative by forward
    differences as in the compiled loop."""
    n = ym.size
    J = np.eye(n)
    for j in range(n):
        eps = 1.4901161193847656e-08 * max(1.0, abs(ym[j]))
        yp = ym.copy()
        yp[j] += eps
        J[:, j] -= 0.5 * h * (rhs(tm, yp) - fm) / eps
    try:
        return np.linalg.inv(J)
    except np.linalg.LinAlgError:
        raise NonFiniteError("the implicit midpoint's Newton matrix is singular; "
                             "reduce dt") from None

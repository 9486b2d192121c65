"""Dynamic relaxation: a stable static equilibrium found by letting the model settle.

Where Newton-Raphson cannot start -- at a guess where the Jacobian of the generalized forces
is singular, such as an arm held horizontal, whose gravity torque has no stiffness there --
the model's own motion finds the rest position: ``q' = N(q) u``, ``u' = a(q, u) - c u``
from the guess at rest, ``a`` the model's accelerations and ``c`` an added damping of about
twice the model's slowest frequency estimated at the guess (``sqrt(max |f_i| / M_ii)``),
until the speeds and accelerations are small.  The added damping changes the path, not
the rest position (``u = 0``, ``a = 0`` there), so the configuration it reaches is an
equilibrium of the model itself -- a stable one -- which Newton-Raphson then polishes.
"""
from __future__ import annotations

import numpy as np

#: how many of the estimated slowest periods the relaxation may take
PERIODS = 60.0


def relax(model, q0, t=0.0):
    """The configuration the model settles in from ``q0`` at rest with added damping, or
    ``None`` when it does not settle (an unstable or moving model)."""
    from scipy.integrate import solve_ivp
    u0 = np.zeros(model.nu)
    f = np.abs(model.forcing(q0, u0, t))
    m = np.abs(np.diag(model.mass_matrix(q0, t)))
    omega = float(np.sqrt(max(np.max(f / np.maximum(m, 1e-300)), 1e-6)))
    c = 2.0 * omega
    nq = model.nq

    def rhs(_, y):
        q, u = y[:nq], y[nq:]
        out = np.empty_like(y)
        out[:nq] = model.coordinate_rates(q, u)
        out[nq:] = model.forward_dynamics(q, u, t) - c * u
        return out

    def settled(_, y):
        u = y[nq:]
        a = model.forward_dynamics(y[:nq], u, t)
        return max(np.abs(u).max() * omega, np.abs(a).max()) - 1e-9 * omega ** 2
    settled.terminal = True
    span = PERIODS * 2 * np.pi / omega
    try:
        sol = solve_ivp(rhs, (0.0, span), np.concatenate([q0, u0]), method="LSODA",
                        rtol=1e-8, atol=1e-10, events=settled)
    except (ValueError, FloatingPointError, np.linalg.LinAlgError):
        return None
    if not sol.success or not np.all(np.isfinite(sol.y[:, -1])):
        return None
    q = sol.y[:nq, -1].copy()
    model.normalize_quaternions(q)
    return q

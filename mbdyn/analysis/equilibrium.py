"""Equilibria by Newton-Raphson: static (``u = 0``) and steady (relative) ones.

An equilibrium is a configuration ``q`` where the generalized forces of the Jourdain form
vanish at the given speeds, ``f(q, u, t) = 0``, so that ``u' = 0``: with ``u = 0`` a static
equilibrium; with the spin speeds of cyclic coordinates held (``u`` given, their
coordinates in ``fixed``) a steady motion; with drives turning at constant rates, a
relative equilibrium in the drives' moving frame -- exact when the equations do not depend
on time there (the textbook's rotating pendulum with its disk at rest on the arm, or with
the disk on the arm's axis), an instantaneous one otherwise (``time_dependent`` says so).

Newton-Raphson on the tangent coordinates (``analysis.tangent``) with the model's own
Jacobian ``df/dq`` (central differences of the compiled model), a backtracking line
search on ``|f|``, and ``scipy.optimize.root`` as the fallback.  A failure is an
``EquilibriumError`` carrying the last iterate; the result reports the residual, the
iterations and the Jacobian's condition number.

A closed mechanism (loop joints) rests on its constraints: the guess is first moved onto
them (``Model.project``), and the unknowns are its independent coordinates
(``analysis.reduction``), the dependent ones solved from the constraints at every
evaluation.  The equations are the reduced ones, ``S^T M S w' = 0`` with ``w'`` the
independent part of the constrained accelerations (``M u' = f + G^T lam``, ``G u' =
gamma``): at rest ``S^T f = 0``, the generalized forces projected on the motions the loops
allow.  The speeds of the independent coordinates are the given ones (zero at rest), the
dependent speeds follow from the constraints.  After each Newton step the chart is centred
again on the new configuration, the partition kept (chosen again by pivoted QR only where
it has become ill-conditioned), so a far equilibrium does not strain it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from . import arguments
from .tangent import Tangent


class EquilibriumError(ModelError):
    """No equilibrium was found; ``last`` holds the last iterate's coordinates."""

    def __init__(self, message, last=None, residual=None):
        super().__init__(message)
        self.last = last
        self.residual = residual


@dataclass
class Equilibrium:
    """``q``, ``u`` and ``t`` of an equilibrium, with how it was found."""
    model: object
    q: np.ndarray
    u: np.ndarray
    t: float
    residual: float
    iterations: int
    condition: float
    method: str
    time_dependent: bool = False
    #: closed loops: the independent coordinates the equations were solved in
    independent: tuple = ()

    def to_dict(self):
        m = self.model
        return {"q": dict(zip(m.coordinates, self.q.tolist())),
                "u": dict(zip(m.speeds, self.u.tolist())), "t": self.t,
                "residual": self.residual, "iterations": self.iterations,
                "condition": self.condition, "method": self.method,
                "time_dependent": self.time_dependent,
                **({"independent": list(self.independent)} if self.independent else {})}


def _unknowns(model, tangent, fixed):
    """Tangent indices that move: all but those of the ``fixed`` coordinates/joints."""
    fixed = [fixed] if isinstance(fixed, str) else list(fixed or ())
    known = set(tangent.names) | set(model.coordinates) | set(model.joints)
    for name in fixed:
        if name not in known:
            raise ModelError(f"equilibrium: unknown coordinate {name!r} to hold fixed; the "
                             f"coordinates are {', '.join(tangent.names)}")
    held = {k for k, nm in enumerate(tangent.names)
            if nm in fixed or model._speed_joint[k] in fixed}
    return [k for k in range(tangent.n) if k not in held]


class _Equations:
    """The equations left free, ``f(q, u, t)[free] = 0``, as functions of the free tangent
    coordinates ``x`` about the guess: their residual, Jacobian and configuration."""

    def __init__(self, model, tangent, free, u, t):
        self.model, self.tangent, self.free, self.u, self.t = model, tangent, free, u, t

    def residual(self, x_free):
        return self.model.forcing(self.configuration(x_free), self.u, self.t)[self.free]

    def jacobian(self, x_free):
        """Central differences of the residual."""
        h = np.cbrt(np.finfo(float).eps)
        n = len(self.free)
        J = np.empty((n, n))
        for j in range(n):
            e = np.zeros(n)
            e[j] = h
            J[:, j] = (self.residual(x_free + e) - self.residual(x_free - e)) / (2 * h)
        return J

    def configuration(self, x_free):
        """The coordinates ``q`` at the free tangent coordinates ``x_free``."""
        x = np.zeros(self.tangent.n)
        x[self.free] = x_free
        return self.tangent.retract(x)


def equilibrium(model, q_guess=None, u=None, t=0.0, fixed=(), tol=1e-10, max_iter=50):
    """An equilibrium of ``model`` near ``q_guess`` (array or ``{name: value}``; default
    the zero configuration) at speeds ``u`` (default zero) and time ``t``.

    ``fixed``: coordinates (or joints) held at their guessed values, e.g. the cyclic spin
    angle of a rotor; their equations are left out too.  ``tol``: on the residual
    ``|f|`` relative to the size of the forces at the guess.
    """
    model, q0, u, t, tol, max_iter, fixed = _checked(model, q_guess, u, t, fixed, tol,
                                                     max_iter)
    if model.has_loops:
        return _loop_equilibrium(model, q0, u, t, fixed, tol, max_iter)
    tangent = Tangent(model, q0)
    free = _unknowns(model, tangent, fixed)
    if not free:
        raise ModelError("equilibrium: every coordinate is held fixed; nothing to solve")
    eqs = _Equations(model, tangent, free, u, t)
    x = np.zeros(len(free))
    r = eqs.residual(x)
    scale = _force_scale(model, q0, u, t, r)
    x, r, iterations, cond = _newton(eqs, x, r, tol, scale, max_iter)
    method = "newton"
    if np.abs(r).max() > tol * scale:
        method = "scipy.optimize.root (hybr)"
        try:
            x, r, iterations, cond = _fallback(eqs, x, r, tol, scale, iterations)
        except EquilibriumError:
            if fixed or np.any(u):
                raise
            eqs, x, r, iterations, cond = _relaxed(model, q0, t, tol, scale, max_iter)
            method = "dynamic relaxation, then newton"
    q = eqs.configuration(x)
    model.normalize_quaternions(q)
    _warn_if_singular(model, q)
    # the equations at other times: do they still vanish (a relative equilibrium)?
    later = [model.forcing(q, u, t + dt)[free] for dt in (0.37, 1.3, 4.1)]
    time_dependent = bool(max(np.abs(f).max() for f in later) > 1e3 * tol * scale)
    return Equilibrium(model, q, u, float(t), float(np.abs(r).max()), iterations, cond,
                       method, time_dependent)


class _LoopEquations(_Equations):
    """A closed mechanism's reduced equations ``(S^T M S w')[free] = 0`` as functions of
    the free independent tangent coordinates about ``red.q0`` (``red``: a
    ``reduction.Reduction``; ``free``: positions in ``red.independent``; ``w``: the
    independent speeds)."""

    def __init__(self, model, red, free, w, t):
        super().__init__(model, red.tangent, free, w, t)
        self.red = red

    def residual(self, x_free):
        q = self.configuration(x_free)
        if q is None:                   # the loops do not close there: a failed trial
            return np.full(len(self.free), np.nan)
        return self.at(q)

    def at(self, q):
        red, model = self.red, self.model
        u = red.speeds(q, self.u)
        ud = model.forward_dynamics(q, u, self.t)[red.independent]
        S = red.velocity_map(q)
        return (S.T @ model.mass_matrix(q, self.t) @ S @ ud)[self.free]

    def configuration(self, x_free):
        z = np.zeros(self.red.n)
        z[self.free] = x_free
        return self.red.configuration(z)


def _loop_equations(model, q, u, t, held, before=None):
    """The ``_LoopEquations`` about ``q`` (on the constraints): the partition of the
    equations ``before``, unless it has become ill-conditioned at ``q`` (or there are none
    before), then one chosen by pivoted QR with the ``held`` speeds independent; ``u``: the
    speeds (its independent part is kept)."""
    from .reduction import REPARTITION_BELOW, Reduction
    red = None if before is None else Reduction(model, q, t, dependent=before.red.dependent)
    if red is None or red.condition < REPARTITION_BELOW:
        red = Reduction(model, q, t, held=held)
    if red.n == 0:
        raise ModelError(f"equilibrium: model {model.name!r} has no degrees of freedom: "
                         "its loops and drives fix every coordinate")
    free = [k for k, i in enumerate(red.independent) if i not in set(held)]
    if not free:
        raise ModelError("equilibrium: every independent coordinate of the closed "
                         "mechanism is held fixed; nothing to solve")
    return _LoopEquations(model, red, free, u[red.independent], t)


def _loop_equilibrium(model, q0, u, t, fixed, tol, max_iter):
    """``equilibrium`` of a closed mechanism: Newton-Raphson on its reduced equations,
    the chart centred again after each step (the module's docstring)."""
    q0, u = model.project(q0, u, t)
    tangent = Tangent(model, q0)
    free = set(_unknowns(model, tangent, fixed))
    held = [k for k in range(tangent.n) if k not in free]
    eqs = _loop_equations(model, q0, u, t, held)
    r = eqs.residual(np.zeros(len(eqs.free)))
    scale = _force_scale(model, q0, u, t, r)
    iterations, cond = 0, np.inf
    while np.abs(r).max() > tol * scale and iterations < max_iter:
        x, r, steps, cond = _newton(eqs, np.zeros(len(eqs.free)), r, tol, scale, 1)
        iterations += steps
        if not np.any(x) or steps == 0:
            break                                  # no step lowered |f|
        q = eqs.configuration(x)
        eqs = _loop_equations(model, q, eqs.red.speeds(q, eqs.u), t, held, eqs)
        r = eqs.residual(np.zeros(len(eqs.free)))
    x, method = np.zeros(len(eqs.free)), "newton"
    if np.abs(r).max() > tol * scale:
        method = "scipy.optimize.root (hybr)"
        x, r, iterations, cond = _fallback(eqs, x, r, tol, scale, iterations)
    q = eqs.configuration(x)
    _warn_if_singular(model, q)
    later = []
    for dt in (0.37, 1.3, 4.1):
        eqs_t = _loop_equations(model, q, eqs.red.speeds(q, eqs.u), t + dt, held, eqs)
        later.append(eqs_t.residual(np.zeros(len(eqs_t.free))))
    time_dependent = bool(max(np.abs(f).max() for f in later) > 1e3 * tol * scale)
    return Equilibrium(model, q, eqs.red.speeds(q, eqs.u), float(t),
                       float(np.abs(r).max()), iterations, cond, method, time_dependent,
                       eqs.red.names)


def _checked(model, q_guess, u, t, fixed, tol, max_iter):
    """The arguments checked (in this order) and the guess as vectors, finite, its
    quaternions normalised."""
    where = "equilibrium"
    model = arguments.model(model, where)
    t = arguments.number(t, where, "t")
    tol = arguments.number(tol, where, "tol", positive=True)
    max_iter = arguments.count(max_iter, where, "max_iter")
    fixed = arguments.names(fixed, where, "fixed")
    q_guess = arguments.state(q_guess, where, "q_guess")
    u = arguments.state(u, where, "u")
    q0 = model.q_vector(dict(q_guess) if isinstance(q_guess, dict) else q_guess).copy()
    u = model.u_vector(dict(u) if isinstance(u, dict) else u).copy()
    if not (np.all(np.isfinite(q0)) and np.all(np.isfinite(u))):
        raise ModelError("equilibrium: the guess holds non-finite values")
    model.normalize_quaternions(q0)
    return model, q0, u, t, tol, max_iter, fixed


def _force_scale(model, q0, u, t, r):
    """The size of the forces at the guess, which ``tol`` is relative to; non-finite
    forces are refused."""
    scale = max(np.abs(r).max(), np.abs(model.forcing(q0, u, t)).max(),
                np.abs(np.diag(model.mass_matrix(q0, t))).max() * 9.81, 1e-300)
    if not (np.all(np.isfinite(r)) and np.isfinite(scale)):
        raise ModelError(f"equilibrium: the generalized forces of model {model.name!r} are "
                         f"not finite at the guess (t = {t:g}); check the speeds u and the "
                         "time t")
    return scale


def _newton(eqs, x, r, tol, scale, max_iter):
    """Newton-Raphson with a backtracking line search on ``|f|``, from ``x`` (residual
    ``r``); stops where a step no longer lowers ``|f|``.  Returns ``x``, its residual, the
    iterations and the last Jacobian's condition number."""
    iterations, cond = 0, np.inf
    while np.abs(r).max() > tol * scale and iterations < max_iter:
        iterations += 1
        J = eqs.jacobian(x)
        cond = float(np.linalg.cond(J))
        try:
            dx = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            break
        lam = _step_length(eqs, x, dx, np.linalg.norm(r))
        if lam <= 1e-6:
            break
        x = x + lam * dx
        r = eqs.residual(x)
    return x, r, iterations, cond


def _step_length(eqs, x, dx, norm0):
    """The backtracking line search on ``|f|``: the first of 1, 1/2, 1/4 ... that lowers
    it enough (``<= 1e-6``: none did)."""
    lam = 1.0
    while lam > 1e-6:
        trial = eqs.residual(x + lam * dx)
        if np.all(np.isfinite(trial)) and np.linalg.norm(trial) < (1 - 1e-4 * lam) * norm0:
            break
        lam *= 0.5
    return lam


def _fallback(eqs, x, r, tol, scale, iterations):
    """``scipy.optimize.root`` from where Newton stopped (``x``, residual ``r``, after
    ``iterations``); an ``EquilibriumError`` with Newton's last iterate if it fails too."""
    from scipy.optimize import root
    sol = root(eqs.residual, x, method="hybr", options={"xtol": 1e-14})
    if np.all(np.isfinite(sol.x)) and np.abs(eqs.residual(sol.x)).max() <= tol * scale:
        x, r = sol.x, eqs.residual(sol.x)
        return x, r, iterations + int(sol.nfev), float(np.linalg.cond(eqs.jacobian(x)))
    raise EquilibriumError(
        f"model {eqs.model.name!r}: no equilibrium found from the guess (residual "
        f"{np.abs(r).max():.3g} after {iterations} Newton iterations and the "
        f"fallback); try another guess, hold cyclic coordinates fixed, or check "
        "that the model can rest (a spinning body needs its spin speed in u)",
        last=eqs.configuration(x), residual=float(np.abs(r).max()))


def _relaxed(model, q0, t, tol, scale, max_iter):
    """Newton-Raphson from where the model settles (``relaxation.relax``): a static
    equilibrium that Newton could not reach from the guess."""
    from .relaxation import relax
    q = relax(model, q0, t)
    if q is None:
        raise EquilibriumError(f"model {model.name!r}: no equilibrium found from the guess, "
                               "and the model does not settle from it either (Newton, "
                               "scipy's root and a damped relaxation failed); give a guess "
                               "near the rest position", last=q0)
    tangent = Tangent(model, q)
    eqs = _Equations(model, tangent, list(range(tangent.n)), np.zeros(model.nu), t)
    x = np.zeros(tangent.n)
    x, r, iterations, cond = _newton(eqs, x, eqs.residual(x), tol, scale, max_iter)
    if np.abs(r).max() > tol * scale:
        x, r, iterations, cond = _fallback(eqs, x, r, tol, scale, iterations)
    return eqs, x, r, iterations, cond


def _warn_if_singular(model, q):
    """A ``SingularityWarning`` (at the caller of ``equilibrium``) if ``q`` puts Euler
    angles at their singular configuration."""
    near = {j: d for j, d in model.euler_singularity(q).items() if d < 1e-6}
    if near:
        import warnings

        from ..errors import SingularityWarning
        warnings.warn(f"model {model.name!r}: the equilibrium found puts the Euler angles of "
                      f"{', '.join(near)} at their singular configuration; the angle rates and "
                      "the mass matrix are singular there -- try another guess, or a "
                      "spherical joint", SingularityWarning, stacklevel=3)

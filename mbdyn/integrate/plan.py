"""The one interface between ``simulate`` and the integrators: a ``Plan`` (what to
integrate, checked) goes in, an ``Outcome`` (the samples, the events found, the
statistics) comes out.  Each family of integrators is a module with a ``run(plan, ...)``:
``scipy_solvers`` (scipy's ``OdeSolver`` classes stepped from Python),
``compiled_adaptive`` (RK45 and DOP853 in compiled stretches), ``fixed_step`` (the
fixed-step schemes, compiled or in Python).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np


class RightHandSide:
    """``y = [q, u] -> [q', u']`` counting evaluations; NaN/Inf becomes an error."""

    def __init__(self, model, method):
        self.model = model
        self.method = method
        self.nq = model.nq
        self.evaluations = 0
        self.symbolic = None
        if method == "symbolic":        # generated from the closed-form equations
            from ..symbolic import compiled_rhs
            self.symbolic = compiled_rhs(model)

    def accelerations(self, q, u, t):
        if self.symbolic is not None:
            return self.symbolic.accelerations(q, u, t)
        return self.model.forward_dynamics(q, u, t, method=self.method)

    def __call__(self, t, y):
        self.evaluations += 1
        if self.symbolic is not None:
            return self.symbolic(t, y)  # a new array every call
        if self.method in ("jourdain", "articulated"):
            return self.model.state_derivative(t, y, self.method)   # a new array every call
        q = y[:self.nq]
        u = y[self.nq:]
        out = np.empty_like(y)      # a fresh array: scipy's solvers keep what they are given
        out[:self.nq] = self.model.coordinate_rates(q, u)
        out[self.nq:] = self.model.forward_dynamics(q, u, t, method=self.method)
        return out


@dataclass
class Plan:
    """A run as ``simulate`` checked it: the right-hand side, the integrator and its
    tolerances (``dt`` for the fixed-step schemes), the interval and initial state, the
    events, the output times (``None``: every accepted step), the progress callback, the
    singularity monitor (``monitor.Monitor``) and the budgets (``budget.make_budget``)."""
    rhs: RightHandSide
    integrator: str
    t0: float
    t_end: float
    y0: np.ndarray
    events: list
    t_eval: np.ndarray | None
    progress: Callable | None
    monitor: object
    budget: dict
    rtol: float = 1e-9
    atol: float = 1e-12
    max_step: float = np.inf
    dt: float | None = None

    @property
    def model(self):
        return self.rhs.model


class Outcome(NamedTuple):
    """What a route returns: sample times ``ts`` (n,), states ``ys`` (n, nq + nu), the
    ``EventRecord``s found, and ``info`` (its statistics; ``"failure"``: why it stopped
    early)."""
    ts: np.ndarray
    ys: np.ndarray
    found: list
    info: dict

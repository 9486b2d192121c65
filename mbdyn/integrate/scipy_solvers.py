"""scipy's ``OdeSolver`` classes (RK45, RK23, DOP853, Radau, BDF, LSODA) stepped from
Python one accepted step at a time: after each step the singularity monitor, the events
(crossings located by brentq on the solver's dense output), the output samples, the
budgets.  A failure keeps the results computed before it.
"""
from __future__ import annotations

import collections

import numpy as np
import scipy                # its submodules load on first use (scipy.integrate: 0.2 s)

from ..errors import NonFiniteError, SimulationError, SingularMassMatrixError
from . import budget as budgets
from .event_search import crossed, event_values
from .events import EventRecord
from .monitor import describe_failure
from .plan import Outcome
from .result import Result
from .settings import ADAPTIVE


def run(plan):
    """Integrate ``plan`` with its scipy solver; an ``Outcome``."""
    model = plan.model
    solver = _start(plan)
    samples = _Output(plan)
    g_old = event_values(plan.events, model, plan.t0, plan.y0) if plan.events else None
    found, steps, failure = [], 0, None
    recent = collections.deque(maxlen=budgets.PROJECTION_STEPS)
    project = model.has_loops and plan.integrator.removeprefix("scipy-") in EXPLICIT
    while solver.status == "running":
        t_prev, y_prev = solver.t, solver.y.copy()
        try:
            message = solver.step()
        except (NonFiniteError, SingularMassMatrixError) as exc:
            failure = describe_failure(model, exc, t_prev, y_prev)
            break
        if solver.status == "failed":
            failure = (f"integrator {plan.integrator} failed at t={solver.t:.6g}: {message}. "
                       "Loosen rtol/atol, or try an implicit method (Radau, BDF) if the "
                       "model is stiff")
            break
        steps += 1
        failure = plan.monitor.check(solver.t, solver.y)
        if failure:
            break
        if project:
            try:
                _project(solver, model)
            except (NonFiniteError, SingularMassMatrixError, SimulationError) as exc:
                failure = describe_failure(model, exc, solver.t, solver.y)
                break
        stop_at = None
        if plan.events:
            try:
                g_old, stop_at = _step_events(plan, solver, t_prev, g_old, found)
            except NonFiniteError as exc:
                failure = describe_failure(model, exc, solver.t, solver.y)
                break
        samples.add(solver, stop_at)
        if plan.progress is not None:
            plan.progress(samples.ts[-1] if samples.ts else solver.t)
        if stop_at is not None:
            break
        if solver.status == "running":
            recent.append(solver.t - t_prev)
            failure = _budget_failure(plan, steps, len(samples.ts), solver.t, t_prev, recent)
            if failure:
                break
    info = {"steps": steps, "njev": getattr(solver, "njev", 0),
            "nlu": getattr(solver, "nlu", 0), "solver_rhs_evaluations": solver.nfev,
            "compiled": False}
    if failure is not None:
        info["failure"] = failure
    ts, ys = samples.arrays(solver)
    return Outcome(ts, ys, found, info)


#: scipy's explicit Runge-Kutta pairs: one-step methods whose state is ``y`` and its
#: derivative ``f`` alone, so a projected ``y`` (and ``f`` evaluated there) starts the next
#: step as any other state would.  Radau and BDF (BDF is multistep) are not projected.
EXPLICIT = ("RK23", "RK45", "DOP853")


def _project(solver, model):
    """The accepted step's end put back onto a closed mechanism's constraints, as the
    compiled integrators do after every step (``Model.project``), and the derivative
    there, which the next step starts from (first-same-as-last)."""
    nq = model.nq
    q, u = model.project(solver.y[:nq], solver.y[nq:], solver.t)
    solver.y = np.concatenate([q, u])
    solver.f = solver.fun(solver.t, solver.y)


def _start(plan):
    """The scipy solver at ``t0``; a failure there is a ``SimulationError`` whose result
    holds the initial state."""
    model, y0 = plan.model, plan.y0
    try:
        return ADAPTIVE[plan.integrator](plan.rhs, plan.t0, y0, plan.t_end, rtol=plan.rtol,
                                         atol=plan.atol, max_step=plan.max_step)
    except (NonFiniteError, SingularMassMatrixError) as exc:
        raise SimulationError(describe_failure(model, exc, plan.t0, y0),
                              Result(model, [plan.t0], y0[None, :model.nq],
                                     y0[None, model.nq:], [], {})) from exc


def _step_events(plan, solver, t_prev, g_old, found):
    """The events of the step just taken: each crossing located by brentq on the dense
    output and appended to ``found`` in time order, up to a terminal one; returns the
    conditions at the step's end and the time of the terminal event (or ``None``)."""
    model, nq = plan.model, plan.model.nq
    t_new = solver.t
    g_new = event_values(plan.events, model, t_new, solver.y)
    dense = None
    hits = []
    for k, e in enumerate(plan.events):
        if crossed(e, g_old[k], g_new[k]):
            dense = dense or solver.dense_output()

            def g(tt, e=e):
                yy = dense(tt)
                return float(e.condition(tt, yy[:nq], yy[nq:]))
            te = scipy.optimize.brentq(g, t_prev, t_new, xtol=4 * np.finfo(float).eps,
                                       rtol=4 * np.finfo(float).eps)
            hits.append((te, e))
    stop_at = None
    for te, e in sorted(hits, key=lambda h: h[0]):
        if stop_at is not None:
            break
        ye = dense(te)
        found.append(EventRecord(e.name, te, ye[:nq], ye[nq:],
                                 model.coordinates + model.speeds))
        if e.terminal:
            stop_at = te
    return g_new, stop_at


def _budget_failure(plan, steps, stored, t_new, t_prev, recent):
    """A used-up budget after a step that did not end the run, or ``None``; every
    ``PROJECTION_STEPS`` steps the step count is projected to ``t_end`` too."""
    failure = budgets.over_budget(plan.budget, steps, stored, t_new, plan.t_end,
                                  h=t_new - t_prev)
    if not failure and steps % budgets.PROJECTION_STEPS == 0:
        failure = budgets.projected_over_budget(plan.budget, steps, t_new, plan.t_end,
                                                recent)
    return failure


class _Output:
    """The samples a scipy run keeps: every accepted step (and the terminal event's
    time), or the output times ``t_eval`` from the dense output."""

    def __init__(self, plan):
        self.t_eval = plan.t_eval
        if self.t_eval is None:
            self.ts, self.ys = [plan.t0], [plan.y0.copy()]
        else:
            first = bool(self.t_eval.size) and self.t_eval[0] == plan.t0
            self.ts, self.ys = ([plan.t0], [plan.y0.copy()]) if first else ([], [])
            self.next_eval = 1 if first else 0

    def add(self, solver, stop_at):
        """The samples of the step just taken, up to ``stop_at`` (a terminal event)."""
        if self.t_eval is None:
            if stop_at is not None:
                self.ts.append(stop_at)
                self.ys.append(solver.dense_output()(stop_at))
            else:
                self.ts.append(solver.t)
                self.ys.append(solver.y.copy())
            return
        t_hi = stop_at if stop_at is not None else solver.t
        sel = self.t_eval[self.next_eval:]
        sel = sel[sel <= t_hi]
        if sel.size:
            dense = solver.dense_output()
            for te in sel:
                self.ts.append(te)
                self.ys.append(dense(te))
            self.next_eval += sel.size
        if stop_at is not None and (not self.ts or self.ts[-1] != stop_at):
            self.ts.append(stop_at)
            self.ys.append(solver.dense_output()(stop_at))

    def arrays(self, solver):
        """``(ts, ys)``; the solver's last state when no output time was reached."""
        if not self.ts:
            return np.array([solver.t]), np.array([solver.y.copy()])
        return np.array(self.ts), np.array(self.ys)

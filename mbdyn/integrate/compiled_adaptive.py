"""RK45 and DOP853 as compiled stretches of accepted steps (``kernels.adaptive``): the same
steps as scipy's solvers, with no Python per step.  After each stretch, in Python and on
whole arrays: the singularity monitor, the events (crossings located by brentq on the
compiled dense output), the budgets, progress.  Output times are sampled inside the
stretch; drives are evaluated there by their programs (``compiled.programs``).
"""
from __future__ import annotations

import time as _time
import warnings

import numpy as np
import scipy                # its submodules load on first use (scipy.integrate: 0.2 s)

from ..errors import NonFiniteError, SimulationError, SingularMassMatrixError
from . import budget as budgets
from .event_search import crossed_rows, event_rows, event_values
from .events import EventRecord
from .monitor import LOOP_STATUS, describe_failure
from .plan import Outcome
from .result import Result

#: accepted steps per compiled stretch: the first, and the most (with events: a terminal
#: event wastes at most a stretch); a stretch doubles while it takes under STRETCH_CPU s
STRETCH_FIRST, STRETCH_MOST, STRETCH_MOST_EVENTS, STRETCH_CPU = 64, 4096, 256, 0.02


def stretch_events(events, model, g_old, t_start, y_start, T, Y, H, out_K, tab, dense_args,
                    nfev, G=None):
    """The events of a stretch of accepted steps ``(T, Y, H)`` after ``(t_start, y_start)``
    (conditions ``g_old`` there; ``dense_args``: the drive programs and the model's arrays
    after ``dense_step``'s first ones): ``(G, ends, found)`` -- the conditions at every row, the
    rows where the stretch ends (``(row, 1, "event")`` at a non-finite condition,
    ``(row, 2, "terminal", t_event, state_at)``) and ``{row: [EventRecord, ...]}``, each
    crossing located by brentq on the step's dense polynomial.  ``G``: the conditions at the
    rows when the stretch computed them (it then ended at its first crossing, and ``out_K``
    holds that last step's stages in its last row)."""
    from ..kernels.adaptive import dense_step
    nq = model.nq
    ends, found = [], {}
    if G is None:
        G = event_rows(events, model, T, Y)
    bad = np.flatnonzero(~np.all(np.isfinite(G), axis=1))
    if bad.size:
        ends.append((int(bad[0]), 1, "event"))
    last = int(bad[0]) if bad.size else len(T)
    before = np.vstack([g_old[None, :], G[:-1]])
    crossing = np.zeros(G.shape, bool)
    for k, e in enumerate(events):
        crossing[:last, k] = crossed_rows(e, before[:last, k], G[:last, k])
    for r in np.flatnonzero(crossing.any(axis=1)):
        t_old = T[r - 1] if r else t_start
        y_old = Y[r - 1] if r else y_start
        F, st = dense_step(tab.A, tab.C, tab.D, tab.stages, t_old, y_old, Y[r], H[r],
                           out_K[min(r, len(out_K) - 1)], *dense_args, nfev)
        if st:          # not expected: the stages of an accepted step were finite
            raise NonFiniteError("the dense output of a step became non-finite")

        def state_at(tt, F=F, y_old=y_old, t_old=t_old, h=H[r]):
            return dense_values(F, y_old, (tt - t_old) / h)[0]
        hits = []
        for k, e in enumerate(events):
            if crossing[r, k]:
                def g(tt, e=e):
                    yy = state_at(tt)
                    return float(e.condition(tt, yy[:nq], yy[nq:]))
                te = scipy.optimize.brentq(g, t_old, T[r], xtol=4 * np.finfo(float).eps,
                                           rtol=4 * np.finfo(float).eps)
                hits.append((te, e))
        records = found[int(r)] = []
        for te, e in sorted(hits, key=lambda h: h[0]):
            ye = state_at(te)
            records.append(EventRecord(e.name, te, ye[:nq], ye[nq:],
                                       model.coordinates + model.speeds))
            if e.terminal:
                ends.append((int(r), 2, "terminal", te, state_at))
                return G, ends, found
    return G, ends, found


def run(plan, programs):
    """Integrate ``plan`` by RK45 or DOP853 in compiled stretches; ``programs``: the
    drives' programs (``compiled.programs.drive_programs``).  An ``Outcome``."""
    motion = _Stretches(plan, programs)
    while motion.t < plan.t_end and motion.failure is None:
        if motion.advance():
            break
    return motion.outcome()


class _Stretch:
    """One call of the compiled stretch: its output arrays and where it started."""

    def __init__(self, m, n, stages, with_events, compiled_conditions, t, y, i_eval):
        self.t_out, self.h_out = np.empty(m), np.empty(m)
        self.y_out = np.empty((m, n))
        self.nfev_out, self.ieval_out = np.empty(m, np.int64), np.empty(m, np.int64)
        self.K = np.empty((0 if not with_events else 1 if compiled_conditions else m,
                           stages, n))
        self.t_start, self.y_start, self.i_start = t, y.copy(), i_eval
        self.accepted = 0
        self.status = 0

    def rows(self):
        a = self.accepted
        return self.t_out[:a], self.y_out[:a], self.h_out[:a]


class _Stretches:
    """The state of a compiled adaptive run between stretches: time, state, step size,
    samples, events, budgets.  ``advance`` runs one stretch and examines it; it returns
    True where the run ends."""

    def __init__(self, plan, programs):
        from ..compiled.programs import EventPrograms
        from ..kernels.adaptive import TABLEAUS
        self.plan, self.programs = plan, programs
        self.model = model = plan.model
        self.conditions = EventPrograms.of(plan.events)   # None: checked in Python
        self.no_events = EventPrograms.none()
        self.tab = TABLEAUS[plan.integrator]
        self.coefficients = self.tab.arrays()
        self.rtol = plan.rtol
        if self.rtol < 100 * np.finfo(float).eps:        # as scipy's solvers do
            warnings.warn("At least one element of `rtol` is too small. Setting "
                          f"`rtol = np.maximum(rtol, {100 * np.finfo(float).eps})`.",
                          stacklevel=4)
            self.rtol = 100 * np.finfo(float).eps
        self.t, self.y = plan.t0, plan.y0.copy()
        self.args = model.loop_arguments(plan.rhs.method)
        self.drives = self.args[5].size          # the driven coordinates (``drive_q``)
        self.f, self.h_abs = self._first_step()
        self.start_evaluations = plan.rhs.evaluations
        self.dense_args = self.args[:2] + self.args[3:]   # dense_step takes no quaternions
        self._start_samples()
        self.g_old = (event_values(plan.events, model, plan.t0, plan.y0) if plan.events
                      else None)
        self.found, self.steps, self.failure = [], 0, None
        self.recent = np.empty(0)                      # the last PROJECTION_STEPS step sizes
        self.nfev = np.zeros(1, np.int64)
        self.fail = np.empty(plan.y0.size + 1)         # a failing stage's time and state
        self.stretch = STRETCH_FIRST
        self.most = (STRETCH_MOST_EVENTS if plan.events and self.conditions is None
                     else STRETCH_MOST)

    def _derivative(self, t, y):
        """``y'`` at ``(t, y)`` by the stretches' own compiled stage
        (``kernels.adaptive.stage``, the same arguments, the drives by the same compiled
        programs as every later stage: no entry point of its own to compile; for a closed
        mechanism with a drive that was 4 s of its first run); an evaluation that fails is
        repeated by ``Model.state_derivative``, which raises the precise error."""
        from ..kernels.adaptive import stage
        from ..kernels.programs import STACK
        self.plan.rhs.evaluations += 1
        nq, slots, _, free_q, free_u, drive_q, drive_u, *arrays = self.args
        ydot = np.empty(y.size)
        status = stage(float(t), y, *self.programs, np.empty(STACK),
                       np.empty((self.drives, 3)), nq, slots, free_q, free_u, drive_q, drive_u,
                       *arrays, ydot, np.zeros(1, np.int64))
        if not status:
            return ydot
        return self.model.state_derivative(t, y, self.plan.rhs.method)

    def _first_step(self):
        """``f(t0, y0)`` and scipy's initial step size; a failure there is a
        ``SimulationError`` whose result holds the initial state."""
        plan, model = self.plan, self.model
        t0, y0, nq = plan.t0, plan.y0, model.nq
        try:
            f = self._derivative(t0, y0)
            h_abs = initial_step(lambda h, y: self._derivative(t0 + h, y), y0, f,
                                 plan.t_end - t0, plan.max_step, self.tab.order, self.rtol,
                                 plan.atol)
        except (NonFiniteError, SingularMassMatrixError) as exc:
            raise SimulationError(describe_failure(model, exc, t0, y0),
                                  Result(model, [t0], y0[None, :nq], y0[None, nq:],
                                         [], {})) from exc
        return f, h_abs

    def _start_samples(self):
        plan, n = self.plan, self.plan.y0.size
        if plan.t_eval is not None:
            self.samples = np.empty((len(plan.t_eval), n))
            self.i_eval = 1 if plan.t_eval[0] == plan.t0 else 0
            self.samples[:self.i_eval] = plan.y0
            self.times = [plan.t_eval[:self.i_eval]]
            self.states = [self.samples[:self.i_eval]]
            self.grid = plan.t_eval
        else:
            self.samples = np.empty((0, n))
            self.i_eval = 0
            self.times, self.states = [np.array([plan.t0])], [plan.y0[None, :].copy()]
            self.grid = np.empty(0)
        self.stored = 1 if plan.t_eval is None else self.i_eval

    def _compute(self):
        """One compiled stretch of at most ``self.stretch`` accepted steps."""
        from ..kernels.adaptive import rk_stretch, stretch_scratch
        plan = self.plan
        m = int(min(self.stretch, plan.budget["max_steps"] - self.steps))
        st = _Stretch(m, self.y.size, self.tab.stages, bool(plan.events),
                      self.conditions is not None, self.t, self.y, self.i_eval)
        st.checks = (self.no_events if self.conditions is None
                     else self.conditions.arguments(self.g_old, m, True))
        cpu = _time.process_time()
        st.accepted, st.status, self.h_abs, self.i_eval = rk_stretch(
            *self.coefficients, self.t, plan.t_end, self.y, self.f, self.h_abs, self.rtol,
            plan.atol, plan.max_step, m, self.grid, self.i_eval, self.samples,
            *self.programs, *self.args, st.t_out, st.y_out, st.h_out, st.nfev_out,
            st.ieval_out, st.K, self.fail, self.nfev, st.checks,
            stretch_scratch(self.tab.A, self.tab.D, self.y.size, self.drives))
        if _time.process_time() - cpu < STRETCH_CPU and self.stretch < self.most:
            self.stretch *= 2
        return st

    def _end(self, st):
        """Where the stretch ends, in the order a step is examined (singularity monitor,
        events, budgets): ``(end or None, G, hits by row)``; ``end`` is ``(row, rank,
        kind, ...)``."""
        plan = self.plan
        T, Y, H = st.rows()
        acc = st.accepted
        ends, G, hits_by_row = [], None, {}
        if plan.events and acc:
            G, ends, hits_by_row = stretch_events(
                plan.events, self.model, self.g_old, st.t_start, st.y_start, T, Y, H, st.K,
                self.tab, self.programs + self.dense_args, self.nfev,
                None if self.conditions is None else st.checks[6][:acc])
        kept = ((self.stored + 1 + np.arange(acc)) if plan.t_eval is None
                else st.ieval_out[:acc])
        ends += budgets.stretch_budget_ends(plan.budget, self.steps, kept, T, H, plan.t_end,
                                            self.recent)
        end = min(ends, key=lambda x: (x[0], x[1])) if ends else None
        upto = end[0] + 1 if end else acc
        n_ok, monitor_failure = plan.monitor.check_rows(T[:upto], Y[:upto])
        if monitor_failure:
            end = (n_ok, 0, "monitor", monitor_failure)
        return end, G, hits_by_row

    def _keep(self, st, end, G, hits_by_row):
        """The rows kept, the events found in them, the samples, the conditions and step
        sizes carried to the next stretch."""
        plan = self.plan
        T, Y, H = st.rows()
        acc = st.accepted
        history = np.concatenate([self.recent, H])
        last_row = end[0] if end else acc - 1      # the last row examined
        keep = end[0] + (1 if end[2] == "budget" else 0) if end else acc
        for r in sorted(hits_by_row):
            if r < keep or (end and end[2] == "terminal" and r == end[0]):
                self.found.extend(hits_by_row[r])
        self.steps += last_row + 1
        stop_at = end[3] if end and end[2] == "terminal" else None
        if plan.t_eval is None:
            self._keep_steps(T, Y, keep, end, stop_at)
        else:
            self._keep_samples(st, keep, end, stop_at)
        if G is not None and 0 <= last_row < acc:
            self.g_old = G[last_row]
        self.recent = history[:len(self.recent) + keep][-budgets.PROJECTION_STEPS:]
        return keep

    def _keep_steps(self, T, Y, keep, end, stop_at):
        self.times.append(T[:keep].copy())
        self.states.append(Y[:keep].copy())
        self.stored += keep
        if stop_at is not None:
            self.times.append(np.array([stop_at]))
            self.states.append(end[4](stop_at)[None, :])
            self.stored += 1

    def _keep_samples(self, st, keep, end, stop_at):
        t_eval = self.plan.t_eval
        upto = (int(np.searchsorted(t_eval, stop_at, side="right")) if stop_at is not None
                else st.ieval_out[keep - 1] if keep else st.i_start)
        upto = min(max(upto, st.i_start), self.i_eval if st.accepted else st.i_start)
        self.times.append(t_eval[st.i_start:upto])
        self.states.append(self.samples[st.i_start:upto])
        self.stored = upto
        if stop_at is not None and (upto == 0 or t_eval[upto - 1] != stop_at):
            self.times.append(np.array([stop_at]))
            self.states.append(end[4](stop_at)[None, :])
            self.stored += 1

    def advance(self):
        """Run and examine one stretch; True where the run ends."""
        plan, rhs = self.plan, self.plan.rhs
        st = self._compute()
        end, G, hits_by_row = self._end(st)
        keep = self._keep(st, end, G, hits_by_row)
        T, Y, H = st.rows()
        if end:
            self.failure = self._end_failure(end, T, Y)
            nfev_kept = int(st.nfev_out[end[0]])
        else:
            nfev_kept = int(self.nfev[0])
            if keep:
                self.t = T[-1]
        if plan.progress is not None:
            plan.progress(self.times[-1][-1] if len(self.times) and len(self.times[-1])
                          else self.t)
        if end:
            rhs.evaluations = self.start_evaluations + nfev_kept
            return True
        rhs.evaluations = self.start_evaluations + int(self.nfev[0])
        if st.status:
            self.failure = self._kernel_failure(st.status)
            return True
        if self.t < plan.t_end:
            self.failure = budgets.over_budget(plan.budget, self.steps, self.stored, self.t,
                                               plan.t_end, h=H[-1] if st.accepted else None)
        return False

    def _end_failure(self, end, T, Y):
        """The failure of a stretch that ended early (``None`` at a terminal event)."""
        if end[2] == "terminal":
            return None
        if end[2] != "event":
            return end[3]
        r = end[0]
        try:
            event_values(self.plan.events, self.model, T[r], Y[r])
        except NonFiniteError as exc:
            return describe_failure(self.model, exc, T[r], Y[r])
        return None

    def _kernel_failure(self, status):
        """The message of a compiled stretch that stopped on ``status``."""
        if status == 4:
            return (f"integrator {self.plan.integrator} failed at t={self.t:.6g}: Required "
                    "step size is less than spacing between numbers.. Loosen rtol/atol, or "
                    "try an implicit method (Radau, BDF) if the model is stiff")
        try:
            self.model.state_derivative(self.fail[0], self.fail[1:])
            exc = LOOP_STATUS[status](self.model)
        except (NonFiniteError, SingularMassMatrixError) as raised:
            exc = raised
        return describe_failure(self.model, exc, self.t, self.y)

    def outcome(self):
        info = {"steps": self.steps, "njev": 0, "nlu": 0,
                "solver_rhs_evaluations": self.plan.rhs.evaluations, "compiled": True}
        if self.failure is not None:
            info["failure"] = self.failure
        ts = np.concatenate(self.times) if self.times else np.empty(0)
        ys = np.vstack(self.states) if self.states else np.empty((0, self.y.size))
        if not len(ts):
            ts, ys = np.array([self.t]), self.y[None, :].copy()
        return Outcome(ts, ys, self.found, info)


# Python helpers of the compiled stretches (run once per run or per sample batch)
def initial_step(fun, y0, f0, span, max_step, order, rtol, atol):
    """A first step size from the size of ``y0``, ``f0`` and a difference estimate of the
    second derivative (Hairer, Norsett & Wanner, II.4); ``fun(h, y)`` is the derivative at
    ``t0 + h``; at most ``span`` and ``max_step``."""
    scale = atol + np.abs(y0) * rtol
    rms = lambda x: np.sqrt(np.mean(x * x))
    d0, d1 = rms(y0 / scale), rms(f0 / scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, span)
    f1 = fun(h0, y0 + h0 * f0)
    d2 = rms((f1 - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return min(100 * h0, h1, span, max_step)


def dense_values(F, y_old, x):
    """The dense polynomial at the fractions ``x`` (array) of the step: ``(len(x), n)``."""
    x = np.atleast_1d(np.asarray(x, dtype=float))[:, None]
    acc = np.zeros((x.shape[0], F.shape[1]))
    for r in range(F.shape[0] - 1, -1, -1):
        acc += F[r]
        acc *= x if r % 2 == 0 else 1.0 - x
    return y_old + acc

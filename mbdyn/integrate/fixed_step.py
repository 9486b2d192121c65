"""The fixed-step schemes (explicit and semi-implicit Euler, RK4, implicit midpoint): in
compiled stretches (``kernels.integrators``) where the model allows, else one Python step
at a time (``python_steps``).  After each stretch, on whole arrays: the singularity
monitor, the events (crossings located by linear interpolation between the two steps
that bracket them), the samples kept (``samples``: output times by cubic Hermite
interpolation), the budgets.  Steps are of size ``dt``, the last one shortened to end at
``t_end`` (``step_plan``); quaternions are projected after every step.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, NonFiniteError, SimulationError, SingularMassMatrixError
from . import budget as budgets
from .event_search import crossed_rows, event_rows, event_values
from .events import EventRecord
from .monitor import LOOP_STATUS, describe_failure
from .plan import Outcome
from .python_steps import fixed_step
from .samples import Samples


def run(plan, compiled):
    """Integrate ``plan`` by its fixed-step scheme, in compiled stretches when
    ``compiled``; an ``Outcome``."""
    model, budget = plan.model, plan.budget
    kept = Samples(plan.t0, plan.y0, budget["decimate"], plan.t_eval)
    t, y = plan.t0, plan.y0
    g_old = event_values(plan.events, model, t, y) if plan.events else None
    found, failure, steps, stop = [], None, 0, False
    chunks = (compiled_chunks(plan, g_old) if compiled else python_chunks(plan))
    for times, states, chunk_failure, G, rates in chunks:
        if plan.events:
            processed, failure, stop, g_old = stretch_events(
                plan.events, model, plan.monitor, t, y, g_old, times, states, found, G)
        else:
            processed, failure = plan.monitor.check_rows(times, states)
        kept.add(times[:processed], states[:processed], rates[:processed])
        steps += processed
        if processed:
            t, y = times[processed - 1], states[processed - 1]
        if plan.progress is not None:
            plan.progress(t)
        failure = failure or (None if stop else chunk_failure)  # past a terminal event: moot
        if failure or stop:
            break
        if t < plan.t_end:
            failure = budgets.over_budget(budget, steps, kept.count, t, plan.t_end)
            if failure:
                break
    ts, ys = kept.arrays(lambda t, y: _rate_or_none(plan.rhs, t, y))
    if not len(ts):                     # t_eval entirely beyond a failure or an event
        ts, ys = np.array([t]), y[None, :]
    info = {"steps": steps, "compiled_loop": bool(compiled)}
    if budget["decimate"] > 1:
        info["samples_kept_every"] = budget["decimate"]
    if failure is not None:
        info["failure"] = failure
    return Outcome(ts, ys, found, info)


def _rate_or_none(rhs, t, y):
    """``y'`` at ``(t, y)``, or ``None`` where it is not finite (a run that failed there)."""
    try:
        return rhs(t, y)
    except (ArithmeticError, ModelError):
        return None


def step_plan(t0, t_end, dt):
    """``(end times of the full steps, h_last)``: as many steps of ``dt`` as fit (within
    rounding), then, unless they reach ``t_end``, one shorter step ``h_last`` that ends
    there (else ``h_last = 0``).  Steps of ``dt`` are kept as given rather than evened out
    (a listing's step runs as the listing's); when they reach ``t_end`` within rounding --
    44,000 steps of 4/44000 end at 3.9999999999999996 -- the last one's time is put on
    ``t_end`` exactly, so that the run ends there and an output time ``t_end`` is kept."""
    ratio = (t_end - t0) / dt
    n_full = int(np.floor(ratio * (1 + 1e-12)))
    times = t0 + dt * np.arange(1, n_full + 1)
    if n_full and ratio - n_full <= 1e-12 * max(1.0, ratio):
        times[-1] = t_end
        return times, 0.0
    return times, t_end - (times[-1] if n_full else t0)


def step_times(t0, t_end, dt):
    """The steps as ``[(h, end times), ...]`` (``step_plan``)."""
    times, h_last = step_plan(t0, t_end, dt)
    steps = [(dt, times)] if len(times) else []
    if h_last:
        steps.append((h_last, np.array([t_end])))
    return steps


def compiled_chunks(plan, g_old=None):
    """Yield ``(times, states, failure, G, rates)`` stretches of the motion from the
    compiled loops (``rates[k]``: ``y'`` at the state before row ``k`` when the run has
    output times, for their dense output).  ``G``: the event conditions at the stretch's rows when the loop evaluated them
    (their programs, ``compiled.programs.EventPrograms``; ``g_old`` at ``y0``), else
    ``None``; such a loop stops after a step where a terminal event occurred or a
    condition is not finite, and so does the motion."""
    from ..compiled.programs import EventPrograms
    from ..kernels.integrators import LOOPS, SCHEMES, STAGES, loop_scratch
    model, rhs = plan.model, plan.rhs
    code = SCHEMES[plan.integrator]
    loop = LOOPS[code]
    args = model.loop_arguments(rhs.method)
    conditions = EventPrograms.of(plan.events)
    checks = EventPrograms.none()
    # stretches between checks in Python: short when there are events the loop cannot
    # check or Euler-angle singularities to watch (a terminal event or a singularity
    # wastes at most a stretch), long otherwise
    chunk = 200 if ((plan.events and conditions is None) or model._euler_middle) else 2000
    t, y = plan.t0, plan.y0.copy()
    for h, ts in step_times(plan.t0, plan.t_end, plan.dt):
        for lo in range(0, len(ts), chunk):
            tk = ts[lo:lo + chunk]
            starts = np.concatenate([[t], tk[:-1]])
            stage_times = (starts[:, None] + h * np.array(STAGES)[None, :]).reshape(-1)
            table = model.drive_values(stage_times).reshape(len(tk), len(STAGES), -1, 3)
            out = np.empty((len(tk) + 1, y.size))
            rates = np.empty((len(tk) if plan.t_eval is not None else 0, y.size))
            nfev = np.zeros(1, np.int64)
            if conditions is not None:
                checks = conditions.arguments(g_old, len(tk), False)
            done, status = loop(h, y, table, *args, out, rates, nfev, tk, checks,
                                loop_scratch(y.size, code))
            rhs.evaluations += int(nfev[0])
            failure = None
            if status:
                t_fail = tk[done - 1] if done else t
                failure = describe_failure(model, LOOP_STATUS[status](model), t_fail,
                                           out[done])
            G = None
            if conditions is not None:
                G, g_old = checks[6][:done], checks[5]
            yield tk[:done], out[1:done + 1], failure, G, rates[:done]
            if status or done < len(tk):
                return
            t, y = tk[-1], out[-1].copy()


def python_chunks(plan):
    """Yield ``(times, states, failure, None, rates)``, one step at a time, in Python
    (models with loads given as Python functions, or ``compiled_loop=False``)."""
    model, nq = plan.model, plan.model.nq
    # a closed mechanism: every step projected onto the constraints, as the compiled
    # loops do (docs/constraints.md)
    project = model.has_loops
    t, y = plan.t0, plan.y0.copy()
    for h, ts in step_times(plan.t0, plan.t_end, plan.dt):
        memory = {}                 # what the implicit midpoint rule keeps over the steps
        for t_new in ts:
            try:
                y_new, rate = fixed_step(plan.rhs, plan.integrator, t, y, h, nq, memory)
                if project:
                    y_new[:nq], y_new[nq:] = model.project(y_new[:nq], y_new[nq:], t_new)
            except (NonFiniteError, SingularMassMatrixError, SimulationError) as exc:
                yield (np.empty(0), np.empty((0, y.size)), describe_failure(model, exc, t, y),
                       None, np.empty((0, y.size)))
                return
            model.normalize_quaternions(y_new[:nq])
            if not np.all(np.isfinite(y_new)):
                bad = [n for n, v in zip(model.coordinates + model.speeds, y_new)
                       if not np.isfinite(v)]
                yield np.empty(0), np.empty((0, y.size)), describe_failure(
                    model, NonFiniteError(f"the state became non-finite in {', '.join(bad)}"),
                    t, y), None, np.empty((0, y.size))
                return
            yield np.array([t_new]), y_new[None, :], None, None, rate[None, :]
            t, y = t_new, y_new


def stretch_events(events, model, monitor, t, y, g_old, times, states, found, G=None):
    """The events of a stretch of fixed steps ``(times, states)`` after ``(t, y)`` (event
    conditions ``g_old`` there), vectorized over the rows but with the outcome of a
    step-by-step pass: each row is checked by ``monitor`` first, then its conditions; a
    crossing is located by linear interpolation between the two rows bracketing it and
    appended to ``found``; a terminal one ends the stretch after its row.  Returns
    ``(rows processed, failure or None, stopped at a terminal event, conditions at the
    last processed row)``.  ``G``: the conditions at the rows, if the loop computed them."""
    m = len(times)
    if G is None:
        G = event_rows(events, model, times, states)
    finite = np.all(np.isfinite(G), axis=1)
    b = int(np.argmin(finite)) if not finite.all() else m      # first non-finite row
    before = np.vstack([g_old[None, :], G[:-1]])
    crossing = np.zeros((m, len(events)), bool)
    for j, e in enumerate(events):
        crossing[:b, j] = crossed_rows(e, before[:b, j], G[:b, j])
    terminal = np.array([e.terminal for e in events], bool)
    rows_t = np.flatnonzero((crossing & terminal).any(axis=1))
    r_t = int(rows_t[0]) if rows_t.size else None
    limit = r_t + 1 if r_t is not None else min(b + 1, m)
    n_ok, failure = monitor.check_rows(times[:limit], states[:limit])
    if n_ok < limit:
        processed = n_ok
    elif r_t is not None:
        processed = r_t + 1
    elif b < m:
        processed = b
        try:
            event_values(events, model, times[b], states[b])    # raises its message
        except NonFiniteError as exc:
            failure = describe_failure(model, exc, times[b], states[b])
    else:
        processed = m
    stop = False
    for r in np.flatnonzero(crossing[:processed].any(axis=1)):
        t_old, y_old = (times[r - 1], states[r - 1]) if r else (t, y)
        t_new, y_new = times[r], states[r]
        hits = []
        for j, e in enumerate(events):
            if crossing[r, j]:
                te = t_old + (t_new - t_old) * before[r, j] / (before[r, j] - G[r, j])
                hits.append((te, e))
        for te, e in sorted(hits, key=lambda x: x[0]):
            w = (te - t_old) / (t_new - t_old) if t_new != t_old else 1.0
            ye = (1 - w) * y_old + w * y_new
            found.append(EventRecord(e.name, te, ye[:model.nq], ye[model.nq:],
                                     model.coordinates + model.speeds))
            if e.terminal:
                stop = True
                break
    return processed, failure, stop, (G[processed - 1] if processed else g_old)

"""``simulate``: integrate ``q' = N(q) u``, ``u' = forward_dynamics(q, u, t)`` from an
initial state, with events, output times, budgets and checks; the integrator families
are behind one interface (``plan``): scipy's solvers stepped from Python
(``scipy_solvers``), RK45 and DOP853 in compiled stretches (``compiled_adaptive``), the
fixed-step schemes (``fixed_step``).

Fixed-step schemes: explicit Euler, semi-implicit (symplectic) Euler -- the textbook's
scheme, velocities first, then positions with the new velocities -- classic RK4 and the
implicit midpoint rule; quaternions are projected back onto the unit sphere after every
step.
"""
from __future__ import annotations

import time as _time
import warnings

import numpy as np

from ..algorithms.forward_dynamics import METHODS as _METHODS
from ..compiled.force_packing import warn_outside_tables
from ..errors import ModelError, ModelWarning, SimulationError
from . import compiled_adaptive, fixed_step, sampled, scipy_solvers
from .budget import check_fixed_step, make_budget
from .closed_loops import closed_initial_state, loop_report, release_rank
from .contacts import warn_contact_step
from .events import Event, as_event, check_conditions
from .monitor import Monitor, conditioning
from .plan import Plan, RightHandSide
from .result import Result
from .sampled import is_sampled
from .settings import ADAPTIVE, COMPILED_ADAPTIVE, DEFAULTS, FIXED_STEP, INTEGRATORS


def simulate(model, t_end, q0=None, u0=None, *, t0=0.0, integrator=DEFAULTS["integrator"],
             rtol=DEFAULTS["rtol"], atol=DEFAULTS["atol"], dt=None, method=DEFAULTS["method"],
             events=(), t_eval=None, max_step=np.inf, outputs=(), points=None, progress=None,
             singularity_threshold=1e-3, reactions_frame="world", compiled_loop=True,
             decimate=1, max_steps=None, max_samples=None, max_wall_time=None,
             error_estimate=False):
    """Integrate ``model`` (a compiled ``Model``, or a ``System`` to compile) from ``t0``
    to ``t_end``.

    ``q0``/``u0``: arrays or ``{name: value}`` over the defaults (zero, identity
    quaternions); in ``u0`` a revolute, prismatic or Euler-angle coordinate's name stands
    for its rate, as in model files.  ``integrator``: one of ``INTEGRATORS`` (default
    ``DEFAULTS``: DOP853 at rtol 1e-9, atol 1e-12, the same as model files and the command
    line); the fixed-step ones need ``dt``.
    ``method``: ``"auto"`` (the default: ``"jourdain"`` for small models, the O(n)
    ``"articulated"`` route for large ones, ``Model.formulation``), ``"jourdain"``,
    ``"articulated"``, ``"newton-euler"``, ``"newton-euler-dense"`` or ``"symbolic"`` (the
    closed-form equations compiled by ``mbdyn.symbolic.compiled_rhs``).  ``events``: ``Event``s.
    ``t_eval``: output times (default every accepted step).  ``outputs``: any of ``"reactions"``,
    ``"energy"``; ``points``: ``{name: (frame, offset)}``; ``reactions_frame``:
    ``"world"`` or ``"child"`` (the child frame's components, as the textbook writes
    reactions).  ``progress``: optional callable
    ``progress(t)`` called after each step.  ``singularity_threshold``: stop when an
    Euler-angle joint comes this close to its singularity (see ``Model.euler_singularity``).
    ``compiled_loop``: run fixed-step schemes, RK45 and DOP853 in compiled stretches when
    the model allows (``method`` ``"jourdain"`` or ``"articulated"``, no Python-function loads and, for RK45 and
    DOP853, drives that ``mbdyn.compiled.programs`` translates); ``False`` forces the Python loop
    (scipy's solvers for RK45 and DOP853, which ``"scipy-RK45"`` and ``"scipy-DOP853"``
    also name).
    ``decimate``: fixed-step schemes store every ``decimate``-th step (and the last); they
    end on ``t_end`` exactly and interpolate ``t_eval`` between steps by cubic Hermite.

    Budgets (``mbdyn.limits``; ``docs/reliability.md``): ``max_steps`` integrator steps
    (default ``MAX_STEPS``), ``max_samples`` stored samples (default ``MAX_SAMPLES``;
    a fixed-step run that would exceed it is refused before it starts, with the estimate),
    ``max_wall_time`` seconds (default none).  A run that reaches a budget stops with a
    ``SimulationError`` that says which one and keeps the motion so far.

    Statistics include the mass matrix's condition number at the start and the end (a
    ``SingularityWarning`` when it is large), the largest quaternion drift and, with
    ``outputs=("energy",)``, the energy drift.  ``error_estimate``: run again at half the
    step (fixed-step) or at rtol/100, atol/100 (adaptive); ``stats["error_estimate"]``
    holds the difference per coordinate and speed (``quality.estimate_error``).

    Raises ``SimulationError`` (its ``result`` holds the motion up to the failure) when
    the integrator fails or NaN/Inf appears.
    """
    if not hasattr(model, "forward_dynamics") and hasattr(model, "compile"):
        model = model.compile()           # a System: compile it here
    _check_kinds(model, events, progress)
    method = _check_method(model, integrator, method)
    t0, t_end = _check_interval(t0, t_end, events, rtol, atol, max_step)
    warn_contact_step(model, integrator, max_step)
    budget = make_budget(max_steps, max_samples, max_wall_time, decimate)
    budget.update(drives=[d[0] for d in getattr(model, "_driven", ())],  # warn_stiff's
                  integrator=integrator, speeds=model.nu, span=t_end - t0)     # measures
    t_eval = _check_t_eval(t_eval, t0, t_end)
    q, u = _initial_state(model, q0, u0, t0)
    given_events = list(events)
    events = [as_event(e, model) for e in given_events]
    if events:
        check_conditions(events, model, t0, q, u)
    rhs = RightHandSide(model, method)
    monitor = Monitor(model, singularity_threshold)
    y0 = np.concatenate([q, u])
    failure = monitor.check(t0, y0)
    if failure:
        raise ModelError("the initial state is unusable: " + failure)
    pre_stats = {}
    conditioning(model, q, t0, pre_stats, "mass_matrix_condition_initial")
    if integrator not in ADAPTIVE:
        dt = check_fixed_step(integrator, dt, t0, t_end, t_eval, budget, 1 + y0.size)
    elif dt is not None:
        warnings.warn(f"dt = {dt!r} is ignored: the adaptive integrator {integrator} chooses "
                      "its own steps (bound them with max_step, or choose a fixed-step "
                      f"integrator: {', '.join(FIXED_STEP)})", ModelWarning, stacklevel=2)
    if t_eval is not None and len(t_eval) > budget["max_samples"]:
        raise ModelError(f"t_eval asks for {len(t_eval)} samples, more than max_samples = "
                         f"{budget['max_samples']}; ask for fewer or raise max_samples")
    start = _time.perf_counter()
    budget["deadline"] = (None if budget["max_wall_time"] is None
                          else start + budget["max_wall_time"])
    plan = Plan(rhs, integrator, t0, t_end, y0, events, t_eval, progress, monitor, budget,
                rtol, atol, max_step, dt if integrator not in ADAPTIVE else None)
    try:
        outcome = (sampled.run(plan, lambda sub: _integrate(sub, compiled_loop))
                   if is_sampled(model) else _integrate(plan, compiled_loop))
    finally:
        if model.has_loops:
            release_rank(model)
    stats = {"integrator": integrator, "method": method, "rtol": rtol, "atol": atol, "dt": dt,
             "rhs_evaluations": rhs.evaluations, "wall_time_s": _time.perf_counter() - start}
    result = _result(model, outcome, stats, pre_stats, monitor)
    if model.has_loops:
        loop_report(model, result)
    if outputs or points:
        result.compute_outputs(outputs, points, frame=reactions_frame)
    if error_estimate:
        from .quality import estimate_error
        same = {"t0": t0, "integrator": integrator, "rtol": rtol, "atol": atol, "dt": dt,
                "method": method, "events": given_events, "max_step": max_step,
                "compiled_loop": compiled_loop, "max_steps": max_steps,
                "singularity_threshold": singularity_threshold,
                "max_samples": max_samples, "max_wall_time": max_wall_time}
        estimate_error(result, lambda **kw: simulate(model, t_end, q, u, **{**same, **kw}),
                       integrator, rtol, atol, dt)
    return result


def _check_kinds(model, events, progress):
    """The arguments whose kind is wrong, refused before anything else looks at them."""
    from ..compiled.model import Model
    if not isinstance(model, Model):
        raise ModelError(f"simulate: model must be a compiled Model or a System, got "
                         f"{type(model).__name__}")
    if events is None or not (hasattr(events, "__iter__") or isinstance(events, Event)):
        raise ModelError("simulate: events must be a list of mb.Event (or empty), got "
                         f"{events!r}")
    if progress is not None and not callable(progress):
        raise ModelError(f"simulate: progress must be a function progress(t), got "
                         f"{progress!r}")


def _check_method(model, integrator, method):
    """The formulation a run uses (``"auto"`` resolved by the model's size)."""
    if integrator not in INTEGRATORS:
        raise ModelError(f"unknown integrator {integrator!r}; use one of {', '.join(INTEGRATORS)}")
    if method not in ("auto",) + _METHODS + ("symbolic",):
        raise ModelError(f"unknown method {method!r}; use one of "
                         f"{', '.join(('auto',) + _METHODS + ('symbolic',))}")
    return method if method == "symbolic" else model.formulation(method)


def _check_interval(t0, t_end, events, rtol, atol, max_step):
    """``(t0, t_end)`` as floats, after the checks of the interval and the tolerances."""
    try:
        t0, t_end = float(t0), float(t_end)
    except (TypeError, ValueError):
        raise ModelError(f"t0 and t_end must be numbers, got {t0!r} and {t_end!r}") from None
    if isinstance(events, (str, Event)):
        raise ModelError("events must be a list of mb.Event, e.g. events=[mb.Event('stop', "
                         "'theta >= 1', terminal=True)]")
    if not (np.isfinite(t0) and np.isfinite(t_end)):
        raise ModelError(f"t0 and t_end must be finite, got {t0} and {t_end}")
    if not t_end > t0:
        raise ModelError(f"t_end ({t_end}) must be greater than t0 ({t0})")
    for name, value in (("rtol", rtol), ("atol", atol), ("max_step", max_step)):
        if (isinstance(value, bool) or not isinstance(value, (int, float, np.number))
                or not (value > 0 and (np.isfinite(value) or name == "max_step"))):
            what = "positive" if name == "max_step" else "a positive number"
            raise ModelError(f"{name} must be {what}, got {value!r}")
    return t0, t_end


def _check_t_eval(t_eval, t0, t_end):
    """The output times as an array (``None``: every accepted step), checked."""
    if t_eval is None:
        return None
    try:
        t_eval = np.asarray(t_eval, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ModelError("t_eval must be a sequence of times (numbers)") from None
    if not t_eval.size:
        raise ModelError("t_eval is empty; give the output times, or None for every step")
    if not np.all(np.isfinite(t_eval)):
        raise ModelError("t_eval holds NaN or infinite times; give finite output times")
    if np.any(np.diff(t_eval) <= 0):
        raise ModelError("t_eval must increase strictly (sorted, no repeats)")
    outside = t_eval[(t_eval < t0 - 1e-12 * max(1.0, abs(t0)))
                     | (t_eval > t_end + 1e-12 * max(1.0, abs(t_end)))]
    if outside.size:
        raise ModelError(f"t_eval has times outside t0..t_end = {t0:g}..{t_end:g} (e.g. "
                         f"{outside[0]:g}); they would be dropped -- raise t_end or remove "
                         "them")
    # a time past t_end by round-off (0.03 / 1e-4 steps of 1e-4 end at 0.030000000000000002)
    # is t_end: the integrator stops there and would never reach it
    t_eval = np.clip(t_eval, t0, t_end)
    if np.any(np.diff(t_eval) <= 0):
        raise ModelError("t_eval has two times that are the same within round-off at t0 or "
                         "t_end; remove one")
    return t_eval


def _initial_state(model, q0, u0, t0):
    """``(q, u)`` from the arrays or ``{name: value}`` given, finite, unit quaternions; a
    closed mechanism's on its constraints (``closed_loops``)."""
    try:
        q = model.q_vector(None if q0 is None else (dict(q0) if isinstance(q0, dict)
                                                    else q0)).copy()
    except ModelError as exc:
        raise ModelError(f"q0: {exc}") from None
    try:
        u = model.u_vector(None if u0 is None else (dict(u0) if isinstance(u0, dict)
                                                    else u0)).copy()
    except ModelError as exc:
        raise ModelError(f"u0: {exc}") from None
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(u))):
        bad = [n for n, v in zip(model.coordinates + model.speeds, np.concatenate([q, u]))
               if not np.isfinite(v)]
        raise ModelError(f"initial state must be finite: q0/u0 hold NaN or Inf in "
                         f"{', '.join(bad)}")
    model.normalize_quaternions(q)
    if model.has_loops:
        q, u = closed_initial_state(model, q, u, t0)
    return q, u


def _integrate(plan, compiled_loop):
    """The route that integrates ``plan``: compiled stretches where the model allows
    (``method`` jourdain or articulated, no Python-function loads; for RK45 and DOP853
    drives that ``compiled.programs`` translates), else scipy's solvers or Python steps."""
    model, method = plan.model, plan.rhs.method
    compiled = (compiled_loop and method in ("jourdain", "articulated")
                and not model.has_callable_loads)
    if plan.integrator not in ADAPTIVE:
        return fixed_step.run(plan, compiled)
    if compiled and plan.integrator in COMPILED_ADAPTIVE and plan.y0.size > 0:
        from ..compiled.programs import drive_programs
        programs = drive_programs([d[3] for d in model._time_inputs])
        if programs is not None:
            return compiled_adaptive.run(plan, programs)
    return scipy_solvers.run(plan)


def _result(model, outcome, stats, pre_stats, monitor):
    """The ``Result`` of a run: unit quaternions reported (their drift in ``stats``), the
    conditioning at the end, the tables' ranges checked; a ``SimulationError`` holding it
    when the run failed."""
    ts, found, info = outcome.ts, outcome.found, outcome.info
    ys = np.asarray(outcome.ys).reshape(len(ts), -1)
    stats["quaternion_drift"] = model.quaternion_drift(ys[:, :model.nq])
    stats.update(pre_stats)
    stats.update(info)
    if monitor.closest:
        stats["euler_singularity_distance"] = dict(monitor.closest)
    if "failure" not in info:
        conditioning(model, ys[-1, :model.nq], ts[-1], stats, "mass_matrix_condition_final",
                     stacklevel=4)
    failure = stats.pop("failure", None)
    qs = ys[:, :model.nq].copy()
    for row in qs:                      # report unit quaternions; the drift is in stats
        model.normalize_quaternions(row)
    result = Result(model, ts, qs, ys[:, model.nq:], found, stats)
    if getattr(model, "_force_elements", ()):
        warn_outside_tables(model, ts, ys[:, model.nq:])
    if failure is not None:
        stats["status"] = "failed"
        result.stats = stats
        raise SimulationError(failure, result)
    result.stats["status"] = "ok"
    return result

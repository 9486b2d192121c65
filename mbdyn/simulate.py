"""Time integration of ``q' = N(q) u``, ``u' = forward_dynamics(q, u, t)``; events; ``Result``.

Adaptive integrators are scipy's ``OdeSolver`` classes (RK45, RK23, DOP853, Radau, BDF,
LSODA), stepped here one accepted step at a time so that events are located on the dense
output, a failure keeps the results computed before it, and NaN/Inf stops the run with the
time and the state; RK45 and DOP853 run instead as compiled stretches of steps
(``kernels.adaptive``) where the model allows, examined stretch by stretch with the same
results.  Fixed-step schemes: explicit Euler, semi-implicit (symplectic) Euler --
the textbook's scheme, velocities first, then positions with the new velocities -- and
classic RK4; quaternions are projected back onto the unit sphere after every step.
"""
from __future__ import annotations

import collections
import collections.abc
import time as _time
import warnings

import numpy as np
import scipy                # its submodules load on first use (scipy.integrate: 0.2 s)

from .balance import energy_balance
from .events import Event, EventRecord, as_event, check_conditions
from .force_packing import warn_outside_tables
from . import limits
from .compile import METHODS as _METHODS
from .errors import (ModelError, ModelWarning, NonFiniteError, SimulationError,
                     SingularityWarning, SingularMassMatrixError)

class _ScipySolvers(collections.abc.Mapping):
    """scipy's ``OdeSolver`` classes by name, ``scipy.integrate`` imported on the first
    look-up of a class (a fixed-step run does not need it).  ``scipy-RK45`` and
    ``scipy-DOP853`` always take scipy's solver; ``RK45`` and ``DOP853`` run compiled
    (``kernels.adaptive``) where the model allows."""
    NAMES = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA", "scipy-RK45", "scipy-DOP853")

    def __getitem__(self, name):
        if name not in self.NAMES:
            raise KeyError(name)
        return getattr(scipy.integrate, name.removeprefix("scipy-"))

    def __iter__(self):
        return iter(self.NAMES)

    def __len__(self):
        return len(self.NAMES)


ADAPTIVE = _ScipySolvers()
#: adaptive pairs that also run as compiled stretches (``kernels.adaptive``); their
#: ``scipy-`` names always take scipy's solver
COMPILED_ADAPTIVE = ("RK45", "DOP853")
FIXED_STEP = ("euler", "semi-implicit-euler", "rk4", "implicit-midpoint")
INTEGRATORS = tuple(ADAPTIVE) + FIXED_STEP
OUTPUTS = ("reactions", "energy", "momentum")


class Result:
    """Time series of a simulation.

    ``t`` (n,), ``q`` (n, nq), ``u`` (n, nu); ``res["theta1"]`` gives a coordinate or speed
    by name; ``events`` is ``[(name, t), ...]`` (``EventRecord``s: each also carries the
    state there, ``.q``, ``.u``, ``.state``); ``stats`` the integrator's statistics;
    on request ``reactions`` ``{joint: (n, 6)}`` (force then moment, world components, at
    the joint origin), ``energy`` (see ``mbdyn.balance.energy_balance``: ``kinetic``,
    ``potential``, ``total`` = T + V, ``dissipated``, ``work``, ``balance``) and ``points``
    ``{name: (n, 3)}``.  With energies, ``stats["energy_drift"]`` is
    ``max |B(t) - B(0)|`` of the balance ``B = T + V + dissipated - work`` over the energy
    scale (the largest of its terms).
    """

    def __init__(self, model, t, q, u, events, stats):
        self.model = model
        self.t = np.asarray(t, dtype=float)
        self.q = np.asarray(q, dtype=float).reshape(len(self.t), model.nq)
        self.u = np.asarray(u, dtype=float).reshape(len(self.t), model.nu)
        self.events = list(events)
        self.stats = dict(stats)
        self.reactions = None
        self.energy = None
        self.points = None
        self.drive_efforts = None
        self.momentum = None

    @property
    def coordinates(self):
        return self.model.coordinates

    @property
    def speeds(self):
        return self.model.speeds

    def __len__(self):
        return len(self.t)

    def to_csv(self, path):
        """Write the results to ``path`` as CSV with named columns (``t``, coordinates,
        speeds, then the energies, reactions, drive efforts and points computed), the same
        columns as ``mbdyn run --out``; written whole or not at all."""
        import io as _io
        names = ["t"] + list(self.coordinates) + list(self.speeds)
        cols = [self.t[:, None], self.q, self.u]
        if self.energy is not None:
            for key, arr in self.energy.items():
                names.append(f"energy_{key}")
                cols.append(np.asarray(arr)[:, None])
        if self.reactions is not None:
            for j, arr in self.reactions.items():
                names += [f"reaction_{j}_{c}" for c in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
                cols.append(np.asarray(arr))
        if self.drive_efforts:
            for j, arr in self.drive_efforts.items():
                names.append(f"effort_{j}")
                cols.append(np.asarray(arr)[:, None])
        if self.points:
            for p, arr in self.points.items():
                names += [f"point_{p}_{a}" for a in "xyz"]
                cols.append(np.asarray(arr))
        table = np.hstack([np.asarray(c, float).reshape(len(self.t), -1) for c in cols])
        buf = _io.StringIO()
        buf.write(",".join(names) + "\n")
        np.savetxt(buf, table, delimiter=",", fmt="%.17g")
        import os
        import tempfile
        directory = os.path.dirname(os.path.abspath(path))
        try:
            fd, tmp = tempfile.mkstemp(prefix=".result.", suffix=".csv", dir=directory)
        except OSError as exc:
            raise OSError(exc.errno, f"cannot write {path}: {exc.strerror}", str(path)) \
                from None
        try:
            with os.fdopen(fd, "w") as fh:
                fh.write(buf.getvalue())
            os.replace(tmp, path)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
        return path

    def __getitem__(self, name):
        if name in self.model.coordinates:
            return self.q[:, self.model.coordinate_index(name)]
        if name in self.model.speeds:
            return self.u[:, self.model.speed_index(name)]
        if self.points and name in self.points:
            return self.points[name]
        raise KeyError(f"{name!r} is neither a coordinate ({', '.join(self.coordinates)}) nor a "
                       f"speed ({', '.join(self.speeds)}) of model {self.model.name!r}")

    def plot(self, series=None, phase=None, out=None, title=None):
        """Time series or a phase portrait of this result: see ``mbdyn.viz.plot_result``
        (imported on call, as matplotlib is)."""
        from .viz import plot_result
        return plot_result(self, series=series, phase=phase, out=out, title=title)

    def animate(self, out, speed=1.0, fps=30.0, title=None, **options):
        """An animation of this result written to ``out``: see ``mbdyn.viz.animate``
        (imported on call)."""
        from .viz import animate
        return animate(self, out, speed=speed, fps=fps, title=title, **options)

    def __repr__(self):
        return (f"<Result {self.model.name!r}: {len(self.t)} samples, t = {self.t[0]:g} .. "
                f"{self.t[-1]:g}, events {self.events}>")

    def compute_outputs(self, outputs=(), points=None, method="auto", frame="world"):
        """Evaluate reactions (``frame``: ``"world"`` or ``"child"`` components), energies
        and point trajectories along the stored motion."""
        model = self.model
        unknown = set(outputs) - set(OUTPUTS)
        if unknown:
            raise ModelError(f"unknown outputs {sorted(unknown)}; choose from {OUTPUTS}")
        n = len(self.t)
        if "reactions" in outputs:
            reac = {j: np.empty((n, 6)) for j in model.joints}
            efforts = {j: np.empty(n) for j in model.driven_joints}
            for k in range(n):
                r = model.reactions(self.q[k], self.u[k], self.t[k], method=method,
                                    frame=frame)
                for j, (f, m) in r.items():
                    reac[j][k, :3] = f
                    reac[j][k, 3:] = m
                for j, val in model.drive_efforts(self.q[k], self.u[k], self.t[k]).items():
                    efforts[j][k] = val
            self.reactions = reac
            self.drive_efforts = efforts
        if "energy" in outputs:
            self.energy = energy_balance(model, self.t, self.q, self.u)
            E = self.energy["balance"]
            scale = max(abs(E[0]), np.abs(self.energy["kinetic"]).max(),
                        np.abs(self.energy["potential"]).max(),
                        np.abs(self.energy["dissipated"]).max(),
                        np.abs(self.energy["work"]).max(), 1e-300)
            self.stats["energy_drift"] = float(np.abs(E - E[0]).max() / scale)
        if "momentum" in outputs:
            lin = np.empty((n, 3))
            ang = np.empty((n, 3))
            for k in range(n):
                lin[k], ang[k] = model.momentum(self.q[k], self.u[k], self.t[k])
            self.momentum = {"linear": lin, "angular": ang}
        if points:
            names = list(points)
            specs = [points[p] for p in names]
            traj = np.array([model.point_positions(self.q[k], specs, self.t[k])
                             for k in range(n)]).reshape(n, len(names), 3)
            self.points = {p: traj[:, k] for k, p in enumerate(names)}
        return self


CONDITION_WARNING = 1e10      # warn when cond(M) exceeds this: ~10 digits are at stake
SINGULARITY_WARNING = 1e-2    # warn when an Euler joint comes this close to its singularity


class _Monitor:
    """Watches accepted steps for Euler-angle joints approaching their singularity.

    Warns once per joint below ``SINGULARITY_WARNING``; stops the run (a failure message)
    below ``threshold`` or when a step crosses the singular configuration, before the angle
    rates blow up.
    """

    def __init__(self, model, threshold):
        self.model = model
        self.threshold = threshold
        self.warned = set()
        self.closest = {}
        self.last = {}

    def check_rows(self, ts, ys):
        """``check`` over the rows of a stretch of accepted steps, vectorized: returns
        ``(n, failure)`` -- the rows before the first failing one and the failure message
        (``None`` if every row is fine)."""
        if not self.model._euler_middle or not len(ts):
            return len(ts), None
        first_bad = len(ts)
        for joint, k, proper in self.model._euler_middle:
            signed = np.sin(ys[:, k]) if proper else np.cos(ys[:, k])
            previous = self.last.get(joint)
            before = np.concatenate([[previous[1] if previous else signed[0]], signed[:-1]])
            bad = np.flatnonzero((np.abs(signed) < self.threshold) | (before * signed < 0))
            if bad.size:
                first_bad = min(first_bad, int(bad[0]))
        # the rows up to the first failing one, through the one-row check (messages,
        # warnings and the closest approach exactly as step by step)
        if first_bad == len(ts):
            for joint, k, proper in self.model._euler_middle:
                signed = np.sin(ys[:, k]) if proper else np.cos(ys[:, k])
                dist = np.abs(signed)
                near = np.flatnonzero(dist < SINGULARITY_WARNING)
                if near.size and joint not in self.warned:
                    self.check(ts[near[0]], ys[near[0]])
                self.closest[joint] = min(self.closest.get(joint, np.inf), float(dist.min()))
                self.last[joint] = (ts[-1], signed[-1])
            return len(ts), None
        for i in range(first_bad + 1):
            failure = self.check(ts[i], ys[i])
            if failure:
                return i, failure
        return first_bad + 1, None          # not reached: row first_bad fails

    def check(self, t, y):
        if not self.model._euler_middle:
            return None
        for joint, k, proper in self.model._euler_middle:
            signed = np.sin(y[k]) if proper else np.cos(y[k])
            dist = abs(signed)
            previous = self.last.get(joint)
            self.last[joint] = (t, signed)
            self.closest[joint] = min(self.closest.get(joint, np.inf), dist)
            crossed = previous is not None and previous[1] * signed < 0
            if dist < self.threshold or crossed:
                where = (f"between t={previous[0]:.6g} and t={t:.6g}" if crossed
                         else f"at t={t:.6g} (distance {dist:.3g} < {self.threshold:g})")
                return (f"joint {joint!r}: its Euler angles reached their singular "
                        f"configuration {where}, where the angle rates are undefined and the "
                        "equations of motion singular.  Model the joint as 'spherical' (unit "
                        "quaternion), which has no singularity, or choose an Euler sequence "
                        "whose singularity the motion avoids")
            if dist < SINGULARITY_WARNING and joint not in self.warned:
                self.warned.add(joint)
                warnings.warn(f"joint {joint!r}: the Euler angles come close to their "
                              f"singularity at t={t:.6g} (distance {dist:.3g}); accuracy and step "
                              "size suffer -- a spherical (quaternion) joint avoids this",
                              SingularityWarning, stacklevel=4)
        return None


def _conditioning(model, q, t, stats, key):
    cond, weak = model.mass_matrix_condition(q, t)
    stats[key] = cond
    if cond > CONDITION_WARNING:
        warnings.warn(f"model {model.name!r} at t={t:.6g}: the mass matrix is nearly singular "
                      f"(condition number {cond:.3g}; about {np.log10(cond):.0f} of 16 digits "
                      f"are lost); speeds {', '.join(weak)} carry almost no inertia.  Check "
                      "the masses and inertias they move, or remove those degrees of freedom",
                      SingularityWarning, stacklevel=3)


class _RightHandSide:
    """``y = [q, u] -> [q', u']`` counting evaluations; NaN/Inf becomes an error."""

    def __init__(self, model, method):
        self.model = model
        self.method = method
        self.nq = model.nq
        self.evaluations = 0
        self.symbolic = None
        if method == "symbolic":        # generated from the closed-form equations
            from .symbolic import compiled_rhs
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


#: The defaults of every run -- Python, model files and the command line: DOP853 at
#: rtol 1e-9, atol 1e-12 (docs/accuracy.md says why).
DEFAULTS = {"integrator": "DOP853", "rtol": 1e-9, "atol": 1e-12, "method": "auto"}


def simulate(model, t_end, q0=None, u0=None, *, t0=0.0, integrator=DEFAULTS["integrator"],
             rtol=DEFAULTS["rtol"], atol=DEFAULTS["atol"], dt=None, method=DEFAULTS["method"], events=(), t_eval=None, max_step=np.inf,
             outputs=(), points=None, progress=None, singularity_threshold=1e-3,
             reactions_frame="world",
             compiled_loop=True, decimate=1, max_steps=None, max_samples=None,
             max_wall_time=None):
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
    DOP853, drives that ``mbdyn.programs`` translates); ``False`` forces the Python loop
    (scipy's solvers for RK45 and DOP853, which ``"scipy-RK45"`` and ``"scipy-DOP853"``
    also name).
    ``decimate``: fixed-step schemes store every ``decimate``-th step (and the last).

    Budgets (``mbdyn.limits``; ``docs/reliability.md``): ``max_steps`` integrator steps
    (default ``MAX_STEPS``), ``max_samples`` stored samples (default ``MAX_SAMPLES``;
    a fixed-step run that would exceed it is refused before it starts, with the estimate),
    ``max_wall_time`` seconds (default none).  A run that reaches a budget stops with a
    ``SimulationError`` that says which one and keeps the motion so far.

    Statistics include the mass matrix's condition number at the start and the end (a
    ``SingularityWarning`` when it is large), the largest quaternion drift and, with
    ``outputs=("energy",)``, the energy drift.

    Raises ``SimulationError`` (its ``result`` holds the motion up to the failure) when
    the integrator fails or NaN/Inf appears.
    """
    if not hasattr(model, "forward_dynamics") and hasattr(model, "compile"):
        model = model.compile()           # a System: compile it here
    if integrator not in INTEGRATORS:
        raise ModelError(f"unknown integrator {integrator!r}; use one of {', '.join(INTEGRATORS)}")
    if method not in ("auto",) + _METHODS + ("symbolic",):
        raise ModelError(f"unknown method {method!r}; use one of "
                         f"{', '.join(('auto',) + _METHODS + ('symbolic',))}")
    if method != "symbolic":
        method = model.formulation(method)   # "auto": by the model's size
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
    for name, value in (("rtol", rtol), ("atol", atol)):
        if not (np.isfinite(value) and value > 0):
            raise ModelError(f"{name} must be a positive number, got {value!r}")
    if not max_step > 0:
        raise ModelError(f"max_step must be positive, got {max_step!r}")
    budget = _budget(max_steps, max_samples, max_wall_time, decimate)
    budget["drives"] = [d[0] for d in getattr(model, "_driven", ())]
    if t_eval is not None:
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
    events = [as_event(e, model) for e in events]
    if events:
        check_conditions(events, model, t0, q, u)
    rhs = _RightHandSide(model, method)
    monitor = _Monitor(model, singularity_threshold)
    y0 = np.concatenate([q, u])
    failure = monitor.check(t0, y0)
    if failure:
        raise ModelError("the initial state is unusable: " + failure)
    pre_stats = {}
    _conditioning(model, q, t0, pre_stats, "mass_matrix_condition_initial")
    if integrator not in ADAPTIVE:
        dt = _check_fixed_step(integrator, dt, t0, t_end, t_eval, budget, 1 + y0.size)
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
    if integrator in ADAPTIVE:
        programs = None
        if (compiled_loop and integrator in COMPILED_ADAPTIVE
                and method in ("jourdain", "articulated")
                and not model.has_callable_loads and y0.size > 0):
            from .programs import drive_programs
            programs = drive_programs([d[3] for d in model._driven])
        if programs is not None:
            ts, ys, found, info = _run_adaptive_compiled(
                rhs, integrator, t0, t_end, y0, rtol, atol, max_step, events, t_eval,
                progress, monitor, budget, programs)
        else:
            ts, ys, found, info = _run_adaptive(rhs, integrator, t0, t_end, y0, rtol, atol,
                                                max_step, events, t_eval, progress, monitor,
                                                budget)
    else:
        compiled = (compiled_loop and method in ("jourdain", "articulated")
                    and not model.has_callable_loads)
        ts, ys, found, info = _run_fixed(rhs, integrator, t0, t_end, y0, float(dt), events,
                                         t_eval, progress, monitor, compiled, budget)
    wall = _time.perf_counter() - start
    ys = np.asarray(ys).reshape(len(ts), -1)
    stats = {"integrator": integrator, "method": method, "rtol": rtol, "atol": atol, "dt": dt,
             "rhs_evaluations": rhs.evaluations, "wall_time_s": wall,
             "quaternion_drift": model.quaternion_drift(ys[:, :model.nq])}
    stats.update(pre_stats)
    stats.update(info)
    if monitor.closest:
        stats["euler_singularity_distance"] = dict(monitor.closest)
    if "failure" not in info:
        _conditioning(model, ys[-1, :model.nq], ts[-1], stats, "mass_matrix_condition_final")
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
    if outputs or points:
        result.compute_outputs(outputs, points, frame=reactions_frame)
    return result


def _budget(max_steps, max_samples, max_wall_time, decimate):
    """The run's budgets, checked: ``{max_steps, max_samples, max_wall_time, decimate}``."""
    out = {"max_steps": limits.MAX_STEPS if max_steps is None else max_steps,
           "max_samples": limits.MAX_SAMPLES if max_samples is None else max_samples,
           "max_wall_time": limits.MAX_WALL_TIME if max_wall_time is None else max_wall_time,
           "decimate": decimate}
    for key in ("max_steps", "max_samples", "decimate"):
        v = out[key]
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ModelError(f"{key} must be a positive whole number, got {v!r}")
    w = out["max_wall_time"]
    if w is not None and (isinstance(w, bool) or not isinstance(w, (int, float))
                          or not w > 0 or not np.isfinite(w)):
        raise ModelError(f"max_wall_time must be a positive number of seconds, got {w!r}")
    return out


def _check_fixed_step(integrator, dt, t0, t_end, t_eval, budget, width):
    """``dt`` as a float, after refusing what a fixed-step run cannot do: no or a bad
    ``dt``, more steps than ``max_steps``, more stored samples than ``max_samples`` (both
    known before the run starts)."""
    if dt is None or isinstance(dt, bool):
        raise ModelError(f"integrator {integrator!r} is fixed-step: give dt > 0")
    try:
        dt = float(dt)
    except (TypeError, ValueError):
        raise ModelError(f"dt must be a number, got {dt!r}") from None
    if not (np.isfinite(dt) and dt > 0):
        raise ModelError(f"integrator {integrator!r} is fixed-step: give dt > 0, got {dt!r}")
    steps = (t_end - t0) / dt
    if steps > budget["max_steps"]:
        raise ModelError(f"(t_end - t0) / dt = {steps:.3g} steps, more than max_steps = "
                         f"{budget['max_steps']}; take a larger dt, a shorter t_end, or "
                         "raise max_steps (--max-steps)")
    stored = len(t_eval) if t_eval is not None else steps / budget["decimate"] + 1
    if stored > budget["max_samples"]:
        raise ModelError(f"the run would store {stored:.3g} samples (about "
                         f"{stored * 8 * width / 1e9:.2g} GB of t, q and u), more than "
                         f"max_samples = {budget['max_samples']}; keep fewer (output_dt in a "
                         "model file, decimate or t_eval in Python) or raise max_samples "
                         "(--max-samples)")
    return dt


def _over_budget(budget, steps, stored, t, t_end, h=None):
    """The message of a budget the run has used up, or ``None``."""
    if steps >= budget["max_steps"]:
        stiff = ""
        if h is not None:
            stiff = (f"; the last step was {h:.3g} s -- a stiff model under an explicit "
                     "integrator takes tiny steps: try Radau or BDF")
        return (f"stopped after max_steps = {budget['max_steps']} steps at t={t:.6g} of "
                f"{t_end:.6g}{stiff}; or raise max_steps (--max-steps)")
    if stored > budget["max_samples"]:
        return (f"stopped at t={t:.6g}: the run has stored max_samples = "
                f"{budget['max_samples']} samples; keep fewer (output_dt, t_eval) or raise "
                "max_samples (--max-samples)")
    if budget["deadline"] is not None and _time.perf_counter() > budget["deadline"]:
        return (f"stopped at t={t:.6g} of {t_end:.6g}: the run took longer than "
                f"max_wall_time = {budget['max_wall_time']:g} s; raise it (--max-wall-time)")
    return None


#: every this many steps an adaptive run projects its step count from the median of its
#: last this many step sizes (a median: a burst of tiny steps at an impact does not count)
PROJECTION_STEPS = 1000


def _projected_over_budget(budget, steps, t, t_end, recent):
    """Stop early a run that cannot finish within ``max_steps`` at its current pace."""
    h = float(np.median(recent))
    if not h > 1e4 * np.finfo(float).eps * max(1.0, abs(t)):
        return None     # at the rounding limit: the integrator's own failure follows, precisely
    projected = steps + (t_end - t) / h
    if projected <= budget["max_steps"]:
        return None
    drives = budget.get("drives")
    suspects = (f"; or the drive of {', '.join(map(repr, drives))} grows without bound or "
                f"becomes singular near t={t:.6g}: check it" if drives else "")
    return (f"stopped at t={t:.6g} of {t_end:.6g} after {steps} steps: at its current step "
            f"size (median {h:.3g} s) the run would need about {projected:.2g} steps, more "
            f"than max_steps = {budget['max_steps']} -- a stiff model under an explicit "
            f"integrator takes tiny steps: try Radau or BDF{suspects}; or raise max_steps "
            "(--max-steps)")


def _describe_failure(model, exc, t, y):
    names = model.coordinates + model.speeds
    state = ", ".join(f"{n}={v:.6g}" for n, v in zip(names, y))
    return f"{exc} (integration stopped at t={t:.6g}; last good state: {state})"


def _event_values(events, model, t, y):
    nq = model.nq
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        values = np.array([float(e.condition(t, y[:nq], y[nq:])) for e in events])
    if not np.all(np.isfinite(values)):
        bad = [e.name for e, v in zip(events, values) if not np.isfinite(v)]
        raise NonFiniteError(f"event {', '.join(map(repr, bad))}: the condition is not a "
                             f"finite number at t={t:.6g} (e.g. a square root or logarithm "
                             "of a negative value, a division by zero), so its crossing "
                             "cannot be found; write a condition defined over the whole motion")
    return values


def _crossed(e, g_old, g_new):
    if e.direction > 0:
        return g_old < 0 <= g_new
    if e.direction < 0:
        return g_old > 0 >= g_new
    return (g_old < 0 <= g_new) or (g_old > 0 >= g_new)


def _run_adaptive(rhs, integrator, t0, t_end, y0, rtol, atol, max_step, events, t_eval,
                  progress, monitor, budget):
    model = rhs.model
    solver_cls = ADAPTIVE[integrator]
    failure = None
    try:
        solver = solver_cls(rhs, t0, y0, t_end, rtol=rtol, atol=atol, max_step=max_step)
    except (NonFiniteError, SingularMassMatrixError) as exc:
        raise SimulationError(_describe_failure(model, exc, t0, y0),
                              Result(model, [t0], y0[None, :model.nq], y0[None, model.nq:],
                                     [], {})) from exc
    ts, ys = [t0], [y0.copy()]
    if t_eval is not None:
        t_eval = np.asarray(t_eval, dtype=float)
        ts, ys = ([t0], [y0.copy()]) if t_eval.size and t_eval[0] == t0 else ([], [])
        next_eval = 1 if ts else 0
    g_old = _event_values(events, model, t0, y0) if events else None
    found = []
    steps = 0
    recent = collections.deque(maxlen=PROJECTION_STEPS)
    while solver.status == "running":
        t_prev, y_prev = solver.t, solver.y.copy()
        try:
            message = solver.step()
        except (NonFiniteError, SingularMassMatrixError) as exc:
            failure = _describe_failure(model, exc, t_prev, y_prev)
            break
        if solver.status == "failed":
            failure = (f"integrator {integrator} failed at t={solver.t:.6g}: {message}. "
                       "Loosen rtol/atol, or try an implicit method (Radau, BDF) if the "
                       "model is stiff")
            break
        steps += 1
        t_new, y_new = solver.t, solver.y
        failure = monitor.check(t_new, y_new)
        if failure:
            break
        stop_at = None
        if events:
            try:
                g_new = _event_values(events, model, t_new, y_new)
            except NonFiniteError as exc:
                failure = _describe_failure(model, exc, t_new, y_new)
                break
            dense = None
            hits = []
            for k, e in enumerate(events):
                if _crossed(e, g_old[k], g_new[k]):
                    dense = dense or solver.dense_output()
                    nq = model.nq

                    def g(tt, e=e):
                        yy = dense(tt)
                        return float(e.condition(tt, yy[:nq], yy[nq:]))
                    te = scipy.optimize.brentq(g, t_prev, t_new, xtol=4 * np.finfo(float).eps,
                                         rtol=4 * np.finfo(float).eps)
                    hits.append((te, e))
            for te, e in sorted(hits, key=lambda h: h[0]):
                if stop_at is not None:
                    break
                ye = dense(te)
                found.append(EventRecord(e.name, te, ye[:model.nq], ye[model.nq:],
                                         model.coordinates + model.speeds))
                if e.terminal:
                    stop_at = te
            g_old = g_new
        if t_eval is None:
            if stop_at is not None:
                ts.append(stop_at)
                ys.append(solver.dense_output()(stop_at))
            else:
                ts.append(t_new)
                ys.append(y_new.copy())
        else:
            t_hi = stop_at if stop_at is not None else t_new
            sel = t_eval[next_eval:]
            sel = sel[sel <= t_hi]
            if sel.size:
                dense = solver.dense_output()
                for te in sel:
                    ts.append(te)
                    ys.append(dense(te))
                next_eval += sel.size
            if stop_at is not None and (not ts or ts[-1] != stop_at):
                ts.append(stop_at)
                ys.append(solver.dense_output()(stop_at))
        if progress is not None:
            progress(ts[-1] if ts else t_new)
        if stop_at is not None:
            break
        if solver.status == "running":
            recent.append(t_new - t_prev)
            failure = _over_budget(budget, steps, len(ts), t_new, t_end, h=t_new - t_prev)
            if not failure and steps % PROJECTION_STEPS == 0:
                failure = _projected_over_budget(budget, steps, t_new, t_end, recent)
            if failure:
                break
    info = {"steps": steps, "njev": getattr(solver, "njev", 0), "nlu": getattr(solver, "nlu", 0),
            "solver_rhs_evaluations": solver.nfev, "compiled": False}
    if failure is not None:
        info["failure"] = failure
    if not ts:
        ts, ys = [solver.t], [solver.y.copy()]
    return np.array(ts), np.array(ys), found, info


#: accepted steps per compiled stretch: the first, and the most (with events: a terminal
#: event wastes at most a stretch); a stretch doubles while it takes under STRETCH_CPU s
STRETCH_FIRST, STRETCH_MOST, STRETCH_MOST_EVENTS, STRETCH_CPU = 64, 4096, 256, 0.02


def _event_rows(events, model, ts, ys):
    """Every event's condition at the rows ``(ts, ys)``: ``(len(ts), len(events))``, NaN
    and Inf left in.  Conditions from text or sympy are evaluated on the whole columns."""
    from .events import CompiledCondition
    nq = model.nq
    out = np.empty((len(ts), len(events)))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for k, e in enumerate(events):
            g = e.condition
            v = g.rows(ts, ys) if isinstance(g, CompiledCondition) else None
            out[:, k] = v if v is not None else [float(g(t, y[:nq], y[nq:]))
                                                 for t, y in zip(ts, ys)]
    return out


def _crossed_rows(e, g_old, g_new):
    """``_crossed`` over arrays."""
    up = (g_old < 0) & (g_new >= 0)
    down = (g_old > 0) & (g_new <= 0)
    return up if e.direction > 0 else down if e.direction < 0 else up | down


def _stretch_events(events, model, g_old, t_start, y_start, T, Y, H, out_K, tab, dense_args,
                    nfev, G=None):
    """The events of a stretch of accepted steps ``(T, Y, H)`` after ``(t_start, y_start)``
    (conditions ``g_old`` there; ``dense_args``: the drive programs and the model's arrays
    after ``dense_step``'s first ones): ``(G, ends, found)`` -- the conditions at every row, the
    rows where the stretch ends (``(row, 1, "event")`` at a non-finite condition,
    ``(row, 2, "terminal", t_event, state_at)``) and ``{row: [EventRecord, ...]}``, each
    crossing located by brentq on the step's dense polynomial.  ``G``: the conditions at the
    rows when the stretch computed them (it then ended at its first crossing, and ``out_K``
    holds that last step's stages in its last row)."""
    from .kernels.adaptive import dense_step, dense_values
    nq = model.nq
    ends, found = [], {}
    if G is None:
        G = _event_rows(events, model, T, Y)
    bad = np.flatnonzero(~np.all(np.isfinite(G), axis=1))
    if bad.size:
        ends.append((int(bad[0]), 1, "event"))
    last = int(bad[0]) if bad.size else len(T)
    before = np.vstack([g_old[None, :], G[:-1]])
    crossing = np.zeros(G.shape, bool)
    for k, e in enumerate(events):
        crossing[:last, k] = _crossed_rows(e, before[:last, k], G[:last, k])
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


def _stretch_budget_ends(budget, steps, kept, T, H, t_end, recent):
    """The first row of a stretch after which a budget is used up, as on scipy's path
    (checked after every step that did not finish the run): ``[(row, 3 or 4, "budget",
    message)]`` or ``[]``.  ``steps`` were taken before the stretch; ``kept[r]`` samples
    are stored after row ``r``; ``recent``: the step sizes before the stretch."""
    ends = []
    going = T < t_end
    counts = steps + 1 + np.arange(len(T))
    over = np.flatnonzero(going & ((counts >= budget["max_steps"])
                                   | (kept > budget["max_samples"])))
    if over.size:
        r = int(over[0])
        ends.append((r, 3, "budget", _over_budget(budget, int(counts[r]), int(kept[r]), T[r],
                                                  t_end, h=H[r])))
    history = np.concatenate([recent, H])
    for r in np.flatnonzero(going & (counts % PROJECTION_STEPS == 0)):
        tail = history[:len(recent) + r + 1][-PROJECTION_STEPS:]
        message = _projected_over_budget(budget, int(counts[r]), T[r], t_end, tail)
        if message:
            ends.append((int(r), 4, "budget", message))
            break
    return ends


def _run_adaptive_compiled(rhs, integrator, t0, t_end, y0, rtol, atol, max_step, events,
                           t_eval, progress, monitor, budget, programs):
    """RK45 or DOP853 as compiled stretches of accepted steps (``kernels.adaptive``): the
    same steps as scipy's solvers; after each stretch, in Python and on whole arrays: the
    singularity monitor, the events (crossings located by brentq on the compiled dense
    output), the budgets, progress.  Output times are sampled inside the stretch; the
    drives are evaluated there by their ``programs`` (``mbdyn.programs``)."""
    from .kernels.adaptive import TABLEAUS, initial_step, rk_stretch
    from .programs import EventPrograms
    model = rhs.model
    conditions = EventPrograms.of(events)       # None: the conditions are checked in Python
    nq, n = model.nq, y0.size
    tab = TABLEAUS[integrator]
    kind, A, B, C, E, E3, D = tab.arrays()
    if rtol < 100 * np.finfo(float).eps:        # as scipy's solvers do
        warnings.warn("At least one element of `rtol` is too small. Setting "
                      f"`rtol = np.maximum(rtol, {100 * np.finfo(float).eps})`.", stacklevel=3)
        rtol = 100 * np.finfo(float).eps

    def derivative(t, y):
        rhs.evaluations += 1
        return model.state_derivative(t, y, rhs.method)

    try:
        f = derivative(t0, y0)
        h_abs = initial_step(lambda h, y: derivative(t0 + h, y), y0, f, t_end - t0,
                             max_step, tab.order, rtol, atol)
    except (NonFiniteError, SingularMassMatrixError) as exc:
        raise SimulationError(_describe_failure(model, exc, t0, y0),
                              Result(model, [t0], y0[None, :nq], y0[None, nq:],
                                     [], {})) from exc
    start_evaluations = rhs.evaluations
    args = model.loop_arguments(rhs.method)
    dense_args = args[:2] + args[3:]                # dense_step takes no quaternion list
    if t_eval is not None:
        samples = np.empty((len(t_eval), n))
        i_eval = 1 if t_eval[0] == t0 else 0
        samples[:i_eval] = y0
        times, states = [t_eval[:i_eval]], [samples[:i_eval]]
        grid = t_eval
    else:
        samples = np.empty((0, n))
        i_eval = 0
        times, states = [np.array([t0])], [y0[None, :].copy()]
        grid = np.empty(0)
    stored = 1 if t_eval is None else i_eval
    g_old = _event_values(events, model, t0, y0) if events else None
    found = []
    steps = 0
    recent = np.empty(0)                            # the last PROJECTION_STEPS step sizes
    nfev = np.zeros(1, np.int64)
    fail = np.empty(n + 1)                          # a failing stage's time and state
    t, y = t0, y0.copy()
    stretch = STRETCH_FIRST
    most = STRETCH_MOST_EVENTS if events and conditions is None else STRETCH_MOST
    no_events = EventPrograms.none()
    failure = None
    while t < t_end and failure is None:
        m = int(min(stretch, budget["max_steps"] - steps))
        out_t, out_h = np.empty(m), np.empty(m)
        out_y = np.empty((m, n))
        out_nfev, out_ieval = np.empty(m, np.int64), np.empty(m, np.int64)
        out_K = np.empty((0 if not events else 1 if conditions else m, tab.stages, n))
        checks = no_events if conditions is None else conditions.arguments(g_old, m, True)
        t_start, y_start, i_start = t, y.copy(), i_eval
        cpu = _time.process_time()
        acc, status, h_abs, i_eval = rk_stretch(kind, A, B, C, E, E3, D, t, t_end, y, f,
                                                h_abs, rtol, atol, max_step, m, grid, i_eval,
                                                samples, *programs, *args, out_t, out_y,
                                                out_h, out_nfev, out_ieval, out_K, fail, nfev,
                                                checks)
        if _time.process_time() - cpu < STRETCH_CPU and stretch < most:
            stretch *= 2
        T, Y, H = out_t[:acc], out_y[:acc], out_h[:acc]
        # where this stretch ends: (row, reason) in the order a step is examined --
        # singularity monitor, events, budgets
        ends, G, hits_by_row = [], None, {}
        if events and acc:
            G, ends, hits_by_row = _stretch_events(
                events, model, g_old, t_start, y_start, T, Y, H, out_K, tab,
                programs + dense_args, nfev, None if conditions is None else checks[6][:acc])
        kept = (stored + 1 + np.arange(acc)) if t_eval is None else out_ieval[:acc]
        ends += _stretch_budget_ends(budget, steps, kept, T, H, t_end, recent)
        history = np.concatenate([recent, H])
        end = min(ends, key=lambda x: (x[0], x[1])) if ends else None
        upto = end[0] + 1 if end else acc
        n_ok, monitor_failure = monitor.check_rows(T[:upto], Y[:upto])
        if monitor_failure:
            end = (n_ok, 0, "monitor", monitor_failure)
        # the rows kept, the events found in them, the samples
        last_row = end[0] if end else acc - 1      # the last row examined
        keep = end[0] + (1 if end[2] == "budget" else 0) if end else acc
        for r in sorted(hits_by_row):
            if r < keep or (end and end[2] == "terminal" and r == end[0]):
                found.extend(hits_by_row[r])
        steps += last_row + 1
        stop_at = end[3] if end and end[2] == "terminal" else None
        if t_eval is None:
            times.append(T[:keep].copy())
            states.append(Y[:keep].copy())
            stored += keep
            if stop_at is not None:
                times.append(np.array([stop_at]))
                states.append(end[4](stop_at)[None, :])
                stored += 1
        else:
            upto_eval = (int(np.searchsorted(t_eval, stop_at, side="right"))
                         if stop_at is not None else out_ieval[keep - 1] if keep else i_start)
            upto_eval = min(max(upto_eval, i_start), i_eval if acc else i_start)
            times.append(t_eval[i_start:upto_eval])
            states.append(samples[i_start:upto_eval])
            stored = upto_eval
            if stop_at is not None and (upto_eval == 0 or t_eval[upto_eval - 1] != stop_at):
                times.append(np.array([stop_at]))
                states.append(end[4](stop_at)[None, :])
                stored += 1
        if G is not None and 0 <= last_row < acc:
            g_old = G[last_row]
        recent = history[:len(recent) + keep][-PROJECTION_STEPS:]
        if end:
            failure = None if end[2] == "terminal" else end[3] if end[2] != "event" else None
            if end[2] == "event":
                r = end[0]
                try:
                    _event_values(events, model, T[r], Y[r])
                except NonFiniteError as exc:
                    failure = _describe_failure(model, exc, T[r], Y[r])
            nfev_kept = int(out_nfev[end[0]])
        else:
            nfev_kept = int(nfev[0])
            if keep:
                t = T[-1]
        if progress is not None:
            last_t = times[-1][-1] if len(times) and len(times[-1]) else t
            progress(last_t)
        if end:
            rhs.evaluations = start_evaluations + nfev_kept
            break
        rhs.evaluations = start_evaluations + int(nfev[0])
        if status:
            if status == 4:
                failure = (f"integrator {integrator} failed at t={t:.6g}: Required step size "
                           "is less than spacing between numbers.. Loosen rtol/atol, or try "
                           "an implicit method (Radau, BDF) if the model is stiff")
            else:
                try:
                    model.state_derivative(fail[0], fail[1:])
                    exc = _LOOP_STATUS[status](model)
                except (NonFiniteError, SingularMassMatrixError) as raised:
                    exc = raised
                failure = _describe_failure(model, exc, t, y)
            break
        if t < t_end:
            failure = _over_budget(budget, steps, stored, t, t_end, h=H[-1] if acc else None)
    info = {"steps": steps, "njev": 0, "nlu": 0,
            "solver_rhs_evaluations": rhs.evaluations, "compiled": True}
    if failure is not None:
        info["failure"] = failure
    ts = np.concatenate(times) if times else np.empty(0)
    ys = np.vstack(states) if states else np.empty((0, n))
    if not len(ts):
        ts, ys = np.array([t]), y[None, :].copy()
    return ts, ys, found, info


def _fixed_chunks(rhs, integrator, t0, t_end, y0, dt, compiled, events=(), g_old=None):
    """Yield ``(times, states, failure, G)`` stretches of the fixed-step motion after ``y0``.

    Compiled path (``kernels.integrators``) when ``compiled``; else one Python step at a
    time.  Steps are of size ``dt``, the last one shortened to end at ``t_end``.  ``G``: the
    event conditions at the stretch's rows when the compiled loop evaluated them (their
    programs, ``mbdyn.programs.EventPrograms``; ``g_old`` at ``y0``), else ``None``; such a
    loop stops after a step where a terminal event occurred or a condition is not finite,
    and so does the motion.
    """
    model = rhs.model
    n_full = int(np.floor((t_end - t0) / dt * (1 + 1e-12)))
    times = t0 + dt * np.arange(1, n_full + 1)
    if n_full and times[-1] > t_end:
        times[-1] = t_end
    plan = [(dt, times)]
    if t_end - (times[-1] if n_full else t0) > 1e-12 * max(1.0, abs(t_end)):
        plan.append((t_end - (times[-1] if n_full else t0), np.array([t_end])))
    y = y0.copy()
    t = t0
    if compiled:
        from .kernels.integrators import LOOPS, SCHEMES, STAGES
        from .programs import EventPrograms
        loop = LOOPS[SCHEMES[integrator]]
        args = model.loop_arguments(rhs.method)
        conditions = EventPrograms.of(events)
        checks = EventPrograms.none()
        # stretches between checks in Python: short when there are events the loop cannot
        # check or Euler-angle singularities to watch (a terminal event or a singularity
        # wastes at most a stretch), long otherwise
        chunk = 200 if ((events and conditions is None) or model._euler_middle) else 2000
        for h, ts in plan:
            for lo in range(0, len(ts), chunk):
                tk = ts[lo:lo + chunk]
                starts = np.concatenate([[t], tk[:-1]])
                stage_times = (starts[:, None] + h * np.array(STAGES)[None, :]).reshape(-1)
                table = model.drive_values(stage_times).reshape(len(tk), len(STAGES), -1, 3)
                out = np.empty((len(tk) + 1, y.size))
                nfev = np.zeros(1, np.int64)
                if conditions is not None:
                    checks = conditions.arguments(g_old, len(tk), False)
                done, status = loop(h, y, table, *args, out, nfev, tk, checks)
                rhs.evaluations += int(nfev[0])
                failure = None
                if status:
                    t_fail = tk[done - 1] if done else t
                    failure = _describe_failure(model, _LOOP_STATUS[status](model), t_fail,
                                                out[done])
                G = None
                if conditions is not None:
                    G, g_old = checks[6][:done], checks[5]
                yield tk[:done], out[1:done + 1], failure, G
                if status or done < len(tk):
                    return
                t, y = tk[-1], out[-1].copy()
        return
    for h, ts in plan:
        for t_new in ts:
            try:
                y_new = _fixed_step(rhs, integrator, t, y, h, model.nq)
            except (NonFiniteError, SingularMassMatrixError) as exc:
                yield (np.empty(0), np.empty((0, y.size)), _describe_failure(model, exc, t, y),
                       None)
                return
            model.normalize_quaternions(y_new[:model.nq])
            if not np.all(np.isfinite(y_new)):
                bad = [n for n, v in zip(model.coordinates + model.speeds, y_new)
                       if not np.isfinite(v)]
                yield np.empty(0), np.empty((0, y.size)), _describe_failure(
                    model, NonFiniteError(f"the state became non-finite in {', '.join(bad)}"),
                    t, y), None
                return
            yield np.array([t_new]), y_new[None, :], None, None
            t, y = t_new, y_new


_LOOP_STATUS = {
    1: lambda m: NonFiniteError("NaN or Inf appeared in the state or the accelerations"),
    2: lambda m: SingularMassMatrixError("the mass matrix is not positive definite"),
    3: lambda m: NonFiniteError("the implicit midpoint's Newton iteration did not converge; "
                                "reduce dt"),
}


class _Samples:
    """The samples a fixed-step run keeps, gathered stretch by stretch (arrays, not rows):
    every ``every``-th step and the last one, or the states interpolated at ``t_eval``
    (linearly between the steps that bracket each time)."""

    def __init__(self, t0, y0, every=1, t_eval=None):
        self.every = every
        self.t_eval = None if t_eval is None else np.asarray(t_eval, dtype=float)
        self.next_eval = 0
        self.times, self.states = [], []
        self.count = 0                  # samples kept
        self.step = 0                   # steps seen
        self.last = (t0, y0)            # the newest state, kept or not
        self.last_kept = False
        self._add([t0], y0[None, :], first=True)

    def _add(self, ts, ys, first=False):
        ts = np.asarray(ts, dtype=float)
        if self.t_eval is not None:
            t_prev, y_prev = self.last
            lo = self.t_eval[self.next_eval:]
            sel = lo[lo <= ts[-1]] if len(ts) else lo[:0]
            if first:
                sel = lo[lo <= ts[0]]
            if sel.size:
                tt = np.concatenate([[t_prev], ts]) if not first else ts
                yy = np.vstack([y_prev[None, :], ys]) if not first else ys
                self.times.append(sel)
                self.states.append(np.column_stack([np.interp(sel, tt, yy[:, c])
                                                    for c in range(yy.shape[1])]))
                self.next_eval += sel.size
                self.count += sel.size
        else:
            if first:
                keep = np.array([0])
            else:
                index = self.step + 1 + np.arange(len(ts))
                keep = np.flatnonzero(index % self.every == 0)
            if keep.size:
                self.times.append(ts[keep])
                self.states.append(np.asarray(ys)[keep])
                self.count += keep.size
            self.last_kept = bool(len(ts)) and (first or keep.size and keep[-1] == len(ts) - 1)
        if len(ts):
            if not first:
                self.step += len(ts)
            self.last = (ts[-1], np.array(ys[-1], dtype=float))

    def add(self, ts, ys):
        if len(ts):
            self._add(ts, ys)

    def arrays(self):
        """``(t, y)`` of the kept samples; the last state is always among them (without
        ``t_eval``)."""
        if self.t_eval is None and not self.last_kept:
            self.times.append(np.array([self.last[0]]))
            self.states.append(self.last[1][None, :])
            self.last_kept = True
        if not self.times:
            return np.empty(0), np.empty((0, self.last[1].size))
        return np.concatenate(self.times), np.vstack(self.states)


def _run_fixed(rhs, integrator, t0, t_end, y0, dt, events, t_eval, progress, monitor,
               compiled, budget):
    model = rhs.model
    kept = _Samples(t0, y0, budget["decimate"], t_eval)
    t, y = t0, y0
    g_old = _event_values(events, model, t, y) if events else None
    found = []
    failure = None
    steps = 0
    stop = False
    for times, states, chunk_failure, G in _fixed_chunks(rhs, integrator, t0, t_end, y0, dt,
                                                         compiled, events, g_old):
        if events:
            processed, failure, stop, g_old = _fixed_stretch_events(
                events, model, monitor, t, y, g_old, times, states, found, G)
        else:
            processed, failure = monitor.check_rows(times, states)
        kept.add(times[:processed], states[:processed])
        steps += processed
        if processed:
            t, y = times[processed - 1], states[processed - 1]
        if progress is not None:
            progress(t)
        failure = failure or (None if stop else chunk_failure)  # past a terminal event: moot
        if failure or stop:
            break
        if t < t_end:
            failure = _over_budget(budget, steps, kept.count, t, t_end)
            if failure:
                break
    ts, ys = kept.arrays()
    if not len(ts):                     # t_eval entirely beyond a failure or an event
        ts, ys = np.array([t]), y[None, :]
    info = {"steps": steps, "compiled_loop": bool(compiled)}
    if budget["decimate"] > 1:
        info["samples_kept_every"] = budget["decimate"]
    if failure is not None:
        info["failure"] = failure
    return ts, ys, found, info


def _fixed_stretch_events(events, model, monitor, t, y, g_old, times, states, found, G=None):
    """The events of a stretch of fixed steps ``(times, states)`` after ``(t, y)`` (event
    conditions ``g_old`` there), vectorized over the rows but with the outcome of a
    step-by-step pass: each row is checked by ``monitor`` first, then its conditions; a
    crossing is located by linear interpolation between the two rows bracketing it and
    appended to ``found``; a terminal one ends the stretch after its row.  Returns
    ``(rows processed, failure or None, stopped at a terminal event, conditions at the
    last processed row)``.  ``G``: the conditions at the rows, if the loop computed them."""
    m = len(times)
    if G is None:
        G = _event_rows(events, model, times, states)
    finite = np.all(np.isfinite(G), axis=1)
    b = int(np.argmin(finite)) if not finite.all() else m      # first non-finite row
    before = np.vstack([g_old[None, :], G[:-1]])
    crossing = np.zeros((m, len(events)), bool)
    for j, e in enumerate(events):
        crossing[:b, j] = _crossed_rows(e, before[:b, j], G[:b, j])
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
            _event_values(events, model, times[b], states[b])    # raises its message
        except NonFiniteError as exc:
            failure = _describe_failure(model, exc, times[b], states[b])
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


def _fixed_step(rhs, integrator, t, y, h, nq):
    """One step of a fixed-step scheme in Python (models with callable loads)."""
    model = rhs.model
    if integrator == "euler":
        return y + h * rhs(t, y)
    if integrator == "semi-implicit-euler":
        q, u = y[:nq], y[nq:]
        rhs.evaluations += 1
        u_new = u + h * rhs.accelerations(q, u, t)
        q_new = q + h * model.coordinate_rates(q, u_new)
        return np.concatenate([q_new, u_new])
    if integrator == "implicit-midpoint":
        return _implicit_midpoint(rhs, t, y, h)
    k1 = rhs(t, y)
    k2 = rhs(t + h / 2, y + h / 2 * k1)
    k3 = rhs(t + h / 2, y + h / 2 * k2)
    k4 = rhs(t + h, y + h * k3)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def _implicit_midpoint(rhs, t, y, h):
    """``y1 = y + h F(t + h/2, (y + y1)/2)`` by Newton with a finite-difference Jacobian
    (the same algorithm as the compiled ``implicit_midpoint_step``)."""
    tm = t + h / 2
    ym = y + h / 2 * rhs(t, y)
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

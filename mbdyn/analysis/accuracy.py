"""What accuracy costs in time: work-precision studies of the integrators on one model.

A reference solution at tight tolerance (DOP853, rtol = atol = 1e-13) is cross-checked by a
second method (Radau at the same tolerance); their largest difference is reported as the
reference's own error estimate.  Every run of the sweep -- adaptive integrators over a range
of tolerances, fixed-step ones over a range of step sizes -- is scored by its error (the
largest coordinate error over evenly spaced samples of the whole run, not only the final
value), its energy drift when the model conserves energy, its wall time (median of
repeats) and its number of right-hand-side evaluations.
"""
from __future__ import annotations

import math
import re
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, SimulationError
from ..integrate.settings import ADAPTIVE, FIXED_STEP
from ..integrate.simulation import simulate

REFERENCE = ("DOP853", 1e-13)
#: a reference whose cross-check differs by more than this cannot score errors below it
REFERENCE_WARNING = 1e-6
CROSS_CHECK = "Radau"
TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)
DEFAULT_INTEGRATORS = ("RK45", "DOP853", "Radau", "LSODA", "semi-implicit-euler", "rk4",
                       "implicit-midpoint")


@dataclass
class Run:
    integrator: str
    setting: float                  # tolerance (adaptive) or step size (fixed-step)
    error: float
    energy_drift: float | None
    wall_time_s: float
    rhs_evaluations: int
    events: list = field(default_factory=list)
    failed: str | None = None

    def as_dict(self):
        """The run in issue 5's schema; a failed run has no error over the whole span, so
        its ``error`` is ``null`` (the text table shows the error up to the failure)."""
        finite = lambda x: x if x is None or math.isfinite(x) else None  # JSON has no Infinity
        return {"integrator": self.integrator, "setting": self.setting,
                "error": None if self.failed else finite(self.error),
                "energy_drift": self.energy_drift, "wall_time_s": self.wall_time_s,
                "rhs_evaluations": self.rhs_evaluations}


@dataclass
class Study:
    model_name: str
    t_end: float
    reference_events: list
    error_estimate: float
    reference_wall_time_s: float
    runs: list
    conservative: bool

    def as_dict(self):
        """The ``mbdyn accuracy --json`` object."""
        return {"reference": {"integrator": REFERENCE[0], "tolerance": REFERENCE[1],
                              "error_estimate": self.error_estimate},
                "runs": [r.as_dict() for r in self.runs]}

    def table(self):
        """The study as a plain-text table."""
        lines = [f"model {self.model_name!r}, t = 0 .. {self.t_end:g} s; reference "
                 f"{REFERENCE[0]} at {REFERENCE[1]:g}, error estimate "
                 f"{self.error_estimate:.2e} (vs {CROSS_CHECK}); reference events: "
                 + (", ".join(f"{n} at {t:.6g} s" for n, t in self.reference_events) or "none"),
                 f"{'integrator':<20} {'setting':>9} {'error':>10} {'energy drift':>13} "
                 f"{'wall [s]':>10} {'rhs evals':>10}  events"]
        for r in self.runs:
            drift = "-" if r.energy_drift is None else f"{r.energy_drift:.2e}"
            ev = r.failed or ", ".join(f"{n} {t:.4g}" for n, t in r.events)
            lines.append(f"{r.integrator:<20} {r.setting:>9.2e} {r.error:>10.2e} {drift:>13} "
                         f"{r.wall_time_s:>10.4f} {r.rhs_evaluations:>10d}  {ev}")
        return "\n".join(lines)


def default_steps(t_end, samples=201, multiples=(1, 3, 10, 30, 100, 300)):
    """Step sizes for the fixed-step sweep: ``t_end / ((samples - 1) m)``, so that every
    sample time is a step time (other steps are sampled by the runs' cubic Hermite output,
    whose error, of order h^4, is below the schemes' own)."""
    return tuple(t_end / ((samples - 1) * m) for m in multiples)


def _conserves_energy(model):
    """No drives and no loads: gravity is the only force, so ``T + V`` is conserved."""
    return not model.driven_joints and not model.loads


#: a scored run stops after this many time budgets (it is then reported as failed), the
#: reference after this many
RUN_BUDGET_FACTOR = 5.0
REFERENCE_BUDGET_FACTOR = 30.0


def accuracy_study(model, q0=None, u0=None, t_end=1.0, *, integrators=DEFAULT_INTEGRATORS,
                   tolerances=TOLERANCES, steps=None, events=(), samples=201, repeats=3,
                   time_budget_s=20.0, method="jourdain", progress=None, atol=None):
    """Run the work-precision sweep; returns a ``Study``.

    ``steps``: step sizes of the fixed-step schemes (default ``default_steps``).  ``atol``:
    the adaptive runs' absolute tolerance (default: each tolerance / 1000).  Runs of
    one integrator stop when a single run takes longer than ``time_budget_s``.  With
    terminal ``events`` every run is compared with the reference on the time span both
    cover.
    """
    unknown = [i for i in integrators if i not in ADAPTIVE and i not in FIXED_STEP]
    if unknown:
        raise ModelError(f"unknown integrators {unknown}; choose from "
                         f"{', '.join(tuple(ADAPTIVE) + FIXED_STEP)}")
    steps = tuple(steps) if steps is not None else default_steps(t_end, samples)
    t_samples = np.linspace(0.0, t_end, samples)
    conservative = _conserves_energy(model)
    outputs = ("energy",) if conservative else ()

    t0 = time.perf_counter()
    # the reference may take longer than a scored run, but not without bound
    limit = REFERENCE_BUDGET_FACTOR * time_budget_s
    try:
        ref = simulate(model, t_end, q0, u0, integrator=REFERENCE[0], rtol=REFERENCE[1],
                       atol=REFERENCE[1], t_eval=t_samples, events=events, method=method,
                       max_wall_time=limit)
        ref_wall = time.perf_counter() - t0
        check = simulate(model, t_end, q0, u0, integrator=CROSS_CHECK, rtol=REFERENCE[1],
                         atol=REFERENCE[1], t_eval=t_samples, events=events, method=method,
                         max_wall_time=limit)
    except SimulationError as exc:
        raise SimulationError(f"the reference solution could not be computed: {exc} -- a "
                              f"shorter t_end, or a larger time budget (now {time_budget_s:g} "
                              f"s per run, {limit:g} s for the reference)", exc.result) from exc
    n = min(len(ref.t), len(check.t))
    error_estimate = float(np.abs(ref.q[:n] - check.q[:n]).max()) if n else float("nan")
    if not error_estimate <= REFERENCE_WARNING:
        warnings.warn(f"the reference ({REFERENCE[0]} at {REFERENCE[1]:g}) and its "
                      f"{CROSS_CHECK} cross-check differ by {error_estimate:.2g}: errors "
                      "smaller than that cannot be measured on this run (chaotic motion or a "
                      "stiff model); a shorter --t-end gives a trustworthy reference",
                      stacklevel=2)

    runs = []
    for integ in integrators:
        settings = tolerances if integ in ADAPTIVE else steps
        _warm_up(model, q0, u0, t_end, integ, settings[0], method)
        for setting in settings:
            run = _score(model, q0, u0, t_end, integ, setting, events, t_samples, ref,
                         outputs, repeats, method, time_budget_s, atol)
            runs.append(run)
            if progress is not None:
                progress(run)
            if run.wall_time_s > time_budget_s:
                break
    return Study(model.name, t_end, list(ref.events), error_estimate, ref_wall, runs,
                 conservative)


def _warm_up(model, q0, u0, t_end, integ, setting, method):
    """A few untimed steps, so that compiling a kernel (numba, first use in a process)
    is not charged to the first timed run."""
    kwargs = {"rtol": 1e-3, "atol": 1e-6} if integ in ADAPTIVE else {"dt": setting}
    span = min(t_end, 5 * setting) if integ not in ADAPTIVE else min(t_end, 1e-3)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            simulate(model, span, q0, u0, integrator=integ, method=method, **kwargs)
    except SimulationError:
        pass


def _score(model, q0, u0, t_end, integ, setting, events, t_samples, ref, outputs, repeats,
           method, time_budget_s=20.0, atol=None):
    kwargs = dict(integrator=integ, events=events, method=method, outputs=outputs,
                  t_eval=t_samples, max_wall_time=RUN_BUDGET_FACTOR * time_budget_s)
    if integ in ADAPTIVE:
        kwargs.update(rtol=setting, atol=setting * 1e-3 if atol is None else atol)
    else:
        kwargs.update(dt=setting)
    walls = []
    res = None
    failed = None
    for k in range(repeats):
        start = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = simulate(model, t_end, q0, u0, **kwargs)
        except SimulationError as exc:
            res = exc.result
            failed = "failed: " + re.split(r"\.\s", str(exc))[0]
        walls.append(time.perf_counter() - start)
        if failed or walls[-1] > 1.0:     # slow runs are not repeated
            break
    error = _max_error(res, ref)
    drift = res.stats.get("energy_drift") if outputs and res is not None else None
    return Run(integ, float(setting), error, drift, float(np.median(walls)),
               int(res.stats.get("rhs_evaluations", 0)) if res is not None else 0,
               list(res.events) if res is not None else [], failed)


def _max_error(res, ref):
    """Largest coordinate error over the sample times both runs cover (adaptive runs are
    sampled on their dense output, fixed-step runs at step times; a run stopped by a
    terminal event ends with a row at its event time, which is compared only when the
    reference has a row at exactly that time)."""
    if res is None or len(res.t) < 2:
        return float("inf")
    n = min(len(res.t), len(ref.t))
    same = res.t[:n] == ref.t[:n]
    if not same.any():
        return float("inf")
    return float(np.abs(res.q[:n][same] - ref.q[:n][same]).max())

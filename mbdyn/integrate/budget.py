"""A run's budgets (``mbdyn.limits``; ``docs/reliability.md``): steps, stored samples and
wall-clock time, checked before a fixed-step run starts, after every step or stretch, and
projected from the recent step sizes, so that a run that cannot finish stops early with
the reason.
"""
from __future__ import annotations

import time as _time
import warnings

import numpy as np

from .. import limits
from ..errors import ModelError, ModelWarning


def make_budget(max_steps, max_samples, max_wall_time, decimate):
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


def check_fixed_step(integrator, dt, t0, t_end, t_eval, budget, width):
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


def over_budget(budget, steps, stored, t, t_end, h=None):
    """The message of a budget the run has used up, or ``None``."""
    if steps >= budget["max_steps"]:
        stiff = ""
        if h is not None:
            stiff = f"; the last step was {h:.3g} s -- {slow_pace_hint(budget)}"
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


#: an adaptive run that at its pace needs more than ``STIFF_STEPS`` steps for at most
#: ``STIFF_SPAN`` seconds of a model of at most ``STIFF_SPEEDS`` speeds is warned about
#: once: it looks stiff or mis-scaled (lengths in mm, stiffnesses in N/mm ...)
STIFF_STEPS = 1_000_000
STIFF_SPAN = 10.0
STIFF_SPEEDS = 12


def warn_stiff(budget, projected, h):
    """The warning of a run that looks stiff or mis-scaled (``STIFF_STEPS``), once."""
    speeds, span = budget.get("speeds"), budget.get("span")
    if (budget.get("stiff_warned") or speeds is None or projected <= STIFF_STEPS
            or span > STIFF_SPAN or speeds > STIFF_SPEEDS):
        return
    budget["stiff_warned"] = True
    warnings.warn(f"at its current pace (median step {h:.3g} s) the run needs about "
                  f"{projected:.2g} steps for {span:g} s of a model with {speeds} speeds: "
                  f"it looks stiff or mis-scaled -- {slow_pace_hint(budget)} (lengths in mm "
                  "or stiffnesses in N/mm where SI is meant make a model stiff)", ModelWarning,
                  stacklevel=2)


def projected_over_budget(budget, steps, t, t_end, recent):
    """Stop early a run that cannot finish within ``max_steps`` at its current pace (and
    warn about one that can but looks stiff or mis-scaled: ``warn_stiff``)."""
    h = float(np.median(recent))
    if not h > 1e4 * np.finfo(float).eps * abs(t):
        return None     # at the rounding limit: the integrator's own failure follows, precisely
    projected = steps + (t_end - t) / h
    if projected <= budget["max_steps"]:
        warn_stiff(budget, projected, h)        # it goes on (a stop says as much itself)
        return None
    drives = budget.get("drives")
    suspects = (f"; or the drive of {', '.join(map(repr, drives))} grows without bound or "
                f"becomes singular near t={t:.6g}: check it" if drives else "")
    return (f"stopped at t={t:.6g} of {t_end:.6g} after {steps} steps: at its current step "
            f"size (median {h:.3g} s) the run would need about {projected:.2g} steps, more "
            f"than max_steps = {budget['max_steps']} -- {slow_pace_hint(budget)}{suspects}; "
            "or raise max_steps (--max-steps)")


#: integrators that solve implicit equations each step (stable on stiff models)
IMPLICIT = ("Radau", "BDF", "LSODA", "implicit-midpoint")


def slow_pace_hint(budget):
    """Why a run may take tiny steps, and what to do, for the run's integrator."""
    integrator = budget.get("integrator")
    if integrator in IMPLICIT:
        return (f"the implicit integrator {integrator} takes tiny steps too, so the motion "
                "itself is fast (an undamped stiff oscillation, which any integrator must "
                "follow, or a very fast rotation) or not smooth: check the stiffnesses and "
                "the units, loosen rtol/atol, or shorten t_end")
    return ("a stiff model under an explicit integrator takes tiny steps: try Radau or BDF, "
            "and check the stiffnesses and the units")


def stretch_budget_ends(budget, steps, kept, T, H, t_end, recent):
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
        ends.append((r, 3, "budget", over_budget(budget, int(counts[r]), int(kept[r]), T[r],
                                                  t_end, h=H[r])))
    history = np.concatenate([recent, H])
    for r in np.flatnonzero(going & (counts % PROJECTION_STEPS == 0)):
        tail = history[:len(recent) + r + 1][-PROJECTION_STEPS:]
        message = projected_over_budget(budget, int(counts[r]), T[r], t_end, tail)
        if message:
            ends.append((int(r), 4, "budget", message))
            break
    return ends

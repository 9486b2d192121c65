"""What a run is worth: its energy balance drift, its quaternion drift and, on request, an
estimate of its error (the same run again at half the step, or at a tolerance a hundred
times tighter, the difference per coordinate); a figure above the threshold
(``mbdyn.limits.WARN_THRESHOLD``, settable) is a warning that names it and the remedy.

``estimate_error`` is ``simulate(error_estimate=True)``; ``assess`` is ``Result.quality``
and the report of ``mbdyn run`` (printed and ``--json``).
"""
from __future__ import annotations

import warnings

import numpy as np

from .. import limits
from ..errors import ModelError, SimulationError
from .settings import ADAPTIVE

#: the tightest tolerance an error estimate runs at (scipy refuses rtol < 100 eps)
TIGHTEST_RTOL = 1e-13
#: the most samples a conservative run's energy is evaluated at when the run did not
#: compute its energies (evenly spread; the drift over them is a lower bound)
ENERGY_SAMPLES = 20_000


def estimate_error(result, rerun, integrator, rtol, atol, dt):
    """``result.stats["error_estimate"]``: ``rerun(**settings)`` is the same run at half
    the step (fixed-step) or at ``rtol/100``, ``atol/100`` (adaptive), sampled at the
    run's own times; the difference per coordinate and speed, largest over the samples
    both runs have, and the largest relative to its coordinate's scale."""
    if integrator in ADAPTIVE:
        tighter = {"rtol": max(rtol / 100, TIGHTEST_RTOL), "atol": atol / 100}
        if tighter["rtol"] >= rtol:
            result.stats["error_estimate"] = {
                "against": None, "failed": f"rtol = {rtol:g} is already the tightest "
                "tolerance an estimate can run at"}
            return
        against = f"rtol = {tighter['rtol']:g}, atol = {tighter['atol']:g}"
    else:
        tighter = {"dt": dt / 2}
        against = f"dt = {dt / 2:g}"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fine = rerun(t_eval=result.t, **tighter)
    except (ModelError, SimulationError) as exc:
        result.stats["error_estimate"] = {"against": against,
                                          "failed": " ".join(str(exc).split())}
        return
    result.stats["error_estimate"] = {"against": against,
                                      **difference(result, fine)}


def difference(coarse, fine):
    """``{"difference": {name: largest |coarse - fine|}, "relative": largest of them over
    its coordinate's scale, "worst": its name}`` at the times both results have."""
    _, i, j = np.intersect1d(coarse.t, fine.t, return_indices=True)
    a = np.hstack([coarse.q[i], coarse.u[i]])
    b = np.hstack([fine.q[j], fine.u[j]])
    names = list(coarse.coordinates) + list(coarse.speeds)
    if not len(i):
        return {"difference": dict.fromkeys(names), "relative": None, "worst": None}
    diff = np.abs(a - b).max(axis=0)
    every = np.hstack([coarse.q, coarse.u])
    scale = np.maximum(np.abs(every).max(axis=0), np.ptp(every, axis=0))
    rel = np.where(scale > 0, diff / np.where(scale > 0, scale, 1.0),
                   np.where(diff > 0, np.inf, 0.0))
    k = int(np.argmax(rel))
    return {"difference": {n: float(d) for n, d in zip(names, diff)},
            "relative": float(rel[k]), "worst": names[k]}


def conservative(model):
    """Gravity the only force: no loads, drives or force elements, so ``T + V`` is
    constant along the exact motion, with no quadrature in its balance."""
    return not (model.loads or model.driven_joints or getattr(model, "forces", None)
                or getattr(model, "flexible_forces", False))


def energy_drift(result):
    """The energy balance drift of ``result`` (``stats["energy_drift"]`` when the run
    computed its energies; else, for a conservative model, ``max |E - E(0)|`` of ``E = T
    + V`` over the energy scale at up to ``ENERGY_SAMPLES`` samples); ``None`` when not
    available (a model with loads, drives or force elements whose run did not compute its
    energy balance)."""
    if "energy_drift" in result.stats:
        return result.stats["energy_drift"]
    model = result.model
    if not conservative(model) or not len(result.t):
        return None
    rows = np.unique(np.linspace(0, len(result.t) - 1, min(len(result.t), ENERGY_SAMPLES))
                     .round().astype(int))
    TV = np.array([model.energy(result.q[k], result.u[k], result.t[k]) for k in rows])
    E = TV.sum(axis=1)
    scale = max(abs(E[0]), np.abs(TV).max(), 1e-300)
    return float(np.abs(E - E[0]).max() / scale)


def _remedy(stats):
    if stats.get("integrator") in ADAPTIVE:
        return ("tighten the tolerances (e.g. --rtol 1e-10 --atol 1e-12; rtol, atol in "
                "Python)")
    return "use DOP853 with rtol 1e-10 (--integrator DOP853 --rtol 1e-10), or a smaller dt"


def assess(result, threshold=None):
    """``{"energy_drift", "quaternion_drift", "error_estimate", "threshold", "warnings"}``
    of a run: the figures (``None`` where not available: no energy balance, no
    quaternion, no estimate asked for) and a sentence for each above ``threshold``
    (default ``limits.WARN_THRESHOLD``), naming the figure and the remedy."""
    threshold = limits.WARN_THRESHOLD if threshold is None else float(threshold)
    stats = result.stats
    drift = energy_drift(result)
    quat = stats.get("quaternion_drift") if result.model._quaternions else None
    estimate = stats.get("error_estimate")
    out = []
    if drift is not None and drift > threshold:
        out.append(f"the energy balance drifted by {drift:.3g} ({100 * drift:.3g} % of the "
                   f"energy scale; above the threshold {threshold:g}): the motion is not "
                   f"trustworthy -- {_remedy(stats)}")
    if quat is not None and quat > threshold:
        out.append(f"the joint quaternions drifted off unit length by {quat:.3g} (above "
                   f"the threshold {threshold:g}) -- {_remedy(stats)}")
    if estimate and estimate.get("relative") is not None and estimate["relative"] > threshold:
        worst = estimate["worst"]
        out.append(f"the error estimate of {worst} is {estimate['difference'][worst]:.3g} "
                   f"({100 * estimate['relative']:.3g} % of its scale; above the threshold "
                   f"{threshold:g}; against the same run at {estimate['against']}) -- "
                   f"{_remedy(stats)}")
    return {"energy_drift": drift, "quaternion_drift": quat, "error_estimate": estimate,
            "threshold": threshold, "warnings": out}

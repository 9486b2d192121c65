"""What a run of a closed mechanism adds: an initial state checked against the loop
constraints, and the report of how well the motion kept them (the drift of positions and
velocities, the rank of the constraints along the way: a singular configuration passed is
named, with its time and loop).
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import ModelError, SimulationError, SingularityWarning
from ..kernels.loop_solve import ROWS

#: an initial state off its constraints by less than this is projected silently
QUIET_PROJECTION = 1e-8
#: a run whose constraint drift exceeds this gets a warning (metres or dimensionless)
DRIFT_WARNING = 1e-8
#: the smallest kept singular value of the constraint Jacobian over the largest below
#: which a configuration is reported as near-singular (a planar four-bar 0.01 rad from
#: its links in line)
NEAR_SINGULAR = 1e-2


def closed_initial_state(model, q, u, t0):
    """``(q, u)`` on the constraints: projected when off by round-off, else an error that
    names the loop joint and points to ``Model.assemble``."""
    phi, psi = model.constraint_residuals(q, u, t0)
    scale = 1.0 + float(np.abs(u).max(initial=0.0))
    if np.abs(phi).max(initial=0.0) > QUIET_PROJECTION or \
            np.abs(psi).max(initial=0.0) > QUIET_PROJECTION * scale:
        bad = phi if np.abs(phi).max() > QUIET_PROJECTION else psi
        k = int(np.argmax(np.abs(bad)))
        what = "position" if bad is phi else "velocity"
        raise ModelError(
            f"model {model.name!r}: the initial state does not close the loop of joint "
            f"{model._row_joint[k]!r} ({what} constraint {model.constraint_rows[k]}: residual "
            f"{bad[k]:.3g}); assemble it first: q0, u0 = model.assemble(initial={{...held "
            "values...}}, initial_speeds={...}, guess={...}) (model files do this from "
            "[initial], [initial_speeds] and [guess])")
    q, u = model.project(q, u, t0)
    info = model._con[7]
    rank, ratio = model.constraint_rank(q, t0)
    info[2] = info[3] = rank                  # the run holds this rank (kernels.constrained)
    info[4] = ratio
    info[ROWS] = -1.0                         # rows to solve on: the first projection's
    return q, u


def release_rank(model):
    """After a run: evaluations decide the rank by the tolerance again."""
    model._con[7][2] = model._con[7][ROWS] = -1.0


def loop_report(model, result):
    """The samples projected onto the constraints, then ``stats["constraint_drift"]``
    (largest position residual over them; ``constraint_drift_unprojected`` before),
    ``stats["constraint_drift_velocity"]``, the constraints' rank at the start and its
    lowest along the run with the time; warnings for drift and singular passages."""
    stats = result.stats
    drift = drift_v = before = 0.0
    ranks = []
    for k, t in enumerate(result.t):
        phi = model.constraint_residuals(result.q[k], result.u[k], t)[0]
        before = max(before, float(np.abs(phi).max(initial=0.0)))
        # samples between steps come from the dense output (or scipy's solver, which does
        # not project): put them on the constraints as the steps are
        try:
            result.q[k], result.u[k] = model.project(result.q[k], result.u[k], t)
        except SimulationError:
            pass                      # reported below as drift
        phi, psi = model.constraint_residuals(result.q[k], result.u[k], t)
        drift = max(drift, float(np.abs(phi).max(initial=0.0)))
        drift_v = max(drift_v, float(np.abs(psi).max(initial=0.0)))
        ranks.append(model.constraint_rank(result.q[k], t))
    stats["constraint_drift"] = drift
    stats["constraint_drift_unprojected"] = before
    stats["constraint_drift_velocity"] = drift_v
    rank0 = ranks[0][0]
    stats["constraint_rank"] = rank0
    stats["mobility"] = model.nu - rank0
    low = min(range(len(ranks)), key=lambda k: (ranks[k][0], ranks[k][1]))
    # the steps' own lowest rank and conditioning (kernels.constrained keeps them): a
    # passage between two samples is seen there; its time is the nearest sample's
    info = model._con[7]
    rank_low = min(ranks[low][0], int(info[3]) if np.isfinite(info[3]) else rank0)
    ratio_low = min(ranks[low][1], float(info[4]))
    stats["constraint_conditioning_min"] = ratio_low
    where = f"near t={result.t[low]:.6g}"
    if rank_low < rank0:
        stats["singular_configuration"] = {"t": float(result.t[low]), "rank": rank_low}
        warnings.warn(
            f"model {model.name!r}: the loop constraints lose rank {where} (rank {rank_low} "
            f"instead of {rank0}): a singular configuration, where the mechanism's mobility "
            "jumps (e.g. a four-bar with its links in line).  The motion went on along the "
            "branch the inertia chose; check it, or avoid the configuration",
            SingularityWarning, stacklevel=3)
    elif ratio_low < NEAR_SINGULAR:
        stats["singular_configuration"] = {"t": float(result.t[low]), "rank": rank_low,
                                           "conditioning": ratio_low}
        warnings.warn(
            f"model {model.name!r}: the motion passes close to a singular configuration "
            f"{where} (the constraints' weakest direction fell to {ratio_low:.2g} of the "
            "strongest): the reactions grow large there and the assembly branch may switch "
            "(a four-bar with its links nearly in line); check the motion",
            SingularityWarning, stacklevel=3)
    if drift > DRIFT_WARNING:
        warnings.warn(f"model {model.name!r}: the loop constraints drifted by {drift:.3g} over "
                      "the run; tighten rtol/atol or reduce dt", SingularityWarning,
                      stacklevel=3)

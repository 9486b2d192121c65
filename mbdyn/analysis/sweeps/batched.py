"""Batched sweeps: members that share one compiled model (they differ only in the initial
state) advanced together in one compiled call of ``kernels.batched``."""
from __future__ import annotations

import numpy as np

from ...errors import ModelError
from .model_file import load_task


def batchable(scene, quantities):
    """Why ``scene`` cannot run batched (a sentence), or None if it can: a fixed-step
    integrator, the Jourdain method, no events, no Euler-angle joints (their singularity
    is checked per step), no Python-function loads, quantities among final/t_final/
    steps/rhs_evaluations (and events, which has no columns without events)."""
    from ...integrate.settings import FIXED_STEP
    s = scene.settings
    model = scene.model
    if s["integrator"] not in FIXED_STEP:
        return f"integrator {s['integrator']!r} is adaptive; batched runs are fixed-step"
    if s["method"] == "symbolic" or model.formulation(s["method"]) not in ("jourdain",
                                                                           "articulated"):
        return ("batched runs use M u' = f or the articulated-body algorithm (methods "
                f"'jourdain', 'articulated', 'auto'); this run's method is {s['method']!r}")
    if scene.events:
        return ("the model has events (batched members keep only their final state, "
                "not the events on the way)")
    if model._euler_middle:
        return "the model has Euler-angle joints (their singularity is checked per step)"
    if model.has_callable_loads:
        return "the model has Python-function loads"
    if getattr(model, "compiled_terms", False):
        return ("the model's compiled flexible terms have one workspace, which members on "
                "threads would share")
    # "events" has no columns here: a model with events was refused above
    bad = [q for q in quantities
           if q not in ("final", "t_final", "steps", "rhs_evaluations", "events")]
    if bad:
        return f"quantities {bad} need the whole motion; batched runs keep the final state"
    return None


def run_batched(scenes, quantities):
    """Rows of members that share one compiled model (their scenes differ only in the
    initial state), advanced together by ``kernels.batched.batched_fixed_step``."""
    from ...compiled.programs import EventPrograms
    from ...integrate.fixed_step import step_plan
    from ...kernels.batched import batched_fixed_step
    from ...kernels.integrators import SCHEMES, STAGES
    scene = scenes[0]
    model = scene.model
    s = scene.settings
    t0, t_end, dt = 0.0, float(s["t_end"]), float(s["dt"])
    times, h_last = step_plan(t0, t_end, dt)                       # as simulate plans it
    n_full = len(times)
    t_last = times[-1] if n_full else t0
    starts = np.concatenate([[t0], times[:-1]])[:n_full]
    stage = (starts[:, None] + dt * np.array(STAGES)[None, :]).reshape(-1)
    table = model.drive_values(stage).reshape(n_full, len(STAGES), -1, 3)
    last = model.drive_values(t_last + h_last * np.array(STAGES)).reshape(1, len(STAGES), -1, 3)
    Y0 = np.array([np.concatenate([sc.q0, sc.u0]) for sc in scenes])
    for y in Y0:
        model.normalize_quaternions(y[:model.nq])
    m = len(scenes)
    Yend = np.empty_like(Y0)
    done = np.zeros(m, np.int64)
    status = np.zeros(m, np.int64)
    nfev = np.zeros(m, np.int64)
    # numba's scope warning on compiling this call is filtered by mbdyn.kernels, as for
    # every compiled loop
    batched_fixed_step(SCHEMES[s["integrator"]], dt, n_full, h_last, Y0, table, last,
                       *model.loop_arguments(model.formulation(s["method"])), Yend, done,
                       status, nfev, EventPrograms.none())
    all_times = np.append(times, t_end) if h_last else times
    rows = []
    for i, sc in enumerate(scenes):
        q = Yend[i, :model.nq].copy()
        model.normalize_quaternions(q)
        row = {"status": "ok", "error": ""}
        if status[i]:
            row.update(status="failed", error=f"loop status {int(status[i])} (NaN/Inf or a "
                       f"singular mass matrix) after {int(done[i])} steps")
        for qn in quantities:
            if qn == "final":
                row.update({f"final.{n}": float(v) for n, v in zip(model.coordinates, q)})
                row.update({f"final.{n}": float(v)
                            for n, v in zip(model.speeds, Yend[i, model.nq:])})
            elif qn == "t_final":
                row["t_final"] = float(all_times[done[i] - 1]) if done[i] else t0
            elif qn == "steps":
                row["steps"] = float(done[i])
            elif qn == "rhs_evaluations":
                row["rhs_evaluations"] = float(nfev[i])
        rows.append(row)
    return rows


def run_batch_task(task):
    """A worker's share of a batched sweep: ``task["members"]`` in one compiled call."""
    scenes, rows = [], []
    for member in task["members"]:
        try:
            scenes.append(load_task(task, member))
            rows.append(None)
        except ModelError as exc:
            rows.append({"status": "error", "error": " ".join(str(exc).split())})
    ok = [i for i, r in enumerate(rows) if r is None]
    # members that share one compiled model: group by everything but the initial state
    groups = {}
    for i in ok:
        m = task["members"][i]
        key = (m["case"], tuple((p, repr(v)) for p, v in m["overrides"]
                                if not p.startswith(("initial.", "initial_speeds."))))
        groups.setdefault(key, []).append(i)
    for idx in groups.values():
        for i, r in zip(idx, run_batched([scenes[ok.index(i)] for i in idx],
                                          task["quantities"])):
            rows[i] = r
    for member, r in zip(task["members"], rows):
        r["member"] = member["index"]
    return rows

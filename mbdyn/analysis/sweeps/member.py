"""One member run by a worker: ``run_member`` takes plain data and returns the member's
row, whatever happens to its simulation."""
from __future__ import annotations

import warnings

from ...errors import ModelError, SimulationError
from .model_file import load_task
from .quantities import measure, needs_energy


def run_member(task):
    """Run one member (``task``: plain data, see ``Sweep.tasks``); returns its row
    ``{"member": i, "status": "ok"|"failed"|"error", "error": text, column: value}``."""
    member = task["member"]
    row = {"member": member["index"], "status": "ok", "error": ""}
    try:
        scene = load_task(task, member)
    except ModelError as exc:
        row.update(status="error", error=" ".join(str(exc).split()))
        return row
    qs = task["quantities"]
    kw = {"outputs": ("energy",) if needs_energy(qs) else (), "points": {}}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = scene.simulate(**kw)
    except SimulationError as exc:
        row.update(status="failed", error=" ".join(str(exc).split()))
        result = exc.result
        if result is None:
            return row
        if needs_energy(qs) and len(result.t):
            try:
                result.compute_outputs(("energy",), None)
            except Exception:            # the failed state may not evaluate: keep NaN
                pass
    except ModelError as exc:
        row.update(status="error", error=" ".join(str(exc).split()))
        return row
    row.update(measure(scene, result, qs))
    return row

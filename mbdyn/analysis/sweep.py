"""Parameter sweeps and ensembles: run one model file over a grid or a list of overrides
and keep a few quantities of each member in a table.

A *member* is plain data -- the model file's text, a case and ``(dotted path, value)``
overrides as ``mbdyn run --set`` takes them -- so it can go to another process or machine
(``schedulers``); each worker loads it with ``mbdyn.io.load_model`` and numba's on-disk
cache makes the compile a load.  Rows are written to the CSV as members finish (flushed
and synced), so an interrupted sweep keeps its finished members and ``resume=True``
completes it; the table is sorted by member number, so it does not depend on the
scheduler or on the order in which members finish.

Quantities (``quantities=``; default ``("final", "events", "t_final")``):

* ``"final"``: the final coordinates and speeds, columns ``final.NAME``;
* ``"t_final"``: the time reached (a terminal event or a failure stops earlier);
* ``"events"``: the time of each event's first occurrence, ``event.NAME`` (NaN: never);
* ``"max:X"``, ``"min:X"``, ``"absmax:X"``, ``"mean:X"``, ``"std:X"`` of a coordinate or a
  speed ``X`` (or ``energy``, the total T + V) over the motion, columns ``max.X`` ...;
* ``"energy_drift"``: final minus initial total energy (J);
* ``"steps"``, ``"rhs_evaluations"``.

A member whose simulation fails keeps its row: ``status`` is ``failed`` and ``error``
holds the reason; its quantities are those of the motion up to the failure.  A member
whose overrides cannot be used has ``status = error``.

The parts are in ``mbdyn.analysis.sweeps``, one job a module (members and grids, the model
file, quantities, one member, batched runs, the table, reading it back, the checks before
the work, progress); this module runs them and keeps their names.  Note on layers: members
are model files, so running one imports ``mbdyn.io`` -- lazily, inside
``sweeps.model_file`` and ``sweeps.grid``, the only places where *analysis* reaches up
to *io*.
"""
from __future__ import annotations

import hashlib
import json
import math
import sys
import time

from .. import files
from .schedulers import make_scheduler
from .sweeps.batched import batchable, run_batch_task, run_batched
from .sweeps.checks import check_arguments, model_path, table_header, table_path
from .sweeps.grid import expand, parse_grid, parse_range
from .sweeps.member import run_member
from .sweeps.model_file import model_text
from .sweeps.progress import ANNOUNCE_AFTER, ESTIMATE_FROM, Callback, tqdm_bar
from .sweeps.progress import Progress as _Progress
from .sweeps.quantities import DEFAULT_QUANTITIES, SIMPLE, STATS, columns, measure
from .sweeps.resume import read_done, read_table
from .sweeps.table import FORMAT_LINE, STATUSES, Table, as_arrays, typed, write_parquet

#: the names of this module, as before its parts moved to ``sweeps`` (``ANNOUNCE_AFTER``
#: and ``ESTIMATE_FROM`` are read from here when a sweep starts)
__all__ = ["sweep", "SweepResult", "DEFAULT_QUANTITIES", "STATS", "SIMPLE", "STATUSES",
           "FORMAT_LINE", "ANNOUNCE_AFTER", "ESTIMATE_FROM", "parse_range", "parse_grid",
           "expand", "columns", "measure", "run_member", "batchable", "run_batched",
           "run_batch_task", "read_table", "write_parquet"]


class SweepResult:
    """The table of a finished sweep: ``columns``, ``rows`` (dicts in member order),
    ``table()`` (a pandas DataFrame if pandas is installed, else ``{column: array}``),
    ``arrays()`` (always ``{column: array}``), ``path`` (the CSV) and ``stats``."""

    def __init__(self, header, rows, path, stats):
        self.columns, self.rows, self.path, self.stats = header, rows, path, stats

    def arrays(self):
        return as_arrays(self.columns, self.rows)

    def table(self):
        arrays = self.arrays()
        try:
            import pandas as pd
        except ImportError:
            return arrays
        return pd.DataFrame(arrays, columns=self.columns)

    def __len__(self):
        return len(self.rows)

    def __repr__(self):
        bad = sum(r.get("status") != "ok" for r in self.rows)
        return f"<SweepResult {len(self.rows)} members ({bad} not ok), {self.columns}>"


def sweep(model, overrides=None, quantities=DEFAULT_QUANTITIES, *, cases=None, fixed=None,
          scheduler="serial", workers=None, out=None, resume=False, batched=False,
          batch_size=None, progress=None, require_columns=(), scheduler_timeout=None):
    """Run the model file ``model`` (a path or a ``Scene`` loaded from one) over
    ``overrides`` and return a ``SweepResult``.

    ``overrides``: a grid ``{path: values}`` (values a list, or a range text
    ``"START:STOP:N"``/``"START:STOP:N:log"``) or a list of ``{path: value}`` members.
    ``cases``: case names to sweep too (default: the scene's case or the file's default).
    ``fixed``: ``{path: value}`` applied to every member first (e.g. ``simulation.dt``).
    ``quantities``: see the module docstring.  ``scheduler``: ``"serial"``,
    ``"processes"``, ``"dask"``, ``"tcp://HOST:PORT"`` or a scheduler object
    (``schedulers``); ``workers``: local worker count.  ``out``: the CSV to write as
    members finish (``.parquet`` too if the name ends so and pyarrow is present), locked
    against a second sweep meanwhile, with its sidecar ``NAME.json`` (the sweep's
    fingerprint, model, quantities, columns, status); ``resume``: keep the finished rows
    of ``out`` and
    run only the rest.  ``batched``: advance members that share one compiled model in one
    compiled call (fixed-step schemes only; see ``batchable``), ``batch_size`` members per
    task.  ``progress``: ``True`` a progress bar on stderr (tqdm's if installed, else a
    counter line), a function ``progress(done, total)`` called after each member,
    ``False`` nothing, ``None`` (default) the counter when stderr is a terminal; a long
    sweep is announced with an estimate of its duration unless it is ``False``.
    ``require_columns``: columns the caller will need (e.g. to plot), checked up front.
    ``scheduler_timeout``: the longest wait, in seconds, on a Dask scheduler at an address
    (connection, handshake, each result, each check that it still answers; default
    ``limits.SCHEDULER_TIMEOUT``).

    Everything that can be checked is checked before any member runs: the arguments, the
    paths, the range texts, the quantities, an empty sweep, the table's name and folder.
    A bad argument raises ``ModelError`` naming it.
    """
    path, cases = model_path(model, cases)
    check_arguments(scheduler, quantities, cases, fixed, workers, batch_size, out, resume,
                    require_columns, scheduler_timeout, progress)
    text = model_text(path)
    members = expand(overrides, cases)
    quantities = tuple(quantities)
    fixed_list = [[p, v] for p, v in (fixed or {}).items()]
    head = table_header(path, text, members, fixed_list, quantities, cases, batched,
                        require_columns)
    for i, m in enumerate(members):
        m["index"] = i
    spec = _fingerprint(text, members, fixed_list, quantities)
    base = {"model_text": text, "model_name": str(path), "fixed": fixed_list,
            "quantities": list(quantities)}
    csv_path = table_path(out)
    lock = files.TableLock(csv_path) if csv_path else None
    meta = {"model": str(path), "members": len(members), "quantities": list(quantities),
            "fixed": dict(fixed or {}), "cases": None if cases is None else list(cases)}
    table = Table(csv_path, head, spec, meta) if csv_path else None
    try:
        if lock is not None:
            lock.acquire()
        rows = _kept_rows(table, resume, members)
        sched = make_scheduler(scheduler, workers, scheduler_timeout)
        start = time.perf_counter()
        todo = [m for m in members if m["index"] not in rows]
        try:
            if table is not None:
                table.open(list(rows.values()))
            if todo:
                _run(sched, todo, base, batched, batch_size, members, rows, table,
                     _progress(len(members), len(rows), progress), head)
        finally:
            if table is not None:
                table.close()
            sched.close()
        wall = time.perf_counter() - start
        ordered = [rows[i] for i in range(len(members))]
        # kept and fresh rows as the same values (numbers as floats, texts as texts)
        ordered = [{c: typed(r.get(c, ""), c) for c in head} for r in ordered]
        if table is not None:
            table.finish(ordered)
            if str(out).endswith(".parquet"):
                write_parquet(str(out), head, ordered)
    finally:
        if lock is not None:
            lock.release()
    stats = {"members": len(members), "ran": len(todo), "wall_time_s": wall,
             "scheduler": getattr(sched, "name", str(scheduler)), "batched": bool(batched)}
    return SweepResult(head, ordered, csv_path, stats)


def _fingerprint(text, members, fixed_list, quantities):
    """The sweep's fingerprint in its table's sidecar JSON: a resume is refused unless
    the model, members, fixed overrides and quantities are the same."""
    return hashlib.sha256(json.dumps([text, members, fixed_list, list(quantities)],
                                     default=repr).encode()).hexdigest()[:20]


def _kept_rows(table, resume, members):
    """``{member: row}`` of the rows a previous run wrote (``resume``), else empty."""
    if table is None or not resume:
        return {}
    return {r["member"]: r for r in read_done(table, members)}


def _progress(total, kept, progress):
    """What the sweep shows as members finish: nothing for ``progress=False``; for
    ``True`` a progress bar on stderr (tqdm's if tqdm is installed, else ``_Progress``'s
    counter line); a function ``progress(done, total)`` called after each member; by
    default (``None``) the counter when stderr is a terminal.  A long sweep is announced
    with an estimate of its duration unless ``progress`` is ``False``, a function or
    tqdm's bar (which shows its own)."""
    if progress is False:
        return None
    if callable(progress):
        return Callback(progress, total, kept)
    if progress is True:
        bar = tqdm_bar(total, kept)
        if bar is not None:
            return bar
    counter = bool(progress) if progress is not None else bool(
        getattr(sys.stderr, "isatty", lambda: False)())
    return _Progress(total, kept, counter, announce_after=ANNOUNCE_AFTER,
                     estimate_from=ESTIMATE_FROM)


def _tasks(todo, base, batched, batch_size, sched):
    """``(function, tasks)`` for the scheduler: one task per member, or per batch."""
    if not batched:
        return run_member, (dict(base, member=m) for m in todo)
    share = 1 if getattr(sched, "name", "") == "serial" else max(1, getattr(sched, "workers", 1))
    size = batch_size or max(1, math.ceil(len(todo) / share))
    return run_batch_task, (dict(base, members=todo[k:k + size])
                            for k in range(0, len(todo), size))


def _run(sched, todo, base, batched, batch_size, members, rows, table, bar, head):
    """Run the members ``todo``; each finished row is labelled with its member's overrides
    (and case), kept in ``rows`` and written to ``table``."""
    with_case = "case" in head
    fn, tasks = _tasks(todo, base, batched, batch_size, sched)
    try:
        for _, result in sched.map_unordered(fn, tasks):
            for row in (result if batched else [result]):
                m = members[row["member"]]
                row.update({p: v for p, v in m["overrides"]})
                if with_case:
                    row["case"] = m["case"]
                rows[row["member"]] = row
                if table is not None:
                    table.write(row)
                if bar is not None:
                    bar.update()
    finally:
        if bar is not None:
            bar.close()


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

Note on layers: members are model files, so running one imports ``mbdyn.io`` -- lazily,
inside the worker function, the one place where *analysis* reaches up to *io*.
"""
from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import math
import numbers
import os
import stat
import sys
import time
import warnings
from collections.abc import Iterable, Mapping

import numpy as np

from .. import files, limits
from ..errors import ModelError, SimulationError
from ..escape import spreadsheet_cell, spreadsheet_text
from .schedulers import check_spec, make_scheduler

DEFAULT_QUANTITIES = ("final", "events", "t_final")
STATS = ("max", "min", "absmax", "mean", "std")
SIMPLE = ("final", "events", "t_final", "energy_drift", "steps", "rhs_evaluations")
STATUSES = ("ok", "failed", "error")
FORMAT_LINE = "# mbdyn sweep table v1 spec="


# --------------------------------------------------------------------------- the grid

def parse_range(text, path="?"):
    """The values of one grid axis from its text: ``START:STOP:N`` (N points, both ends
    included), ``START:STOP:N:log`` (log spacing, same signs), a TOML array
    ``[a, b, "pi/4"]`` or a single value."""
    from ..io.schema import parse_set_value
    text = str(text).strip()
    if not text:
        raise ModelError(f"grid {path}: the values are empty; give START:STOP:N or [a, b, ...]")
    if text.startswith("["):
        try:
            values = parse_set_value(text)
        except ValueError as exc:
            raise ModelError(f"grid {path}={text}: {exc}") from None
        if not isinstance(values, list):
            raise ModelError(f"grid {path}={text}: not a list; write [a, b, ...] "
                             "(strings in quotes)")
        return values
    if ":" in text:
        parts = text.split(":")
        how = "lin"
        if len(parts) == 4:
            how = parts.pop().strip()
        if len(parts) != 3 or how not in ("lin", "log"):
            raise ModelError(f"grid {path}={text}: a range is START:STOP:N or "
                             "START:STOP:N:log, e.g. parameters.Mz=-0.03:-0.001:8")
        try:
            a, b = float(parts[0]), float(parts[1])
            n = int(parts[2])
        except ValueError:
            raise ModelError(f"grid {path}={text}: START and STOP must be numbers and N a "
                             "whole number, e.g. 0.1:0.5:5") from None
        if n < 1:
            raise ModelError(f"grid {path}={text}: N = {n} gives no members; use N >= 1")
        if n > limits.MAX_RANGE_POINTS:
            raise ModelError(f"grid {path}={text}: N = {n} is more than "
                             f"{limits.MAX_RANGE_POINTS} values on one axis")
        if how == "log":
            if a == 0 or b == 0 or (a > 0) != (b > 0):
                raise ModelError(f"grid {path}={text}: log spacing needs START and STOP "
                                 "non-zero and of one sign")
            sign = 1.0 if a > 0 else -1.0
            return (sign * np.geomspace(abs(a), abs(b), n)).tolist()
        return np.linspace(a, b, n).tolist()
    return [parse_set_value(text)]


def parse_grid(items):
    """``["PATH=VALUES", ...]`` -> ``{path: [values]}`` (see ``parse_range``)."""
    grid = {}
    for item in items:
        if "=" not in item:
            raise ModelError(f"grid {item!r}: expected PATH=VALUES, e.g. "
                             "parameters.Mz=-0.03:-0.001:8")
        path, text = item.split("=", 1)
        path = path.strip()
        if path in grid:
            raise ModelError(f"grid {path}: given twice; give each path once")
        grid[path] = parse_range(text, path)
    return grid


def expand(overrides=None, cases=None):
    """The members: ``overrides`` is a grid ``{path: [values] or "START:STOP:N"}`` (every
    combination, the last path varying fastest) or a list of ``{path: value}`` (one member
    each); ``cases`` a list of case names (an outer loop), or None for the file's default.
    Returns ``[{"case": ..., "overrides": [[path, value], ...]}]``."""
    if overrides is None:
        combos = [[]]
    elif isinstance(overrides, Mapping):
        axes = []
        for path, values in overrides.items():
            _check_path_text(path, "grid path")
            if isinstance(values, str):
                values = parse_range(values, path)
            elif not isinstance(values, (list, tuple, np.ndarray)):
                values = [values]
            values = [v.item() if isinstance(v, np.generic) else v for v in values]
            if not values:
                raise ModelError(f"grid {path}: no values; the sweep would have no members")
            axes.append([(path, v) for v in values])
        size = math.prod(len(a) for a in axes) * max(1, len(cases or ()))
        if size > limits.MAX_SWEEP_MEMBERS:
            raise ModelError(f"the sweep would have {size} members, more than "
                             f"{limits.MAX_SWEEP_MEMBERS}; split it into several sweeps")
        combos = [list(c) for c in itertools.product(*axes)]
    else:
        combos = _member_list(overrides)
    case_list = list(cases) if cases else [None]
    members = [{"case": c, "overrides": [[p, v] for p, v in combo]}
               for c in case_list for combo in combos]
    if not members:
        raise ModelError("the sweep has no members; give at least one override value")
    return members


def _check_path_text(path, what):
    """A dotted path given in Python must be text (``"parameters.Mz"``)."""
    if not isinstance(path, str):
        raise ModelError(f"sweep: {what} {path!r} ({type(path).__name__}) is not a dotted "
                         "path such as 'parameters.Mz'")


def _member_list(overrides):
    """``[[(path, value), ...], ...]`` of a list of members ``{path: value}``, each setting
    the same paths (their columns in the table)."""
    if isinstance(overrides, (str, bytes)) or not isinstance(overrides, Iterable):
        raise ModelError(f"sweep: overrides must be a grid {{path: values}} or a list of "
                         f"members {{path: value}}, not {type(overrides).__name__} "
                         f"{_brief(overrides)}")
    combos = []
    for k, m in enumerate(overrides):
        if len(combos) >= limits.MAX_SWEEP_MEMBERS:
            raise ModelError(f"the sweep has more than {limits.MAX_SWEEP_MEMBERS} members; "
                             "split it into several sweeps")
        if not isinstance(m, Mapping):
            raise ModelError(f"sweep: overrides[{k}] is {type(m).__name__} {_brief(m)}, not a "
                             "member {path: value}, e.g. {'parameters.Mz': -0.01}")
        for p in m:
            _check_path_text(p, f"overrides[{k}] path")
        if combos and {p for p, _ in combos[0]} != set(m):
            raise ModelError(f"sweep: overrides[{k}] sets {', '.join(m) or 'nothing'} but "
                             f"overrides[0] sets {', '.join(p for p, _ in combos[0]) or 'nothing'}"
                             "; every member sets the same paths (the table's columns)")
        combos.append(list(m.items()))
    return combos


def _brief(value, width=40):
    """``repr(value)``, shortened to ``width`` characters for a message."""
    text = repr(value)
    return text if len(text) <= width else text[:width - 3] + "..."


# --------------------------------------------------------------------------- one member

def _triples(fixed, overrides):
    """``(path, value, origin)`` for ``load_model``: the fixed ones, then the member's."""
    return ([(p, v, f"fixed {p}={v!r}") for p, v in fixed]
            + [(p, v, f"sweep {p}={v!r}") for p, v in overrides])


def _load(task, member):
    """The ``Scene`` of one member, from the model text the task carries (no file is
    written: messages name the model file the sweep was given)."""
    from ..io.loader import load_model
    over = _triples(task["fixed"], member["overrides"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_model(task["model_name"], case=member["case"], overrides=over,
                          text=task["model_text"])


def _series(result, name):
    if name in ("energy", "total_energy"):
        return np.asarray(result.energy["total"]) if result.energy is not None else None
    try:
        return np.asarray(result[name], dtype=float)
    except (KeyError, IndexError, ValueError, TypeError):
        return None


def columns(scene, quantities):
    """The quantity columns of ``scene`` for ``quantities`` (errors name the bad one)."""
    model = scene.model
    names = list(model.coordinates) + list(model.speeds)
    cols = []
    for q in quantities:
        if q == "final":
            cols += [f"final.{n}" for n in names]
        elif q == "events":
            cols += [f"event.{e.name}" for e in scene.events]
        elif q in SIMPLE:
            cols.append(q)
        elif ":" in q and q.split(":", 1)[0] in STATS:
            stat, x = q.split(":", 1)
            if x not in names + ["energy"]:
                raise ModelError(f"quantity {q!r}: {x!r} is not a coordinate, a speed or "
                                 f"energy; the names are: {', '.join(names)}, energy")
            cols.append(f"{stat}.{x}")
        else:
            raise ModelError(f"unknown quantity {q!r}; use {', '.join(SIMPLE)} or "
                             f"STAT:NAME with STAT one of {', '.join(STATS)}")
    return cols


def _needs_energy(quantities):
    return any(q == "energy_drift" or q.endswith(":energy") for q in quantities)


def measure(scene, result, quantities):
    """``{column: float}`` of a (possibly partial) result."""
    model = scene.model
    out = {}
    n = len(result.t)
    for q in quantities:
        if q == "final":
            for name, v in zip(model.coordinates, result.q[-1] if n else [np.nan] * model.nq):
                out[f"final.{name}"] = float(v)
            for name, v in zip(model.speeds, result.u[-1] if n else [np.nan] * model.nu):
                out[f"final.{name}"] = float(v)
        elif q == "events":
            for e in scene.events:
                times = [t for name, t in result.events if name == e.name]
                out[f"event.{e.name}"] = float(times[0]) if times else math.nan
        elif q == "t_final":
            out["t_final"] = float(result.t[-1]) if n else math.nan
        elif q == "energy_drift":
            s = _series(result, "energy")
            out[q] = float(s[-1] - s[0]) if s is not None and len(s) else math.nan
        elif q in ("steps", "rhs_evaluations"):
            out[q] = float(result.stats.get(q, math.nan))
        else:
            stat, x = q.split(":", 1)
            s = _series(result, x)
            if s is None or not len(s):
                out[f"{stat}.{x}"] = math.nan
                continue
            fn = {"max": np.max, "min": np.min, "mean": np.mean, "std": np.std,
                  "absmax": lambda a: np.max(np.abs(a))}[stat]
            out[f"{stat}.{x}"] = float(fn(s))
    return out


def run_member(task):
    """Run one member (``task``: plain data, see ``Sweep.tasks``); returns its row
    ``{"member": i, "status": "ok"|"failed"|"error", "error": text, column: value}``."""
    member = task["member"]
    row = {"member": member["index"], "status": "ok", "error": ""}
    try:
        scene = _load(task, member)
    except ModelError as exc:
        row.update(status="error", error=" ".join(str(exc).split()))
        return row
    qs = task["quantities"]
    kw = {"outputs": ("energy",) if _needs_energy(qs) else (), "points": {}}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = scene.simulate(**kw)
    except SimulationError as exc:
        row.update(status="failed", error=" ".join(str(exc).split()))
        result = exc.result
        if result is None:
            return row
        if _needs_energy(qs) and len(result.t):
            try:
                result.compute_outputs(("energy",), None)
            except Exception:            # the failed state may not evaluate: keep NaN
                pass
    except ModelError as exc:
        row.update(status="error", error=" ".join(str(exc).split()))
        return row
    row.update(measure(scene, result, qs))
    return row


# --------------------------------------------------------------------------- batched

def batchable(scene, quantities):
    """Why ``scene`` cannot run batched (a sentence), or None if it can: a fixed-step
    integrator, the Jourdain method, no events, no Euler-angle joints (their singularity
    is checked per step), no Python-function loads, quantities among final/t_final/
    steps/rhs_evaluations (and events, which has no columns without events)."""
    from ..integrate.settings import FIXED_STEP
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
    # "events" has no columns here: a model with events was refused above
    bad = [q for q in quantities
           if q not in ("final", "t_final", "steps", "rhs_evaluations", "events")]
    if bad:
        return f"quantities {bad} need the whole motion; batched runs keep the final state"
    return None


def run_batched(scenes, quantities):
    """Rows of members that share one compiled model (their scenes differ only in the
    initial state), advanced together by ``kernels.batched.batched_fixed_step``."""
    from ..kernels.batched import batched_fixed_step
    from ..kernels.integrators import SCHEMES, STAGES
    scene = scenes[0]
    model = scene.model
    s = scene.settings
    t0, t_end, dt = 0.0, float(s["t_end"]), float(s["dt"])
    n_full = int(np.floor((t_end - t0) / dt * (1 + 1e-12)))       # as simulate plans it
    times = t0 + dt * np.arange(1, n_full + 1)
    if n_full and times[-1] > t_end:
        times[-1] = t_end
    t_last = times[-1] if n_full else t0
    h_last = t_end - t_last if t_end - t_last > 1e-12 * max(1.0, abs(t_end)) else 0.0
    starts = np.concatenate([[t0], times[:-1]])
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
                       status, nfev)
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
            scenes.append(_load(task, member))
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


# --------------------------------------------------------------------------- the table

def _fmt(v):
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else str(v)


def _cell(v):
    """The CSV cell of a table value: a number as itself, a text escaped so that a
    spreadsheet never reads it as a formula (``escape.spreadsheet_cell``)."""
    return spreadsheet_cell(v) if isinstance(v, str) else _fmt(v)


def _open_regular(path):
    """``path`` opened for reading in binary if it is a regular file (a FIFO or a device
    is refused, never waited on)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise ModelError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise ModelError(f"{path}: is not a regular file (a FIFO, device or socket); give "
                         "the sweep's table, or write elsewhere with --out")
    if hasattr(os, "set_blocking"):
        os.set_blocking(fd, True)
    return os.fdopen(fd, "rb")


def _table_lines(fh, path):
    """The lines of a table file as text, each checked: at most ``limits.MAX_TABLE_LINE``
    bytes, UTF-8, no NUL.  A last line without its newline (a row cut by a kill) is left
    out: its member runs again."""
    number = 0
    while True:
        raw = fh.readline(limits.MAX_TABLE_LINE + 1)
        if not raw:
            return
        number += 1
        if not raw.endswith(b"\n"):
            if len(raw) > limits.MAX_TABLE_LINE:
                raise _resume_error(path, number, f"is longer than {limits.MAX_TABLE_LINE} "
                                    "bytes")
            return
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise _resume_error(path, number, f"is not UTF-8 text ({exc.reason} at byte "
                                f"{exc.start})") from None
        if "\x00" in text:
            raise _resume_error(path, number, "holds a NUL byte")
        yield text


def _resume_error(path, line, problem):
    """The error of a table that cannot be resumed: its file, the line, what is wrong."""
    return ModelError(f"{path}: line {line}: {problem}; this is not a table of this sweep "
                      "as mbdyn writes it -- remove it, or write elsewhere with --out")


class _Table:
    """The CSV written row by row: a format line with the sweep's fingerprint, the
    header, then one line per finished member (flushed and synced)."""

    def __init__(self, path, header, spec):
        self.path, self.header, self.spec = path, header, spec
        self.fh = None

    def read_done(self, members):
        """The rows a previous run of this sweep wrote (resume), read as the input they
        are: a regular file, line by line (each at most ``limits.MAX_TABLE_LINE`` bytes,
        UTF-8, no NUL), every row checked against the sweep's ``members``; errors name the
        file and the line.  The rows' override and case cells are the members' own values.
        [] if there is no table yet."""
        if not os.path.lexists(self.path):
            return []
        with _open_regular(self.path) as fh:
            lines = _table_lines(fh, self.path)
            if next(lines, "") != FORMAT_LINE + self.spec + "\n":
                raise ModelError(f"{self.path}: not a table of this sweep (model, grid, "
                                 "cases or quantities differ); remove it or write elsewhere "
                                 "with --out")
            reader = csv.reader(lines)
            rows, seen = [], set()
            try:
                if next(reader, None) != [_cell(c) for c in self.header]:
                    return []                    # no row yet, or another mbdyn's columns
                for cells in reader:     # at most one row per member (checked): bounded
                    rows.append(self._kept_row(cells, reader.line_num + 1, members, seen))
            except csv.Error as exc:
                raise _resume_error(self.path, reader.line_num + 1, str(exc)) from None
        return rows

    def _kept_row(self, cells, line, members, seen):
        """One row read back, checked: its size, member number, status, overrides and
        numbers; returns it with the member's own override (and case) values."""
        if len(cells) != len(self.header):
            raise _resume_error(self.path, line, f"has {len(cells)} cells, the table "
                                f"{len(self.header)} columns")
        row = dict(zip(self.header, cells))
        text = row["member"]
        if not (text.isascii() and text.isdigit() and int(text) < len(members)):
            raise _resume_error(self.path, line, f"member {_brief(text)} is not a member "
                                f"number of this sweep (0 to {len(members) - 1})")
        index = int(text)
        if index in seen:
            raise _resume_error(self.path, line, f"member {index} appears twice")
        seen.add(index)
        if row["status"] not in STATUSES:
            raise _resume_error(self.path, line, f"status {_brief(row['status'])} is not one "
                                f"of {', '.join(STATUSES)}")
        member = members[index]
        own = dict(member["overrides"], case=member["case"])
        for column, value in own.items():
            # as the live table wrote it, or as the finished one did (numbers as floats)
            if column in row and row[column] not in (_cell(value), _cell(_typed(value, column))):
                raise _resume_error(self.path, line, f"member {index}'s {column} is "
                                    f"{_brief(row[column])}, the sweep's is {_cell(value)!r}")
        kept = {"member": index, "status": row["status"],
                "error": spreadsheet_text(row["error"])}
        for column in self.header:
            if column not in kept and column not in own:
                number = _number(row[column])
                if number is None:
                    raise _resume_error(self.path, line, f"{column} holds "
                                        f"{_brief(row[column])}, not a number")
                kept[column] = number
        kept.update((c, v) for c, v in own.items() if c in self.header)
        return kept

    def open(self, done_rows):
        """Start the table with the rows kept from a previous run: written whole beside
        ``path`` and renamed over it (the old table stays until then; a symbolic link at
        ``path`` is replaced, never written through), then appended to."""
        fd, tmp = files.temporary(self.path)
        self.fh = os.fdopen(fd, "w", encoding="utf-8", newline="")
        self.writer = csv.writer(self.fh, lineterminator="\n")
        try:
            self.fh.write(FORMAT_LINE + self.spec + "\n")
            self.writer.writerow([_cell(c) for c in self.header])
            for r in done_rows:
                self.writer.writerow([_cell(r.get(c, "")) for c in self.header])
            self._sync()
        except BaseException:
            self.close()
            files.remove(tmp)
            raise
        files.replace(tmp, self.path)

    def write(self, row):
        self.writer.writerow([_cell(row.get(c, "")) for c in self.header])
        self._sync()

    def _sync(self):
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self):
        if self.fh is not None:
            self.fh.close()
            self.fh = None

    def finish(self, rows):
        """Rewrite the file sorted by member (whole or not at all: ``files``)."""
        self.close()
        buf = io.StringIO()
        buf.write(FORMAT_LINE + self.spec + "\n")
        w = csv.writer(buf, lineterminator="\n")
        w.writerow([_cell(c) for c in self.header])
        for r in rows:
            w.writerow([_cell(r.get(c, "")) for c in self.header])
        files.atomic_write(self.path, buf.getvalue())


def read_table(path):
    """A sweep CSV as ``{column: array}`` (numbers as floats, text as objects; the
    escapes of text cells undone), read with the bounds of a resume."""
    with _open_regular(path) as fh:
        lines = _table_lines(fh, path)
        reader = csv.reader(line for line in lines if not line.startswith(FORMAT_LINE))
        try:
            rows = [[spreadsheet_text(c) for c in r] for r in reader]
        except csv.Error as exc:
            raise ModelError(f"{path}: {exc}; not a table mbdyn wrote") from None
    if not rows:
        raise ModelError(f"{path}: is empty; not a table mbdyn wrote")
    header, body = rows[0], rows[1:]
    return _as_arrays(header, [dict(zip(header, r)) for r in body])


def _number(v):
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v)
    try:
        return float(v) if v != "" else math.nan
    except (TypeError, ValueError):
        return None


def _as_arrays(header, rows):
    out = {}
    for c in header:
        vals = [r.get(c, "") for r in rows]
        nums = [_number(v) for v in vals]
        if c in ("status", "error", "case") or any(n is None for n in nums):
            out[c] = np.array([_fmt(v) for v in vals], dtype=object)
        elif c == "member":
            out[c] = np.array(nums, dtype=np.int64)
        else:
            out[c] = np.array(nums, dtype=float)
    return out


# --------------------------------------------------------------------------- the sweep

class SweepResult:
    """The table of a finished sweep: ``columns``, ``rows`` (dicts in member order),
    ``table()`` (a pandas DataFrame if pandas is installed, else ``{column: array}``),
    ``arrays()`` (always ``{column: array}``), ``path`` (the CSV) and ``stats``."""

    def __init__(self, header, rows, path, stats):
        self.columns, self.rows, self.path, self.stats = header, rows, path, stats

    def arrays(self):
        return _as_arrays(self.columns, self.rows)

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


#: a sweep whose members left would take longer than this many seconds is announced on
#: stderr (members, estimated duration) once its first members have finished
ANNOUNCE_AFTER = 10.0
#: finished members timed before the estimate (fewer if the sweep is smaller, or if
#: ANNOUNCE_AFTER seconds pass first)
ESTIMATE_FROM = 3


class _Progress:
    """What a sweep tells on stderr while it runs.

    * Once the first ``ESTIMATE_FROM`` members have finished (or ``ANNOUNCE_AFTER``
      seconds have passed), the time per member is measured -- between the first and the
      last finished member, so a worker's start-up does not count, or the first member's
      whole time if only one finished -- and the rest extrapolated; if it comes to more
      than ``ANNOUNCE_AFTER`` seconds, one line says how many members and about how long.
    * ``counter``: a plain counter line, rewritten in place at most five times a second:
      members done of all, time so far, about how long left.
    """

    def __init__(self, total, kept, counter, stream=None, clock=time.monotonic):
        self.total, self.kept, self.done = total, kept, kept
        self.todo = total - kept
        self.counter = counter
        self.stream = stream if stream is not None else sys.stderr
        self.clock = clock
        self.start = clock()
        self.first = None                 # when the first member finished
        self.per_member = None            # seconds, once estimated
        self.shown = 0.0                  # when the counter was last written
        self.counted = False

    def update(self):
        """One more member finished."""
        now = self.clock()
        self.done += 1
        ran = self.done - self.kept
        if self.first is None:
            self.first = now
        if self.per_member is None and (ran >= min(ESTIMATE_FROM, self.todo)
                                        or now - self.start >= ANNOUNCE_AFTER):
            self.per_member = ((now - self.first) / (ran - 1) if ran > 1
                               else now - self.start)
            left = self.per_member * (self.total - self.done)
            if left > ANNOUNCE_AFTER:
                self._line(f"mbdyn sweep: {self.todo} members to run"
                           + (f" ({self.kept} kept from before)" if self.kept else "")
                           + f"; about {_duration(left)} left ({_duration(self.per_member)}"
                           f" a member, from the first {ran})")
        if self.counter and (now - self.shown >= 0.2 or self.done == self.total):
            self.shown = now
            left = (f", about {_duration(self.per_member * (self.total - self.done))} left"
                    if self.per_member is not None and self.done < self.total else "")
            self.stream.write(f"\rmbdyn sweep: {self.done}/{self.total} members, "
                              f"{_duration(now - self.start)}{left}   ")
            self.stream.flush()
            self.counted = True

    def _line(self, text):
        """``text`` as a line of its own (after the counter's line, if one is shown)."""
        self.stream.write(("\n" if self.counted else "") + text + "\n")
        self.stream.flush()
        self.counted = False

    def close(self):
        if self.counted:
            self.stream.write("\n")
            self.stream.flush()
            self.counted = False


def _duration(seconds):
    """A duration for people: ``0.2 s``, ``42 s``, ``3.5 min``, ``58 min``, ``1.5 h``,
    ``3.2 days``."""
    if seconds < 10:
        return f"{seconds:.2g} s"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 600:
        return f"{seconds / 60:.1f} min"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    if seconds < 172800:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"


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
    against a second sweep meanwhile; ``resume``: keep the finished rows of ``out`` and
    run only the rest.  ``batched``: advance members that share one compiled model in one
    compiled call (fixed-step schemes only; see ``batchable``), ``batch_size`` members per
    task.  ``progress``: a counter on stderr (default: when stderr is a terminal; a long
    sweep is announced with an estimate of its duration either way; False: nothing).
    ``require_columns``: columns the caller will need (e.g. to plot), checked up front.
    ``scheduler_timeout``: the longest wait, in seconds, on a Dask scheduler at an address
    (connection, handshake, each result, each check that it still answers; default
    ``limits.SCHEDULER_TIMEOUT``).

    Everything that can be checked is checked before any member runs: the arguments, the
    paths, the range texts, the quantities, an empty sweep, the table's name and folder.
    A bad argument raises ``ModelError`` naming it.
    """
    path, cases = _model_path(model, cases)
    _check_arguments(scheduler, quantities, cases, fixed, workers, batch_size, out, resume,
                     require_columns, scheduler_timeout)
    text = _model_text(path)
    members = expand(overrides, cases)
    quantities = tuple(quantities)
    fixed_list = [[p, v] for p, v in (fixed or {}).items()]
    head = _header(path, text, members, fixed_list, quantities, cases, batched,
                   require_columns)
    for i, m in enumerate(members):
        m["index"] = i
    spec = hashlib.sha256(json.dumps([text, members, fixed_list, list(quantities)],
                                     default=repr).encode()).hexdigest()[:20]
    base = {"model_text": text, "model_name": str(path), "fixed": fixed_list,
            "quantities": list(quantities)}
    csv_path = _table_path(out)
    lock = files.TableLock(csv_path) if csv_path else None
    table = _Table(csv_path, head, spec) if csv_path else None
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
        ordered = [{c: _typed(r.get(c, ""), c) for c in head} for r in ordered]
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


def _model_path(model, cases):
    """The model file's path (``model`` or a ``Scene``'s) and the cases to sweep (a
    ``Scene``'s own case when none are given)."""
    path = getattr(model, "path", model)
    if not isinstance(path, (str, os.PathLike)):
        raise ModelError(f"sweep: model must be the path of a model file (or a Scene loaded "
                         f"from one), not {type(model).__name__} {_brief(model)}")
    if cases is None and getattr(model, "case", None) is not None and not isinstance(
            model, (str, os.PathLike)):
        cases = [model.case]
    return path, cases


def _whole(value, at_least=1):
    """Whether ``value`` is a whole number (not a bool) of at least ``at_least``."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool) \
        and value >= at_least


def _check_arguments(scheduler, quantities, cases, fixed, workers, batch_size, out, resume,
                     require_columns, scheduler_timeout):
    """Refuse arguments of the wrong kind, naming the argument and what to give."""
    check_spec(scheduler)
    timeout = scheduler_timeout
    if timeout is not None and not (isinstance(timeout, numbers.Real) and not isinstance(
            timeout, bool) and math.isfinite(timeout) and timeout > 0):
        raise ModelError(f"sweep: scheduler_timeout={_brief(scheduler_timeout)}: give a "
                         "positive number of seconds, or None for "
                         f"{limits.SCHEDULER_TIMEOUT:g}")
    if isinstance(quantities, str) or not isinstance(quantities, Iterable) or not all(
            isinstance(q, str) for q in quantities):
        raise ModelError(f"sweep: quantities={_brief(quantities)}: give a list of quantity "
                         "names, e.g. ('final', 'max:theta')")
    if cases is not None and (isinstance(cases, str) or not isinstance(cases, Iterable)):
        raise ModelError(f"sweep: cases={_brief(cases)}: give a list of case names, e.g. "
                         f"cases=[{_brief(cases)}]")
    if fixed is not None and not isinstance(fixed, Mapping):
        raise ModelError(f"sweep: fixed={_brief(fixed)}: give a table {{path: value}}, e.g. "
                         "{'simulation.t_end': 10}")
    for p in fixed or {}:
        _check_path_text(p, "fixed path")
    if workers is not None and not _whole(workers):
        raise ModelError(f"sweep: workers={_brief(workers)}: give a whole number >= 1 (local "
                         "worker processes), or None for one per core")
    if batch_size is not None and not _whole(batch_size):
        raise ModelError(f"sweep: batch_size={_brief(batch_size)}: give a whole number >= 1 "
                         "(members per task), or None for an even share per worker")
    if out is not None and not isinstance(out, (str, os.PathLike)):
        raise ModelError(f"sweep: out={_brief(out)}: give the path of a .csv (or .parquet) "
                         "table, or None")
    if out is not None and not str(out).endswith((".csv", ".parquet")):
        raise ModelError(f"sweep: out={str(out)!r}: the table is written as .csv (or "
                         ".parquet); name the file so")
    if resume and out is None:
        raise ModelError("sweep: resume=True needs out= (the table to complete)")
    if isinstance(require_columns, str) or not all(isinstance(c, str)
                                                   for c in require_columns):
        raise ModelError(f"sweep: require_columns={_brief(require_columns)}: give a list of "
                         "column names")
    if out is not None and str(out).endswith(".parquet"):
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise ModelError(f"{out}: writing Parquet needs pyarrow (pip install pyarrow); "
                             "or write a .csv") from None


def _model_text(path):
    """The model file's text, read once as ``load_model`` reads a file (a regular file,
    bounded, UTF-8), newlines as a text-mode read gives them: every member gets it."""
    from ..io.loader import decode_text, read_bytes
    text = decode_text(read_bytes(path), str(path))
    return text.replace("\r\n", "\n").replace("\r", "\n")


def _header(path, text, members, fixed_list, quantities, cases, batched, require_columns):
    """The table's columns, found by loading the first and the last member (every path
    appears in both; a value that only fails in the middle becomes that member's error);
    a sweep that cannot run batched, or lacks a required column, is refused here."""
    from ..io.loader import load_model
    header = None
    for member in (members[0], members[-1]):
        over = _triples(fixed_list, member["overrides"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = load_model(path, case=member["case"], overrides=over, text=text)
        header = header or columns(scene, quantities)
    if batched:
        why = batchable(scene, quantities)
        if why:
            raise ModelError(f"cannot run batched: {why}; run without batching")
    paths = [p for p, _ in members[0]["overrides"]]
    with_case = cases is not None and len(set(m["case"] for m in members)) > 1
    head = ["member"] + (["case"] if with_case else []) + paths + ["status", "error"] + header
    missing = [c for c in require_columns if c not in head]
    if missing:
        raise ModelError(f"{', '.join(missing)}: not a column of the table; the columns are: "
                         + ", ".join(head))
    return head


def _table_path(out):
    """The CSV of ``out`` (``NAME.csv`` for ``NAME.parquet``), its folder created and the
    path checked before any work (``files.check_target``); None without ``out``."""
    if out is None:
        return None
    csv_path = str(out)[:-8] + ".csv" if str(out).endswith(".parquet") else str(out)
    os.makedirs(os.path.dirname(os.path.abspath(csv_path)), exist_ok=True)
    files.check_target(csv_path, (".csv",), "table")
    if str(out).endswith(".parquet"):
        files.check_target(out, (".parquet",), "table")
    return csv_path


def _kept_rows(table, resume, members):
    """``{member: row}`` of the rows a previous run wrote (``resume``), else empty."""
    if table is None or not resume:
        return {}
    return {r["member"]: r for r in table.read_done(members)}


def _progress(total, kept, progress):
    """The sweep's ``_Progress`` (None for ``progress=False``: nothing on stderr); its
    counter shown for ``progress=True``, or by default when stderr is a terminal."""
    if progress is False:
        return None
    counter = bool(progress) if progress is not None else bool(
        getattr(sys.stderr, "isatty", lambda: False)())
    return _Progress(total, kept, counter)


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


def _typed(v, column):
    if column in ("status", "error", "case"):
        return "" if v is None else str(v)
    if column == "member":
        return int(v)
    if isinstance(v, str):
        n = _number(v)
        return v if n is None else n
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v)
    return v


def write_parquet(path, header, rows):
    """The table as Parquet (needs pyarrow)."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise ModelError(f"{path}: writing Parquet needs pyarrow (pip install pyarrow); "
                         "the CSV beside it holds the same table") from None
    arrays = _as_arrays(header, rows)
    with files.replacing(path) as tmp:
        pq.write_table(pa.table({c: list(arrays[c]) for c in header}), tmp)

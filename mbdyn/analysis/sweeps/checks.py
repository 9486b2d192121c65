"""Everything a sweep settles before any member runs: its arguments (``check_arguments``),
the model file's path (``model_path``), the table's columns, found by loading the first
and the last member (``table_header``), and the table's path (``table_path``)."""
from __future__ import annotations

import math
import numbers
import os
from collections.abc import Iterable, Mapping

from ... import files, limits
from ...errors import ModelError
from ..arguments import brief
from ..schedulers import check_spec
from .batched import batchable
from .grid import check_path_text
from .model_file import load_member
from .quantities import columns


def model_path(model, cases):
    """The model file's path (``model`` or a ``Scene``'s) and the cases to sweep (a
    ``Scene``'s own case when none are given)."""
    path = getattr(model, "path", model)
    if not isinstance(path, (str, os.PathLike)):
        raise ModelError(f"sweep: model must be the path of a model file (or a Scene loaded "
                         f"from one), not {type(model).__name__} {brief(model)}")
    if cases is None and getattr(model, "case", None) is not None and not isinstance(
            model, (str, os.PathLike)):
        cases = [model.case]
    return path, cases


def _whole(value, at_least=1):
    """Whether ``value`` is a whole number (not a bool) of at least ``at_least``."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool) \
        and value >= at_least


def check_arguments(scheduler, quantities, cases, fixed, workers, batch_size, out, resume,
                    require_columns, scheduler_timeout, progress=None):
    """Refuse arguments of the wrong kind, naming the argument and what to give."""
    check_spec(scheduler)
    if not (progress is None or isinstance(progress, bool) or callable(progress)):
        raise ModelError(f"sweep: progress={brief(progress)}: give True (a progress bar), "
                         "False (nothing), None (a counter on a terminal) or a function "
                         "progress(done, total)")
    timeout = scheduler_timeout
    if timeout is not None and not (isinstance(timeout, numbers.Real) and not isinstance(
            timeout, bool) and math.isfinite(timeout) and timeout > 0):
        raise ModelError(f"sweep: scheduler_timeout={brief(scheduler_timeout)}: give a "
                         "positive number of seconds, or None for "
                         f"{limits.SCHEDULER_TIMEOUT:g}")
    if isinstance(quantities, str) or not isinstance(quantities, Iterable) or not all(
            isinstance(q, str) for q in quantities):
        raise ModelError(f"sweep: quantities={brief(quantities)}: give a list of quantity "
                         "names, e.g. ('final', 'max:theta')")
    if cases is not None and (isinstance(cases, str) or not isinstance(cases, Iterable)):
        raise ModelError(f"sweep: cases={brief(cases)}: give a list of case names, e.g. "
                         f"cases=[{brief(cases)}]")
    if fixed is not None and not isinstance(fixed, Mapping):
        raise ModelError(f"sweep: fixed={brief(fixed)}: give a table {{path: value}}, e.g. "
                         "{'simulation.t_end': 10}")
    for p in fixed or {}:
        check_path_text(p, "fixed path")
    if workers is not None and not _whole(workers):
        raise ModelError(f"sweep: workers={brief(workers)}: give a whole number >= 1 (local "
                         "worker processes), or None for one per core")
    if batch_size is not None and not _whole(batch_size):
        raise ModelError(f"sweep: batch_size={brief(batch_size)}: give a whole number >= 1 "
                         "(members per task), or None for an even share per worker")
    if out is not None and not isinstance(out, (str, os.PathLike)):
        raise ModelError(f"sweep: out={brief(out)}: give the path of a .csv (or .parquet) "
                         "table, or None")
    if out is not None and not str(out).endswith((".csv", ".parquet")):
        raise ModelError(f"sweep: out={str(out)!r}: the table is written as .csv (or "
                         ".parquet); name the file so")
    if resume and out is None:
        raise ModelError("sweep: resume=True needs out= (the table to complete)")
    if isinstance(require_columns, str) or not all(isinstance(c, str)
                                                   for c in require_columns):
        raise ModelError(f"sweep: require_columns={brief(require_columns)}: give a list of "
                         "column names")
    if out is not None and str(out).endswith(".parquet"):
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise ModelError(f"{out}: writing Parquet needs pyarrow (pip install pyarrow); "
                             "or write a .csv") from None


def table_header(path, text, members, fixed_list, quantities, cases, batched, require_columns):
    """The table's columns, found by loading the first and the last member (every path
    appears in both; a value that only fails in the middle becomes that member's error);
    a sweep that cannot run batched, or lacks a required column, is refused here."""
    header = None
    for member in (members[0], members[-1]):
        scene = load_member(path, text, fixed_list, member)
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


def table_path(out):
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


"""The table of a sweep: the CSV written row by row as members finish (``Table``) with its
sidecar JSON, the values of its cells, and the Parquet copy.  Reading it back is
``resume``'s.

The CSV is a plain table -- a header, then one row per member -- that ``pandas.read_csv``
reads as it is; what describes it (the sweep's fingerprint, model, quantities, columns,
whether it is complete) is in ``NAME.json`` beside ``NAME.csv`` (``sidecar_path``), as a
results CSV has its JSON.  Tables of mbdyn before this format began with a line
``FORMAT_LINE + fingerprint``; they are still read (and resumed).
"""
from __future__ import annotations

import csv
import datetime
import io
import json
import math
import os

import numpy as np

from ... import files
from ...errors import ModelError
from ...escape import spreadsheet_cell

STATUSES = ("ok", "failed", "error")
#: the first line of a table of the old format (fingerprint after it); no longer written
FORMAT_LINE = "# mbdyn sweep table v1 spec="
#: the sidecar's ``format`` and ``version``
SIDECAR_FORMAT, SIDECAR_VERSION = "mbdyn sweep table", 2


def sidecar_path(csv_path):
    """``NAME.json`` beside the table ``NAME.csv``."""
    return str(csv_path)[:-4] + ".json" if str(csv_path).endswith(".csv") else \
        str(csv_path) + ".json"


def _fmt(v):
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else str(v)


def cell(v):
    """The CSV cell of a table value: a number as itself, a text escaped so that a
    spreadsheet never reads it as a formula (``escape.spreadsheet_cell``)."""
    return spreadsheet_cell(v) if isinstance(v, str) else _fmt(v)


class Table:
    """The CSV written row by row (a header, then one line per finished member, flushed
    and synced) and its sidecar JSON (``sidecar_path``: the fingerprint ``spec``, the
    columns, ``meta`` -- model, quantities, ... --, and ``"status"``: ``"running"``, then
    ``"complete"``).  The pair is replaced as ``mbdyn run --out``'s is: the old JSON
    removed, the CSV renamed into place and the JSON last, signals held, so that a JSON
    beside a CSV always describes it."""

    def __init__(self, path, header, spec, meta=None):
        self.path, self.header, self.spec = path, header, spec
        self.meta = dict(meta or {})
        self.json_path = sidecar_path(path)
        self.fh = None

    def sidecar(self, status, rows):
        """The sidecar's text."""
        return json.dumps({
            "format": SIDECAR_FORMAT, "version": SIDECAR_VERSION, "spec": self.spec,
            "csv": os.path.basename(self.path), "status": status, "rows": rows,
            "columns": list(self.header), **self.meta,
            "written": datetime.datetime.now(datetime.UTC).isoformat(
                timespec="seconds")}, indent=2, default=repr) + "\n"

    def _install(self, csv_tmp, status, rows):
        """Rename the finished CSV temporary and a new sidecar into place, as one unit."""
        try:
            json_tmp = files.write_temporary(self.json_path, self.sidecar(status, rows))
        except BaseException:
            files.remove(csv_tmp)
            raise
        with files.signals_held():
            files.remove(self.json_path)
            try:
                files.replace(csv_tmp, self.path)
            except BaseException:
                files.remove(json_tmp)
                raise
            files.replace(json_tmp, self.json_path)

    def open(self, done_rows):
        """Start the table with the rows kept from a previous run: written whole beside
        ``path`` and renamed over it with its sidecar (the old table stays until then; a
        symbolic link at ``path`` is replaced, never written through), then appended
        to."""
        fd, tmp = files.temporary(self.path)
        self.fh = os.fdopen(fd, "w", encoding="utf-8", newline="")
        self.writer = csv.writer(self.fh, lineterminator="\n")
        try:
            self.writer.writerow([cell(c) for c in self.header])
            for r in done_rows:
                self.writer.writerow([cell(r.get(c, "")) for c in self.header])
            self._sync()
        except BaseException:
            self.close()
            files.remove(tmp)
            raise
        self._install(tmp, "running", len(done_rows))

    def write(self, row):
        self.writer.writerow([cell(row.get(c, "")) for c in self.header])
        self._sync()

    def _sync(self):
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self):
        if self.fh is not None:
            self.fh.close()
            self.fh = None

    def finish(self, rows):
        """Rewrite the file sorted by member, and its sidecar ``complete`` (whole or not
        at all: ``files``)."""
        self.close()
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow([cell(c) for c in self.header])
        for r in rows:
            w.writerow([cell(r.get(c, "")) for c in self.header])
        self._install(files.write_temporary(self.path, buf.getvalue()), "complete",
                      len(rows))


def as_number(v):
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v)
    try:
        return float(v) if v != "" else math.nan
    except (TypeError, ValueError):
        return None


def as_arrays(header, rows):
    out = {}
    for c in header:
        vals = [r.get(c, "") for r in rows]
        nums = [as_number(v) for v in vals]
        if c in ("status", "error", "case") or any(n is None for n in nums):
            out[c] = np.array([_fmt(v) for v in vals], dtype=object)
        elif c == "member":
            out[c] = np.array(nums, dtype=np.int64)
        else:
            out[c] = np.array(nums, dtype=float)
    return out


def typed(v, column):
    if column in ("status", "error", "case"):
        return "" if v is None else str(v)
    if column == "member":
        return int(v)
    if isinstance(v, str):
        n = as_number(v)
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
    arrays = as_arrays(header, rows)
    with files.replacing(path) as tmp:
        pq.write_table(pa.table({c: list(arrays[c]) for c in header}), tmp)

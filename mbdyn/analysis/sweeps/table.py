"""The table of a sweep: the CSV written row by row as members finish (``Table``), the
values of its cells, and the Parquet copy.  Reading it back is ``resume``'s."""
from __future__ import annotations

import csv
import io
import math
import os

import numpy as np

from ... import files
from ...errors import ModelError
from ...escape import spreadsheet_cell

STATUSES = ("ok", "failed", "error")
FORMAT_LINE = "# mbdyn sweep table v1 spec="


def _fmt(v):
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else str(v)


def cell(v):
    """The CSV cell of a table value: a number as itself, a text escaped so that a
    spreadsheet never reads it as a formula (``escape.spreadsheet_cell``)."""
    return spreadsheet_cell(v) if isinstance(v, str) else _fmt(v)


class Table:
    """The CSV written row by row: a format line with the sweep's fingerprint, the
    header, then one line per finished member (flushed and synced)."""

    def __init__(self, path, header, spec):
        self.path, self.header, self.spec = path, header, spec
        self.fh = None


    def open(self, done_rows):
        """Start the table with the rows kept from a previous run: written whole beside
        ``path`` and renamed over it (the old table stays until then; a symbolic link at
        ``path`` is replaced, never written through), then appended to."""
        fd, tmp = files.temporary(self.path)
        self.fh = os.fdopen(fd, "w", encoding="utf-8", newline="")
        self.writer = csv.writer(self.fh, lineterminator="\n")
        try:
            self.fh.write(FORMAT_LINE + self.spec + "\n")
            self.writer.writerow([cell(c) for c in self.header])
            for r in done_rows:
                self.writer.writerow([cell(r.get(c, "")) for c in self.header])
            self._sync()
        except BaseException:
            self.close()
            files.remove(tmp)
            raise
        files.replace(tmp, self.path)

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
        """Rewrite the file sorted by member (whole or not at all: ``files``)."""
        self.close()
        buf = io.StringIO()
        buf.write(FORMAT_LINE + self.spec + "\n")
        w = csv.writer(buf, lineterminator="\n")
        w.writerow([cell(c) for c in self.header])
        for r in rows:
            w.writerow([cell(r.get(c, "")) for c in self.header])
        files.atomic_write(self.path, buf.getvalue())


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

"""A sweep's table read back as the input it is: ``read_done`` the rows a previous run
wrote (resume), each line and row checked against the sweep; ``read_table`` any table."""
from __future__ import annotations

import csv
import itertools
import json
import os
import stat

from ... import limits
from ...errors import ModelError
from ...escape import spreadsheet_text
from ..arguments import brief
from .table import (
    FORMAT_LINE,
    SIDECAR_FORMAT,
    STATUSES,
    as_arrays,
    as_number,
    cell,
    sidecar_path,
    typed,
)


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


def read_sidecar(path):
    """The sidecar JSON of the table ``path`` (``table.sidecar_path``) as a dict, read as
    input (a regular file, at most ``limits.MAX_TABLE_LINE`` bytes, JSON of the format);
    ``None`` if there is none."""
    json_path = sidecar_path(path)
    if not os.path.lexists(json_path):
        return None
    with _open_regular(json_path) as fh:
        data = fh.read(limits.MAX_TABLE_LINE + 1)
    problem, meta = None, None
    if len(data) > limits.MAX_TABLE_LINE:
        problem = f"is longer than {limits.MAX_TABLE_LINE} bytes"
    else:
        try:
            meta = json.loads(data.decode("utf-8"))
        except (ValueError, UnicodeDecodeError) as exc:
            problem = f"is not JSON ({brief(str(exc), 80)})"
    if problem is None and not (isinstance(meta, dict)
                                and meta.get("format") == SIDECAR_FORMAT):
        problem = "is not the sidecar of a sweep table as mbdyn writes it"
    if problem:
        raise ModelError(f"{json_path}: {problem}; remove it (and its table), or write "
                         "elsewhere with --out")
    return meta


def _check_spec(table, first_line):
    """Whether the table on disk is one of this sweep: its sidecar's fingerprint (or, in
    a table of the old format, its first line's); returns the lines before the header
    (0 or 1)."""
    old = first_line.startswith(FORMAT_LINE)
    if old:
        spec = first_line[len(FORMAT_LINE):].rstrip("\n")
    else:
        meta = read_sidecar(table.path)
        if meta is None:
            raise ModelError(f"{table.path}: has no {os.path.basename(sidecar_path(table.path))}"
                             " beside it, so it cannot be told to be a table of this sweep; "
                             "remove it or write elsewhere with --out")
        spec = meta.get("spec")
    if spec != table.spec:
        raise ModelError(f"{table.path}: not a table of this sweep (model, grid, "
                         "cases or quantities differ); remove it or write elsewhere "
                         "with --out")
    return 1 if old else 0


def read_done(table, members):
    """The rows a previous run of this sweep wrote to ``table`` (a ``Table``: its path,
    header and fingerprint), read as the input they are: a regular file, line by line
    (each at most ``limits.MAX_TABLE_LINE`` bytes, UTF-8, no NUL), every row checked
    against the sweep's ``members``; errors name the file and the line.  The table is
    this sweep's if its sidecar's fingerprint is (or, in the old format, its first
    line's).  The rows' override and case cells are the members' own values.  [] if
    there is no table yet."""
    if not os.path.lexists(table.path):
        return []
    with _open_regular(table.path) as fh:
        lines = _table_lines(fh, table.path)
        first = next(lines, "")
        skipped = _check_spec(table, first)
        reader = csv.reader(lines if skipped else itertools.chain([first], lines))
        rows, seen = [], set()
        try:
            if next(reader, None) != [cell(c) for c in table.header]:
                return []                    # no row yet, or another mbdyn's columns
            for cells in reader:     # at most one row per member (checked): bounded
                rows.append(_kept_row(table, cells, reader.line_num + skipped, members,
                                      seen))
        except csv.Error as exc:
            raise _resume_error(table.path, reader.line_num + skipped, str(exc)) from None
    return rows


def _kept_row(table, cells, line, members, seen):
    """One row read back, checked: its size, member number, status, overrides and
    numbers; returns it with the member's own override (and case) values."""
    if len(cells) != len(table.header):
        raise _resume_error(table.path, line, f"has {len(cells)} cells, the table "
                            f"{len(table.header)} columns")
    row = dict(zip(table.header, cells))
    text = row["member"]
    if not (text.isascii() and text.isdigit() and int(text) < len(members)):
        raise _resume_error(table.path, line, f"member {brief(text)} is not a member "
                            f"number of this sweep (0 to {len(members) - 1})")
    index = int(text)
    if index in seen:
        raise _resume_error(table.path, line, f"member {index} appears twice")
    seen.add(index)
    if row["status"] not in STATUSES:
        raise _resume_error(table.path, line, f"status {brief(row['status'])} is not one "
                            f"of {', '.join(STATUSES)}")
    member = members[index]
    own = dict(member["overrides"], case=member["case"])
    for column, value in own.items():
        # as the live table wrote it, or as the finished one did (numbers as floats)
        if column in row and row[column] not in (cell(value), cell(typed(value, column))):
            raise _resume_error(table.path, line, f"member {index}'s {column} is "
                                f"{brief(row[column])}, the sweep's is {cell(value)!r}")
    kept = {"member": index, "status": row["status"],
            "error": spreadsheet_text(row["error"])}
    for column in table.header:
        if column not in kept and column not in own:
            number = as_number(row[column])
            if number is None:
                raise _resume_error(table.path, line, f"{column} holds "
                                    f"{brief(row[column])}, not a number")
            kept[column] = number
    kept.update((c, v) for c, v in own.items() if c in table.header)
    return kept


def read_table(path):
    """A sweep CSV as ``{column: array}`` (numbers as floats, text as objects; the
    escapes of text cells undone), read with the bounds of a resume; a table of the old
    format's first line is skipped."""
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
    return as_arrays(header, [dict(zip(header, r)) for r in body])


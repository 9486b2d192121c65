"""A model file's text and TOML, read within the input limits (``mbdyn.limits``): a
regular file of bounded size, UTF-8, no NUL, TOML whose nesting, integers, numbers, keys
and strings are checked (``scan_document``); and the TOML value of ``--set PATH=VALUE``.
Errors are ``ModelFileError``s naming the file (and the line of a syntax error).
"""
from __future__ import annotations

import math
import os
import re
import stat
import tomllib
import unicodedata

from .. import limits
from ..names import label_problem, shown
from .errors import ModelFileError
from .wording import format_path


def read_document(path):
    """The parsed TOML of ``path``; errors name the file (and the line of a syntax error).

    Only regular files of at most ``limits.max_file_bytes()`` are read (a FIFO or a device
    such as ``/dev/zero`` would block or never end); the parsed document is then checked
    against the nesting and number limits (``scan_document``).
    """
    return parse_document(read_bytes(path), str(path))


def read_bytes(path):
    """The bytes of the model file ``path``: a regular file of at most
    ``limits.max_file_bytes()`` (errors name the file)."""
    file = str(path)
    limit = limits.max_file_bytes()
    try:
        # non-blocking open: a FIFO without a writer must not hang the reader
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                raise ModelFileError(file, "", "is not a regular file (a FIFO, device or "
                                     "socket); give a .toml model file")
            if info.st_size > limit:
                raise ModelFileError(file, "", f"is {info.st_size} bytes, more than a model "
                                     f"file may be ({limit}); is it really a model file? A "
                                     "large generated model may raise the limit: "
                                     "MBDYN_MAX_FILE_BYTES=BYTES")
            if hasattr(os, "set_blocking"):
                os.set_blocking(fd, True)
            data = fh.read(limit + 1)
    except FileNotFoundError:
        raise ModelFileError(file, "", "no such file; check the path") from None
    except IsADirectoryError:
        raise ModelFileError(file, "", "is a directory; give a .toml model file") from None
    except PermissionError:
        raise ModelFileError(file, "", "cannot be read (permission denied)") from None
    except OSError as exc:
        raise ModelFileError(file, "", f"cannot be read ({exc.strerror or exc})") from None
    if len(data) > limit:
        raise ModelFileError(file, "", f"grew beyond {limit} bytes while "
                             "being read; give a finished model file")
    return data


def decode_text(data, file="<text>"):
    """The text of a model file's bytes ``data`` (UTF-8); errors name ``file``."""
    try:
        return data.decode("utf-8") if isinstance(data, bytes) else data
    except UnicodeDecodeError as exc:
        raise ModelFileError(file, "", f"is not UTF-8 text ({exc.reason} at byte "
                             f"{exc.start}); save it as UTF-8") from None


def parse_document(data, file="<text>"):
    """The parsed TOML of ``data`` (bytes or text); errors name ``file``."""
    text = decode_text(data, file)
    if "\x00" in text:
        raise ModelFileError(file, f"line {text.count(chr(10), 0, text.index(chr(0))) + 1}",
                             "holds a NUL character; is it a binary file?")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
        if m:
            msg = msg[:m.start()].strip()
            raise ModelFileError(file, f"line {m.group(1)}", f"TOML syntax error: {msg} "
                                 f"(column {m.group(2)}); see docs/model-files.md") from None
        msg = re.sub(r"\s*\(at end of document\)", "", msg)
        raise ModelFileError(file, "end of file", f"TOML syntax error: {msg}") from None
    except RecursionError:
        raise ModelFileError(file, "", f"arrays or tables are nested too deeply (at most "
                             f"{limits.MAX_NESTING} levels)") from None
    except ValueError:                # an integer literal of thousands of digits
        raise ModelFileError(file, "", f"holds an integer literal of more than 4300 digits "
                             f"(at most {limits.MAX_INTEGER_DIGITS}); write it as a float "
                             "such as 1.5e30") from None
    scan_document(doc, file)
    return doc


def scan_document(doc, file):
    """Check every value of a parsed model file against the input limits (``mbdyn.limits``):
    nesting depth, integer size, finite and bounded numbers, no control characters in keys
    or strings (tab and newline aside).  Iterative: a hostile nesting cannot exhaust the
    stack.  Raises ``ModelFileError`` at the first offending key."""
    stack = [((), doc)]
    while stack:
        path, value = stack.pop()
        where = format_path(path) if path else ""
        if len(path) > limits.MAX_NESTING:
            raise ModelFileError(file, format_path(path[:limits.MAX_NESTING]),
                                 f"arrays or tables are nested more than {limits.MAX_NESTING} "
                                 "levels deep; no model key needs that")
        if isinstance(value, dict):
            for k, v in value.items():
                problem = label_problem(k) if k != "" else "must not be empty"
                if problem or len(k) > limits.MAX_NAME_LENGTH:
                    raise ModelFileError(file, format_path(path + (shown(k)[:60],)),
                                         f"the key {problem or 'is too long'}")
                stack.append((path + (k,), v))
        elif isinstance(value, list):
            stack.extend((path + (i,), v) for i, v in enumerate(value))
        elif isinstance(value, bool):
            continue
        elif isinstance(value, int):
            if len(str(abs(value))) > limits.MAX_INTEGER_DIGITS:
                raise ModelFileError(file, where, f"the integer has {len(str(abs(value)))} "
                                     f"digits (at most {limits.MAX_INTEGER_DIGITS}); write it "
                                     "as a float such as 1.5e30 if you mean it")
            _check_magnitude(file, where, float(value))
        elif isinstance(value, float):
            if not math.isfinite(value):
                raise ModelFileError(file, where, f"{value} is not a finite number")
            _check_magnitude(file, where, value)
        elif isinstance(value, str):
            bad = [c for c in value if unicodedata.category(c) == "Cc" and c not in "\t\n\r"]
            if bad:
                raise ModelFileError(file, where, "the text holds control characters ("
                                     + ", ".join(f"U+{ord(c):04X}" for c in bad[:3])
                                     + "); remove them")


def _check_magnitude(file, where, value):
    problem = limits.magnitude_problem(value)
    if problem:
        raise ModelFileError(file, where, problem)


def parse_set_value(text):
    """The value of ``--set PATH=VALUE``: a TOML value (number, boolean, array, quoted
    string) if ``VALUE`` reads as one, otherwise the text itself (an expression or a name)."""
    text = text.strip()
    if not text:
        raise ValueError("the value is empty")
    if "\x00" in text:
        raise ValueError("the value holds a NUL character")
    try:
        value = tomllib.loads("v = " + text)["v"]
    except tomllib.TOMLDecodeError:
        return text
    except RecursionError:
        raise ValueError(f"arrays are nested too deeply (at most {limits.MAX_NESTING})") \
            from None
    except ValueError:                # an integer literal of thousands of digits
        raise ValueError(f"the integer has more than 4300 digits (at most "
                         f"{limits.MAX_INTEGER_DIGITS})") from None
    try:
        scan_document({"v": value}, "--set")
    except ModelFileError as exc:
        raise ValueError(exc.problem) from None
    return value

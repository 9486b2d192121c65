"""What a name may be, and how a name or any text is shown safely.

Coordinates, speeds, parameters and file-side element names become sympy symbols, CSV
columns and expression names, so they are *identifiers*: ASCII letters, digits and ``_``,
not starting with a digit.  Unicode look-alikes (a full-width ``ｔ``, a Greek ``π``) are
refused rather than taken as new symbols that merely look like ``t`` or ``pi``.  Labels
given in Python (frame and joint names) may hold any printable text.  Control characters
are refused everywhere: printed raw they would drive the user's terminal.
"""
from __future__ import annotations

import keyword
import unicodedata

from .limits import MAX_NAME_LENGTH


def _controls(text):
    return [c for c in text if unicodedata.category(c) in ("Cc", "Cf", "Cs", "Co", "Cn")]


def label_problem(name):
    """Why ``name`` cannot label an element (``None`` if it can)."""
    if not isinstance(name, str):
        return f"must be a string, got {type(name).__name__}"
    if not name.strip():
        return "must not be empty"
    bad = _controls(name)
    if bad:
        return "holds control characters (" + ", ".join(f"U+{ord(c):04X}" for c in bad[:3]) \
            + "); use printable text"
    if len(name) > MAX_NAME_LENGTH:
        return f"is {len(name)} characters long (at most {MAX_NAME_LENGTH})"
    return None


def identifier_problem(name):
    """Why ``name`` is not an identifier mbdyn accepts (``None`` if it is)."""
    problem = label_problem(name)
    if problem:
        return problem
    if not name.isascii():
        plain = unicodedata.normalize("NFKC", name)
        hint = f" (it reads like {plain!r})" if plain.isascii() and plain != name else ""
        return (f"has characters outside ASCII{hint}; use ASCII letters, digits and "
                "underscores")
    if not name.isidentifier():
        return ("is not an identifier: use letters, digits and underscores, not starting "
                "with a digit")
    if keyword.iskeyword(name):
        return "is a Python keyword, which generated code cannot use as a name"
    if name.startswith("__") and name.endswith("__"):
        return "is a special (dunder) name; choose another"
    return None


def is_identifier(name):
    return identifier_problem(name) is None


def shown(text):
    """``text`` with control characters escaped, safe to print on a terminal."""
    text = str(text)
    if not _controls(text.replace("\n", "").replace("\t", "")):
        return text
    return "".join(c if c in "\n\t" or not _controls(c) else
                   c.encode("unicode_escape").decode("ascii") for c in text)

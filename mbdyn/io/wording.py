"""How a model file's messages name things: a key path (``bodies[2].mass``), the kind and
text of a value as the file wrote it, a close match for a misspelt name."""
from __future__ import annotations

import difflib

from ..names import shown


def format_path(path):
    """``("bodies", 2, "mass")`` -> ``"bodies[2].mass"``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def suggest(word, choices):
    """``"did you mean 'X'? "`` for the choice closest to ``word``, else ``""``."""
    low = {str(c).lower(): str(c) for c in choices}
    if str(word).lower() in low:        # a matter of case first (rk45 -> RK45)
        close = [low[str(word).lower()]]
    else:
        close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1,
                                          cutoff=0.6)
    return f"did you mean {close[0]!r}? " if close else ""


def kind_of(value):
    """What a TOML value is, in words: ``"a number"``, ``"an array"``, ..."""
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return type(value).__name__


def show(value):
    """A value as the file wrote it, shortened to a line."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        text = shown(value)
        return f'"{text}"' if len(text) < 60 else f'"{text[:56]}..."'
    text = repr(value)
    return text if len(text) < 60 else text[:57] + "..."

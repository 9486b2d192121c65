"""The arguments of the analysis functions, checked before any work.

A wrong type, a non-finite number or a count below one is a ``ModelError`` that names the
function and the argument and says what it must be -- never a raw ``TypeError`` from deep
inside, and never a result computed from NaN.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from ..errors import ModelError


def brief(value, width=40):
    """``repr(value)``, shortened to ``width`` characters for a message."""
    text = repr(value)
    return text if len(text) <= width else text[:width - 3] + "..."


def model(value, where):
    """A compiled ``Model``."""
    from ..compiled.model import Model
    if not isinstance(value, Model):
        raise ModelError(f"{where}: model must be a compiled Model (System.compile(), or "
                         f"mb.load_model(...).model), got {type(value).__name__}")
    return value


def number(value, where, name, positive=False):
    """A finite real number (``positive``: > 0)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ModelError(f"{where}: {name} must be a number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise ModelError(f"{where}: {name} must be a finite number, got {v}")
    if positive and not v > 0:
        raise ModelError(f"{where}: {name} must be > 0, got {v:g}")
    return v


def count(value, where, name):
    """A whole number >= 1."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise ModelError(f"{where}: {name} must be a whole number >= 1, got {value!r}")
    return int(value)


def names(value, where, name):
    """A name or a list of names (``None``: none)."""
    if value is None:
        return []
    if isinstance(value, str):
        return [value]
    if isinstance(value, (list, tuple, set, frozenset)) and \
            all(isinstance(n, str) for n in value):
        return list(value)
    raise ModelError(f"{where}: {name} must be a name or a list of names, got {value!r}")


def pairs(value, where, name):
    """A list of pairs of names, e.g. ``[("y", "z")]``."""
    if value is None:
        return []
    if isinstance(value, (list, tuple)) and all(
            isinstance(p, (list, tuple)) and len(p) == 2 and all(isinstance(n, str) for n in p)
            for p in value):
        return [tuple(p) for p in value]
    raise ModelError(f"{where}: {name} must be a list of pairs of coordinate names, e.g. "
                     f"[(\"y\", \"z\")], got {value!r}")


def state(value, where, name):
    """An array of numbers, or ``None``/a mapping ``{name: value}`` left as it is."""
    if value is None or isinstance(value, dict):
        return value
    try:
        return np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{where}: {name} must be an array of numbers or a mapping "
                         f"{{name: value}}, got {value!r}") from None

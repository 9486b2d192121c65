"""Loads: a force at a point of a body and/or a moment on it, constant, a function of
``(t, q, u)`` or sympy expressions, each validated on creation.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy

from ..errors import ModelError
from .values import _vector3, has_symbols, numeric, substitute


@dataclass(frozen=True)
class Load:
    """A force at a point of a body and/or a moment on it, in world or body components.

    ``force`` and ``moment`` are each a constant array, a callable ``(t, q, u) -> 3 values``,
    or a tuple of three sympy expressions of ``t`` and the model's coordinate and speed
    names (parameters already substituted), turned into a callable at compile.
    """
    name: str
    body: str
    force: object
    moment: object
    point: np.ndarray
    in_body: bool
    symbolic: dict = field(default_factory=dict)


def make_load(name, body, force=None, moment=None, point=(0, 0, 0), frame="world",
              parameters=None):
    element = f"load {name!r}"
    parameters = parameters or {}
    raw = {"force": force, "moment": moment, "point": point}
    symbolic = {k: v for k, v in raw.items() if not callable(v) and has_symbols(v)}
    point = numeric(point, parameters, element, "point")
    if frame not in ("world", "body"):
        raise ModelError(f"{element}: frame must be 'world' or 'body', got {frame!r}")
    if force is None and moment is None:
        raise ModelError(f"{element}: give a force, a moment or both")
    parts = []
    for what, val in (("force", force), ("moment", moment)):
        if val is None:
            parts.append(np.zeros(3))
        elif callable(val):
            parts.append(val)
        elif has_symbols(val):
            exprs = tuple(substitute(v if isinstance(v, sympy.Basic) else sympy.Float(float(v)),
                                     parameters) for v in val)
            if len(exprs) != 3:
                raise ModelError(f"{element}: {what} must have three components")
            if all(not e.free_symbols for e in exprs):
                parts.append(_vector3([float(e) for e in exprs], what, element))
            else:
                parts.append(exprs)
        else:
            parts.append(_vector3(val, what, element))
    point = _vector3(point, "point", element)
    return Load(name, body, parts[0], parts[1], point, frame == "body", symbolic)

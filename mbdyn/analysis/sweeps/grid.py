"""The members of a sweep: grid axes from their texts (``parse_range``), grids and lists
of overrides expanded into members (``expand``)."""
from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Mapping

import numpy as np

from ... import limits
from ...errors import ModelError
from ..arguments import brief


def parse_range(text, path="?"):
    """The values of one grid axis from its text: ``START:STOP:N`` (N points, both ends
    included), ``START:STOP:N:log`` (log spacing, same signs), a TOML array
    ``[a, b, "pi/4"]`` or a single value."""
    from ...io.schema import parse_set_value
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
            check_path_text(path, "grid path")
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


def check_path_text(path, what):
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
                         f"{brief(overrides)}")
    combos = []
    for k, m in enumerate(overrides):
        if len(combos) >= limits.MAX_SWEEP_MEMBERS:
            raise ModelError(f"the sweep has more than {limits.MAX_SWEEP_MEMBERS} members; "
                             "split it into several sweeps")
        if not isinstance(m, Mapping):
            raise ModelError(f"sweep: overrides[{k}] is {type(m).__name__} {brief(m)}, not a "
                             "member {path: value}, e.g. {'parameters.Mz': -0.01}")
        for p in m:
            check_path_text(p, f"overrides[{k}] path")
        if combos and {p for p, _ in combos[0]} != set(m):
            raise ModelError(f"sweep: overrides[{k}] sets {', '.join(m) or 'nothing'} but "
                             f"overrides[0] sets {', '.join(p for p, _ in combos[0]) or 'nothing'}"
                             "; every member sets the same paths (the table's columns)")
        combos.append(list(m.items()))
    return combos

"""What a sweep keeps of each member: the quantities, their columns (``columns``) and
their values from a result (``measure``); see mbdyn.analysis.sweep's docstring."""
from __future__ import annotations

import math

import numpy as np

from ...errors import ModelError

DEFAULT_QUANTITIES = ("final", "events", "t_final")
STATS = ("max", "min", "absmax", "mean", "std")
SIMPLE = ("final", "events", "t_final", "energy_drift", "steps", "rhs_evaluations")


def _series(result, name):
    if name in ("energy", "total_energy"):
        return np.asarray(result.energy["total"]) if result.energy is not None else None
    try:
        return np.asarray(result[name], dtype=float)
    except (KeyError, IndexError, ValueError, TypeError):
        return None


def columns(scene, quantities):
    """The quantity columns of ``scene`` for ``quantities`` (errors name the bad one)."""
    model = scene.model
    names = list(model.coordinates) + list(model.speeds)
    cols = []
    for q in quantities:
        if q == "final":
            cols += [f"final.{n}" for n in names]
        elif q == "events":
            cols += [f"event.{e.name}" for e in scene.events]
        elif q in SIMPLE:
            cols.append(q)
        elif ":" in q and q.split(":", 1)[0] in STATS:
            stat, x = q.split(":", 1)
            if x not in names + ["energy"]:
                raise ModelError(f"quantity {q!r}: {x!r} is not a coordinate, a speed or "
                                 f"energy; the names are: {', '.join(names)}, energy")
            cols.append(f"{stat}.{x}")
        else:
            raise ModelError(f"unknown quantity {q!r}; use {', '.join(SIMPLE)} or "
                             f"STAT:NAME with STAT one of {', '.join(STATS)}")
    return cols


def column_of(name):
    """The table column ``name`` stands for: a column name as it is, or a quantity as
    ``-q`` spells it, ``STAT:X``, as its column ``STAT.X`` (``-q absmax:pitch`` makes the
    column ``absmax.pitch``; ``--plot`` takes either back)."""
    stat, sep, x = str(name).partition(":")
    return f"{stat}.{x}" if sep and stat in STATS else str(name)


def needs_energy(quantities):
    return any(q == "energy_drift" or q.endswith(":energy") for q in quantities)


def measure(scene, result, quantities):
    """``{column: float}`` of a (possibly partial) result."""
    model = scene.model
    out = {}
    n = len(result.t)
    for q in quantities:
        if q == "final":
            for name, v in zip(model.coordinates, result.q[-1] if n else [np.nan] * model.nq):
                out[f"final.{name}"] = float(v)
            for name, v in zip(model.speeds, result.u[-1] if n else [np.nan] * model.nu):
                out[f"final.{name}"] = float(v)
        elif q == "events":
            for e in scene.events:
                times = [t for name, t in result.events if name == e.name]
                out[f"event.{e.name}"] = float(times[0]) if times else math.nan
        elif q == "t_final":
            out["t_final"] = float(result.t[-1]) if n else math.nan
        elif q == "energy_drift":
            s = _series(result, "energy")
            out[q] = float(s[-1] - s[0]) if s is not None and len(s) else math.nan
        elif q in ("steps", "rhs_evaluations"):
            out[q] = float(result.stats.get(q, math.nan))
        else:
            stat, x = q.split(":", 1)
            s = _series(result, x)
            if s is None or not len(s):
                out[f"{stat}.{x}"] = math.nan
                continue
            fn = {"max": np.max, "min": np.min, "mean": np.mean, "std": np.std,
                  "absmax": lambda a: np.max(np.abs(a))}[stat]
            out[f"{stat}.{x}"] = float(fn(s))
    return out

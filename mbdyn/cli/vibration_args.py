"""Arguments shared by ``mbdyn equilibrium``, ``mbdyn modes`` and ``mbdyn campbell``."""
from __future__ import annotations

import numpy as np

from .. import limits
from ..errors import ModelError
from .common import finite


def add_vibration_arguments(p, whirl=True):
    p.add_argument("--fixed", metavar="NAMES", default="",
                   help="coordinates or joints held at their initial values (comma-separated),"
                        " e.g. a cyclic spin angle")
    p.add_argument("--t", type=finite, default=0.0, metavar="T",
                   help="time of the operating point (drives, time-dependent loads)")
    if whirl:
        p.add_argument("--whirl", metavar="Y,Z", action="append", default=[],
                       help="a pair of lateral coordinates across the spin axis (Y x Z along "
                            "the spin), to tell forward from backward whirl; repeatable")
    p.add_argument("--json", action="store_true", help="one JSON object on stdout")


def names(text):
    return [n.strip() for n in str(text).split(",") if n.strip()]


def whirl_pairs(args):
    pairs = []
    for item in args.whirl:
        pair = names(item)
        if len(pair) != 2:
            raise ModelError(f"--whirl {item!r}: give two coordinate names, e.g. --whirl y,z")
        pairs.append(tuple(pair))
    return pairs


def _too_many(text, n):
    raise ModelError(f"--values {text!r}: {n} values are more than {limits.MAX_RANGE_POINTS}; "
                     "give fewer")


def _check_bounds(text, *bounds):
    for v in bounds:
        problem = f"{v:g} is not a finite number" if not np.isfinite(v) else \
            limits.magnitude_problem(v)
        if problem:
            raise ModelError(f"--values {text!r}: {problem}")


def value_range(text):
    """``START:STOP:N`` (linear), ``START:STOP:Nlog`` (logarithmic) or ``a,b,c``."""
    text = str(text).strip()
    try:
        if ":" in text:
            start, stop, n = text.split(":")
            log = n.endswith("log")
            n = int(n[:-3] if log else n)
            if n < 2:
                raise ValueError
            if n > limits.MAX_RANGE_POINTS:
                return _too_many(text, n)
            start, stop = float(start), float(stop)
            _check_bounds(text, start, stop)
            if log:
                if not (start * stop > 0):
                    raise ModelError(f"--values {text!r}: a logarithmic range needs START "
                                     f"and STOP of one sign, neither zero (got {start:g} and "
                                     f"{stop:g}); for a linear range write {start:g}:{stop:g}:"
                                     f"{n}")
                return np.geomspace(start, stop, n)
            return np.linspace(start, stop, n)
        values = np.array([float(v) for v in text.split(",")])
    except ModelError:
        raise
    except ValueError:
        raise ModelError(f"--values {text!r}: give START:STOP:N (N >= 2), START:STOP:Nlog "
                         "or a comma-separated list of numbers") from None
    if len(values) < 2:
        raise ModelError(f"--values {text!r}: give at least two values")
    _check_bounds(text, *values)
    return values

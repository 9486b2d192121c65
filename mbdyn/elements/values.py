"""The values a user gives an element: numbers or sympy expressions of parameters, vectors,
axes, orientations and Euler sequences, checked; and ``t``, the time symbol of drives and
loads.  Every error names the element and says what to change.
"""
from __future__ import annotations

import math

import numpy as np
import sympy

from ..errors import ModelError

#: The time symbol for drive expressions: ``drive=Omega * mb.t``.
t = sympy.Symbol("t", real=True)


def deg(x):
    """``x`` degrees in radians (``mb.deg(30)``, ``q0={"theta": mb.deg(45)}``), as
    ``deg(...)`` in model-file expressions: a float for a number, an array for an array,
    ``x*pi/180`` for a sympy expression (``drive=mb.deg(10) * mb.t`` stays exact)."""
    if isinstance(x, sympy.Basic):
        return x * sympy.pi / 180
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.number, list,
                                                             tuple, np.ndarray)):
        raise ModelError(f"deg: give a number of degrees, got {x!r}")
    if isinstance(x, (list, tuple, np.ndarray)):
        return np.deg2rad(np.asarray(x, dtype=float))
    return math.radians(x)


AXIS_NAMES = {"x": 0, "y": 1, "z": 2}


def has_symbols(value):
    """True if ``value`` (a number, sympy object or nested sequence) holds a sympy expression."""
    if isinstance(value, sympy.Basic):
        return not value.is_number
    if isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray) and value.dtype == object):
        return any(has_symbols(v) for v in value)
    return False


def substitute(expr, parameters):
    """``expr`` with every symbol named in ``parameters`` replaced by its value."""
    if not isinstance(expr, sympy.Basic):
        return expr
    return expr.subs({s: parameters[s.name] for s in expr.free_symbols if s.name in parameters})


def numeric(value, parameters, element, what):
    """Evaluate ``value`` (numbers, sympy expressions of parameters, nested sequences) to
    floats; unknown symbols are an error that names them."""
    if isinstance(value, sympy.Basic):
        v = substitute(value, parameters)
        if v.free_symbols:
            names = ", ".join(sorted(x.name for x in v.free_symbols))
            raise ModelError(f"{element}: {what} uses {names}, which are not parameters of the "
                             "system; add them to System(parameters={...}) or use numbers")
        try:
            return float(v)
        except TypeError:
            raise ModelError(f"{element}: {what} = {value} is not a real number") from None
    if isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray) and value.dtype == object):
        return [numeric(v, parameters, element, what) for v in value]
    return value


def _vector3(value, what, element):
    try:
        arr = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {what} must be three numbers, got {value!r}") from None
    if arr.shape != (3,):
        raise ModelError(f"{element}: {what} must be three numbers, got {value!r}")
    if not np.all(np.isfinite(arr)):
        raise ModelError(f"{element}: {what} must be finite, got {value!r}")
    return arr


def square_matrix(value, n, element, expected, nonfinite, show=False):
    """A finite ``n x n`` float array from ``n`` diagonal values or the matrix itself.
    The errors say ``expected`` (what the value must be; ``show``: quoting a value that
    is not numbers) and ``nonfinite`` (of an entry that is not finite)."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {expected}" + (f", got {value!r}" if show else "")) \
            from None
    if arr.shape == (n,):
        arr = np.diag(arr)
    if arr.shape != (n, n):
        raise ModelError(f"{element}: {expected}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ModelError(f"{element}: {nonfinite}")
    return arr


def parse_axis(axis, element):
    """A unit vector from ``"x"``/``"-y"``/... or three numbers; refuses zero and non-finite."""
    if isinstance(axis, str):
        key = axis.strip().lower()
        sign = -1.0 if key.startswith("-") else 1.0
        key = key.lstrip("+-")
        if key not in AXIS_NAMES:
            raise ModelError(f"{element}: axis {axis!r} is not one of 'x', 'y', 'z' "
                             "(optionally signed) or a vector of three numbers")
        a = np.zeros(3)
        a[AXIS_NAMES[key]] = sign
        return a
    a = _vector3(axis, "axis", element)
    norm = np.linalg.norm(a)
    if norm < 1e-12:
        raise ModelError(f"{element}: axis {tuple(a)} has zero length; give a direction "
                         "such as (0, 0, 1) or 'z'")
    return a / norm


def parse_orientation(orientation, element):
    """Rotation matrix ``C`` of a joint frame in its parent (``P s = C . J s``).

    Accepts None (identity), a 3x3 rotation matrix, a unit quaternion ``(w, x, y, z)``,
    or an axis-angle pair ``(axis, angle)`` such as ``("z", pi/2)``.
    """
    if orientation is None:
        return np.eye(3)
    if (isinstance(orientation, (tuple, list)) and len(orientation) == 2
            and not np.ndim(orientation[1])):
        axis = parse_axis(orientation[0], element + " orientation")
        try:
            angle = float(orientation[1])
        except (TypeError, ValueError):
            raise ModelError(f"{element}: the angle of orientation (axis, angle) must be a "
                             f"number, got {orientation[1]!r}") from None
        if not math.isfinite(angle):
            raise ModelError(f"{element}: the angle of orientation (axis, angle) must be "
                             f"finite, got {angle}")
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
    try:
        arr = np.asarray(orientation, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: orientation must be a 3x3 rotation matrix, a unit "
                         f"quaternion (w, x, y, z) or (axis, angle), got {orientation!r}") \
            from None
    if arr.shape == (4,):
        n = np.linalg.norm(arr)
        if not np.isfinite(n) or abs(n - 1.0) > 1e-6:
            raise ModelError(f"{element}: orientation quaternion {tuple(arr)} must have unit "
                             f"length (it has {n:.6g}); normalise it")
        w, x, y, z = arr / n
        return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    if arr.shape != (3, 3) or not np.all(np.isfinite(arr)):
        raise ModelError(f"{element}: orientation must be a 3x3 rotation matrix, a unit "
                         "quaternion (w, x, y, z) or (axis, angle)")
    if (np.abs(arr.T @ arr - np.eye(3)).max() > 1e-8 or np.linalg.det(arr) < 0):
        raise ModelError(f"{element}: orientation matrix is not a proper rotation "
                         "(needs C^T C = I and det C = +1)")
    return arr


def parse_sequence(sequence, element):
    """Axis indices of an Euler sequence such as ``"ZXZ"``; consecutive axes must differ."""
    seq = "ZXZ" if sequence is None else str(sequence).upper()
    if len(seq) != 3 or any(c not in "XYZ" for c in seq) or seq[0] == seq[1] or seq[1] == seq[2]:
        raise ModelError(f"{element}: Euler sequence {sequence!r} is not valid; use three "
                         "of X, Y, Z with no axis repeated twice in a row (e.g. 'ZXZ', 'XYZ')")
    return tuple("XYZ".index(c) for c in seq)

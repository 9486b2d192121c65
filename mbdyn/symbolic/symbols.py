"""The symbols of a model and exact sympy values of its numbers.

Parameters, coordinates, speeds, speed rates and the time ``t`` become real sympy symbols
named as in the model (``s.symbols("m l")`` gives the same objects).  Numbers given as floats
become exact rationals (or simple surds such as ``sqrt(2)/2``) so that trigonometric
identities and cancellations work exactly; a float that no simple exact number matches stays
a float.
"""
from __future__ import annotations

import math

import numpy as np
import sympy

from ..elements.values import t as TIME
from ..errors import ModelError

__all__ = ["TIME", "exact", "exact_vector", "exact_matrix", "canonical", "rotation_about_axis",
           "rotation_about_coordinate_axis", "quaternion_matrix", "orientation_matrix",
           "cross", "Symbols"]


def canonical(expr, table):
    """``expr`` with every free symbol replaced by the symbol of the same name in ``table``
    (``{name: Symbol}``), so that symbols built with other assumptions still match."""
    if not isinstance(expr, sympy.Basic):
        return exact(expr)
    mapping = {}
    for s in expr.free_symbols:
        new = table.get(s.name)
        if new is not None and new is not s:
            mapping[s] = new
    expr = expr.xreplace(mapping) if mapping else expr
    floats = expr.atoms(sympy.Float)
    if floats:
        expr = expr.xreplace({f: exact(float(f)) for f in floats})
    return expr


def exact(x, snap=0.0):
    """An exact sympy number for the float ``x``: a short decimal becomes a rational
    (0.07 -> 7/100), a simple surd is recognised (0.7071... -> sqrt(2)/2); values with
    ``|x| <= snap`` become 0 (used for rotation matrices computed in floating point)."""
    if isinstance(x, sympy.Basic):
        return x
    x = float(x)
    if not math.isfinite(x):
        raise ModelError(f"cannot use the non-finite number {x} in a symbolic derivation")
    if abs(x) <= snap or x == 0.0:
        return sympy.Integer(0)
    if x.is_integer() and abs(x) < 1e15:
        return sympy.Integer(int(x))
    text = repr(x)
    mantissa = text.split("e")[0].replace("-", "").replace(".", "").lstrip("0")
    if len(mantissa) <= 10:
        return sympy.Rational(text)
    tol = 4e-16 * max(1.0, abs(x))
    sign = 1 if x > 0 else -1
    square = sympy.Rational(x * x).limit_denominator(1000)          # sqrt(2)/2, sqrt(3)/2
    guess = sign * sympy.sqrt(square)
    if abs(float(guess) - x) <= tol:
        return guess
    turns = sympy.Rational(x / math.pi).limit_denominator(360)        # angles: pi/6, 2*pi/3
    if abs(float(turns) * math.pi - x) <= tol:
        return turns * sympy.pi
    return sympy.Float(x)


def exact_vector(values, table, n=3, snap=0.0):
    vals = list(np.asarray(values, dtype=object).reshape(-1))
    if len(vals) != n:
        raise ModelError(f"expected {n} values, got {values!r}")
    return sympy.Matrix([canonical(v, table) if isinstance(v, sympy.Basic) else exact(v, snap)
                         for v in vals])


def exact_matrix(values, table, snap=0.0):
    arr = np.asarray(values, dtype=object)
    return sympy.Matrix(3, 3, [canonical(v, table) if isinstance(v, sympy.Basic)
                               else exact(v, snap) for v in arr.reshape(-1)])


def cross(a, b):
    return sympy.Matrix([a[1] * b[2] - a[2] * b[1],
                         a[2] * b[0] - a[0] * b[2],
                         a[0] * b[1] - a[1] * b[0]])


def rotation_about_coordinate_axis(k, angle):
    """Rotation by ``angle`` about coordinate axis ``k`` mapping rotated to fixed components;
    the textbook's ``T_k(angle)`` is its transpose."""
    c, s = sympy.cos(angle), sympy.sin(angle)
    R = sympy.zeros(3, 3)
    i, j = (k + 1) % 3, (k + 2) % 3
    R[k, k] = 1
    R[i, i] = c
    R[j, j] = c
    R[i, j] = -s
    R[j, i] = s
    return R


def rotation_about_axis(axis, angle):
    """Rodrigues' rotation by ``angle`` about the unit vector ``axis`` (rotated -> fixed)."""
    nz = [k for k in range(3) if axis[k] != 0]
    if len(nz) == 1 and axis[nz[0]] in (1, -1):
        return rotation_about_coordinate_axis(nz[0], angle if axis[nz[0]] == 1 else -angle)
    c, s = sympy.cos(angle), sympy.sin(angle)
    x, y, z = axis
    K = sympy.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return (sympy.eye(3) * c + s * K + (1 - c) * (axis * axis.T)).applyfunc(sympy.expand)


def quaternion_matrix(w, x, y, z):
    """Rotation matrix of the unit quaternion ``(w, x, y, z)`` (rotated -> fixed)."""
    return sympy.Matrix([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def axis_vector(axis, table):
    """A unit axis from ``"x"``/``"-y"`` or a (possibly symbolic) vector."""
    if isinstance(axis, str):
        key = axis.strip().lower()
        sign = -1 if key.startswith("-") else 1
        v = sympy.zeros(3, 1)
        v["xyz".index(key.lstrip("+-"))] = sign
        return v
    v = exact_vector(axis, table)
    n2 = sympy.simplify((v.T * v)[0])
    if n2 == 1:
        return v
    return (v / sympy.sqrt(n2)).applyfunc(sympy.simplify)


def orientation_matrix(raw, numeric, table):
    """``C`` (parent <- joint frame) from a joint's raw orientation (None, (axis, angle), a
    quaternion or a 3x3 matrix, possibly symbolic) or from its numeric matrix."""
    if raw is None:
        return exact_matrix(numeric, table, snap=1e-15)
    if isinstance(raw, (tuple, list)) and len(raw) == 2 and not np.ndim(raw[1]):
        axis = axis_vector(raw[0], table)
        angle = canonical(raw[1], table) if isinstance(raw[1], sympy.Basic) else exact(raw[1])
        return rotation_about_axis(axis, angle)
    arr = np.asarray(raw, dtype=object)
    if arr.shape == (4,):
        w, x, y, z = [canonical(v, table) if isinstance(v, sympy.Basic) else exact(v)
                      for v in arr]
        return quaternion_matrix(w, x, y, z)
    return exact_matrix(arr, table)


def _rate_name(speed, taken):
    base = speed[:-4] + "_ddot" if speed.endswith("_dot") else speed + "_dot"
    name = base
    while name in taken:
        name += "_rate"
    return name


class Symbols:
    """The symbols of a compiled model: ``params``, ``q``, ``u``, ``ud`` (speed rates) and
    ``t``, each a real ``sympy.Symbol`` named as in the model; ``table`` maps every name to
    its symbol."""

    def __init__(self, model):
        self.t = TIME
        self.params = {n: sympy.Symbol(n, real=True) for n in model.parameters}
        self.q = [sympy.Symbol(n, real=True) for n in model.coordinates]
        self.u = [sympy.Symbol(n, real=True) for n in model.speeds]
        taken = set(model.parameters) | set(model.coordinates) | set(model.speeds) | {"t"}
        names = []
        for s in model.speeds:
            nm = _rate_name(s, taken)
            taken.add(nm)
            names.append(nm)
        self.ud = [sympy.Symbol(n, real=True) for n in names]
        self.table = {"t": self.t}
        self.table.update(self.params)
        for s in self.q + self.u + self.ud:
            self.table[s.name] = s
        clash = set(model.parameters) & (set(model.coordinates) | set(model.speeds))
        if clash:
            raise ModelError(f"model {model.name!r}: names {sorted(clash)} are both parameters "
                             "and coordinates/speeds; rename one of them")

    @property
    def rate_of(self):
        """``{speed symbol: rate symbol}``."""
        return dict(zip(self.u, self.ud))

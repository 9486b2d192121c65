"""What a force element is given, read and checked: numbers, points, 6x6 matrices, tables,
laws ``f(x, v)``, the frames it acts between and its keys.  Every error names the
element and says what to change.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ModelError
from .tables import make_table
from .values import _vector3, numeric, square_matrix


class Given:
    """The keywords ``kw`` of force element ``element`` (``"force 'name'"``), read with the
    system's ``parameters``; ``gravity`` gives a contact's default plane normal."""

    def __init__(self, kw, element, parameters, gravity):
        self.kw = kw
        self.element = element
        self.parameters = parameters
        self.gravity = gravity
        self.interp = kw.get("interpolation", "pchip")

    def num(self, value, what, minimum=None, positive=False):
        """A finite float of ``value`` (see ``number``)."""
        return number(value, self.parameters, self.element, what, minimum, positive)

    def table(self, key, clamp=False):
        """The ``Table`` of keyword ``key``, or None where it is not given."""
        return (None if self.kw.get(key) is None
                else make_table(self.kw[key], self.element, key, self.interp, clamp))

    def vector(self, key):
        """The three numbers of keyword ``key`` (default the origin)."""
        return _vector3(numeric(self.kw.get(key, (0, 0, 0)), self.parameters, self.element,
                                key), key, self.element)

    def matrix6(self, value, what):
        """A 6x6 matrix from six diagonal values or the matrix itself."""
        v = numeric(value, self.parameters, self.element, what)
        return square_matrix(v, 6, self.element, f"{what} must be six diagonal values or a "
                             "6x6 matrix", f"{what} holds non-finite numbers")

    def check_keys(self, allowed, kind, required, missing):
        """Refuses a keyword a ``kind`` does not take, then the lack of the ``required``
        one (``missing`` says what to give)."""
        extra = sorted(set(self.kw) - set(allowed))
        if extra:
            raise ModelError(f"{self.element}: unknown key(s) {', '.join(extra)} for a {kind}; "
                             f"known: {', '.join(sorted(allowed))}")
        if required not in self.kw:
            raise ModelError(f"{self.element}: {missing}")

    def two_frames(self, what):
        """``(body_a, body_b)`` of an element between two frames (``body_b`` default the
        ground): names, and two different ones."""
        element, kw = self.element, self.kw
        frames = (kw["body_a"], kw.get("body_b", "ground"))
        for key, frame in zip(("body_a", "body_b"), frames):
            if not isinstance(frame, str):
                raise ModelError(f"{element}: {key} must be the name of a body, got {frame!r}")
        if frames[0] == frames[1]:
            raise ModelError(f"{element}: body_a and body_b are both {frames[0]!r}; {what} "
                             "acts between two bodies (or a body and the ground)")
        return frames


def number(value, parameters, element, what, minimum=None, positive=False):
    """The finite float of ``value`` (a number or an expression of ``parameters``), checked
    against ``minimum`` or to be ``positive``."""
    v = numeric(value, parameters, element, what)
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {what} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ModelError(f"{element}: {what} must be finite, got {value!r}")
    if positive and v <= 0:
        raise ModelError(f"{element}: {what} must be positive, got {v:g}")
    if minimum is not None and v < minimum:
        raise ModelError(f"{element}: {what} must be >= {minimum:g}, got {v:g}"
                         + ("; a negative damping feeds energy in" if "damping" in what else ""))
    return v


@dataclass(frozen=True)
class Law:
    """A force law ``law(x, v)`` of an elongation (or coordinate offset) ``x`` and its rate
    ``v``: ``function`` for the numbers, ``expression`` (sympy, in the symbols ``x`` and
    ``v`` and the system's parameters) when it was given as one, for the symbolic layer."""
    function: object
    expression: object = None
    #: the expression with the parameters' values in, in the symbols ``x`` and ``v`` (what
    #: compiled code evaluates: ``compiled.programs``)
    numeric: object = None

    def __call__(self, x, v):
        return self.function(x, v)


def make_law(law, parameters, element):
    """A ``Law`` from a callable ``f(x, v)`` or a sympy expression of ``x`` and ``v``."""
    if law is None:
        return None
    if callable(law) and not hasattr(law, "free_symbols"):
        return Law(law)
    import sympy
    if not isinstance(law, sympy.Basic):
        raise ModelError(f"{element}: law must be a function f(x, v) or a sympy expression of "
                         "x (elongation) and v (its rate)")
    named = {s.name: s for s in law.free_symbols}
    extra = sorted(set(named) - {"x", "v"} - set(parameters))
    if extra:
        raise ModelError(f"{element}: law uses {', '.join(extra)}, which are neither x, v nor "
                         "parameters of the system")
    numeric_law = law.subs({named[n]: parameters[n] for n in named if n in parameters})
    xs, vs = sympy.Symbol("x"), sympy.Symbol("v")
    numeric_law = numeric_law.subs({s: (xs if s.name == "x" else vs)
                                    for s in numeric_law.free_symbols})
    fn = sympy.lambdify((xs, vs), numeric_law, "math")
    return Law(lambda x, v: float(fn(x, v)), law, numeric_law)

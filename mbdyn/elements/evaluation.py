"""The numeric value of an expression: ``to_float`` evaluates a sympy expression in floating
point node by node, with the functions of ``FLOAT_FUNCTIONS``; the parser
(``mbdyn.elements.expressions``) computes the value of constant parts with the same
functions, so that a constant that overflows or leaves a function's domain is refused
before sympy's exact arithmetic is asked for it.
"""
from __future__ import annotations

import math

import sympy

from .. import limits

MAX_CONSTANT = limits.MAX_CONSTANT             # |value| of any constant part


class ExpressionError(ValueError):
    """An expression that cannot be read; the message quotes it and says what is allowed."""


#: The same functions on floats, for the value of constant parts and of ``to_float``.
FLOAT_FUNCTIONS = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "atan2": math.atan2, "sinh": math.sinh, "cosh": math.cosh,
    "tanh": math.tanh, "sqrt": math.sqrt, "exp": math.exp,
    "log": lambda x, b=None: math.log(x) if b is None else math.log(x, b),
    "abs": abs, "sign": lambda x: math.copysign(1.0, x) if x else 0.0, "min": min, "max": max,
    "deg": math.radians,
}


def _float_call(fname, args):
    """``FLOAT_FUNCTIONS[fname](*args)``, or the reason it has no finite real value."""
    try:
        v = FLOAT_FUNCTIONS[fname](*args)
    except OverflowError:
        return None, f"{fname}() overflows (beyond {MAX_CONSTANT:g})"
    except (ValueError, ZeroDivisionError):
        shown = ", ".join(f"{a:.6g}" for a in args)
        if fname == "log" and args[0] == 0:
            return None, "log(0) is not finite"
        return None, (f"{fname}({shown}) is not a real number (outside the function's "
                      "domain)")
    if isinstance(v, complex) or not math.isfinite(v):
        return None, f"{fname}() has no finite real value here"
    return float(v), None


def _float_power(a, b):
    try:
        v = a ** b
    except OverflowError:
        return None, f"the power {a:.6g}**{b:.6g} overflows (beyond {MAX_CONSTANT:g})"
    except ZeroDivisionError:
        return None, "zero to a negative power"
    if isinstance(v, complex):
        return None, f"{a:.6g}**{b:.6g} is not a real number"
    if not math.isfinite(v):
        return None, f"the power {a:.6g}**{b:.6g} overflows (beyond {MAX_CONSTANT:g})"
    return float(v), None


def to_float(expr, values=None):
    """``float`` of a sympy expression with ``values`` ``{name: number}`` for its symbols;
    raises ``ExpressionError`` if it is not a finite real number.

    Evaluated in floating point node by node (never ``evalf``, whose exact arithmetic on
    a huge constant such as ``sin(exp(exp(exp(9))))`` has no time bound).
    """
    if isinstance(expr, (int, float)) and not isinstance(expr, bool):
        v = float(expr)
        if not math.isfinite(v):
            raise ExpressionError(f"{expr} is not finite")
        return v
    missing = sorted(s.name for s in expr.free_symbols if s.name not in (values or {}))
    if missing:
        raise ExpressionError(f"{expr} still depends on {', '.join(missing)}")
    v = _evaluate(expr, values or {})
    if abs(v) > MAX_CONSTANT:
        raise ExpressionError(f"{expr} is too large ({v:.6g}; the limit is {MAX_CONSTANT:g})")
    return v


_SYMPY_FLOAT = {"Abs": "abs", "Min": "min", "Max": "max"}


def _evaluate(expr, values):
    """The float value of ``expr`` (symbols from ``values``), iteratively over its tree."""
    memo = {}
    stack = [expr]
    while stack:
        e = stack[-1]
        if e in memo:
            stack.pop()
            continue
        pending = [a for a in e.args if a not in memo]
        if pending and not (e.is_Number or e.is_NumberSymbol or e.is_Symbol):
            stack.extend(pending)
            continue
        stack.pop()
        memo[e] = _evaluate_node(e, [memo.get(a) for a in e.args], values)
    return memo[expr]


def _evaluate_node(e, args, values):
    if e.is_Symbol:
        v = float(values[e.name])
    elif e.is_Integer:
        if abs(e.p).bit_length() > 1024:
            raise ExpressionError(f"an integer of {len(str(abs(e.p)))} digits is too large")
        v = float(e.p)
    elif e.is_Number or e.is_NumberSymbol:
        try:
            v = float(e)
        except (TypeError, OverflowError):
            raise ExpressionError(f"{e} is not a finite real number") from None
    elif e.is_Add:
        v = math.fsum(args)
    elif e.is_Mul:
        v = math.prod(args)
    elif e.is_Pow:
        v, why = _float_power(*args)
        if why:
            raise ExpressionError(why)
    else:
        name = type(e).__name__
        fname = _SYMPY_FLOAT.get(name, name)
        if fname == "exp" or fname in FLOAT_FUNCTIONS:
            v, why = _float_call(fname, args)
            if why:
                raise ExpressionError(why)
        elif e == sympy.I or e.is_imaginary:
            raise ExpressionError(f"{e} is not a real number")
        else:
            raise ExpressionError(f"{e} cannot be evaluated to a number")
    if not math.isfinite(v):
        raise ExpressionError(f"{e} is not finite")
    return v

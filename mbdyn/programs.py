"""Drives written as programs for compiled code (``kernels.programs``): each drive's
``q(t)``, ``q'(t)``, ``q''(t)`` from its sympy expression, so that a compiled integrator can
evaluate them at any stage time.  Only the sympy building blocks the stack machine knows
are translated (numbers, ``t``, sums, products, powers and the elementary functions);
anything else -- a Piecewise, a drive given as Python functions -- makes
``drive_programs`` return ``None`` and the run keeps the Python evaluation.
"""
from __future__ import annotations

import numpy as np
import sympy

from .kernels import programs as kp

_UNARY = {sympy.sin: kp.SIN, sympy.cos: kp.COS, sympy.tan: kp.TAN, sympy.exp: kp.EXP,
          sympy.log: kp.LOG, sympy.asin: kp.ASIN, sympy.acos: kp.ACOS, sympy.atan: kp.ATAN,
          sympy.sinh: kp.SINH, sympy.cosh: kp.COSH, sympy.tanh: kp.TANH, sympy.Abs: kp.ABS}


class Unsupported(Exception):
    """An expression the stack machine cannot evaluate."""


def _emit(expr, ops, consts):
    """Append ``expr`` in postfix order; returns the stack depth it needs."""
    if expr.is_Number or expr.is_NumberSymbol:
        value = float(expr)
        if not np.isfinite(value):
            raise Unsupported(str(expr))
        consts.append(value)
        ops.append((kp.CONST, len(consts) - 1))
        return 1
    if expr.is_Symbol:
        if expr.name != "t":
            raise Unsupported(expr.name)
        ops.append((kp.TIME, 0))
        return 1
    if isinstance(expr, (sympy.Add, sympy.Mul)):
        depth = max(k + _emit(a, ops, consts) for k, a in enumerate(expr.args))
        ops.append((kp.ADD if isinstance(expr, sympy.Add) else kp.MUL, len(expr.args)))
        return depth
    if isinstance(expr, sympy.Pow):
        depth = max(_emit(expr.base, ops, consts), 1 + _emit(expr.exp, ops, consts))
        ops.append((kp.POW, 0))
        return depth
    if isinstance(expr, sympy.atan2):
        depth = max(_emit(expr.args[0], ops, consts), 1 + _emit(expr.args[1], ops, consts))
        ops.append((kp.ATAN2, 0))
        return depth
    if expr.func in _UNARY and len(expr.args) == 1:
        depth = _emit(expr.args[0], ops, consts)
        ops.append((_UNARY[expr.func], 0))
        return depth
    raise Unsupported(type(expr).__name__)


def drive_programs(drives):
    """``(ops, consts, starts)`` of the drives' positions, velocities and accelerations
    (programs ``3 d``, ``3 d + 1``, ``3 d + 2`` of drive ``d``), or ``None`` when one of
    them is not a sympy expression the stack machine can evaluate."""
    ops, consts, starts = [], [], [0]
    t = sympy.Symbol("t", real=True)
    for drive in drives:
        expr = getattr(drive, "expression", None)
        if expr is None:
            return None
        for part in (expr, expr.diff(t), expr.diff(t, 2)):
            try:
                if _emit(part, ops, consts) > kp.STACK:
                    return None
            except Unsupported:
                return None
            starts.append(len(ops))
    return (np.array(ops, np.int64).reshape(-1, 2), np.array(consts, float),
            np.array(starts, np.int64))

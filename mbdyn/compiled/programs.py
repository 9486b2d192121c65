"""Expressions written as programs for compiled code (``kernels.programs``): each drive's
``q(t)``, ``q'(t)``, ``q''(t)`` from its sympy expression, so that a compiled integrator can
evaluate them at any stage time, and each event condition ``g(t, q, u)``, so that a
compiled loop checks its events after every step.  Only the sympy building blocks the stack
machine knows are translated (numbers, ``t``, the state's names, sums, products, powers, the
elementary functions, ``sign``, ``Min``, ``Max``); anything else -- a Piecewise, a drive or
a condition given as a Python function -- makes ``drive_programs`` return ``None``
(``condition_program`` likewise) and the run keeps the Python evaluation.
"""
from __future__ import annotations

import numpy as np
import sympy

from ..kernels import programs as kp

_UNARY = {sympy.sin: kp.SIN, sympy.cos: kp.COS, sympy.tan: kp.TAN, sympy.exp: kp.EXP,
          sympy.log: kp.LOG, sympy.asin: kp.ASIN, sympy.acos: kp.ACOS, sympy.atan: kp.ATAN,
          sympy.sinh: kp.SINH, sympy.cosh: kp.COSH, sympy.tanh: kp.TANH, sympy.Abs: kp.ABS,
          sympy.sign: kp.SIGN}
_NARY = {sympy.Add: kp.ADD, sympy.Mul: kp.MUL, sympy.Min: kp.MIN, sympy.Max: kp.MAX}


class Unsupported(Exception):
    """An expression the stack machine cannot evaluate."""


def _emit(expr, ops, consts, variables=None):
    """Append ``expr`` in postfix order; returns the stack depth it needs.  ``variables``:
    ``{name: index in y}`` of the symbols besides ``t``."""
    if expr.is_Number or expr.is_NumberSymbol:
        value = float(expr)
        if not np.isfinite(value):
            raise Unsupported(str(expr))
        consts.append(value)
        ops.append((kp.CONST, len(consts) - 1))
        return 1
    if expr.is_Symbol:
        if expr.name == "t":
            ops.append((kp.TIME, 0))
        elif variables is not None and expr.name in variables:
            ops.append((kp.VAR, variables[expr.name]))
        else:
            raise Unsupported(expr.name)
        return 1
    if isinstance(expr, (sympy.Add, sympy.Mul, sympy.Min, sympy.Max)):
        depth = max(k + _emit(a, ops, consts, variables) for k, a in enumerate(expr.args))
        ops.append((_NARY[expr.func], len(expr.args)))
        return depth
    if isinstance(expr, sympy.Pow) and expr.exp == sympy.S.Half:
        depth = _emit(expr.base, ops, consts, variables)
        ops.append((kp.SQRT, 0))
        return depth
    if isinstance(expr, sympy.Pow):
        depth = max(_emit(expr.base, ops, consts, variables),
                    1 + _emit(expr.exp, ops, consts, variables))
        ops.append((kp.POW, 0))
        return depth
    if isinstance(expr, sympy.atan2):
        depth = max(_emit(expr.args[0], ops, consts, variables),
                    1 + _emit(expr.args[1], ops, consts, variables))
        ops.append((kp.ATAN2, 0))
        return depth
    if expr.func in _UNARY and len(expr.args) == 1:
        depth = _emit(expr.args[0], ops, consts, variables)
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


def condition_program(g, variables):
    """``(ops, consts)`` of the condition ``g`` (a sympy expression of ``t`` and the names
    in ``variables``, ``{name: index in y = [q, u]}``), or ``None`` when the stack machine
    cannot evaluate it."""
    ops, consts = [], []
    try:
        if _emit(g, ops, consts, variables) > kp.STACK:
            return None
    except Unsupported:
        return None
    return np.array(ops, np.int64).reshape(-1, 2), np.array(consts, float)


def program_block(expr, codes):
    """The numbers of ``expr`` as a program stored among a force element's numbers
    (``kernels.actuation.program_value``): ``[n_ops, n_consts, n_vars, ops, consts,
    variable codes]``; ``codes``: ``{symbol name: variable code}`` of the symbols it may
    read besides ``t``.  ``None`` when the stack machine cannot evaluate ``expr``."""
    from ..kernels.actuation import MAX_VARS
    names = sorted(s.name for s in expr.free_symbols if s.name != "t")
    if any(n not in codes for n in names) or len(names) > MAX_VARS:
        return None
    program = condition_program(expr, {n: k for k, n in enumerate(names)})
    if program is None:
        return None
    ops, consts = program
    return np.concatenate([[len(ops), len(consts), len(names)], ops.reshape(-1).astype(float),
                           consts, [float(codes[n]) for n in names]])


class EventPrograms:
    """The conditions of a run's events as one set of programs (``kernels.events``), or
    ``of(events)`` is ``None`` when one of them has no program (a Python function, or an
    expression the stack machine cannot evaluate)."""

    def __init__(self, events):
        parts = [e.condition.program for e in events]
        self.starts = np.cumsum([0] + [len(ops) for ops, _ in parts]).astype(np.int64)
        shift = np.cumsum([0] + [len(c) for _, c in parts[:-1]])
        self.ops = np.vstack([np.empty((0, 2), np.int64)]
                             + [ops + [0, k] * (ops[:, :1] == kp.CONST)
                                for (ops, _), k in zip(parts, shift)]).astype(np.int64)
        self.consts = np.concatenate([np.empty(0)] + [c for _, c in parts])
        self.direction = np.array([e.direction for e in events], np.int64)
        self.terminal = np.array([e.terminal for e in events], np.int64)

    @classmethod
    def of(cls, events):
        if not events or any(getattr(e.condition, "program", None) is None for e in events):
            return None
        return cls(events)

    @staticmethod
    def none():
        """The loops' argument for a run without compiled conditions."""
        return (np.zeros((0, 2), np.int64), np.zeros(0), np.zeros(1, np.int64),
                np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 0)),
                np.zeros(kp.STACK), False)

    def arguments(self, g_old, rows, any_crossing):
        """The loops' argument: conditions ``g_old`` before the first step, room for
        ``rows`` steps' conditions (``[6]``, ``out_g``)."""
        return (self.ops, self.consts, self.starts, self.direction, self.terminal,
                np.array(g_old, dtype=float), np.empty((rows, len(self.direction))),
                np.empty(kp.STACK), bool(any_crossing))

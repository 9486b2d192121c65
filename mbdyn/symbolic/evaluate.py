"""Evaluate large sympy expressions at numbers quickly: one pass over the expression DAG.

``lambdify`` prints an expression as a tree, which for the nested expressions of a long
chain is exponentially larger than the DAG; ``lambdify(cse=True)`` avoids that but spends
seconds in ``cse``.  For checks at a handful of states, walking the DAG once per state with
a memo is simpler and fast.
"""
from __future__ import annotations

import math

import sympy

_FUNCS = {sympy.sin: math.sin, sympy.cos: math.cos, sympy.tan: math.tan,
          sympy.exp: math.exp, sympy.log: math.log, sympy.atan: math.atan,
          sympy.asin: math.asin, sympy.acos: math.acos, sympy.sinh: math.sinh,
          sympy.cosh: math.cosh, sympy.tanh: math.tanh, sympy.Abs: abs,
          sympy.sign: lambda x: math.copysign(1.0, x) if x else 0.0}


def evaluate(exprs, values):
    """Floats of ``exprs`` (a list of expressions) with ``values`` ``{Symbol: float}``."""
    memo = {}

    def ev(e):
        r = memo.get(e)
        if r is not None:
            return r
        if e.is_Symbol:
            r = float(values[e])
        elif e.is_Number or e.is_NumberSymbol:
            r = float(e)
        elif e.is_Add:
            r = math.fsum(ev(a) for a in e.args)
        elif e.is_Mul:
            r = 1.0
            for a in e.args:
                r *= ev(a)
        elif e.is_Pow:
            b, x = e.args
            if x == sympy.S.Half:
                r = math.sqrt(ev(b))
            elif x.is_Integer:
                r = ev(b) ** int(x)
            else:
                r = ev(b) ** ev(x)
        elif type(e) in _FUNCS:
            r = _FUNCS[type(e)](*[ev(a) for a in e.args])
        elif hasattr(type(e), "_imp_"):          # a tabulated coefficient
            r = float(type(e)._imp_(*[ev(a) for a in e.args]))
        else:
            r = float(e.evalf(subs=values))
        memo[e] = r
        return r
    return [ev(sympy.sympify(e)) for e in exprs]


def function(exprs, symbols, shape=None):
    """A callable ``f(*values)`` -> numpy array of ``exprs`` (flattened, reshaped to
    ``shape``) at ``symbols = values``."""
    import numpy as np
    exprs = list(exprs)
    symbols = list(symbols)

    def f(*vals):
        out = np.array(evaluate(exprs, dict(zip(symbols, vals))), dtype=float)
        return out.reshape(shape) if shape is not None else out
    return f

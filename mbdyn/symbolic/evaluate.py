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


_DERIVATIVES = {
    sympy.sin: lambda x: math.cos(x), sympy.cos: lambda x: -math.sin(x),
    sympy.tan: lambda x: 1.0 / math.cos(x) ** 2, sympy.exp: math.exp,
    sympy.log: lambda x: 1.0 / x, sympy.atan: lambda x: 1.0 / (1.0 + x * x),
    sympy.asin: lambda x: 1.0 / math.sqrt(1.0 - x * x),
    sympy.acos: lambda x: -1.0 / math.sqrt(1.0 - x * x),
    sympy.sinh: math.cosh, sympy.cosh: math.sinh,
    sympy.tanh: lambda x: 1.0 - math.tanh(x) ** 2,
    sympy.Abs: lambda x: math.copysign(1.0, x) if x else 0.0,
    sympy.sign: lambda x: 0.0,
}


def evaluate_derivative(exprs, values, var):
    """Values of ``exprs`` and their exact derivatives with respect to the symbol ``var``
    at ``values`` ``{Symbol: float}``: the chain rule applied node by node over the
    expression DAG (forward-mode differentiation), each shared subexpression once -- where
    sympy's ``diff`` would expand the nested expressions of a long chain as a tree."""
    memo = {}

    def ev(e):
        r = memo.get(e)
        if r is not None:
            return r
        if e.is_Symbol:
            r = (float(values[e]), 1.0 if e == var else 0.0)
        elif e.is_Number or e.is_NumberSymbol:
            r = (float(e), 0.0)
        elif e.is_Add:
            parts = [ev(a) for a in e.args]
            r = (math.fsum(p[0] for p in parts), math.fsum(p[1] for p in parts))
        elif e.is_Mul:
            v, d = 1.0, 0.0
            for a in e.args:
                va, da = ev(a)
                v, d = v * va, d * va + v * da
            r = (v, d)
        elif e.is_Pow:
            b, x = e.args
            vb, db = ev(b)
            if x.is_Number:
                n = float(x)
                v = vb ** n if not x.is_Integer else vb ** int(x)
                r = (v, n * vb ** (n - 1) * db if db else 0.0)
            else:
                vx, dx = ev(x)
                v = vb ** vx
                r = (v, v * (dx * math.log(vb) + vx * db / vb) if (dx or db) else 0.0)
        elif type(e) in _DERIVATIVES and len(e.args) == 1:
            va, da = ev(e.args[0])
            r = (_FUNCS[type(e)](va), _DERIVATIVES[type(e)](va) * da if da else 0.0)
        elif isinstance(e, sympy.Piecewise):
            for expr, cond in e.args:
                if cond == sympy.true or bool(cond.xreplace(
                        {s: sympy.Float(values[s]) for s in cond.free_symbols})):
                    r = ev(expr)
                    break
            else:
                raise ValueError(f"no branch of {e} holds")
        elif isinstance(e, (sympy.Max, sympy.Min)):
            parts = [ev(a) for a in e.args]
            pick = max if isinstance(e, sympy.Max) else min
            r = pick(parts, key=lambda p: p[0])
        elif hasattr(type(e), "_imp_") and len(e.args) == 1:     # a tabulated coefficient
            va, da = ev(e.args[0])
            f = type(e)._imp_
            h = 1e-6 * max(1.0, abs(va))
            r = (float(f(va)), (float(f(va + h)) - float(f(va - h))) / (2 * h) * da
                 if da else 0.0)
        else:
            raise ValueError(f"cannot differentiate {type(e).__name__} numerically")
        memo[e] = r
        return r
    pairs = [ev(sympy.sympify(e)) for e in exprs]
    return [p[0] for p in pairs], [p[1] for p in pairs]

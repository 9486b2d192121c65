"""Compact expressions: exact, cheap simplification and the measure of size.

The textbook keeps expressions short by writing every vector in the frame where it is
shortest; what remains is the Pythagorean identity ``sin^2 + cos^2 = 1`` (the body's
rotation cancelling out of ``J^T I J``, a spinning top's spin angle dropping out of its mass
matrix).  ``compact`` expands a polynomial in sines and cosines and, angle by angle, keeps
whichever of ``sin^2 -> 1 - cos^2``, ``cos^2 -> 1 - sin^2`` or neither gives the fewest
operations.  It is exact, fast and never makes an expression longer; ``trigsimp`` can do
more but is orders of magnitude slower and is used only on request.

Size is measured with ``sympy.count_ops`` (every addition, multiplication, power and function
call counted once per occurrence in the expression tree), before and after common
subexpression elimination (``sympy.cse``: then each shared subexpression counts once).
"""
from __future__ import annotations

import sympy

__all__ = ["compact", "compact_matrix", "operations", "operations_after_cse", "MODES"]

#: ``"compact"`` (default): expand + Pythagorean reduction; ``"expand"``: expand only;
#: ``"none"``: the raw expressions of the walk; ``"trigsimp"``: compact, then sympy's
#: ``trigsimp`` on each entry (slow: small models only).
MODES = ("compact", "expand", "none", "trigsimp")

# expansions larger than this stay unexpanded (expanding nested products of long sums can
# grow them exponentially)
EXPAND_LIMIT = 6000


def _trig_powers(expr):
    """Arguments ``a`` of ``sin(a)**k``/``cos(a)**k`` (k >= 2) in ``expr``."""
    args = {}
    for p in expr.atoms(sympy.Pow):
        b, e = p.args
        if e.is_Integer and e >= 2 and isinstance(b, (sympy.sin, sympy.cos)):
            args.setdefault(b.args[0], set()).add(type(b))
    return args


def _reduce(expr, arg, fn):
    """Replace ``fn(arg)**k`` (k >= 2) by ``fn(arg)**(k-2) (1 - other(arg)**2)``, repeatedly."""
    other = sympy.cos if fn is sympy.sin else sympy.sin
    f, g = fn(arg), other(arg)
    mapping = {}
    for p in expr.atoms(sympy.Pow):
        b, e = p.args
        if b == f and e.is_Integer and e >= 2:
            k = int(e)
            mapping[p] = f ** (k % 2) * (1 - g ** 2) ** (k // 2)
    if not mapping:
        return expr
    return sympy.expand(expr.xreplace(mapping))


def operations(expr):
    """``sympy.count_ops`` of an expression, a matrix or a list of them (summed)."""
    if isinstance(expr, (list, tuple)):
        return sum(operations(e) for e in expr)
    if isinstance(expr, sympy.MatrixBase):
        return sum(sympy.count_ops(e) for e in expr)
    return int(sympy.count_ops(expr))


def operations_after_cse(exprs):
    """Operations of ``exprs`` (list of expressions/matrices) after ``sympy.cse``: the
    shared subexpressions once each plus the reduced expressions."""
    flat = []
    for e in exprs:
        flat.extend(list(e) if isinstance(e, sympy.MatrixBase) else [e])
    repl, reduced = sympy.cse(flat, order="none")
    return sum(sympy.count_ops(v) for _, v in repl) + sum(sympy.count_ops(e) for e in reduced)


def compact(expr, mode="compact"):
    """A short exact form of ``expr`` (see the module docstring for the modes)."""
    if not isinstance(expr, sympy.Basic) or expr.is_Atom or mode == "none":
        return expr
    size = sympy.count_ops(expr)
    if size > EXPAND_LIMIT:
        return expr
    e = sympy.expand(expr)
    if mode == "expand":
        return e
    best, best_size = e, sympy.count_ops(e)
    for arg in sorted(_trig_powers(e), key=sympy.default_sort_key):
        for fn in (sympy.sin, sympy.cos):
            cand = _reduce(best, arg, fn)
            if cand is best:
                continue
            n = sympy.count_ops(cand)
            if n < best_size:
                best, best_size = cand, n
    if mode == "trigsimp":
        t = sympy.trigsimp(best)
        if sympy.count_ops(t) < best_size:
            best = t
    if sympy.count_ops(expr) < best_size:      # expansion made it longer: keep the original
        return expr
    return best


def compact_matrix(M, mode="compact"):
    return M.applyfunc(lambda e: compact(e, mode))

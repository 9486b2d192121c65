"""Compact expressions: exact, cheap simplification and the measure of size.

The textbook keeps expressions short by writing every vector in the frame where it is
shortest; what remains is the Pythagorean identity ``sin^2 + cos^2 = 1`` (the body's
rotation cancelling out of ``J^T I J``, a spinning top's spin angle dropping out of its mass
matrix).  ``compact`` expands a polynomial in sines and cosines and, angle by angle, keeps
whichever of ``sin^2 -> 1 - cos^2``, ``cos^2 -> 1 - sin^2`` or neither gives the fewest
operations.  It is exact, fast and never makes an expression longer; ``trigsimp`` can do
more but is orders of magnitude slower and is used only on request.  The unit quaternions
of spherical and free joints are reduced the same way with ``w^2 + x^2 + y^2 + z^2 = 1``.

Size is measured with ``sympy.count_ops`` (every addition, multiplication, power and function
call counted once per occurrence in the expression tree), before and after common
subexpression elimination (``sympy.cse``: then each shared subexpression counts once).
"""
from __future__ import annotations

import sympy

from ..elements.expressions import ObjectMemo, expanded_terms

__all__ = ["compact", "compact_matrix", "finish", "finish_matrix", "collect_trig", "operations",
           "operations_after_cse", "tree_size", "expanded_terms", "free_symbols", "diff",
           "replace_shared", "MODES"]

#: ``"compact"`` (default): expand + Pythagorean reduction; ``"expand"``: expand only;
#: ``"none"``: the raw expressions of the walk; ``"trigsimp"``: compact, then sympy's
#: ``trigsimp`` on each entry (slow: small models only).
MODES = ("compact", "expand", "none", "trigsimp")

# expansions larger than this stay unexpanded (expanding nested products of long sums can
# grow them exponentially)
EXPAND_LIMIT = 2000
# ... and so do expressions whose expansion would have more terms than this
TERMS_LIMIT = 32
# an expanded, reduced form is kept unless it is this much longer than the original
KEEP_RATIO = 1.0
# results (M, f, solutions) are expanded up to this many terms and then tidied
FINISH_LIMIT = 400
# sums of angles are contracted and terms grouped in expressions up to this tree size
TIDY_LIMIT = 400
TIDY_TERMS = 16


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


_SIZE_CACHE = ObjectMemo()


def tree_size(expr):
    """Number of nodes of the expression *tree* (a repeated subexpression counts each time
    it occurs, as in ``count_ops``), computed over the expression DAG with memoisation, so
    it is fast even for huge nested expressions.  A cheap proxy for ``count_ops``."""
    if expr.is_Atom:
        return 0
    n = _SIZE_CACHE.get(expr)
    if n is None:
        n = len(expr.args) + sum(tree_size(a) for a in expr.args)
        _SIZE_CACHE.put(expr, n)
    return n


def replace_shared(expr, mapping):
    """``expr.xreplace(mapping)`` visiting each shared subexpression once.

    The walk's expressions share their parts (a link's velocity is inside every later
    link's), so their trees are exponentially larger than the objects that hold them: sympy's
    ``xreplace`` walks the tree (20 s for a 18-link chain), this walks the objects."""
    memo = {}

    def visit(e):
        hit = memo.get(id(e))
        if hit is not None:
            return hit[1]
        if e in mapping:
            out = mapping[e]
        elif not e.args:
            out = e
        else:
            args = tuple(visit(a) for a in e.args)
            out = e.func(*args) if any(a is not b for a, b in zip(args, e.args)) else e
        memo[id(e)] = (e, out)          # the key object is kept alive with its id
        return out
    if isinstance(expr, sympy.MatrixBase):
        return expr.applyfunc(visit)
    return visit(expr) if isinstance(expr, sympy.Basic) else expr


def _reduce_unit(expr, unit, k):
    """Replace ``unit[k]**n`` (n >= 2) using ``sum(unit[i]**2) = 1`` (a unit quaternion)."""
    x = unit[k]
    rest = 1 - sum(u**2 for i, u in enumerate(unit) if i != k)
    mapping = {}
    for p in expr.atoms(sympy.Pow):
        b, e = p.args
        if b == x and e.is_Integer and e >= 2:
            n = int(e)
            mapping[p] = x ** (n % 2) * rest ** (n // 2)
    if not mapping:
        return expr
    return sympy.expand(expr.xreplace(mapping))


def compact(expr, mode="compact", terms_limit=None, units=()):
    """A short exact form of ``expr`` (see the module docstring for the modes).

    Expressions whose expansion would exceed ``terms_limit`` terms (default
    ``TERMS_LIMIT``) are left as they are: for long chains the nested form of the walk is
    shorter than any expansion.  ``units``: tuples of symbols whose squares sum to one
    (the unit quaternions of spherical and free joints), reduced like ``sin^2 + cos^2``.
    """
    if not isinstance(expr, sympy.Basic) or expr.is_Atom or mode == "none":
        return expr
    limit = TERMS_LIMIT if terms_limit is None else terms_limit
    if tree_size(expr) > EXPAND_LIMIT or expanded_terms(expr) > limit:
        return expr
    e = sympy.expand(expr)
    if mode == "expand":
        return e
    best, best_size = e, tree_size(e)
    for arg in sorted(_trig_powers(e), key=sympy.default_sort_key):
        for fn in (sympy.sin, sympy.cos):
            cand = _reduce(best, arg, fn)
            if cand is best:
                continue
            n = tree_size(cand)
            if n < best_size:
                best, best_size = cand, n
    for unit in units:
        if not any(u in free_symbols(best) for u in unit):
            continue
        for k in range(len(unit)):
            cand = _reduce_unit(best, unit, k)
            if cand is best:
                continue
            n = tree_size(cand)
            if n < best_size:
                best, best_size = cand, n
    if mode == "trigsimp":
        t = sympy.trigsimp(best)
        if tree_size(t) < best_size:
            best = t
    if best_size > KEEP_RATIO * tree_size(expr):    # expanding made it much longer
        return expr
    return best


def compact_matrix(M, mode="compact", terms_limit=None, units=()):
    return M.applyfunc(lambda e: compact(e, mode, terms_limit, units))


def _trig_part(term):
    trig, rest = [], []
    for f in sympy.Mul.make_args(term):
        (trig if f.has(sympy.sin, sympy.cos) else rest).append(f)
    return sympy.Mul(*trig), sympy.Mul(*rest)


def collect_trig(expr):
    """Group the terms of a sum by their trigonometric factor and factor each coefficient:
    ``l1**2*m1 + l1**2*m2`` -> ``l1**2*(m1 + m2)``."""
    if not expr.is_Add:
        return expr
    groups = {}
    for term in expr.args:
        trig, rest = _trig_part(term)
        groups[trig] = groups.get(trig, 0) + rest
    if len(groups) == len(expr.args) and all(not c.is_Add for c in groups.values()):
        return expr
    return sympy.Add(*[sympy.factor_terms(c) * t for t, c in groups.items()])


def finish(expr, mode="compact", limit=FINISH_LIMIT, units=()):
    """The last touch for printed results: ``compact``, then contract sums of angles
    (``sin a cos b + cos a sin b -> sin(a + b)``, sympy's ``TR10i``) and group terms by
    their trigonometric factor, each only where it shortens the expression."""
    if not isinstance(expr, sympy.Basic) or expr.is_Atom or mode == "none":
        return expr
    expr = compact(expr, mode, terms_limit=limit, units=units)
    if tree_size(expr) > TIDY_LIMIT:
        return expr
    from sympy.simplify.fu import TR10i
    best, size = expr, tree_size(expr)
    # TR10i compares terms pairwise: only for short sums
    steps = (TR10i, collect_trig) if len(sympy.Add.make_args(expr)) <= TIDY_TERMS \
        else (collect_trig,)
    for step in steps:
        try:
            cand = step(best)
        except Exception:       # a simplification that fails is simply not applied
            continue
        n = tree_size(cand)
        if n < size:
            best, size = cand, n
    return best


def finish_matrix(M, mode="compact", limit=FINISH_LIMIT, units=()):
    return M.applyfunc(lambda e: finish(e, mode, limit, units))


# ---------------------------------------------------------------------------- fast calculus
_FS_CACHE = ObjectMemo()


def free_symbols(expr):
    """``expr.free_symbols`` computed over the expression DAG with memoisation (sympy walks
    the whole tree each time, which is exponential in the depth of nested expressions)."""
    if expr.is_Symbol:
        return frozenset((expr,))
    if expr.is_Atom:
        return frozenset()
    out = _FS_CACHE.get(expr)
    if out is None:
        out = frozenset().union(*[free_symbols(a) for a in expr.args])
        _FS_CACHE.put(expr, out)
    return out


def diff(expr, x, _memo=None):
    """``d expr / d x`` for a symbol ``x``, over the DAG with memoisation (sums, products,
    integer powers, sin and cos directly; anything else through sympy)."""
    if not isinstance(expr, sympy.Basic) or x not in free_symbols(expr):
        return sympy.Integer(0)
    if expr == x:
        return sympy.Integer(1)
    memo = {} if _memo is None else _memo
    got = memo.get(expr)
    if got is not None:
        return got
    if expr.is_Add:
        out = sympy.Add(*[diff(a, x, memo) for a in expr.args])
    elif expr.is_Mul:
        args = expr.args
        terms = []
        for k, a in enumerate(args):
            da = diff(a, x, memo)
            if da != 0:
                terms.append(sympy.Mul(*(args[:k] + (da,) + args[k + 1:])))
        out = sympy.Add(*terms)
    elif expr.is_Pow and x not in free_symbols(expr.exp):
        b, e = expr.args
        out = e * b ** (e - 1) * diff(b, x, memo)
    elif isinstance(expr, sympy.sin):
        out = sympy.cos(expr.args[0]) * diff(expr.args[0], x, memo)
    elif isinstance(expr, sympy.cos):
        out = -sympy.sin(expr.args[0]) * diff(expr.args[0], x, memo)
    else:
        out = expr.diff(x)
    memo[expr] = out
    return out

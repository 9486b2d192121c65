"""The size of an expression once expanded: the loader and the symbolic layer expand an
expression only when ``expanded_terms`` says the result stays small.
"""
from __future__ import annotations

import math

import sympy


class ObjectMemo:
    """A memo keyed by the object itself (its ``id``), never by equality: two equal
    expressions built separately share a hash, and comparing them walks both trees --
    exponential for the walk's nested expressions.  Each entry keeps its object alive, so
    an ``id`` is never reused while its entry exists."""

    def __init__(self, size=200000):
        self.entries, self.size = {}, size

    def get(self, expr):
        hit = self.entries.get(id(expr))
        return None if hit is None else hit[1]

    def put(self, expr, value):
        if len(self.entries) > self.size:
            self.entries.clear()
        self.entries[id(expr)] = (expr, value)


_TERMS_CACHE = ObjectMemo()


def expanded_terms(expr):
    """An upper estimate of the number of terms ``expand(expr)`` has (memoised)."""
    if expr.is_Atom or isinstance(expr, sympy.Function):
        return 1
    n = _TERMS_CACHE.get(expr)
    if n is None:
        if expr.is_Add:
            n = sum(expanded_terms(a) for a in expr.args)
        elif expr.is_Mul:
            n = 1
            for a in expr.args:
                n *= expanded_terms(a)
        elif expr.is_Pow and expr.exp.is_Integer and expr.exp > 0:
            b = expanded_terms(expr.base)
            k = int(expr.exp)
            n = math.comb(b + k - 1, k) if b > 1 else 1
        else:
            n = 1
        n = min(n, 10**9)
        _TERMS_CACHE.put(expr, n)
    return n

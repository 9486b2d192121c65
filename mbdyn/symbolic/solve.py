"""Solving ``M u' = f`` in closed form, and the reactions with it.

Up to four speeds by Cramer's rule, as the textbook solves the double pendulum: every
acceleration is ``det(M_k) / det(M)`` over the common denominator ``det(M)``, numerators
and denominator each brought to a compact polynomial in sines and cosines.  Beyond four
speeds the determinants explode; sympy's LU solve is used and the result left as it comes.
"""
from __future__ import annotations

import sympy

from .simplify import finish

CRAMER_MAX = 4
#: numerators and denominators are expanded and reduced up to this many terms
SOLVE_LIMIT = 4000


def _det(M):
    n = M.rows
    if n == 1:
        return M[0, 0]
    if n == 2:
        return M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
    return M.det(method="berkowitz")


def solve_linear(M, f, mode="compact", units=()):
    """``(numerators, denominator)`` with ``u'_k = numerators[k] / denominator``."""
    n = M.rows
    if n == 0:
        return [], sympy.Integer(1)
    if n > CRAMER_MAX:
        x = M.LUsolve(f)
        return [x[k] for k in range(n)], sympy.Integer(1)
    den = finish(_det(M), mode, limit=SOLVE_LIMIT, units=units)
    nums = []
    for k in range(n):
        Mk = M.copy()
        Mk[:, k] = f
        nums.append(finish(_det(Mk), mode, limit=SOLVE_LIMIT, units=units))
    return nums, den


def substitute_rates(row, bias, nums, den, mode="compact", units=()):
    """The numerator of ``row . u' + bias`` with ``u'_k = nums[k] / den`` inserted, over
    the common denominator ``den`` (a compact polynomial)."""
    out = bias * den
    for a, num in zip(row, nums):
        if a != 0:
            out += a * num
    return finish(out, mode, limit=SOLVE_LIMIT, units=units)

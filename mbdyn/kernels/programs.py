"""A small stack machine for expressions in compiled code: the drives' ``q(t)``, ``q'(t)``,
``q''(t)``, and the event conditions ``g(t, q, u)``.

A program is a row range of ``ops`` (``(opcode, argument)`` pairs, postfix order) over the
constants ``consts``; ``mbdyn.compiled.programs`` writes them from sympy expressions.  Opcodes:
``CONST k`` pushes ``consts[k]``, ``TIME`` pushes ``t``, ``VAR k`` pushes the state's
``y[k]`` (``y = [q, u]``), ``ADD n``/``MUL n``/``MIN n``/``MAX n`` replace the top ``n``
values by their sum/product/least/greatest, ``POW`` replaces ``base, exponent`` by the
power, ``ATAN2`` replaces ``y, x`` by ``atan2(y, x)``, the others apply a function of one
value to the top.  ``ops`` may be an integer array or a float array holding the same
integers (an actuator's program stored among its element's numbers, ``kernels.actuation``).
"""
import numpy as np
from numba import njit

from .views import UNCOUNTED

(CONST, TIME, ADD, MUL, POW, SIN, COS, TAN, EXP, LOG, ASIN, ACOS, ATAN, SINH, COSH, TANH,
 ABS, ATAN2, VAR, SQRT, SIGN, MIN, MAX) = range(23)
#: the deepest stack a program may need
STACK = 64


@njit(**UNCOUNTED)  # allocates nothing: the uncounted loops and Python share one compile
def evaluate(ops, consts, first, last, t, y, stack):
    """The value at ``(t, y)`` of the program ``ops[first:last]`` (``stack``: scratch space
    of ``STACK`` values)."""
    # long: the stack machine's interpreter: one branch per opcode in one loop (a table of
    # functions would be an indirect call per operation in compiled code).
    top = 0
    for k in range(first, last):
        op = int(ops[k, 0])             # int(): a program may be stored as floats
        arg = int(ops[k, 1])
        if op == CONST:
            stack[top] = consts[arg]
            top += 1
        elif op == TIME:
            stack[top] = t
            top += 1
        elif op == VAR:
            stack[top] = y[arg]
            top += 1
        elif op == ADD:
            acc = 0.0
            for j in range(top - arg, top):
                acc += stack[j]
            top -= arg
            stack[top] = acc
            top += 1
        elif op == MUL:
            acc = 1.0
            for j in range(top - arg, top):
                acc *= stack[j]
            top -= arg
            stack[top] = acc
            top += 1
        elif op == MIN or op == MAX:
            acc = stack[top - arg]
            for j in range(top - arg + 1, top):
                v = stack[j]
                if v != v or ((v < acc) if op == MIN else (v > acc)):     # NaN sticks
                    acc = v
            top -= arg
            stack[top] = acc
            top += 1
        elif op == POW:
            top -= 1
            stack[top - 1] = stack[top - 1] ** stack[top]
        elif op == ATAN2:
            top -= 1
            stack[top - 1] = np.arctan2(stack[top - 1], stack[top])
        else:
            x = stack[top - 1]
            if op == SIN:
                x = np.sin(x)
            elif op == COS:
                x = np.cos(x)
            elif op == TAN:
                x = np.tan(x)
            elif op == EXP:
                x = np.exp(x)
            elif op == LOG:
                x = np.log(x) if x >= 0.0 else np.nan
            elif op == ASIN:
                x = np.arcsin(x)
            elif op == ACOS:
                x = np.arccos(x)
            elif op == ATAN:
                x = np.arctan(x)
            elif op == SINH:
                x = np.sinh(x)
            elif op == COSH:
                x = np.cosh(x)
            elif op == TANH:
                x = np.tanh(x)
            elif op == SQRT:
                x = np.sqrt(x) if x >= 0.0 else np.nan
            elif op == SIGN:
                x = np.sign(x)
            else:
                x = abs(x)
            stack[top - 1] = x
    return stack[0]


@njit(cache=True, inline="always")
def drive_values(ops, consts, starts, t, stack, out):
    """``out[d] = (q, q', q'')`` of every drive ``d`` at ``t``: programs ``3 d .. 3 d + 2``
    (``starts[k] .. starts[k + 1]`` their rows).  Drives are functions of ``t`` alone (no
    ``VAR``), so the state argument is a stand-in."""
    for d in range(out.shape[0]):
        for p in range(3):
            k = 3 * d + p
            out[d, p] = evaluate(ops, consts, starts[k], starts[k + 1], t, stack, stack)

"""A small, safe reader of the expressions in model files.

``parse("b*Omega**2*cos(omega*t)", names)`` returns a sympy expression built node by node
from Python's ``ast``: the text is parsed with ``ast.parse(mode="eval")`` and every node is
checked against an allow-list -- numbers, names, ``+ - * / **``, unary ``+ -``, calls of the
functions in ``FUNCTIONS`` and (for event conditions only) one comparison.  Nothing is ever
passed to ``eval``, ``exec`` or ``sympify``; attribute access, indexing, strings, lambdas,
comprehensions and keyword arguments are refused with a message that says what is allowed.

The same sympy object serves the numeric layers (substitute parameter values, ``float``, or
``lambdify``) and the symbolic layer (which reads the parameter symbols).
"""
from __future__ import annotations

import ast
import difflib
import math

import sympy

from .. import limits
from .evaluation import (FLOAT_FUNCTIONS, ExpressionError, _float_call, _float_power,  # noqa: F401
                         to_float)
from .expansion import ObjectMemo, expanded_terms  # noqa: F401  (their old import path)

def degrees_to_radians(x):
    """``deg(x)``: ``x`` degrees in radians, ``x*pi/180`` (exact: ``deg(90)`` is ``pi/2``)."""
    return x * sympy.pi / 180


#: Functions an expression may call: name -> (sympy function, allowed numbers of arguments).
FUNCTIONS = {
    "sin": (sympy.sin, (1,)), "cos": (sympy.cos, (1,)), "tan": (sympy.tan, (1,)),
    "asin": (sympy.asin, (1,)), "acos": (sympy.acos, (1,)), "atan": (sympy.atan, (1,)),
    "atan2": (sympy.atan2, (2,)),
    "sinh": (sympy.sinh, (1,)), "cosh": (sympy.cosh, (1,)), "tanh": (sympy.tanh, (1,)),
    "sqrt": (sympy.sqrt, (1,)), "exp": (sympy.exp, (1,)), "log": (sympy.log, (1, 2)),
    "abs": (sympy.Abs, (1,)), "sign": (sympy.sign, (1,)),
    "min": (sympy.Min, (2, 3, 4, 5, 6, 7, 8)), "max": (sympy.Max, (2, 3, 4, 5, 6, 7, 8)),
    "deg": (degrees_to_radians, (1,)),
}
#: Named constants.
CONSTANTS = {"pi": sympy.pi}
#: Names a parameter, coordinate or speed may not take.
RESERVED = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | {"t"}

MAX_LENGTH = limits.MAX_EXPRESSION_LENGTH      # characters of one expression
MAX_NODES = limits.MAX_EXPRESSION_NODES        # ast nodes of one expression
MAX_DEPTH = limits.MAX_EXPRESSION_DEPTH        # nesting of one expression
MAX_EXPONENT = limits.MAX_EXPONENT             # |exponent| of a power
MAX_CONSTANT = limits.MAX_CONSTANT             # |value| of any constant part

COMPARISONS = {ast.GtE: ">=", ast.Gt: ">", ast.LtE: "<=", ast.Lt: "<", ast.Eq: "=="}

_NODE_NAMES = {
    ast.Attribute: "attribute access (a.b)", ast.Subscript: "indexing (a[i])",
    ast.Lambda: "lambda", ast.IfExp: "'if ... else'", ast.BoolOp: "'and'/'or'",
    ast.Dict: "a dictionary", ast.Set: "a set", ast.List: "a list", ast.Tuple: "a tuple",
    ast.ListComp: "a comprehension", ast.SetComp: "a comprehension",
    ast.DictComp: "a comprehension", ast.GeneratorExp: "a generator",
    ast.Await: "await", ast.Yield: "yield", ast.YieldFrom: "yield", ast.Starred: "'*'",
    ast.JoinedStr: "an f-string", ast.NamedExpr: "':='", ast.Slice: "a slice",
}
_OPERATOR_HINTS = {
    ast.BitXor: "'^' is not a power here; write a**b",
    ast.FloorDiv: "'//' is not allowed; use '/'",
    ast.Mod: "'%' is not allowed",
    ast.MatMult: "'@' is not allowed",
    ast.BitAnd: "'&' is not allowed", ast.BitOr: "'|' is not allowed",
    ast.LShift: "'<<' is not allowed", ast.RShift: "'>>' is not allowed",
}

ALLOWED_SUMMARY = ("numbers, names, + - * / **, parentheses, pi and the functions "
                   + ", ".join(FUNCTIONS))


def symbol(name):
    """The sympy symbol a model file uses for ``name`` (real, as ``System.symbols``)."""
    return sympy.Symbol(name, real=True)


class _Builder:
    """Builds the sympy expression of a parse tree, node by node.

    ``build`` returns ``(expression, value)``: ``value`` is the float of a constant part
    (``None`` where a name enters), computed alongside so that a constant that overflows
    or leaves a function's domain is refused before sympy's exact arithmetic is asked for
    it (``exp(exp(exp(9)))`` would otherwise cost unbounded time and memory).
    """

    def __init__(self, text, names, comparison):
        self.text = text
        self.names = names
        self.comparison = comparison
        self.used = set()

    def fail(self, what, node=None):
        col = getattr(node, "col_offset", None)
        where = f" (at column {col + 1})" if col is not None else ""
        raise ExpressionError(f"cannot read {self.text!r}{where}: {what}")

    def bounded(self, value, node):
        if value is not None and abs(value) > MAX_CONSTANT:
            self.fail(f"the number {value:.6g} is too large (the limit is {MAX_CONSTANT:g})",
                      node)
        return value

    def build(self, node):
        if isinstance(node, ast.Constant):
            v = node.value
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                self.fail(f"{v!r} is not a number; expressions hold {ALLOWED_SUMMARY}", node)
            if isinstance(v, int):
                if v.bit_length() > 1000:
                    self.fail(f"the integer is too large (the limit is {MAX_CONSTANT:g})", node)
                return sympy.Integer(v), self.bounded(float(v), node)
            if not math.isfinite(v):
                self.fail("the number is not finite", node)
            return sympy.Float(v), self.bounded(v, node)
        if isinstance(node, ast.Name):
            return self.name(node)
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, (ast.USub, ast.UAdd)):
                e, v = self.build(node.operand)
                if isinstance(node.op, ast.USub):
                    return -e, (None if v is None else -v)
                return e, v
            self.fail("'not' and '~' are not allowed", node)
        if isinstance(node, ast.BinOp):
            hint = _OPERATOR_HINTS.get(type(node.op))
            if hint:
                self.fail(hint, node)
            (a, va), (b, vb) = self.build(node.left), self.build(node.right)
            known = va is not None and vb is not None
            if isinstance(node.op, ast.Add):
                return a + b, (self.bounded(va + vb, node) if known else None)
            if isinstance(node.op, ast.Sub):
                return a - b, (self.bounded(va - vb, node) if known else None)
            if isinstance(node.op, ast.Mult):
                return a * b, (self.bounded(va * vb, node) if known else None)
            if isinstance(node.op, ast.Div):
                if b.is_zero or vb == 0:
                    self.fail("division by zero", node)
                return a / b, (self.bounded(va / vb, node) if known else None)
            if isinstance(node.op, ast.Pow):
                if vb is not None and abs(vb) > MAX_EXPONENT:
                    self.fail(f"exponent {vb:.6g} is too large (at most {MAX_EXPONENT})", node)
                if (a.is_zero or va == 0) and vb is not None and vb < 0:
                    self.fail("zero to a negative power", node)
                value = None
                if known:
                    value, why = _float_power(va, vb)
                    if why:
                        self.fail(why, node)
                    self.bounded(value, node)
                return a ** b, value
            self.fail("operator not allowed", node)
        if isinstance(node, ast.Call):
            return self.call(node)
        if isinstance(node, ast.Compare):
            self.fail("a comparison is only allowed as an event condition "
                      "(e.g. condition = \"theta >= pi/2\")", node)
        what = _NODE_NAMES.get(type(node), f"'{type(node).__name__}'")
        self.fail(f"{what} is not allowed; expressions hold {ALLOWED_SUMMARY}", node)

    def name(self, node):
        n = node.id
        if n in CONSTANTS:
            return CONSTANTS[n], float(CONSTANTS[n])
        if n in FUNCTIONS:
            self.fail(f"{n} is a function; call it, e.g. {n}(x)", node)
        if not n.isascii():
            self.fail(f"the name {n!r} has characters outside ASCII (a look-alike of "
                      f"{_ascii_hint(n)!r}?); names are ASCII letters, digits and '_'", node)
        if self.names is None:          # syntax check only
            self.used.add(n)
            return symbol(n), None
        if n in self.names:
            self.used.add(n)
            e = self.names[n]
            value = None
            if getattr(e, "is_Number", False) or isinstance(e, (int, float)):
                value = float(e)
            return e, value
        known = sorted(self.names)
        close = difflib.get_close_matches(n, known + list(CONSTANTS), n=1, cutoff=0.6)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        avail = ", ".join(known + list(CONSTANTS)) if known else "pi (no names are defined here)"
        self.fail(f"unknown name {n!r}{hint}; names allowed here: {avail}", node)

    def call(self, node):
        if not isinstance(node.func, ast.Name):
            self.fail("only the functions " + ", ".join(FUNCTIONS) + " can be called", node)
        fname = node.func.id
        if fname not in FUNCTIONS:
            close = difflib.get_close_matches(fname, list(FUNCTIONS), n=1, cutoff=0.6)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            self.fail(f"unknown function {fname!r}{hint}; allowed: {', '.join(FUNCTIONS)}", node)
        if node.keywords:
            self.fail(f"{fname}() takes no keyword arguments", node)
        func, arities = FUNCTIONS[fname]
        if any(isinstance(a, ast.Starred) for a in node.args):
            self.fail("'*' arguments are not allowed", node)
        if len(node.args) not in arities:
            n = " or ".join(str(k) for k in arities[:2]) + (" or more" if len(arities) > 2 else "")
            self.fail(f"{fname}() takes {n} argument(s), got {len(node.args)}", node)
        built = [self.build(a) for a in node.args]
        values = [v for _, v in built]
        value = None
        if all(v is not None for v in values):
            value, why = _float_call(fname, values)
            if why:
                self.fail(why, node)
            self.bounded(value, node)
        return func(*[e for e, _ in built]), value


def _ascii_hint(name):
    """The ASCII letters a look-alike name stands for (NFKC: full-width, ligatures)."""
    import unicodedata
    return unicodedata.normalize("NFKC", name).encode("ascii", "replace").decode()


def _parse_tree(text):
    if not isinstance(text, str):
        raise ExpressionError(f"expected an expression string, got {text!r}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"expression of {len(text)} characters is too long "
                              f"(at most {MAX_LENGTH})")
    if not text.strip():
        raise ExpressionError("empty expression; write a number or an expression such as 'pi/4'")
    if not text.isascii():
        # Python's parser would NFKC-normalise a full-width 't' into the name t
        col, char = next((i, c) for i, c in enumerate(text) if not c.isascii())
        plain = _ascii_hint(char)
        hint = f" (a look-alike of {plain!r}?)" if plain.isascii() and plain != "?" else ""
        if char in "\u03c0\u03a0":
            hint = " (write pi)"
        raise ExpressionError(f"cannot read {text[:60]!r}: the character {char!r} "
                              f"(U+{ord(char):04X}) at column {col + 1} is not ASCII{hint}; "
                              "expressions are written in ASCII")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise ExpressionError(f"cannot read {text!r}: syntax error{col} ({exc.msg}); "
                              f"expressions hold {ALLOWED_SUMMARY}") from None
    except (RecursionError, MemoryError, ValueError):
        raise ExpressionError(f"cannot read {text[:60]!r}...: too deeply nested") from None
    if sum(1 for _ in ast.walk(tree)) > MAX_NODES:
        raise ExpressionError(f"expression {text[:60]!r}... is too complex "
                              f"(more than {MAX_NODES} parts)")
    depth = _depth(tree.body)
    if depth > MAX_DEPTH:
        raise ExpressionError(f"expression {text[:60]!r}... is nested {depth} deep "
                              f"(at most {MAX_DEPTH}); split it into parameters")
    return tree.body


def _depth(root):
    """Nesting depth of a parse tree, without recursion."""
    deepest, stack = 0, [(root, 1)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend((child, d + 1) for child in ast.iter_child_nodes(node))
    return deepest


def parse(text, names=None):
    """The sympy expression of ``text``.

    ``names``: ``{name: sympy object}`` of the names the expression may use (besides
    ``pi``); ``None`` accepts any identifier as a real symbol (a syntax check).
    Raises ``ExpressionError``.
    """
    node = _parse_tree(text)
    builder = _Builder(text, names, comparison=False)
    try:
        return builder.build(node)[0]
    except RecursionError:
        raise ExpressionError(f"cannot read {text[:60]!r}: too deeply nested") from None


def parse_condition(text, names=None):
    """An event condition: ``lhs OP rhs`` with ``OP`` one of ``>= > <= < ==``, or a bare
    expression (its zero crossings).  Returns ``(g, direction)``: ``g = lhs - rhs`` and
    the crossing direction the comparison implies (+1 for ``>=``/``>``, -1 for ``<=``/``<``,
    ``None`` for ``==`` or a bare expression)."""
    node = _parse_tree(text)
    builder = _Builder(text, names, comparison=True)
    try:
        if isinstance(node, ast.Compare):
            if len(node.ops) != 1:
                builder.fail("a chained comparison (a < b < c) is not allowed; use one "
                             "comparison per event", node)
            op = type(node.ops[0])
            if op not in COMPARISONS:
                builder.fail(f"comparison not allowed; use one of {', '.join(COMPARISONS.values())}",
                             node)
            g = builder.build(node.left)[0] - builder.build(node.comparators[0])[0]
            direction = {ast.GtE: 1, ast.Gt: 1, ast.LtE: -1, ast.Lt: -1}.get(op)
            return g, direction
        return builder.build(node)[0], None
    except RecursionError:
        raise ExpressionError(f"cannot read {text[:60]!r}: too deeply nested") from None


def names_in(text):
    """The identifiers an expression uses (besides ``pi`` and the functions)."""
    node = _parse_tree(text)
    builder = _Builder(text, None, comparison=True)
    if isinstance(node, ast.Compare):
        for part in [node.left] + list(node.comparators):
            builder.build(part)
    else:
        builder.build(node)
    return set(builder.used)

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

#: Functions an expression may call: name -> (sympy function, allowed numbers of arguments).
FUNCTIONS = {
    "sin": (sympy.sin, (1,)), "cos": (sympy.cos, (1,)), "tan": (sympy.tan, (1,)),
    "asin": (sympy.asin, (1,)), "acos": (sympy.acos, (1,)), "atan": (sympy.atan, (1,)),
    "atan2": (sympy.atan2, (2,)),
    "sinh": (sympy.sinh, (1,)), "cosh": (sympy.cosh, (1,)), "tanh": (sympy.tanh, (1,)),
    "sqrt": (sympy.sqrt, (1,)), "exp": (sympy.exp, (1,)), "log": (sympy.log, (1, 2)),
    "abs": (sympy.Abs, (1,)), "sign": (sympy.sign, (1,)),
    "min": (sympy.Min, (2, 3, 4, 5, 6, 7, 8)), "max": (sympy.Max, (2, 3, 4, 5, 6, 7, 8)),
}
#: Named constants.
CONSTANTS = {"pi": sympy.pi}
#: Names a parameter, coordinate or speed may not take.
RESERVED = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | {"t"}

MAX_LENGTH = 2000          # characters of one expression
MAX_NODES = 1000           # ast nodes of one expression
MAX_EXPONENT = 1000        # |exponent| of a numeric power

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


class ExpressionError(ValueError):
    """An expression that cannot be read; the message quotes it and says what is allowed."""


def symbol(name):
    """The sympy symbol a model file uses for ``name`` (real, as ``System.symbols``)."""
    return sympy.Symbol(name, real=True)


class _Builder:
    def __init__(self, text, names, comparison):
        self.text = text
        self.names = names
        self.comparison = comparison
        self.used = set()

    def fail(self, what, node=None):
        col = getattr(node, "col_offset", None)
        where = f" (at column {col + 1})" if col is not None else ""
        raise ExpressionError(f"cannot read {self.text!r}{where}: {what}")

    def build(self, node):
        if isinstance(node, ast.Constant):
            v = node.value
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                self.fail(f"{v!r} is not a number; expressions hold {ALLOWED_SUMMARY}", node)
            if isinstance(v, int):
                return sympy.Integer(v)
            if not math.isfinite(v):
                self.fail("the number is not finite", node)
            return sympy.Float(v)
        if isinstance(node, ast.Name):
            return self.name(node)
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.USub):
                return -self.build(node.operand)
            if isinstance(node.op, ast.UAdd):
                return self.build(node.operand)
            self.fail("'not' and '~' are not allowed", node)
        if isinstance(node, ast.BinOp):
            hint = _OPERATOR_HINTS.get(type(node.op))
            if hint:
                self.fail(hint, node)
            a, b = self.build(node.left), self.build(node.right)
            if isinstance(node.op, ast.Add):
                return a + b
            if isinstance(node.op, ast.Sub):
                return a - b
            if isinstance(node.op, ast.Mult):
                return a * b
            if isinstance(node.op, ast.Div):
                if b.is_zero:
                    self.fail("division by zero", node)
                return a / b
            if isinstance(node.op, ast.Pow):
                if b.is_number and abs(complex(b.evalf(15))) > MAX_EXPONENT:
                    self.fail(f"exponent {b} is too large (at most {MAX_EXPONENT})", node)
                if a.is_zero and b.is_number and b.is_negative:
                    self.fail("zero to a negative power", node)
                return a ** b
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
            return CONSTANTS[n]
        if n in FUNCTIONS:
            self.fail(f"{n} is a function; call it, e.g. {n}(x)", node)
        if self.names is None:          # syntax check only
            self.used.add(n)
            return symbol(n)
        if n in self.names:
            self.used.add(n)
            return self.names[n]
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
        args = [self.build(a) for a in node.args]
        return func(*args)


def _parse_tree(text):
    if not isinstance(text, str):
        raise ExpressionError(f"expected an expression string, got {text!r}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"expression of {len(text)} characters is too long "
                              f"(at most {MAX_LENGTH})")
    if not text.strip():
        raise ExpressionError("empty expression; write a number or an expression such as 'pi/4'")
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
    return tree.body


def parse(text, names=None):
    """The sympy expression of ``text``.

    ``names``: ``{name: sympy object}`` of the names the expression may use (besides
    ``pi``); ``None`` accepts any identifier as a real symbol (a syntax check).
    Raises ``ExpressionError``.
    """
    node = _parse_tree(text)
    builder = _Builder(text, names, comparison=False)
    try:
        return builder.build(node)
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
            g = builder.build(node.left) - builder.build(node.comparators[0])
            direction = {ast.GtE: 1, ast.Gt: 1, ast.LtE: -1, ast.Lt: -1}.get(op)
            return g, direction
        return builder.build(node), None
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


def to_float(expr, values=None):
    """``float`` of a sympy expression after substituting ``values`` ``{name: number}``;
    raises ``ExpressionError`` if it is not a finite real number."""
    if isinstance(expr, (int, float)) and not isinstance(expr, bool):
        v = float(expr)
    else:
        if values:
            expr = expr.subs({s: values[s.name] for s in expr.free_symbols if s.name in values})
        if expr.free_symbols:
            names = ", ".join(sorted(s.name for s in expr.free_symbols))
            raise ExpressionError(f"{expr} still depends on {names}")
        try:
            c = complex(expr.evalf(30))
        except (TypeError, ValueError):
            raise ExpressionError(f"{expr} is not a number") from None
        if abs(c.imag) > 1e-12 * max(1.0, abs(c.real)):
            raise ExpressionError(f"{expr} is not a real number (it is {c:.6g})")
        v = c.real
    if not math.isfinite(v):
        raise ExpressionError(f"{expr} is not finite")
    return v

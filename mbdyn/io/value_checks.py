"""The checks of one value of a model file by its kind in the schema (``mbdyn.io.keys``):
``CHECKS[kind](checker, value, path)`` refuses a value of the wrong shape with the
checker's error at ``path``; a ``("choice", options)`` kind is checked by ``choice``.
Each check reads its parts through the checker (``check_expr``, ``check_table``,
``check_value``), so that an error names the place the value was written.
"""
from __future__ import annotations

from ..names import identifier_problem, is_identifier
from .expressions import RESERVED, ExpressionError, parse_condition
from .keys import DIRECTIONS, POINT_KEYS, SHAPE_KEYS
from .wording import kind_of, show, suggest


def choice(c, value, path, options):
    if not isinstance(value, str) or value not in options:
        raise c.error(path, f"{show(value)} is not allowed; {suggest(value, options)}"
                      f"use one of: {', '.join(options)}")


def _string(c, value, path):
    if not isinstance(value, str):
        raise c.error(path, f"must be a string, got {kind_of(value)} {show(value)}")


def _paths(c, value, path):
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, list) or not all(isinstance(p, str) and p.strip()
                                              for p in items):
        raise c.error(path, f"must be a folder or an array of folders (strings), got "
                      f"{kind_of(value)} {show(value)}")


def _name(c, value, path):
    problem = identifier_problem(value)
    if problem:
        raise c.error(path, f"must be a name of ASCII letters, digits and underscores "
                      f"(not starting with a digit): {show(value)} {problem}")


def _boolean(c, value, path):
    if not isinstance(value, bool):
        raise c.error(path, f"must be true or false, got {kind_of(value)} {show(value)}")


def _expression(c, value, path):
    c.check_expr(value, path)


def _vector(c, value, path):
    if not isinstance(value, list) or len(value) != 3:
        raise c.error(path, f"must be an array of three numbers or expressions, e.g. "
                      f"[0, 0, \"-l\"], got {show(value)}")
    for i, v in enumerate(value):
        c.check_expr(v, path + (i,))


def _place(c, value, path):
    """A point: three numbers or expressions, or the name of a flexible body's node."""
    if isinstance(value, str):
        _name(c, value, path)
    else:
        _vector(c, value, path)


def _axis(c, value, path):
    if isinstance(value, str):
        if value.strip().lower().lstrip("+-") not in ("x", "y", "z"):
            raise c.error(path, f"{show(value)} is not an axis; use \"x\", \"y\", \"z\" "
                          "(optionally \"-x\" ...) or an array of three numbers")
    else:
        c.check_value("vector", value, path)


def _inertia(c, value, path):
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        if value != 0:
            raise c.error(path, "a single number is not an inertia; give three principal "
                          "moments [Ixx, Iyy, Izz], a 3x3 array, or 0 for a particle")
    elif isinstance(value, list) and len(value) == 3 and all(
            isinstance(r, list) for r in value):
        for i, row in enumerate(value):
            if len(row) != 3:
                raise c.error(path + (i,), "each row of a 3x3 inertia needs three values")
            for j, v in enumerate(row):
                c.check_expr(v, path + (i, j))
    elif isinstance(value, list) and len(value) == 3:
        for i, v in enumerate(value):
            c.check_expr(v, path + (i,))
    else:
        raise c.error(path, "must be three principal moments [Ixx, Iyy, Izz], a 3x3 "
                      f"array or 0 (a particle), got {show(value)}")


def _orientation(c, value, path):
    if isinstance(value, dict):
        for k in value:
            if k not in ("axis", "angle"):
                raise c.error(path + (k,), f"unknown key; {suggest(k, ('axis', 'angle'))}"
                              "an orientation table has axis and angle")
        for k in ("axis", "angle"):
            if k not in value:
                raise c.error(path, f"{k} is missing; write {{ axis = \"z\", angle = "
                              "\"pi/2\" }")
        c.check_value("axis", value["axis"], path + ("axis",))
        c.check_expr(value["angle"], path + ("angle",))
    elif isinstance(value, list) and len(value) == 4:
        for i, v in enumerate(value):
            c.check_expr(v, path + (i,))
    elif isinstance(value, list) and len(value) == 3 and all(
            isinstance(r, list) and len(r) == 3 for r in value):
        for i, row in enumerate(value):
            for j, v in enumerate(row):
                c.check_expr(v, path + (i, j))
    else:
        raise c.error(path, "must be { axis = ..., angle = ... }, a unit quaternion "
                      "[w, x, y, z] or a 3x3 rotation matrix")


def _names(c, value, path):
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, list) or not all(is_identifier(n) for n in items):
        bad = next((n for n in items if not is_identifier(n)), value) \
            if isinstance(items, list) else value
        why = identifier_problem(bad) if isinstance(bad, str) else "is not a name"
        raise c.error(path, "must be a name or an array of names (ASCII letters, digits, "
                      f"underscores): {show(bad)} {why}")
    for n in items:
        if n in RESERVED:
            raise c.error(path, f"{n!r} is a reserved name (t, pi and the functions); "
                          "choose another")


def _condition(c, value, path):
    if not isinstance(value, str):
        raise c.error(path, "must be a string such as \"theta >= pi/2\", got "
                      f"{kind_of(value)}")
    try:
        parse_condition(value)
    except ExpressionError as exc:
        raise c.error(path, str(exc)) from None


def _direction(c, value, path):
    ok = (isinstance(value, str) and value in DIRECTIONS) or (
        isinstance(value, int) and not isinstance(value, bool) and value in (-1, 0, 1))
    if not ok:
        raise c.error(path, f"{show(value)} is not a direction; {suggest(value, DIRECTIONS)}"
                      "use \"rising\", \"falling\" or \"either\" (or 1, -1, 0)")


def _reactions(c, value, path):
    if isinstance(value, bool):
        return
    if not isinstance(value, list) or not all(isinstance(n, str) for n in value):
        raise c.error(path, "must be true, false or an array of joint names")


def _shape(c, value, path):
    c.check_table(value, SHAPE_KEYS, path, required=("type",))


def _expressions(c, value, path):
    if not isinstance(value, list) or not value:
        raise c.error(path, f"must be an array of numbers, got {show(value)}")
    for i, v in enumerate(value):
        c.check_expr(v, path + (i,))


def _coefficient(c, value, path):
    if isinstance(value, list):
        c.check_value("exprs", value, path)
    else:
        c.check_expr(value, path)


def _matrix6(c, value, path):
    if isinstance(value, list):
        rows = value if all(isinstance(r, list) for r in value) else [value]
        for i, row in enumerate(rows):
            if not isinstance(row, list):
                raise c.error(path, "must be a number, six numbers or a 6x6 array")
            for j, v in enumerate(row):
                c.check_expr(v, path + ((i, j) if len(rows) > 1 else (j,)))
    else:
        c.check_expr(value, path)


def _table(c, value, path):
    if not isinstance(value, list) or not all(
            isinstance(r, list) and len(r) == 2 for r in value):
        raise c.error(path, "must be an array of [x, y] pairs, e.g. [[0, 0], [0.01, 50], "
                      f"[0.02, 180]], got {show(value)}")
    for i, (x, y) in enumerate(value):
        c.check_expr(x, path + (i, 0))
        c.check_expr(y, path + (i, 1))


def _signal(c, value, path):
    """A number, an expression, or a table of t (an actuator's value or setpoint)."""
    if isinstance(value, list):
        _table(c, value, path)
    else:
        c.check_expr(value, path)


def _points(c, value, path):
    if not isinstance(value, dict):
        raise c.error(path, "must be a table of points: NAME = { frame = \"...\", offset "
                      "= [x, y, z] }")
    for name, point in value.items():
        problem = identifier_problem(str(name))
        if problem:
            raise c.error(path + (name,), f"a point name {problem}")
        c.check_table(point, POINT_KEYS, path + (name,), required=("frame",))


def _pairs(c, value, path):
    if not isinstance(value, list) or not value:
        raise c.error(path, f"must be an array of pairs of shape names, e.g. [[\"ball1\", "
                      f"\"ball2\"]], got {show(value)}")
    for i, pair in enumerate(value):
        if not isinstance(pair, list) or len(pair) != 2:
            raise c.error(path + (i,), f"must be two shape names [\"a\", \"b\"], got "
                          f"{show(pair)}")
        for k, n in enumerate(pair):
            _name(c, n, path + (i, k))


def _flexible(c, value, path):
    """A flexible body's table: its keys here, their values when the body is built
    (``mbdyn.elements.flexible_bodies``, every error naming its key)."""
    from ..elements.flexible_bodies import KEYS
    if not isinstance(value, dict):
        raise c.error(path, "must be a table, e.g. { beam = { length = 1.0, elements = 10, "
                      "E = 2.1e11, rho = 7850, circle = 0.02 }, modes = 4 } or "
                      "{ data = \"blade.npz\" }")
    for k in value:
        if k not in KEYS:
            raise c.error(path + (k,), f"unknown key; the keys here are: {', '.join(KEYS)}")


#: kind -> its check
CHECKS = {"string": _string, "name": _name, "bool": _boolean, "expr": _expression,
          "vector": _vector, "place": _place, "axis": _axis, "inertia": _inertia,
          "orientation": _orientation,
          "names": _names, "paths": _paths, "condition": _condition, "direction": _direction,
          "reactions": _reactions, "shape": _shape, "exprs": _expressions,
          "coefficient": _coefficient, "matrix6": _matrix6, "table": _table,
          "points": _points, "signal": _signal, "pairs": _pairs, "flexible": _flexible}

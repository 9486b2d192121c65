"""The structure of a model file: known keys and value shapes, cases and overrides.

This module checks the *shape* of a parsed TOML document (every key known, every value of
the right kind, every expression syntactically valid) and merges cases and ``--set``
overrides into it, remembering where each overridden value came from so that an error
points at the place the user wrote it (``cases.a.initial.theta``, ``--set ...``).  What the
values mean (names that must exist, numbers that must be positive) is checked when the
model is built (``mbdyn.io.loader``).
"""
from __future__ import annotations

import copy
import difflib
import math
import re
import tomllib
import unicodedata

from .errors import ModelFileError
from .. import limits
from ..names import identifier_problem, is_identifier, label_problem, shown
from .expressions import RESERVED, ExpressionError, parse, parse_condition

# ---------------------------------------------------------------------------- the schema
# value kinds: "string", "name", "expr", "vector", "axis", "inertia", "orientation",
# "names", "bool", "condition", "direction", "reactions", ("choice", options)
MODEL_KEYS = {"name": "string", "description": "string", "gravity": "vector",
              "default_case": "string"}
BODY_KEYS = {"name": "name", "mass": "expr", "com": "vector", "inertia": "inertia",
             "inertia_about": ("choice", ("com", "origin")), "shape": "shape"}
SHAPE_KEYS = {"type": ("choice", ("sphere", "box", "cylinder", "disk", "rod")),
              "radius": "expr", "length": "expr", "size": "vector", "center": "vector",
              "start": "vector", "end": "vector", "axis": "axis", "color": "string"}
JOINT_KINDS = ("revolute", "prismatic", "euler", "spherical", "fixed", "free")
JOINT_KEYS = {"name": "name", "kind": ("choice", JOINT_KINDS), "parent": "name",
              "child": "name", "axis": "axis", "position": "vector",
              "orientation": "orientation", "sequence": "string", "coordinates": "names",
              "speeds": "names", "drive": "expr"}
LOAD_KEYS = {"name": "name", "body": "name", "force": "vector", "moment": "vector",
             "point": "vector", "frame": ("choice", ("world", "body"))}
SIMULATION_KEYS = {"t_end": "expr", "integrator": "string", "method": "string",
                   "rtol": "expr", "atol": "expr", "dt": "expr", "max_step": "expr",
                   "output_dt": "expr", "max_steps": "expr", "max_samples": "expr",
                   "max_wall_time": "expr"}
OUTPUT_KEYS = {"reactions": "reactions", "reactions_frame": ("choice", ("world", "child")),
               "energy": "bool", "points": "points"}
POINT_KEYS = {"frame": "name", "offset": "vector"}
FORCE_KINDS = ("spring-damper", "joint-spring-damper", "bushing", "bearing", "contact")
FORCE_KEYS = {"name": "name", "kind": ("choice", FORCE_KINDS),
              "body_a": "name", "point_a": "vector", "body_b": "name", "point_b": "vector",
              "body": "name", "point": "vector", "housing": "name", "center": "vector",
              "joint": "name", "axis": "axis", "stiffness": "matrix6", "damping": "matrix6",
              "free_length": "expr", "preload": "expr", "rest": "expr", "min_length": "expr",
              "force_table": "table", "damping_table": "table", "law": "expr",
              "interpolation": ("choice", ("pchip", "linear")),
              "speed": "name", "speeds": "exprs",
              "kxx": "coefficient", "kxy": "coefficient", "kyx": "coefficient",
              "kyy": "coefficient", "cxx": "coefficient", "cxy": "coefficient",
              "cyx": "coefficient", "cyy": "coefficient",
              "radius": "expr", "shape": ("choice", ("sphere", "disk")),
              "plane_point": "vector", "plane_normal": "axis", "exponent": "expr",
              "restitution": "expr", "impact_speed": "expr", "friction": "expr",
              "slip_speed": "expr"}
EFFECT_KEYS = {"gravity": "bool", "gyroscopic": "bool", "off": "names", "on": "names"}
EVENT_KEYS = {"name": "name", "condition": "condition", "terminal": "bool",
              "direction": "direction"}

#: section -> (layout, keys): "table" (fixed keys), "map" (any names -> expr),
#: "array" (array of tables with a name each)
SECTIONS = {
    "model": ("table", MODEL_KEYS),
    "parameters": ("map", None),
    "bodies": ("array", BODY_KEYS),
    "joints": ("array", JOINT_KEYS),
    "loads": ("array", LOAD_KEYS),
    "forces": ("array", FORCE_KEYS),
    "effects": ("table", EFFECT_KEYS),
    "initial": ("map", None),
    "initial_speeds": ("map", None),
    "simulation": ("table", SIMULATION_KEYS),
    "outputs": ("table", OUTPUT_KEYS),
    "events": ("array", EVENT_KEYS),
    "cases": ("cases", None),
}
ARRAY_ELEMENT = {"bodies": "body", "joints": "joint", "loads": "load", "forces": "force",
                 "events": "event"}
DIRECTIONS = {"rising": 1, "falling": -1, "either": 0}


# ---------------------------------------------------------------------------- key paths
def format_path(path):
    """``("bodies", 2, "mass")`` -> ``"bodies[2].mass"``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _suggest(word, choices):
    low = {str(c).lower(): str(c) for c in choices}
    if str(word).lower() in low:        # a matter of case first (rk45 -> RK45)
        close = [low[str(word).lower()]]
    else:
        close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1,
                                          cutoff=0.6)
    return f"did you mean {close[0]!r}? " if close else ""


def _kind_of(value):
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return type(value).__name__


def _show(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        text = shown(value)
        return f'"{text}"' if len(text) < 60 else f'"{text[:56]}..."'
    text = repr(value)
    return text if len(text) < 60 else text[:57] + "..."


def scan_document(doc, file):
    """Check every value of a parsed model file against the input limits (``mbdyn.limits``):
    nesting depth, integer size, finite and bounded numbers, no control characters in keys
    or strings (tab and newline aside).  Iterative: a hostile nesting cannot exhaust the
    stack.  Raises ``ModelFileError`` at the first offending key."""
    stack = [((), doc)]
    while stack:
        path, value = stack.pop()
        where = format_path(path) if path else ""
        if len(path) > limits.MAX_NESTING:
            raise ModelFileError(file, format_path(path[:limits.MAX_NESTING]),
                                 f"arrays or tables are nested more than {limits.MAX_NESTING} "
                                 "levels deep; no model key needs that")
        if isinstance(value, dict):
            for k, v in value.items():
                problem = label_problem(k) if k != "" else "must not be empty"
                if problem or len(k) > limits.MAX_NAME_LENGTH:
                    raise ModelFileError(file, format_path(path + (shown(k)[:60],)),
                                         f"the key {problem or 'is too long'}")
                stack.append((path + (k,), v))
        elif isinstance(value, list):
            stack.extend((path + (i,), v) for i, v in enumerate(value))
        elif isinstance(value, bool):
            continue
        elif isinstance(value, int):
            if len(str(abs(value))) > limits.MAX_INTEGER_DIGITS:
                raise ModelFileError(file, where, f"the integer has {len(str(abs(value)))} "
                                     f"digits (at most {limits.MAX_INTEGER_DIGITS}); write it "
                                     "as a float such as 1.5e30 if you mean it")
            _check_magnitude(file, where, float(value))
        elif isinstance(value, float):
            if not math.isfinite(value):
                raise ModelFileError(file, where, f"{value} is not a finite number")
            _check_magnitude(file, where, value)
        elif isinstance(value, str):
            bad = [c for c in value if unicodedata.category(c) == "Cc" and c not in "\t\n\r"]
            if bad:
                raise ModelFileError(file, where, "the text holds control characters ("
                                     + ", ".join(f"U+{ord(c):04X}" for c in bad[:3])
                                     + "); remove them")


def _check_magnitude(file, where, value):
    problem = limits.magnitude_problem(value)
    if problem:
        raise ModelFileError(file, where, problem)


# ---------------------------------------------------------------------------- checking
class Checker:
    """Checks the shape of a document; ``where(path)`` maps a path of the merged document
    back to where its value was written (a case, an override)."""

    def __init__(self, file):
        self.file = str(file)
        self.origins = {}            # path tuple -> display prefix of where it was set

    def where(self, path):
        path = tuple(path)
        for n in range(len(path), 0, -1):
            origin = self.origins.get(path[:n])
            if origin is not None:
                rest = format_path(path[n:])
                if not rest:
                    return origin
                return origin + (rest if rest.startswith("[") else "." + rest)
        return format_path(path)

    def error(self, path, problem):
        return ModelFileError(self.file, self.where(path), problem)

    # -- the document
    def check_document(self, doc):
        for key in doc:
            if key not in SECTIONS:
                raise self.error((key,), f"unknown section; {_suggest(key, SECTIONS)}"
                                 f"the sections are: {', '.join(SECTIONS)}")
        for key, value in doc.items():
            self.check_section(key, value, (key,), in_case=False)
        for name, case in doc.get("cases", {}).items():
            _known_parameters(doc, case.get("parameters", {}), self,
                              lambda k, name=name: f"cases.{name}.parameters.{k}")

    def check_section(self, key, value, path, in_case):
        layout, keys = SECTIONS[key]
        if layout == "cases":
            if in_case:
                raise self.error(path, "a case cannot hold cases; move it to the top level")
            if not isinstance(value, dict):
                raise self.error(path, f"must be tables [cases.NAME], got {_kind_of(value)}")
            for name, case in value.items():
                cpath = path + (name,)
                if not isinstance(case, dict):
                    raise self.error(cpath, f"must be a table [cases.{name}] of overrides, "
                                     f"got {_kind_of(case)}")
                for ckey, cval in case.items():
                    if ckey not in SECTIONS or ckey == "cases":
                        raise self.error(cpath + (ckey,), "unknown section in a case; "
                                         f"{_suggest(ckey, SECTIONS)}a case overrides any of: "
                                         + ", ".join(k for k in SECTIONS if k != "cases"))
                    self.check_section(ckey, cval, cpath + (ckey,), in_case=True)
            return
        if layout == "table":
            self.check_table(value, keys, path, required=())
        elif layout == "map":
            if not isinstance(value, dict):
                raise self.error(path, f"must be a table [{key}] of name = value, got "
                                 f"{_kind_of(value)}")
            for name, v in value.items():
                if key == "parameters":
                    problem = identifier_problem(str(name))
                    if problem:
                        raise self.error(path + (name,), f"a parameter name {problem}")
                    if name in RESERVED:
                        raise self.error(path + (name,), f"{name!r} is a reserved name (t, pi "
                                         "and the functions); choose another parameter name")
                self.check_value("expr", v, path + (name,))
        else:  # array of named tables
            element = ARRAY_ELEMENT[key]
            if isinstance(value, dict):
                if not in_case:
                    raise self.error(path, f"must be an array of tables: write [[{key}]] (two "
                                     f"brackets) for each {element}")
                # in a case: a table keyed by element name, each a partial element
                for name, partial in value.items():
                    if not isinstance(partial, dict):
                        raise self.error(path + (name,), f"must be a table of the {element}'s "
                                         f"keys to override, got {_kind_of(partial)}")
                    self.check_table(partial, keys, path + (name,), required=())
                return
            if not isinstance(value, list):
                raise self.error(path, f"must be an array of tables [[{key}]], got "
                                 f"{_kind_of(value)}")
            for i, item in enumerate(value):
                if not isinstance(item, dict):
                    raise self.error(path + (i,), f"must be a table ([[{key}]]), got "
                                     f"{_kind_of(item)}")
                self.check_table(item, keys, path + (i,), required=())

    def check_table(self, table, keys, path, required):
        if not isinstance(table, dict):
            raise self.error(path, f"must be a table, got {_kind_of(table)}")
        for k in table:
            if k not in keys:
                raise self.error(path + (k,), f"unknown key; {_suggest(k, keys)}"
                                 f"the keys here are: {', '.join(keys)}")
        for k in required:
            if k not in table:
                raise self.error(path, f"{k} is missing; add {k} = ...")
        for k, v in table.items():
            self.check_value(keys[k], v, path + (k,))

    def check_value(self, kind, value, path):
        fail = self.error
        if isinstance(kind, tuple):            # ("choice", options)
            options = kind[1]
            if not isinstance(value, str) or value not in options:
                raise fail(path, f"{_show(value)} is not allowed; {_suggest(value, options)}"
                           f"use one of: {', '.join(options)}")
            return
        if kind == "string":
            if not isinstance(value, str):
                raise fail(path, f"must be a string, got {_kind_of(value)} {_show(value)}")
        elif kind == "name":
            problem = identifier_problem(value)
            if problem:
                raise fail(path, f"must be a name of ASCII letters, digits and underscores "
                           f"(not starting with a digit): {_show(value)} {problem}")
        elif kind == "bool":
            if not isinstance(value, bool):
                raise fail(path, f"must be true or false, got {_kind_of(value)} {_show(value)}")
        elif kind == "expr":
            self.check_expr(value, path)
        elif kind == "vector":
            if not isinstance(value, list) or len(value) != 3:
                raise fail(path, f"must be an array of three numbers or expressions, e.g. "
                           f"[0, 0, \"-l\"], got {_show(value)}")
            for i, v in enumerate(value):
                self.check_expr(v, path + (i,))
        elif kind == "axis":
            if isinstance(value, str):
                if value.strip().lower().lstrip("+-") not in ("x", "y", "z"):
                    raise fail(path, f"{_show(value)} is not an axis; use \"x\", \"y\", \"z\" "
                               "(optionally \"-x\" ...) or an array of three numbers")
            else:
                self.check_value("vector", value, path)
        elif kind == "inertia":
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                if value != 0:
                    raise fail(path, "a single number is not an inertia; give three principal "
                               "moments [Ixx, Iyy, Izz], a 3x3 array, or 0 for a particle")
            elif isinstance(value, list) and len(value) == 3 and all(
                    isinstance(r, list) for r in value):
                for i, row in enumerate(value):
                    if len(row) != 3:
                        raise fail(path + (i,), "each row of a 3x3 inertia needs three values")
                    for j, v in enumerate(row):
                        self.check_expr(v, path + (i, j))
            elif isinstance(value, list) and len(value) == 3:
                for i, v in enumerate(value):
                    self.check_expr(v, path + (i,))
            else:
                raise fail(path, "must be three principal moments [Ixx, Iyy, Izz], a 3x3 "
                           f"array or 0 (a particle), got {_show(value)}")
        elif kind == "orientation":
            if isinstance(value, dict):
                for k in value:
                    if k not in ("axis", "angle"):
                        raise fail(path + (k,), f"unknown key; {_suggest(k, ('axis', 'angle'))}"
                                   "an orientation table has axis and angle")
                for k in ("axis", "angle"):
                    if k not in value:
                        raise fail(path, f"{k} is missing; write {{ axis = \"z\", angle = "
                                   "\"pi/2\" }")
                self.check_value("axis", value["axis"], path + ("axis",))
                self.check_expr(value["angle"], path + ("angle",))
            elif isinstance(value, list) and len(value) == 4:
                for i, v in enumerate(value):
                    self.check_expr(v, path + (i,))
            elif isinstance(value, list) and len(value) == 3 and all(
                    isinstance(r, list) and len(r) == 3 for r in value):
                for i, row in enumerate(value):
                    for j, v in enumerate(row):
                        self.check_expr(v, path + (i, j))
            else:
                raise fail(path, "must be { axis = ..., angle = ... }, a unit quaternion "
                           "[w, x, y, z] or a 3x3 rotation matrix")
        elif kind == "names":
            items = [value] if isinstance(value, str) else value
            if not isinstance(items, list) or not all(is_identifier(n) for n in items):
                bad = next((n for n in items if not is_identifier(n)), value) \
                    if isinstance(items, list) else value
                why = identifier_problem(bad) if isinstance(bad, str) else "is not a name"
                raise fail(path, "must be a name or an array of names (ASCII letters, digits, "
                           f"underscores): {_show(bad)} {why}")
            for n in items:
                if n in RESERVED:
                    raise fail(path, f"{n!r} is a reserved name (t, pi and the functions); "
                               "choose another")
        elif kind == "condition":
            if not isinstance(value, str):
                raise fail(path, "must be a string such as \"theta >= pi/2\", got "
                           f"{_kind_of(value)}")
            try:
                parse_condition(value)
            except ExpressionError as exc:
                raise fail(path, str(exc)) from None
        elif kind == "direction":
            ok = (isinstance(value, str) and value in DIRECTIONS) or (
                isinstance(value, int) and not isinstance(value, bool) and value in (-1, 0, 1))
            if not ok:
                raise fail(path, f"{_show(value)} is not a direction; {_suggest(value, DIRECTIONS)}"
                           "use \"rising\", \"falling\" or \"either\" (or 1, -1, 0)")
        elif kind == "reactions":
            if isinstance(value, bool):
                return
            if not isinstance(value, list) or not all(isinstance(n, str) for n in value):
                raise fail(path, "must be true, false or an array of joint names")
        elif kind == "shape":
            self.check_table(value, SHAPE_KEYS, path, required=("type",))
        elif kind == "exprs":
            if not isinstance(value, list) or not value:
                raise fail(path, f"must be an array of numbers, got {_show(value)}")
            for i, v in enumerate(value):
                self.check_expr(v, path + (i,))
        elif kind == "coefficient":
            if isinstance(value, list):
                self.check_value("exprs", value, path)
            else:
                self.check_expr(value, path)
        elif kind == "matrix6":
            if isinstance(value, list):
                rows = value if all(isinstance(r, list) for r in value) else [value]
                for i, row in enumerate(rows):
                    if not isinstance(row, list):
                        raise fail(path, "must be a number, six numbers or a 6x6 array")
                    for j, v in enumerate(row):
                        self.check_expr(v, path + ((i, j) if len(rows) > 1 else (j,)))
            else:
                self.check_expr(value, path)
        elif kind == "table":
            if not isinstance(value, list) or not all(
                    isinstance(r, list) and len(r) == 2 for r in value):
                raise fail(path, "must be an array of [x, y] pairs, e.g. [[0, 0], [0.01, 50], "
                           f"[0.02, 180]], got {_show(value)}")
            for i, (x, y) in enumerate(value):
                self.check_expr(x, path + (i, 0))
                self.check_expr(y, path + (i, 1))
        elif kind == "points":
            if not isinstance(value, dict):
                raise fail(path, "must be a table of points: NAME = { frame = \"...\", offset "
                           "= [x, y, z] }")
            for name, point in value.items():
                problem = identifier_problem(str(name))
                if problem:
                    raise fail(path + (name,), f"a point name {problem}")
                self.check_table(point, POINT_KEYS, path + (name,), required=("frame",))
        else:  # pragma: no cover - a schema bug
            raise AssertionError(kind)

    def check_expr(self, value, path):
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise self.error(path, f"must be a number or an expression string such as "
                             f"\"pi/4\", got {_kind_of(value)} {_show(value)}")
        if isinstance(value, float) and value != value:
            raise self.error(path, "nan is not allowed; give a finite number")
        if isinstance(value, float) and value in (float("inf"), float("-inf")):
            raise self.error(path, "inf is not allowed; give a finite number")
        if isinstance(value, str):
            try:
                parse(value)
            except ExpressionError as exc:
                raise self.error(path, str(exc)) from None


# ---------------------------------------------------------------------------- merging
def _element_index(items, name):
    for i, item in enumerate(items):
        if isinstance(item, dict) and item.get("name") == name:
            return i
    return None


def apply_case(doc, case_name, checker):
    """The document with case ``case_name`` merged in (``doc`` is not modified)."""
    cases = doc.get("cases", {})
    if case_name not in cases:
        known = ", ".join(cases) or "(this file defines no cases)"
        raise checker.error(("cases",), f"no case {case_name!r}; {_suggest(case_name, cases)}"
                            f"the cases are: {known}")
    out = copy.deepcopy({k: v for k, v in doc.items() if k != "cases"})
    prefix = f"cases.{case_name}"
    for key, value in cases[case_name].items():
        layout = SECTIONS[key][0]
        if layout == "array":
            base = out.setdefault(key, [])
            if isinstance(value, list):
                out[key] = copy.deepcopy(value)
                checker.origins[(key,)] = f"{prefix}.{key}"
                continue
            for name, partial in value.items():
                idx = _element_index(base, name)
                if idx is None:
                    base.append({"name": name})
                    idx = len(base) - 1
                    checker.origins[(key, idx)] = f"{prefix}.{key}.{name}"
                for k, v in partial.items():
                    base[idx][k] = copy.deepcopy(v)
                    checker.origins[(key, idx, k)] = f"{prefix}.{key}.{name}.{k}"
        else:
            if key == "parameters":
                _known_parameters(out, value, checker, lambda k: f"{prefix}.parameters.{k}")
            if key == "effects":
                _drop_switches(out.setdefault(key, {}), value)
            _merge_table(out.setdefault(key, {}), value, (key,), f"{prefix}.{key}", checker)
    return out


def _drop_switches(base, over):
    """Remove from the file's ``[effects]`` the names a case's ``[effects]`` switches: the
    case decides them (it may switch on what the file switches off), and one merged table
    never says both (``mbdyn.effects`` refuses a table that does)."""
    def listed(value):                  # the shapes are checked later, with the merge
        return [value] if isinstance(value, str) else \
            [n for n in value if isinstance(n, str)] if isinstance(value, list) else []
    names = set()
    for key, value in over.items():
        names.update(listed(value) if key in ("on", "off") else [key])
    for key in list(base):
        if key in ("on", "off") and isinstance(base[key], (str, list)):
            base[key] = [n for n in listed(base[key]) if n not in names]
        elif key in names:
            del base[key]


def _known_parameters(doc, names, checker, where):
    """Cases and overrides change parameters; they cannot declare new ones (a typo must
    not pass silently)."""
    declared = doc.get("parameters", {})
    for k in names:
        if k not in declared:
            raise ModelFileError(checker.file, where(k), f"{k!r} is not a parameter of the "
                                 f"model; {_suggest(k, declared)}the parameters are: "
                                 f"{', '.join(declared) or '(none)'} -- declare new ones in "
                                 "[parameters]")


def _merge_table(base, over, path, prefix, checker):
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            _merge_table(base[k], v, path + (k,), f"{prefix}.{k}", checker)
        else:
            base[k] = copy.deepcopy(v)
            checker.origins[path + (k,)] = f"{prefix}.{k}"


_SEGMENT = re.compile(r"([^.\[\]]+)|\[(\d+)\]")


def split_path(text):
    """``"bodies[0].mass"`` / ``"bodies.0.mass"`` / ``"bodies.disk.mass"`` -> segments."""
    text = text.strip()
    if not text or text.startswith(".") or text.endswith(".") or ".." in text:
        raise ValueError(f"{text!r} is not a dotted key path such as parameters.b or "
                         "bodies.disk.mass")
    parts = []
    pos = 0
    for m in _SEGMENT.finditer(text):
        between = text[pos:m.start()]
        if between not in ("", "."):
            raise ValueError(f"{text!r} is not a dotted key path")
        parts.append(m.group(1) if m.group(1) is not None else int(m.group(2)))
        pos = m.end()
    if pos != len(text):
        raise ValueError(f"{text!r} is not a dotted key path")
    return [int(p) if isinstance(p, str) and p.isdigit() else p for p in parts]


def parse_set_value(text):
    """The value of ``--set PATH=VALUE``: a TOML value (number, boolean, array, quoted
    string) if ``VALUE`` reads as one, otherwise the text itself (an expression or a name)."""
    text = text.strip()
    if not text:
        raise ValueError("the value is empty")
    if "\x00" in text:
        raise ValueError("the value holds a NUL character")
    try:
        value = tomllib.loads("v = " + text)["v"]
    except tomllib.TOMLDecodeError:
        return text
    except RecursionError:
        raise ValueError(f"arrays are nested too deeply (at most {limits.MAX_NESTING})") \
            from None
    except ValueError:                # an integer literal of thousands of digits
        raise ValueError(f"the integer has more than 4300 digits (at most "
                         f"{limits.MAX_INTEGER_DIGITS})") from None
    try:
        scan_document({"v": value}, "--set")
    except ModelFileError as exc:
        raise ValueError(exc.problem) from None
    return value


def apply_override(doc, path_text, value, checker, origin):
    """Set the value at dotted ``path_text`` in ``doc`` (in place)."""
    try:
        parts = split_path(path_text)
    except ValueError as exc:
        raise ModelFileError(checker.file, origin, str(exc)) from None
    if parts[0] == "cases":
        raise ModelFileError(checker.file, origin, "cannot override cases; choose one with "
                             "--case and override its values by their normal paths")
    if parts[0] not in SECTIONS:
        raise ModelFileError(checker.file, origin, f"unknown section {parts[0]!r}; "
                             f"{_suggest(parts[0], SECTIONS)}the sections are: "
                             + ", ".join(k for k in SECTIONS if k != "cases"))
    if parts[0] == "parameters" and len(parts) == 2:
        _known_parameters(doc, [parts[1]], checker, lambda k: origin)
    node = doc
    path = []
    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        if isinstance(node, list):
            if isinstance(part, int):
                if not 0 <= part < len(node):
                    raise ModelFileError(checker.file, origin, f"{format_path(path)} has "
                                         f"{len(node)} entries; index {part} does not exist")
                idx = part
            else:
                idx = _element_index(node, part)
                if idx is None:
                    names = ", ".join(str(x.get("name")) for x in node if isinstance(x, dict))
                    raise ModelFileError(checker.file, origin, f"{format_path(path)} has no "
                                         f"entry named {part!r}; {_suggest(part, names.split(', '))}"
                                         f"the names are: {names or '(none)'}")
            key = idx
        elif isinstance(node, dict):
            if isinstance(part, int):
                raise ModelFileError(checker.file, origin, f"{format_path(path) or 'the file'} "
                                     f"is a table; [{part}] does not apply")
            key = part
        else:
            raise ModelFileError(checker.file, origin, f"{format_path(path)} is a value, not a "
                                 "table; shorten the path")
        path.append(key)
        if last:
            existing = node[key] if (isinstance(node, list) or key in node) else None
            if isinstance(existing, dict) and not isinstance(value, dict):
                raise ModelFileError(checker.file, origin, f"{format_path(path)} is a table; "
                                     f"set one of its keys ({', '.join(existing)})")
            if (isinstance(existing, list) and existing
                    and all(isinstance(x, dict) for x in existing)
                    and not isinstance(value, list)):
                raise ModelFileError(checker.file, origin, f"{format_path(path)} is an array "
                                     f"of tables; set a key of one entry, e.g. "
                                     f"{format_path(path)}[0].name")
            node[key] = value
            checker.origins[tuple(path)] = origin
            return
        if isinstance(node, dict) and key not in node:
            nxt = parts[depth + 1]
            if depth == 0 and SECTIONS[key][0] == "array":
                raise ModelFileError(checker.file, origin, f"the file has no [[{key}]]; "
                                     "there is nothing to override")
            node[key] = {} if not isinstance(nxt, int) else []
        node = node[key]

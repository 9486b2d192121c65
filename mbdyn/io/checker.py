"""The shape of a model file: every section and key known, every value of its kind (the
schema is ``mbdyn.io.keys``, the check of each kind ``mbdyn.io.value_checks``), every
expression syntactically valid.  What the values mean is checked when the model is built.
"""
from __future__ import annotations

from ..names import identifier_problem
from .cases import known_parameters
from .errors import ModelFileError
from .expressions import RESERVED, ExpressionError, parse
from .keys import ARRAY_ELEMENT, SECTIONS
from .value_checks import CHECKS, choice
from .wording import format_path, kind_of, show, suggest


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
                raise self.error((key,), f"unknown section; {suggest(key, SECTIONS)}"
                                 f"the sections are: {', '.join(SECTIONS)}")
        for key, value in doc.items():
            self.check_section(key, value, (key,), in_case=False)
        for name, case in doc.get("cases", {}).items():
            known_parameters(doc, case.get("parameters", {}), self,
                             lambda k, name=name: f"cases.{name}.parameters.{k}")

    def check_section(self, key, value, path, in_case):
        layout, keys = SECTIONS[key]
        if layout == "cases":
            self.check_cases(value, path, in_case)
        elif layout == "table":
            self.check_table(value, keys, path, required=())
        elif layout == "map":
            self.check_map(key, value, path)
        else:
            self.check_array(key, value, keys, path, in_case)

    def check_cases(self, value, path, in_case):
        """``[cases.NAME]`` tables, each overriding any section but the cases."""
        if in_case:
            raise self.error(path, "a case cannot hold cases; move it to the top level")
        if not isinstance(value, dict):
            raise self.error(path, f"must be tables [cases.NAME], got {kind_of(value)}")
        for name, case in value.items():
            cpath = path + (name,)
            if not isinstance(case, dict):
                raise self.error(cpath, f"must be a table [cases.{name}] of overrides, "
                                 f"got {kind_of(case)}")
            for ckey, cval in case.items():
                if ckey not in SECTIONS or ckey == "cases":
                    raise self.error(cpath + (ckey,), "unknown section in a case; "
                                     f"{suggest(ckey, SECTIONS)}a case overrides any of: "
                                     + ", ".join(k for k in SECTIONS if k != "cases"))
                self.check_section(ckey, cval, cpath + (ckey,), in_case=True)

    def check_map(self, key, value, path):
        """``[parameters]``, ``[initial]``...: any names, each an expression."""
        if not isinstance(value, dict):
            raise self.error(path, f"must be a table [{key}] of name = value, got "
                             f"{kind_of(value)}")
        for name, v in value.items():
            if key == "parameters":
                problem = identifier_problem(str(name))
                if problem:
                    raise self.error(path + (name,), f"a parameter name {problem}")
                if name in RESERVED:
                    raise self.error(path + (name,), f"{name!r} is a reserved name (t, pi "
                                     "and the functions); choose another parameter name")
            self.check_value("expr", v, path + (name,))

    def check_array(self, key, value, keys, path, in_case):
        """``[[bodies]]``...: an array of tables, or in a case tables keyed by name."""
        element = ARRAY_ELEMENT[key]
        if isinstance(value, dict):
            if not in_case:
                raise self.error(path, f"must be an array of tables: write [[{key}]] (two "
                                 f"brackets) for each {element}")
            # in a case: a table keyed by element name, each a partial element
            for name, partial in value.items():
                if not isinstance(partial, dict):
                    raise self.error(path + (name,), f"must be a table of the {element}'s "
                                     f"keys to override, got {kind_of(partial)}")
                self.check_table(partial, keys, path + (name,), required=())
            return
        if not isinstance(value, list):
            raise self.error(path, f"must be an array of tables [[{key}]], got "
                             f"{kind_of(value)}")
        for i, item in enumerate(value):
            if not isinstance(item, dict):
                raise self.error(path + (i,), f"must be a table ([[{key}]]), got "
                                 f"{kind_of(item)}")
            self.check_table(item, keys, path + (i,), required=())

    def check_table(self, table, keys, path, required):
        if not isinstance(table, dict):
            raise self.error(path, f"must be a table, got {kind_of(table)}")
        for k in table:
            if k not in keys:
                raise self.error(path + (k,), f"unknown key; {suggest(k, keys)}"
                                 f"the keys here are: {', '.join(keys)}")
        for k in required:
            if k not in table:
                raise self.error(path, f"{k} is missing; add {k} = ...")
        for k, v in table.items():
            self.check_value(keys[k], v, path + (k,))

    def check_value(self, kind, value, path):
        if isinstance(kind, tuple):            # ("choice", options)
            choice(self, value, path, kind[1])
            return
        check = CHECKS.get(kind)
        if check is None:  # pragma: no cover - a schema bug
            raise AssertionError(kind)
        check(self, value, path)

    def check_expr(self, value, path):
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise self.error(path, f"must be a number or an expression string such as "
                             f"\"pi/4\", got {kind_of(value)} {show(value)}")
        if isinstance(value, float) and value != value:
            raise self.error(path, "nan is not allowed; give a finite number")
        if isinstance(value, float) and value in (float("inf"), float("-inf")):
            raise self.error(path, "inf is not allowed; give a finite number")
        if isinstance(value, str):
            try:
                parse(value)
            except ExpressionError as exc:
                raise self.error(path, str(exc)) from None

"""The signature of a model's generated equations: a hash of everything the generated
code depends on -- structure, expressions, numbers that are not parameters, parameter
*names*, force elements -- and of the generator itself, under which ``codegen`` caches
the generated module on disk.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import sympy

from ..errors import ModelError

#: bump when the generated code changes for the same model
GENERATOR_VERSION = "1"


def _describe_value(record, key, numeric):
    sy = record.symbolic if isinstance(record.symbolic, dict) else {}
    if key in sy:
        return "S" + sympy.srepr(sympy.sympify(sy[key]) if not isinstance(sy[key], (list, tuple))
                                 else sympy.Tuple(*[sympy.sympify(v) if v is not None else 0
                                                    for v in np.asarray(sy[key], dtype=object)
                                                    .reshape(-1)]))
    if callable(numeric):
        raise ModelError(f"{type(record).__name__.lower()} {record.name!r}: its {key} is a "
                         "Python function; method='symbolic' needs constants or sympy "
                         "expressions of t and the coordinates/speeds")
    if isinstance(numeric, tuple):
        return "E" + sympy.srepr(sympy.Tuple(*numeric))
    return "N" + repr(np.asarray(numeric, dtype=float).round(15).tolist())


def _describe_parameter(value):
    """A force element's parameter as text for the signature: numbers and arrays by their
    values, expressions by ``srepr``, laws by their expression, tables by their knots."""
    if isinstance(value, sympy.Basic):
        return sympy.srepr(value)
    if hasattr(value, "expression") and hasattr(value, "function"):      # a Law
        return "law:" + (sympy.srepr(value.expression) if value.expression is not None
                         else f"function@{id(value.function)}")
    if hasattr(value, "block"):                                          # a Table
        return "table:" + repr(np.asarray(value.block()).tolist())
    if isinstance(value, np.ndarray):
        return repr(value.tolist())
    return repr(value)


def model_signature(model):
    """A hash of everything the generated code depends on (structure, expressions, numbers
    that are not parameters, parameter *names*) and of the generator itself."""
    bodies, joints, loads = model.elements
    parts = [GENERATOR_VERSION, sympy.__version__, "P" + repr(list(model.parameters)),
             "G" + (sympy.srepr(sympy.Tuple(*[sympy.sympify(g) for g in model.gravity_symbolic]))
                    if model.gravity_symbolic is not None else repr(model.gravity.tolist())),
             "C" + repr(model.coordinates), "U" + repr(model.speeds)]
    for b in bodies:
        parts.append(f"B{b.name}|" + "|".join(_describe_value(b, k, getattr(b, k))
                                              for k in ("mass", "com", "inertia")))
    for j in joints:
        drive = ""
        if j.drive is not None:
            expr = j.symbolic.get("drive") if isinstance(j.symbolic, dict) else None
            expr = expr if expr is not None else j.drive.expression
            if expr is None:
                raise ModelError(f"joint {j.name!r}: its drive is given as Python functions; "
                                 "method='symbolic' needs a sympy expression of mb.t")
            drive = sympy.srepr(sympy.sympify(expr))
        geometry = "|".join(_describe_value(j, k, getattr(j, k))
                            for k in ("axis", "position", "orientation"))
        parts.append(f"J{j.name}|{j.kind}|{j.parent}|{j.child}|{j.sequence}|{j.coordinates}|"
                     f"{j.speeds}|{drive}|{geometry}")
    for ld in loads:
        parts.append(f"L{ld.name}|{ld.body}|{ld.in_body}|" + "|".join(
            _describe_value(ld, k, getattr(ld, k)) for k in ("force", "moment", "point")))
    for el in getattr(model, "_force_elements", ()):
        parts.append(f"F{el.name}|{el.kind}|{el.frames}|" + "|".join(
            f"{k}={_describe_parameter(v)}" for k, v in sorted(el.params.items()))
            + "|" + "|".join(f"{k}={_describe_parameter(v)}"
                             for k, v in sorted(el.symbolic.items())))
    own = Path(__file__).parent
    for name in ("codegen.py", "signature.py", "walk.py", "methods.py", "symbols.py",
                 "simplify.py", "force_elements.py"):
        parts.append(hashlib.sha256((own / name).read_bytes()).hexdigest())
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()

"""Joints and drives: the kind, axis, placement and coordinates of each joint, and the
prescribed motion ``q(t)`` of a driven one, each validated on creation.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import sympy

from ..errors import ModelError, NonFiniteError
from ..kernels.joints import KIND_CODES, NQ, NU
from ..names import identifier_problem
from .expressions import RESERVED
from .values import (_vector3, has_symbols, numeric, parse_axis, parse_orientation,
                     parse_sequence, substitute, t)


@dataclass(frozen=True)
class Drive:
    """A prescribed motion ``q(t)`` of a 1-DoF joint with its exact derivatives."""
    position: Callable[[float], float]
    velocity: Callable[[float], float]
    acceleration: Callable[[float], float]
    expression: sympy.Expr | None = None


def make_drive(drive, element, parameters=None):
    if drive is None:
        return None
    if isinstance(drive, Drive):
        return drive
    if isinstance(drive, (tuple, list)):
        if len(drive) != 3 or not all(callable(f) for f in drive):
            raise ModelError(f"{element}: drive must be a sympy expression of mb.t or three "
                             "callables (q(t), q'(t), q''(t))")
        return Drive(*(_guarded(f, element, what, callable_=True)
                       for f, what in zip(drive, DRIVE_PARTS)))
    if isinstance(drive, (bool, str)):
        raise ModelError(f"{element}: drive must be a sympy expression of mb.t or three "
                         f"callables (q(t), q'(t), q''(t)), got {drive!r}")
    try:
        expr = sympy.Float(drive) if isinstance(drive, (int, float)) else drive
        expr = substitute(expr, parameters or {})
        free = expr.free_symbols
    except AttributeError:
        raise ModelError(f"{element}: drive must be a sympy expression of mb.t or three "
                         f"callables (q(t), q'(t), q''(t)), got {drive!r}") from None
    # accept any symbol named 't' as time, whatever its assumptions
    other = {s for s in free if s.name != "t"}
    if other:
        names = ", ".join(sorted(s.name for s in other))
        raise ModelError(f"{element}: drive depends on symbols {names} besides t; make them "
                         "parameters of the system or substitute numbers (expr.subs(...))")
    tsyms = [s for s in free if s.name == "t"]
    expr = expr.subs({s: t for s in tsyms})
    derivatives = (expr, expr.diff(t), expr.diff(t, 2))
    if any(d.has(sympy.DiracDelta) for d in derivatives):
        raise ModelError(f"{element}: the drive {expr} has a kink or a jump (its "
                         "acceleration holds an impulse, DiracDelta); give a motion that is "
                         "twice differentiable, e.g. smooth the corner")
    funcs = [sympy.lambdify(t, e, "math") for e in derivatives]
    return Drive(*(_guarded(f, element, what) for f, what in zip(funcs, DRIVE_PARTS)),
                 expression=expr)


DRIVE_PARTS = ("position", "velocity", "acceleration")


def _guarded(f, element, what, callable_=False):
    """``f(t)`` as a float; a value that is undefined or not finite at ``t`` raises
    ``NonFiniteError`` naming the joint, the drive's part and the time (never a bare
    ``math domain error``); an exception of a user's function is named, not swallowed."""
    def value(time):
        try:
            v = float(f(time))
        except (ValueError, ZeroDivisionError, OverflowError) as exc:
            raise NonFiniteError(f"{element}: the drive's {what} is undefined at t={time:.6g} "
                                 f"({exc}); give a drive defined over the whole run "
                                 "(e.g. log(t + 1) rather than log(t))") from None
        except Exception as exc:
            if not callable_:
                raise
            raise ModelError(f"{element}: the drive's {what} function raised "
                             f"{type(exc).__name__}: {exc} at t={time:.6g}") from exc
        if not math.isfinite(v):
            raise NonFiniteError(f"{element}: the drive's {what} is {v} at t={time:.6g}; give "
                                 "a drive that stays finite over the whole run")
        return v
    return value


@dataclass(frozen=True)
class Joint:
    """A joint between ``parent`` and ``child`` frames; see ``System.add_joint``."""
    name: str
    kind: str
    parent: str
    child: str
    axis: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    sequence: tuple
    coordinates: tuple
    speeds: tuple
    drive: Drive | None
    symbolic: dict = field(default_factory=dict)

    @property
    def code(self):
        return KIND_CODES[self.kind]

    @property
    def nq(self):
        return NQ[self.code]

    @property
    def nu(self):
        return NU[self.code]


def _default_names(name, kind, coordinates, speeds, element):
    nq, nu = NQ[KIND_CODES[kind]], NU[KIND_CODES[kind]]
    if kind in ("revolute", "prismatic"):
        qn = (name,)
    elif kind == "euler":
        qn = tuple(f"{name}_{k}" for k in range(1, 4))
    elif kind == "spherical":
        qn = tuple(f"{name}_{k}" for k in ("qw", "qx", "qy", "qz"))
    elif kind == "free":
        qn = tuple(f"{name}_{k}" for k in ("x", "y", "z", "qw", "qx", "qy", "qz"))
    else:
        qn = ()
    for key, given in (("coordinates", coordinates), ("speeds", speeds)):
        if given is not None and not isinstance(given, (str, list, tuple)):
            raise ModelError(f"{element}: {key} must be a name or a list of names, got "
                             f"{given!r}")
    if coordinates is not None:
        coordinates = (coordinates,) if isinstance(coordinates, str) else tuple(coordinates)
        if len(coordinates) != nq:
            raise ModelError(f"{element}: a {kind} joint has {nq} coordinate(s), "
                             f"got names {coordinates}")
        qn = coordinates
    if speeds is not None:
        speeds = (speeds,) if isinstance(speeds, str) else tuple(speeds)
        if len(speeds) != nu:
            raise ModelError(f"{element}: a {kind} joint has {nu} speed(s), got names {speeds}")
        un = speeds
    elif kind in ("revolute", "prismatic", "euler"):
        un = tuple(f"{c}_dot" for c in qn)
    elif kind == "spherical":
        un = tuple(f"{name}_{k}" for k in ("wx", "wy", "wz"))
    elif kind == "free":
        un = tuple(f"{name}_{k}" for k in ("vx", "vy", "vz", "wx", "wy", "wz"))
    else:
        un = ()
    repeated = sorted({n for n in qn + un if (qn + un).count(n) > 1})
    if repeated:
        raise ModelError(f"{element}: the names {repeated} are given to more than one of its "
                         "coordinates and speeds; give each its own name")
    for n in qn + un:
        problem = identifier_problem(n)
        if problem:
            raise ModelError(f"{element}: coordinate/speed name {n!r} {problem}")
        if n in RESERVED:
            raise ModelError(f"{element}: coordinate/speed name {n!r} is reserved (t, pi and "
                             "the functions of expressions); name the joint otherwise or "
                             "pass coordinates=[...]")
    return qn, un


def make_joint(name, kind, parent, child, *, axis=None, position=(0, 0, 0), orientation=None,
               sequence=None, coordinates=None, speeds=None, drive=None, parameters=None):
    """Validate and build a ``Joint``; see ``System.add_joint``.  Numbers may be sympy
    expressions of ``parameters`` (kept in ``symbolic``)."""
    element = f"joint {name!r}"
    parameters = parameters or {}
    raw = {"axis": axis, "position": position, "orientation": orientation, "drive": drive}
    symbolic = {k: v for k, v in raw.items() if not callable(v) and has_symbols(v)}
    if not isinstance(axis, str):
        axis = numeric(axis, parameters, element, "axis")
    position = numeric(position, parameters, element, "position")
    if isinstance(orientation, (tuple, list)) and len(orientation) == 2 and \
            isinstance(orientation[0], str):
        orientation = (orientation[0], numeric(orientation[1], parameters, element, "orientation"))
    else:
        orientation = numeric(orientation, parameters, element, "orientation")
    if not isinstance(kind, str) or kind not in KIND_CODES:
        raise ModelError(f"{element}: unknown kind {kind!r}; use one of "
                         + ", ".join(repr(k) for k in KIND_CODES))
    if kind in ("revolute", "prismatic"):
        if axis is None:
            raise ModelError(f"{element}: a {kind} joint needs an axis, e.g. axis='z'")
        axis = parse_axis(axis, element)
    elif axis is not None:
        raise ModelError(f"{element}: a {kind} joint takes no axis (remove axis=...)")
    else:
        axis = np.array([0.0, 0.0, 1.0])
    if sequence is not None and kind != "euler":
        raise ModelError(f"{element}: only an euler joint takes a sequence")
    seq = parse_sequence(sequence, element) if kind == "euler" else (2, 0, 2)
    position = _vector3(position, "position", element)
    C = parse_orientation(orientation, element)
    qn, un = _default_names(name, kind, coordinates, speeds, element)
    drv = make_drive(drive, element, parameters)
    if drv is not None and kind not in ("revolute", "prismatic"):
        raise ModelError(f"{element}: only a revolute or prismatic joint can be driven "
                         f"(this one is {kind})")
    return Joint(name, kind, parent, child, axis, position, C, seq, qn, un, drv, symbolic)

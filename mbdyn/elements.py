"""The elements a user assembles: bodies, joints, drives and loads, each validated on creation.

These are plain records; the tree that connects them is ``mbdyn.model.System``.  Every
error raised here names the element and says what to change.
"""
from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import sympy

from .errors import ModelError, ModelWarning, NonFiniteError
from .expressions import RESERVED
from .names import identifier_problem
from .kernels.joints import KIND_CODES, NQ, NU

#: The time symbol for drive expressions: ``drive=Omega * mb.t``.
t = sympy.Symbol("t", real=True)

AXIS_NAMES = {"x": 0, "y": 1, "z": 2}


def has_symbols(value):
    """True if ``value`` (a number, sympy object or nested sequence) holds a sympy expression."""
    if isinstance(value, sympy.Basic):
        return not value.is_number
    if isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray) and value.dtype == object):
        return any(has_symbols(v) for v in value)
    return False


def substitute(expr, parameters):
    """``expr`` with every symbol named in ``parameters`` replaced by its value."""
    if not isinstance(expr, sympy.Basic):
        return expr
    return expr.subs({s: parameters[s.name] for s in expr.free_symbols if s.name in parameters})


def numeric(value, parameters, element, what):
    """Evaluate ``value`` (numbers, sympy expressions of parameters, nested sequences) to
    floats; unknown symbols are an error that names them."""
    if isinstance(value, sympy.Basic):
        v = substitute(value, parameters)
        if v.free_symbols:
            names = ", ".join(sorted(x.name for x in v.free_symbols))
            raise ModelError(f"{element}: {what} uses {names}, which are not parameters of the "
                             "system; add them to System(parameters={...}) or use numbers")
        try:
            return float(v)
        except TypeError:
            raise ModelError(f"{element}: {what} = {value} is not a real number") from None
    if isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray) and value.dtype == object):
        return [numeric(v, parameters, element, what) for v in value]
    return value


def _vector3(value, what, element):
    try:
        arr = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {what} must be three numbers, got {value!r}") from None
    if arr.shape != (3,):
        raise ModelError(f"{element}: {what} must be three numbers, got {value!r}")
    if not np.all(np.isfinite(arr)):
        raise ModelError(f"{element}: {what} must be finite, got {value!r}")
    return arr


def parse_axis(axis, element):
    """A unit vector from ``"x"``/``"-y"``/... or three numbers; refuses zero and non-finite."""
    if isinstance(axis, str):
        key = axis.strip().lower()
        sign = -1.0 if key.startswith("-") else 1.0
        key = key.lstrip("+-")
        if key not in AXIS_NAMES:
            raise ModelError(f"{element}: axis {axis!r} is not one of 'x', 'y', 'z' "
                             "(optionally signed) or a vector of three numbers")
        a = np.zeros(3)
        a[AXIS_NAMES[key]] = sign
        return a
    a = _vector3(axis, "axis", element)
    norm = np.linalg.norm(a)
    if norm < 1e-12:
        raise ModelError(f"{element}: axis {tuple(a)} has zero length; give a direction "
                         "such as (0, 0, 1) or 'z'")
    return a / norm


def parse_orientation(orientation, element):
    """Rotation matrix ``C`` of a joint frame in its parent (``P s = C . J s``).

    Accepts None (identity), a 3x3 rotation matrix, a unit quaternion ``(w, x, y, z)``,
    or an axis-angle pair ``(axis, angle)`` such as ``("z", pi/2)``.
    """
    if orientation is None:
        return np.eye(3)
    if (isinstance(orientation, (tuple, list)) and len(orientation) == 2
            and not np.ndim(orientation[1])):
        axis = parse_axis(orientation[0], element + " orientation")
        try:
            angle = float(orientation[1])
        except (TypeError, ValueError):
            raise ModelError(f"{element}: the angle of orientation (axis, angle) must be a "
                             f"number, got {orientation[1]!r}") from None
        if not math.isfinite(angle):
            raise ModelError(f"{element}: the angle of orientation (axis, angle) must be "
                             f"finite, got {angle}")
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
    try:
        arr = np.asarray(orientation, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: orientation must be a 3x3 rotation matrix, a unit "
                         f"quaternion (w, x, y, z) or (axis, angle), got {orientation!r}") \
            from None
    if arr.shape == (4,):
        n = np.linalg.norm(arr)
        if not np.isfinite(n) or abs(n - 1.0) > 1e-6:
            raise ModelError(f"{element}: orientation quaternion {tuple(arr)} must have unit "
                             f"length (it has {n:.6g}); normalise it")
        w, x, y, z = arr / n
        return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    if arr.shape != (3, 3) or not np.all(np.isfinite(arr)):
        raise ModelError(f"{element}: orientation must be a 3x3 rotation matrix, a unit "
                         "quaternion (w, x, y, z) or (axis, angle)")
    if (np.abs(arr.T @ arr - np.eye(3)).max() > 1e-8 or np.linalg.det(arr) < 0):
        raise ModelError(f"{element}: orientation matrix is not a proper rotation "
                         "(needs C^T C = I and det C = +1)")
    return arr


def parse_sequence(sequence, element):
    """Axis indices of an Euler sequence such as ``"ZXZ"``; consecutive axes must differ."""
    seq = "ZXZ" if sequence is None else str(sequence).upper()
    if len(seq) != 3 or any(c not in "XYZ" for c in seq) or seq[0] == seq[1] or seq[1] == seq[2]:
        raise ModelError(f"{element}: Euler sequence {sequence!r} is not valid; use three "
                         "of X, Y, Z with no axis repeated twice in a row (e.g. 'ZXZ', 'XYZ')")
    return tuple("XYZ".index(c) for c in seq)


@dataclass(frozen=True)
class Body:
    """A frame with mass properties: ``mass``, centre of mass ``com`` (body components,
    from the frame origin) and ``inertia`` about the centre of mass in body axes.
    A massless frame is a body of mass 0 and no inertia."""
    name: str
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    symbolic: dict = field(default_factory=dict)
    shape: dict | None = None       # how pictures draw it (see make_shape)

    @property
    def has_inertia(self):
        return self.mass > 0.0 or bool(np.any(self.inertia != 0.0))


SHAPES = {"sphere": ("radius",), "box": ("size",), "cylinder": ("radius", "length"),
          "disk": ("radius", "length"), "rod": ("start", "end")}


def make_shape(shape, element, parameters=None):
    """A validated drawing shape in body axes: ``{"type": "sphere", "radius": r}``,
    ``{"type": "box", "size": [a, b, c]}``, ``{"type": "cylinder"|"disk", "radius": r,
    "length": l, "axis": "z"}``, ``{"type": "rod", "start": [...], "end": [...]}``; each
    with optional ``center`` (default the origin; a rod has none), ``radius`` of a rod
    (its thickness) and ``color`` (a matplotlib/CSS colour name or "#rrggbb")."""
    if shape is None:
        return None
    if not isinstance(shape, dict) or "type" not in shape:
        raise ModelError(f"{element}: shape must be a table with a type, e.g. "
                         "{type = \"sphere\", radius = 0.02}")
    kind = shape["type"]
    if kind not in SHAPES:
        raise ModelError(f"{element}: shape type {kind!r} is not one of "
                         f"{', '.join(SHAPES)}")
    known = set(SHAPES[kind]) | {"type", "center", "color", "axis", "radius"}
    extra = sorted(set(shape) - known)
    if extra:
        raise ModelError(f"{element}: unknown shape key(s) {', '.join(extra)} for a {kind}; "
                         f"known: {', '.join(sorted(known))}")
    missing = [k for k in SHAPES[kind] if k not in shape]
    if missing:
        raise ModelError(f"{element}: a {kind} shape needs {', '.join(missing)}")
    out = {"type": kind, "color": str(shape.get("color", "") or "")}
    if out["color"] and not re.fullmatch(r"#[0-9a-fA-F]{6}|#[0-9a-fA-F]{3}|[A-Za-z]{3,20}",
                                         out["color"]):
        raise ModelError(f"{element}: shape color {out['color']!r} is neither \"#rrggbb\" "
                         "nor a colour name such as \"steelblue\"")
    p = parameters or {}
    for key in ("radius", "length"):
        if key in shape:
            v = numeric(shape[key], p, element, f"shape {key}")
            try:
                v = float(v)
            except (TypeError, ValueError):
                raise ModelError(f"{element}: shape {key} must be a number") from None
            if not (math.isfinite(v) and v > 0):
                raise ModelError(f"{element}: shape {key} must be positive, got {v!r}")
            out[key] = v
    for key in ("center", "start", "end", "size"):
        if key in shape:
            out[key] = _vector3(numeric(shape[key], p, element, f"shape {key}"),
                                f"shape {key}", element)
    if kind == "box" and np.any(out["size"] <= 0):
        raise ModelError(f"{element}: box size must be three positive lengths")
    out.setdefault("center", np.zeros(3))
    if kind in ("cylinder", "disk"):
        out["axis"] = parse_axis(shape.get("axis", "z"), element)
    return out


def make_body(name, mass=0.0, com=(0, 0, 0), inertia=None, parameters=None, shape=None):
    """Validate and build a ``Body``; see ``System.add_body``.

    Values may be sympy expressions of ``parameters`` (``{name: value}``); the record keeps
    them in ``symbolic`` for the symbolic layer and uses their values everywhere else.
    """
    element = f"body {name!r}"
    parameters = parameters or {}
    raw = {"mass": mass, "com": com, "inertia": inertia}
    symbolic = {k: v for k, v in raw.items() if has_symbols(v)}
    mass = numeric(mass, parameters, element, "mass")
    com = numeric(com, parameters, element, "com")
    inertia = numeric(inertia, parameters, element, "inertia")
    try:
        mass = float(mass)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: mass must be a number, got {mass!r}") from None
    if not math.isfinite(mass) or mass < 0.0:
        raise ModelError(f"{element}: mass must be finite and >= 0, got {mass!r}")
    com = _vector3(com, "com", element)
    inertia = inertia_tensor(inertia, element)
    return Body(name, mass, com, inertia, symbolic, make_shape(shape, element, parameters))


def inertia_tensor(inertia, element):
    """A symmetric positive semi-definite 3x3 tensor from None/0, three principal values or
    a 3x3 matrix.  Warns when the principal moments break the triangle inequality."""
    if inertia is None or (np.isscalar(inertia) and inertia == 0):
        return np.zeros((3, 3))
    try:
        arr = np.asarray(inertia, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: inertia must be None, three principal moments or a "
                         f"3x3 tensor, got {inertia!r}") from None
    if arr.shape == (3,):
        arr = np.diag(arr)
    if arr.shape != (3, 3):
        raise ModelError(f"{element}: inertia must be None, three principal moments or a "
                         f"3x3 tensor, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ModelError(f"{element}: inertia has non-finite entries")
    scale = max(np.abs(arr).max(), 1e-300)
    if np.abs(arr - arr.T).max() > 1e-9 * scale:
        raise ModelError(f"{element}: inertia tensor is not symmetric; "
                         "I[i][j] must equal I[j][i]")
    arr = 0.5 * (arr + arr.T)
    principal = np.linalg.eigvalsh(arr)
    if principal[0] < -1e-12 * scale:
        raise ModelError(f"{element}: inertia tensor is not positive semi-definite "
                         f"(principal moments {principal.tolist()}); moments of inertia "
                         "cannot be negative")
    a, b, c = np.sort(np.maximum(principal, 0.0))
    if a + b < c * (1 - 1e-9):
        warnings.warn(f"{element}: principal moments of inertia {a:.6g}, {b:.6g}, {c:.6g} "
                      "about the centre of mass break the triangle inequality (A + B >= C); "
                      "no real body has them.  Check the data (e.g. moments given about another "
                      "point than the centre of mass).", ModelWarning, stacklevel=4)
    return arr


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


@dataclass(frozen=True)
class Load:
    """A force at a point of a body and/or a moment on it, in world or body components.

    ``force`` and ``moment`` are each a constant array, a callable ``(t, q, u) -> 3 values``,
    or a tuple of three sympy expressions of ``t`` and the model's coordinate and speed
    names (parameters already substituted), turned into a callable at compile.
    """
    name: str
    body: str
    force: object
    moment: object
    point: np.ndarray
    in_body: bool
    symbolic: dict = field(default_factory=dict)


def make_load(name, body, force=None, moment=None, point=(0, 0, 0), frame="world",
              parameters=None):
    element = f"load {name!r}"
    parameters = parameters or {}
    raw = {"force": force, "moment": moment, "point": point}
    symbolic = {k: v for k, v in raw.items() if not callable(v) and has_symbols(v)}
    point = numeric(point, parameters, element, "point")
    if frame not in ("world", "body"):
        raise ModelError(f"{element}: frame must be 'world' or 'body', got {frame!r}")
    if force is None and moment is None:
        raise ModelError(f"{element}: give a force, a moment or both")
    parts = []
    for what, val in (("force", force), ("moment", moment)):
        if val is None:
            parts.append(np.zeros(3))
        elif callable(val):
            parts.append(val)
        elif has_symbols(val):
            exprs = tuple(substitute(v if isinstance(v, sympy.Basic) else sympy.Float(float(v)),
                                     parameters) for v in val)
            if len(exprs) != 3:
                raise ModelError(f"{element}: {what} must have three components")
            if all(not e.free_symbols for e in exprs):
                parts.append(_vector3([float(e) for e in exprs], what, element))
            else:
                parts.append(exprs)
        else:
            parts.append(_vector3(val, what, element))
    point = _vector3(point, "point", element)
    return Load(name, body, parts[0], parts[1], point, frame == "body", symbolic)

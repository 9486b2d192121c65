"""Bodies: frames with mass properties (mass, centre of mass, inertia about it in body axes)
and the shapes the pictures draw, each validated on creation.
"""
from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass, field

import numpy as np
import sympy

from ..errors import ModelError, ModelWarning
from .values import _vector3, has_symbols, numeric, parse_axis, square_matrix


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
    shape: dict | tuple | None = None   # how pictures draw it: one shape or several
                                        # (see make_shape)

    @property
    def has_inertia(self):
        return self.mass > 0.0 or bool(np.any(self.inertia != 0.0))


SHAPES = {"sphere": ("radius",), "box": ("size",), "cylinder": ("radius", "length"),
          "disk": ("radius", "length"), "rod": ("start", "end"), "mesh": ("file",)}


def shapes_of(body):
    """The drawing shapes of ``body`` as a list (none, one or several)."""
    shape = body.shape
    return [] if shape is None else list(shape) if isinstance(shape, tuple) else [shape]


def make_shape(shape, element, parameters=None):
    """A validated drawing shape in body axes: ``{"type": "sphere", "radius": r}``,
    ``{"type": "box", "size": [a, b, c]}``, ``{"type": "cylinder"|"disk", "radius": r,
    "length": l, "axis": "z"}``, ``{"type": "rod", "start": [...], "end": [...]}``,
    ``{"type": "mesh", "file": path, "scale": [sx, sy, sz]}`` (a triangle-mesh file the
    pictures read, ``mbdyn.viz.mesh_files``); each with optional ``center`` (default the
    origin; a rod has none), ``rotation`` (a 3x3 rotation matrix: the shape's axes in body
    axes, applied about ``center``), ``radius`` of a rod (its thickness) and ``color`` (a
    matplotlib/CSS colour name or "#rrggbb").  A list of such tables is several shapes
    (a tuple of them)."""
    if shape is None:
        return None
    if isinstance(shape, (list, tuple)):
        if not shape:
            return None
        return tuple(make_shape(s, element, parameters) for s in shape)
    if not isinstance(shape, dict) or "type" not in shape:
        raise ModelError(f"{element}: shape must be a table with a type, e.g. "
                         "{type = \"sphere\", radius = 0.02}")
    kind = shape["type"]
    if kind not in SHAPES:
        raise ModelError(f"{element}: shape type {kind!r} is not one of "
                         f"{', '.join(SHAPES)}")
    known = set(SHAPES[kind]) | {"type", "center", "color", "axis", "radius", "rotation"}
    if kind == "mesh":
        known.add("scale")
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
    if kind == "mesh":
        _mesh_keys(shape, out, element)
    if "rotation" in shape:
        out["rotation"] = _rotation(shape["rotation"], element)
    if kind in ("cylinder", "disk"):
        out["axis"] = parse_axis(shape.get("axis", "z"), element)
    return out


def _mesh_keys(shape, out, element):
    """A mesh's ``file`` (a non-empty path) and ``scale`` (three non-zero numbers)."""
    if not isinstance(shape["file"], str) or not shape["file"].strip():
        raise ModelError(f"{element}: a mesh shape's file must be the path of a mesh file")
    out["file"] = shape["file"]
    scale = np.asarray(shape.get("scale", (1.0, 1.0, 1.0)), dtype=float).reshape(-1)
    if scale.shape != (3,) or not np.all(np.isfinite(scale)) or np.any(scale == 0):
        raise ModelError(f"{element}: a mesh's scale must be three non-zero numbers")
    out["scale"] = scale


def _rotation(value, element):
    try:
        R = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        R = np.zeros(0)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)) or \
            np.abs(R @ R.T - np.eye(3)).max() > 1e-6 or np.linalg.det(R) < 0:
        raise ModelError(f"{element}: a shape's rotation must be a 3x3 rotation matrix")
    return R


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
    arr = square_matrix(inertia, 3, element, "inertia must be None, three principal moments "
                        "or a 3x3 tensor", "inertia has non-finite entries", show=True)
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


def origin_inertia_parts(name, mass, com, inertia):
    """``(I_O, c, m)`` as sympy objects for ``inertia_about="origin"``: the inertia about
    the origin (three principal moments or a 3x3 tensor), the centre of mass (three
    values) and the mass (a number or an expression), each checked first."""
    element = f"body {name!r}"
    if not (isinstance(mass, (int, float, sympy.Basic)) and not isinstance(mass, bool)):
        raise ModelError(f"{element}: mass must be a number or an expression of parameters, "
                         f"got {mass!r}")
    shape = np.shape(np.asarray(inertia, dtype=object))
    if shape not in ((3,), (3, 3)):
        raise ModelError(f"{element}: inertia_about='origin' takes three principal moments "
                         f"or a 3x3 tensor, got {inertia!r}")
    if np.shape(np.asarray(com, dtype=object)) != (3,):
        raise ModelError(f"{element}: com must be three values, got {com!r}")
    entries = list(np.ravel(np.asarray(inertia, dtype=object))) + list(com)
    if not all(isinstance(v, (int, float, np.number, sympy.Basic)) and not isinstance(v, bool)
               for v in entries):
        raise ModelError(f"{element}: inertia and com must be numbers or sympy expressions "
                         "of parameters")
    try:
        I_O = sympy.Matrix(np.diag(inertia) if shape == (3,) else inertia)
        c = sympy.Matrix(list(com))
    except (TypeError, ValueError, sympy.SympifyError):
        raise ModelError(f"{element}: inertia and com must be numbers or expressions of "
                         "parameters") from None
    return I_O, c, mass

"""The sections of a model file that make the ``System``: ``[[bodies]]``, ``[[joints]]``,
``[[loads]]`` and ``[[forces]]``.  Each ``add_*`` reads its entries through the
``SceneBuilder`` ``b`` (values, key paths, errors), adds them to ``b.system`` and returns
the entries as written (the ``Scene``'s ``*_specs``).
"""
from __future__ import annotations

from pathlib import Path

import sympy

from .. import limits
from ..assembly.system import GROUND
from ..elements.expansion import expanded_terms
from .expressions import ExpressionError, symbol, to_float
from .keys import LOOP_JOINT_KEYS
from .wording import suggest


# ---------------------------------------------------------------- [[bodies]]
def add_bodies(b):
    specs = []
    for path, body, name in b.entries("bodies", "body"):
        mass = b.pval(body.get("mass", 0.0), path + ("mass",))
        com = b.pvector(body.get("com"), path + ("com",))
        raw = body.get("inertia")
        if raw is None or (not isinstance(raw, list) and raw == 0):
            inertia = None
        else:
            inertia = b.numbers(raw, path + ("inertia",), read=b.pval)
        about = body.get("inertia_about", "com")
        if about == "origin":
            if inertia is None:
                raise b.error(path + ("inertia_about",), "\"origin\" needs an inertia "
                              "to convert; give inertia = [...] or remove inertia_about")
            inertia = inertia_about_com(inertia, mass, com)
        shape = None
        if "shape" in body:
            shape = dict(body["shape"])
            for key in ("radius", "length"):
                if key in shape:
                    shape[key] = b.number(shape[key], path + ("shape", key), positive=True)
            for key in ("center", "start", "end", "size"):
                if key in shape:
                    shape[key] = b.numbers(shape[key], path + ("shape", key))
        flexible = _flexible(b, body.get("flexible"))
        with b.engine(path + (("flexible",) if flexible is not None else ())):
            b.system.add_body(name, mass=mass, com=com, inertia=inertia, shape=shape,
                              flexible=flexible)
        specs.append(dict(body))
    return specs


def _flexible(b, spec):
    """A ``flexible`` table with its ``data`` file found beside the model file."""
    if spec is None or "data" not in spec or not isinstance(spec["data"], str):
        return spec
    data = Path(spec["data"])
    if not data.is_absolute() and b.path is not None:
        data = Path(b.path).parent / data
    return {**spec, "data": str(data)}


def inertia_about_com(inertia, mass, com):
    """Inertia about the centre of mass from an inertia about the frame origin
    (``I_G = I_O - m (|d|^2 E - d d^T)``, ``d`` the centre of mass), kept symbolic: each
    entry expanded unless its expansion would exceed ``limits.MAX_EXPANDED_TERMS`` terms
    (``(a+b+c)**1000`` has half a million; it stays as written, which is as exact)."""
    def sym(v):                   # numbers and sympy objects only -- never text
        return v if isinstance(v, sympy.Basic) else sympy.Float(float(v))
    if not isinstance(inertia[0], list):
        I_O = sympy.diag(*[sym(v) for v in inertia])
    else:
        I_O = sympy.Matrix([[sym(v) for v in row] for row in inertia])
    d = sympy.Matrix([sym(v) for v in com])
    m = sym(mass)
    I_G = I_O - m * ((d.T * d)[0, 0] * sympy.eye(3) - d * d.T)
    out = []
    for r in range(3):
        row = []
        for c in range(3):
            e = I_G[r, c]
            if expanded_terms(e) <= limits.MAX_EXPANDED_TERMS:
                e = sympy.expand(e)
            row.append(float(e) if not e.free_symbols else e)
        out.append(row)
    return out


# ---------------------------------------------------------------- [[joints]]
def add_joints(b):
    specs = []
    for path, j, name in b.entries("joints", "joint"):
        kind = b.required(j, "kind", path, "joint")
        loop = {k: j[k] for k in LOOP_JOINT_KEYS if k in j}
        if kind in ("universal", "cylindrical") and set(loop) <= {"axis2"}:
            add_composite(b, path, j, name, kind)      # a tree joint of two parts
            specs.append(dict(j))
            continue
        if kind == "coupling" or loop or kind == "distance":
            add_loop_joint(b, path, j, name, kind, loop)
            specs.append(dict(j))
            continue
        child = b.required(j, "child", path, "joint")
        parent = j.get("parent", GROUND)
        _check_frames(b, path, parent, child)
        axis = j.get("axis")
        if isinstance(axis, list):
            axis = b.pvector(axis, path + ("axis",))
        orientation = _orientation(b, j.get("orientation"), path + ("orientation",))
        drive = None
        if "drive" in j:
            drive = b.expr(j["drive"], path + ("drive",), b.PT)
        coordinates = j.get("coordinates")
        speeds = j.get("speeds")
        for key, names in (("coordinates", coordinates), ("speeds", speeds)):
            for n in ([names] if isinstance(names, str) else names or []):
                if n in b.P:
                    raise b.error(path + (key,), f"{n!r} is also a parameter; rename "
                                  "the coordinate or the parameter")
        with b.engine(path):
            b.system.add_joint(name, kind, parent, child, axis=axis,
                               position=_place(b, j.get("position"), path + ("position",)),
                               orientation=orientation, sequence=j.get("sequence"),
                               coordinates=coordinates, speeds=speeds, drive=drive)
        _check_added_joint(b, b.system.joints[name], path)
        specs.append(dict(j))
    return specs


def add_composite(b, path, j, name, kind):
    """A tree ``universal`` or ``cylindrical`` joint (``assembly.composite``)."""
    child = b.required(j, "child", path, "joint")
    parent = j.get("parent", GROUND)
    _check_frames(b, path, parent, child)
    axes = {k: (b.pvector(j[k], path + (k,)) if isinstance(j[k], list) else j[k])
            for k in ("axis", "axis2") if k in j}
    with b.engine(path):
        b.system.add_joint(name, kind, parent, child,
                           position=b.pvector(j.get("position"), path + ("position",)),
                           orientation=_orientation(b, j.get("orientation"),
                                                    path + ("orientation",)),
                           coordinates=j.get("coordinates"), speeds=j.get("speeds"),
                           drive=j.get("drive"), sequence=j.get("sequence"), **axes)


def add_loop_joint(b, path, j, name, kind, loop):
    """A joint that closes a loop (``child_position`` ...), a distance or a coupling."""
    parent = child = None
    if kind != "coupling":
        child = b.required(j, "child", path, "joint")
        parent = j.get("parent", GROUND)
        _check_frames(b, path, parent, child)
    for key in ("child_position",):
        if key in loop:
            loop[key] = _place(b, loop[key], path + (key,))
    if "child_orientation" in loop:
        loop["child_orientation"] = _orientation(b, loop["child_orientation"],
                                                 path + ("child_orientation",))
    for key in ("length", "ratio", "offset"):
        if key in loop:
            loop[key] = b.pval(loop[key], path + (key,))
    for key in ("axis", "axis2"):
        if isinstance(j.get(key), list):
            loop[key] = b.pvector(j[key], path + (key,))
        elif key in j:
            loop[key] = j[key]
    for key in ("drive", "sequence", "coordinates", "speeds"):
        if key in j:
            raise b.error(path + (key,), f"a loop joint has no coordinates of its own: "
                          f"remove {key} (it belongs on a tree joint)")
    position = _place(b, j.get("position"), path + ("position",)) if "position" in j \
        else (0, 0, 0)
    orientation = _orientation(b, j.get("orientation"), path + ("orientation",))
    with b.engine(path):
        b.system.add_joint(name, kind, parent, child, position=position,
                           orientation=orientation, **loop)


def _check_frames(b, path, parent, child):
    """A joint's parent and child are frames already in the tree."""
    for role, frame in (("parent", parent), ("child", child)):
        if frame not in b.system.graph:
            known = [n for n in b.system.graph]
            raise b.error(path + (role,), f"unknown frame {frame!r}; "
                          f"{suggest(frame, known)}the frames are: "
                          f"{', '.join(known)} (add bodies with [[bodies]])")


def _orientation(b, orientation, path):
    """A joint's orientation for the engine: ``(axis, angle)`` from ``{axis, angle}``, the
    numbers of a quaternion or a rotation matrix, else as written (None)."""
    if isinstance(orientation, dict):
        oaxis = orientation["axis"]
        if isinstance(oaxis, list):
            oaxis = b.pvector(oaxis, path + ("axis",))
        return (oaxis, b.pval(orientation["angle"], path + ("angle",)))
    if isinstance(orientation, list):
        return b.numbers(orientation, path)
    return orientation


def _check_added_joint(b, joint, path):
    """A drive defined where the run starts; a free joint's coordinate and speed names
    apart from the parameters and ``t``."""
    if joint.drive is not None:
        try:                  # defined where the run starts (the files' t0 is 0)
            for part in (joint.drive.position, joint.drive.velocity,
                         joint.drive.acceleration):
                part(0.0)
        except ArithmeticError as exc:
            raise b.error(path + ("drive",), str(exc)) from None
    if joint.drive is None:
        clash = [n for n in joint.coordinates + joint.speeds if n in b.P or n == "t"]
        if clash:
            raise b.error(path, f"its coordinate/speed names {clash} are also "
                          "parameter names (or t); name them with coordinates = "
                          "[...] / speeds = [...]")


# ---------------------------------------------------------------- [[loads]]
def add_loads(b):
    specs = []
    for path, ld, name in b.entries("loads", "load"):
        body = b.required(ld, "body", path, "load")
        parts = {}
        for key in ("force", "moment"):
            if key in ld:
                exprs = tuple(b.expr(v, path + (key, k), b.PTQ)
                              for k, v in enumerate(ld[key]))
                for k, e in enumerate(exprs):
                    e0 = e.subs({s: b.values[s.name] for s in e.free_symbols
                                 if s.name in b.values})
                    if not e0.free_symbols:
                        try:
                            to_float(e0)
                        except ExpressionError as exc:
                            raise b.error(path + (key, k), str(exc)) from None
                parts[key] = exprs
        with b.engine(path):
            b.system.add_load(name, body, force=parts.get("force"),
                              moment=parts.get("moment"),
                              point=_place(b, ld.get("point"), path + ("point",)),
                              frame=ld.get("frame", "world"))
        specs.append(dict(ld))
    return specs


# ---------------------------------------------------------------- [[forces]]
#: keys handed to the engine as written (names and choices)
FORCE_NAME_KEYS = ("body_a", "body_b", "body", "housing", "joint", "speed", "shape",
                   "interpolation")
#: keys that are points
FORCE_POINT_KEYS = ("point_a", "point_b", "point", "center", "plane_point")


def add_forces(b):
    """``[[forces]]``: each table's keys handed to ``System.add_force``."""
    specs = []
    for path, fe, name in b.entries("forces", "force element"):
        kind = b.required(fe, "kind", path, "force element")
        kw = {key: _force_value(b, key, value, path + (key,))
              for key, value in fe.items() if key not in ("name", "kind")}
        with b.engine(path):
            b.system.add_force(name, kind, **kw)
        specs.append(dict(fe))
    return specs


def _place(b, value, path):
    """A point's three values, or a flexible body's node named (kept as the name)."""
    return value if isinstance(value, str) else b.pvector(value, path)


def _force_value(b, key, value, path):
    """The value of one key of a force element, for ``System.add_force``."""
    if key in FORCE_NAME_KEYS:
        return value
    if key in FORCE_POINT_KEYS:
        return _place(b, value, path)
    if key in ("axis", "plane_normal"):
        return value if isinstance(value, str) else b.pvector(value, path)
    if key == "law":
        for n in ("x", "v"):
            if n in b.P:
                raise b.error(path, f"a law's variables are x (elongation) and "
                              f"v (its rate), but {n!r} is also a parameter; "
                              "rename the parameter")
        return b.expr(value, path, dict(b.P, x=symbol("x"), v=symbol("v")))
    if isinstance(value, list):         # numbers, rows of numbers, [x, y] table rows
        return b.numbers(value, path)
    return b.pval(value, path)


# ---------------------------------------------------------------- [[actuators]]
#: an actuator's keys read as sources: a number, an expression (of t, the free coordinates
#: and speeds, and parameters) or a table of t
ACTUATOR_SIGNALS = ("value", "setpoint", "command")


def add_actuators(b):
    """``[[actuators]]``: each table's keys handed to ``System.add_actuator``."""
    specs = []
    for path, act, name in b.entries("actuators", "actuator"):
        joint = b.required(act, "joint", path, "actuator")
        kw = {}
        for key, value in act.items():
            at = path + (key,)
            if key in ("name", "joint", "kind", "interpolation", "gravity_compensation",
                       "anti_windup", "feedforward"):
                if key not in ("name", "joint", "kind"):
                    kw[key] = value
            elif key in ACTUATOR_SIGNALS and isinstance(value, list):
                kw[key] = b.numbers(value, at)
            elif key in ACTUATOR_SIGNALS:
                e = b.expr(value, at, b.PTQ)
                kw[key] = e if e.free_symbols else b.number(value, at)
            elif key == "torque_speed":
                kw[key] = b.numbers(value, at)
            else:
                kw[key] = b.pval(value, at)
        with b.engine(path):
            b.system.add_actuator(name, joint, act.get("kind", "torque"), **kw)
        specs.append(dict(act))
    return specs

"""Contact shapes attached to bodies, and contact elements between them, each validated
on creation (``System.add_shape``, ``System.add_contact``; docs/contact.md).

A shape is a named record: its kind, its body (or ``"ground"``), its position and its axes
in the body's axes, its sizes.  Kinds: ``sphere`` (``radius``), ``plane`` (a half-space of
its body: a ``position`` on the plane and the outward ``normal``), ``box`` (``half_sizes`` or
``sizes``, ``orientation``), ``capsule`` and ``cylinder`` (``radius``, ``length`` along
``axis``), ``cam`` (a planar ``profile`` of radius against angle about ``axis``, extruded
along it).  A contact element acts between listed ``pairs`` of shapes, or every pair of
a ``group``; its force is the floor contact's (``mbdyn.forces``, kind ``contact``):
Hunt-Crossley normal force, damping from a coefficient of restitution at ``impact_speed``,
regularised Coulomb friction.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..names import identifier_problem
from .force_kinds import compliant_law, radial_directions
from .force_values import number
from .forces import ForceElement, check_name
from .values import _vector3, numeric, parse_axis, parse_orientation

SHAPE_KINDS = ("sphere", "plane", "box", "capsule", "cylinder", "cam")
#: the pairs of kinds that have a narrow phase (kernels/contact_geometry.py)
SUPPORTED = frozenset(frozenset(p) for p in (
    ("sphere",), ("sphere", "plane"), ("sphere", "box"), ("sphere", "capsule"),
    ("sphere", "cam"), ("plane", "box"), ("plane", "capsule"), ("plane", "cylinder"),
    ("plane", "cam"), ("capsule",), ("cylinder", "cam")))
SUPPORTED_TEXT = ("sphere-sphere, sphere-plane, sphere-box, sphere-capsule, capsule-capsule, "
                  "plane-box, plane-capsule, plane-cylinder (its rims), and a cam against a "
                  "plane (flat follower), a sphere or a cylinder (rollers)")
KIND = "shape-contact"
#: the keys each shape kind takes besides ``position``
SHAPE_KEYS = {"sphere": ("radius",), "plane": ("normal",),
              "box": ("half_sizes", "sizes", "orientation"),
              "capsule": ("radius", "length", "axis"), "cylinder": ("radius", "length", "axis"),
              "cam": ("profile", "axis")}
CONTACT_KEYS = ("stiffness", "exponent", "restitution", "impact_speed", "friction",
                "slip_speed", "broad_phase")


@dataclass(frozen=True)
class ContactShape:
    """A validated contact shape: ``axes`` (3x3) holds its local x, y, z in the body's axes
    as columns (a plane's outward normal, and the axis of a capsule, a cylinder or a cam,
    is local z); ``size`` three numbers (a sphere's radius; a box's half sizes; a capsule's
    or a cylinder's radius and half length); ``bound`` the radius of a sphere about
    ``position`` that holds it (0 for a plane: unbounded); ``profile`` a cam's
    ``(angles, radii)``."""
    name: str
    kind: str
    body: str
    position: np.ndarray
    axes: np.ndarray
    size: tuple
    bound: float
    profile: tuple = None


def make_shape(name, kind, body, parameters=None, **kw):
    """Validate and build a ``ContactShape`` (its body is checked by ``System.add_shape``)."""
    element = f"shape {name!r}"
    parameters = parameters or {}
    problem = identifier_problem(name)
    if problem:
        raise ModelError(f"shape {name!r}: the name {problem}")
    if kind not in SHAPE_KINDS:
        raise ModelError(f"{element}: unknown kind {kind!r}; use one of "
                         f"{', '.join(SHAPE_KINDS)}")
    if not isinstance(body, str):
        raise ModelError(f"{element}: body must be the name of a body (or 'ground'), got "
                         f"{body!r}")
    extra = sorted(set(kw) - set(SHAPE_KEYS[kind]) - {"position"})
    if extra:
        raise ModelError(f"{element}: unknown key(s) {', '.join(extra)} for a {kind}; known: "
                         f"{', '.join(('position',) + SHAPE_KEYS[kind])}")

    def num(key, minimum=0.0, positive=True):
        if kw.get(key) is None:
            raise ModelError(f"{element}: missing {key} of the {kind}")
        return number(kw[key], parameters, element, key, minimum=minimum, positive=positive)
    position = _vector3(numeric(kw.get("position", (0, 0, 0)), parameters, element,
                                "position"), "position", element)
    profile = None
    if kind == "box":
        size, axes = _box(kw, parameters, element), parse_orientation(
            numeric(kw.get("orientation"), parameters, element, "orientation"), element)
        bound = float(np.linalg.norm(size))
    elif kind == "sphere":
        size, axes = (num("radius", positive=False), 0.0, 0.0), np.eye(3)
        bound = size[0]
    else:
        key = "normal" if kind == "plane" else "axis"
        z = parse_axis(numeric(kw.get(key, "z"), parameters, element, key), element)
        axes = np.column_stack(radial_directions(z) + (z,))
        size = ((num("radius"), 0.5 * num("length"), 0.0) if kind in ("capsule", "cylinder")
                else (0.0, 0.0, 0.0))
        bound = (0.0 if kind == "plane" else size[0] + size[1] if kind == "capsule" else
                 float(np.hypot(size[0], size[1])))
        if kind == "cam":
            profile, bound = cam_profile(kw.get("profile"), parameters, element)
    return ContactShape(name, kind, body, position, axes, tuple(float(s) for s in size),
                        float(bound), profile)


def _box(kw, parameters, element):
    """A box's half sizes from ``half_sizes`` or ``sizes`` (one of them)."""
    given = [k for k in ("half_sizes", "sizes") if kw.get(k) is not None]
    if len(given) != 1:
        raise ModelError(f"{element}: give the box's half_sizes or its sizes (one of them)")
    size = _vector3(numeric(kw[given[0]], parameters, element, given[0]), given[0], element)
    if np.any(size <= 0):
        raise ModelError(f"{element}: {given[0]} must be positive, got {tuple(size)}")
    return size * (0.5 if given[0] == "sizes" else 1.0)


def cam_profile(value, parameters, element):
    """``((angles, radii), largest radius)`` of a cam's profile: rows ``[angle, radius]``
    (radians, increasing, within one turn), fitted by a periodic cubic spline (its
    curvature, hence the follower's acceleration, continuous)."""
    try:
        rows = np.asarray(numeric(value, parameters, element, "profile"), dtype=float)
    except (TypeError, ValueError):
        rows = None
    if rows is None or rows.ndim != 2 or rows.shape[1] != 2 or len(rows) < 4:
        raise ModelError(f"{element}: profile must be rows [angle (rad), radius], at least "
                         f"four, got {value!r}")
    angles, radii = rows[:, 0], rows[:, 1]
    if not np.all(np.isfinite(rows)):
        raise ModelError(f"{element}: profile holds non-finite numbers")
    if np.any(np.diff(angles) <= 0) or angles[-1] - angles[0] >= 2 * np.pi:
        raise ModelError(f"{element}: profile angles must increase and span less than one "
                         "turn (2 pi; the profile closes on its first point)")
    if np.any(radii <= 0):
        raise ModelError(f"{element}: profile radii must be positive")
    knots, coefficients = cam_spline(angles, radii)
    fine = np.linspace(0.0, 1.0, 16, endpoint=False)
    values = [np.polyval(c, s * h) for c, h in zip(coefficients, np.diff(knots)) for s in fine]
    if min(values) <= 0:
        raise ModelError(f"{element}: the profile's spline falls to radius {min(values):.3g} "
                         "between its points; give more points")
    return (angles, radii), 1.001 * max(values)


def cam_spline(angles, radii):
    """Knots (closing at the first angle plus a turn) and per-segment cubic coefficients
    (highest power first) of the periodic cubic spline through a cam's profile."""
    from scipy.interpolate import CubicSpline
    knots = np.append(angles, angles[0] + 2 * np.pi)
    spline = CubicSpline(knots, np.append(radii, radii[0]), bc_type="periodic")
    return knots, np.ascontiguousarray(spline.c.T)


@dataclass(frozen=True)
class ContactElement(ForceElement):
    """A contact element between shapes: a force element of kind ``"shape-contact"``
    whose ``params`` hold its shapes (``ContactShape``, in order), its ``pairs`` (index
    pairs, or None for every pair of a group), its ``mode`` (``"pairs"``, ``"sweep"``,
    ``"all"``) and the force law's numbers."""

    def describe(self):
        p = self.params
        names = [s.name for s in p["shapes"]]
        which = (", ".join(f"{names[i]}-{names[j]}" for i, j in p["pairs"])
                 if p["pairs"] is not None else
                 f"every pair of {', '.join(names)} ("
                 + ("sweep and prune" if p["mode"] == "sweep" else "all pairs tested") + ")")
        return (f"{which}; k = {p['stiffness']:g}, n = {p['exponent']:g}, "
                f"e = {p['restitution']:g}, mu = {p['friction']:g}")


def make_contact(name, shapes, parameters=None, pairs=None, group=None, **kw):
    """Validate and build a ``ContactElement`` between the named ``shapes`` (``{name:
    ContactShape}``, those of the system): ``pairs`` (a list of two shape names each) or
    ``group`` (shape names: every pair of them whose shapes are on different bodies)."""
    element = f"contact {name!r}"
    check_name(element, name)
    extra = sorted(set(kw) - set(CONTACT_KEYS))
    if extra:
        raise ModelError(f"{element}: unknown key(s) {', '.join(extra)}; known: pairs, "
                         f"group, {', '.join(CONTACT_KEYS)}")
    if (pairs is None) == (group is None):
        raise ModelError(f"{element}: give pairs = [[shape, shape], ...] or group = [shape, "
                         "...] (one of them)")
    used, index_pairs = _pairs(element, shapes, pairs, group)
    params = compliant_law(element, parameters or {}, kw)   # as the floor contact's
    broad = kw.get("broad_phase", True)
    if not isinstance(broad, (bool, np.bool_)):
        raise ModelError(f"{element}: broad_phase must be true or false, got {broad!r}")
    params.update(shapes=tuple(shapes[n] for n in used),
                  pairs=None if group is not None else tuple(index_pairs),
                  mode="pairs" if group is None else "sweep" if broad else "all")
    frames = tuple(dict.fromkeys(shapes[n].body for n in used))
    return ContactElement(name, KIND, frames, params)


def _pairs(element, shapes, pairs, group):
    """The shape names an element uses, in order, and its pairs as indices into them;
    every name known, every pair of a supported kind and between two bodies."""
    key = "group" if pairs is None else "pairs"
    names = group if pairs is None else pairs
    if isinstance(names, str) or not isinstance(names, (list, tuple)):
        raise ModelError(f"{element}: {key} must be a list, got {names!r}")
    if pairs is not None:
        for k, pr in enumerate(pairs):
            if (isinstance(pr, str) or not isinstance(pr, (list, tuple)) or len(pr) != 2):
                raise ModelError(f"{element}: pairs[{k}] must be two shape names, got {pr!r}")
    flat = [n for pr in pairs for n in pr] if pairs is not None else list(group)
    for n in flat:
        if not isinstance(n, str) or n not in shapes:
            raise ModelError(f"{element}: {key} names unknown shape {n!r}; the shapes are "
                             f"{', '.join(shapes) or '(none: add them with add_shape)'}")
    used = list(dict.fromkeys(flat))
    if pairs is None:
        if len(used) < 2:
            raise ModelError(f"{element}: group needs at least two shapes, got {used}")
        if len(used) != len(group):
            raise ModelError(f"{element}: group names a shape twice")
        todo = [(i, j) for i in range(len(used)) for j in range(i + 1, len(used))
                if shapes[used[i]].body != shapes[used[j]].body]
    else:
        todo = [(used.index(a), used.index(b)) for a, b in pairs]
        if len({frozenset(p) for p in todo}) != len(todo):
            raise ModelError(f"{element}: pairs lists a pair twice")
    for i, j in todo:
        a, b = shapes[used[i]], shapes[used[j]]
        what = f"{key} ({a.name!r}, {b.name!r})"
        if a.body == b.body:
            raise ModelError(f"{element}: {what}: both shapes are on {a.body!r}; a contact "
                             "acts between two bodies (or a body and the ground)")
        if frozenset((a.kind, b.kind)) not in SUPPORTED:
            raise ModelError(f"{element}: {what}: {a.kind}-{b.kind} contact is not "
                             f"supported; the supported pairs are {SUPPORTED_TEXT}"
                             + (" (list the pairs you need with pairs = [...])"
                                if pairs is None else ""))
    return used, todo

"""What a picture of a model draws, described once and fixed to the frames that carry it.

A ``Drawing`` lists every piece as attached to a *mover* -- a frame of the model (its index)
or one of the extra primitives (after the frames), or the ground (-1) -- with its points in
the mover's axes.  Each instant then only needs every mover's pose: ``realise`` turns the
drawing and the poses into a ``Scene3D`` in world axes (matplotlib), and the HTML view's
script does the same in the browser from poses alone (``viz.view_data``, ``view.js``).

Pieces: body shapes as shaded solids (``viz.meshes``); links (parent origin -> joint ->
centre of mass) and each frame's axes as polylines; loop joints in red; springs
(``spring-damper`` with stiffness, a table or a law) as coils, dampers (with damping) as a
cylinder and a piston rod; a contact's plane as a ground plane; bushings and bearings as
small diamonds; joint actuators as an orange ring about the actuated joint's axis, joint
springs as a grey one.  ``extra_primitives`` is the hook for more solids: it returns
``(kind, pose, size)`` primitives (``viz.meshes.PRIMITIVES``) of an instant.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .contact_shapes import contact_primitives, ground_planes
from .flexible_shapes import flexible_primitives
from .meshes import frame_of, primitive_mesh

AXES = ("#e41a1c", "#4daf4a", "#377eb8")
LINK = "#444444"
LOOP = "#d62728"
SPRING = "#3d5a80"
DAMPER = "#7f5539"
ACTUATOR = "#ff7f0e"
MOUNT = "#6a3d9a"
PLANE = "#9a9a9a"
PRIMITIVE = "#8c8c8c"
FORCE = "#d62728"
#: sizes in the scene's half-width: coil and damper radii, rings, a plane's half-width
SIZES = {"coil": 0.035, "damper": 0.018, "ring": 0.07, "plane": 1.0}
#: polyline widths (points) of the groups
WIDTHS = {"link": 1.5, "axis": 1.0, "loop": 2.5, "ring": 3.0, "trail": 0.8}


@dataclass
class Drawing:
    """Static pieces; an attachment is ``(mover, point in its axes)`` (mover -1: world)."""
    solids: list = field(default_factory=list)     # (mover, vertices, faces, colour)
    polylines: list = field(default_factory=list)  # (colour, width, [attachments])
    springs: list = field(default_factory=list)    # (name, a, b)
    dampers: list = field(default_factory=list)    # (name, a, b)
    tags: list = field(default_factory=list)       # (name, attachment, colour)
    markers: list = field(default_factory=list)    # (name, attachment (com), colour, size)
    planes: list = field(default_factory=list)     # (name, world vertices, faces)
    primitives: list = field(default_factory=list)  # (kind, size) of the extra movers
    sizes: dict = field(default_factory=dict)


def extra_primitives(model, kin, q=None, scale=1.0):
    """Hook: extra solids of an instant as ``[(kind, (R, p), size)]`` (world pose; kinds
    and sizes as ``viz.meshes.PRIMITIVES``), the same kinds and sizes at every instant, in
    the same order: the contact shapes (``viz.contact_shapes``) and the flexible bodies'
    deformed shapes at the state ``q``, deflections drawn ``scale`` times
    (``viz.flexible_shapes``)."""
    return contact_primitives(model, kin) + flexible_primitives(model, kin, q, scale)


def _at(model, frame, point):
    return (-1 if frame == "ground" else model.frame_index(frame), np.asarray(point, float))


def _ring(mover, centre, axis, radius, n=24):
    e1, e2 = frame_of(np.asarray(axis, float) / np.linalg.norm(axis))
    s = 2 * np.pi * np.arange(n + 1) / n
    pts = centre + radius * (np.outer(np.cos(s), e1) + np.outer(np.sin(s), e2))
    return [(mover, p) for p in pts]


def _plane(point, normal, centre, half):
    """A square of half-width ``half`` in the plane, centred where ``centre`` projects."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    c = centre - ((centre - point) @ n) * n
    e1, e2 = frame_of(n)
    corners = np.array([c + half * (a * e1 + b * e2) for a, b in
                        ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    return corners, np.array([[0, 1, 2], [0, 2, 3]])


def _forces(model, d, centre, half):
    """The force elements' pieces."""
    for name in model.forces:
        el = model.force_element(name)
        p = el.params
        if el.kind == "spring-damper":
            a, b = _at(model, el.frames[0], p["point_a"]), _at(model, el.frames[1], p["point_b"])
            if p["stiffness"] or p["preload"] or p["force_table"] is not None \
                    or p["law"] is not None:
                d.springs.append((name, a, b))
            if p["damping"] or p["damping_table"] is not None:
                d.dampers.append((name, a, b))
        elif el.kind in ("bushing", "bearing"):
            keys = ("point_a", "point_b") if el.kind == "bushing" else ("point", "center")
            for frame, key in zip(el.frames, keys):
                if frame != "ground":
                    d.tags.append((name, _at(model, frame, p[key]), MOUNT))
        elif el.kind == "contact":
            d.planes.append((name, *_plane(p["plane_point"], p["plane_normal"], centre, half)))
        elif el.kind in ("actuator", "joint-spring-damper"):
            j = model.joint(p["joint"])
            if j.kind in ("revolute", "prismatic"):
                radius = d.sizes["ring"] * (1.0 if el.kind == "actuator" else 0.7)
                colour = ACTUATOR if el.kind == "actuator" else SPRING
                d.polylines.append((colour, WIDTHS["ring"], _ring(
                    model.frame_index(j.child), np.zeros(3), j.axis, radius)))


def _loops(model, d):
    for name in model.loop_joints if getattr(model, "has_loops", False) else ():
        j = model.joint(name)
        if j.kind == "coupling":           # acts on coordinates: nothing to draw
            continue
        ends = [_at(model, j.parent, j.position), _at(model, j.child, j.child_position)]
        for mover, point in ends:
            d.polylines.append((LOOP, WIDTHS["loop"], [(mover, np.zeros(3)), (mover, point)]))
        if j.kind == "distance":
            d.polylines.append((LOOP, WIDTHS["loop"] + 0.5, ends))


def build(model, geometry, centre, half, primitives=()):
    """The ``Drawing`` of ``model`` for a scene of ``centre`` and half-width ``half``;
    ``primitives`` are the extra primitives of the first instant."""
    d = Drawing(sizes={k: v * half for k, v in SIZES.items()})
    for i, g in enumerate(geometry):
        for vertices, faces, colour in g["meshes"]:
            d.solids.append((i, vertices, faces, colour))
        for k in range(3):
            d.polylines.append((AXES[k], WIDTHS["axis"], [(i, np.zeros(3)),
                                                          (i, g["triad"] * np.eye(3)[k])]))
        if g["attached"]:
            d.polylines.append((LINK, WIDTHS["link"], [(g["parent"], np.zeros(3)),
                                                       (i, np.zeros(3))]))
        d.polylines.append((LINK, WIDTHS["link"], [(i, np.zeros(3)), (i, g["com"])]))
        if g["mass"] > 0:
            d.markers.append((g["name"], (i, g["com"]), g["color"], g["size"]))
    _loops(model, d)
    _forces(model, d, centre, half)
    for name, point, normal in ground_planes(model):
        d.planes.append((name, *_plane(point, normal, centre, half)))
    for k, (kind, _, size, *colour) in enumerate(primitives):
        d.solids.append((len(geometry) + k, *primitive_mesh(kind, (np.eye(3), np.zeros(3)),
                                                            size), *(colour or [PRIMITIVE])))
        d.primitives.append((kind, size))
    return d


def coil(a, b, radius, turns=8, per_turn=12):
    """A coil spring from ``a`` to ``b``: straight leads of a tenth at each end."""
    axis = b - a
    length = np.linalg.norm(axis)
    e1, e2 = frame_of(axis / length if length > 0 else np.array([0.0, 0.0, 1.0]))
    s = np.linspace(0.0, 1.0, turns * per_turn + 1)
    phase = 2 * np.pi * turns * s
    helix = (a + np.outer(0.1 + 0.8 * s, axis) + radius * (np.outer(np.cos(phase), e1)
                                                           + np.outer(np.sin(phase), e2)))
    return np.vstack([a, a + 0.1 * axis, helix, b - 0.1 * axis, b])


def damper(a, b):
    """A damper from ``a`` to ``b``: its cylinder (the first 55 %) and its piston rod (from
    40 % on: it enters the cylinder)."""
    return np.array([a, a + 0.55 * (b - a)]), np.array([a + 0.4 * (b - a), b])


def world(R, r, attachment):
    """The world position of an attachment, given every mover's ``R`` and ``r``."""
    mover, point = attachment
    return point if mover < 0 else r[mover] + R[mover] @ point

"""Triangle meshes of the drawing shapes, and the few other solids a picture needs.

A mesh is ``(vertices (n, 3), faces (m, 3) int)``; every face is ordered counter-clockwise
seen from outside, so ``(v1 - v0) x (v2 - v0)`` is its outward normal (the tests check this
on every shape).  Shapes are those of ``mbdyn.elements.bodies.make_shape`` (sphere, box,
cylinder, disk, rod), in body axes.  ``shade`` gives each face a Lambert shade for
matplotlib, which has no lighting of its own; the HTML view's viewer lights the meshes
(``view_gl.js``, ``view_2d.js``: the same headlight Lambert term and ambient).
``primitive_mesh`` builds the mesh of a ``(kind, pose, size)`` primitive in world axes: the
hook through which other elements (contact shapes) add solids to a picture.
"""
from __future__ import annotations

import numpy as np

#: segments around a cylinder, disk or rod; a sphere's meridians and parallels
ROUND = 24
SPHERE = (16, 10)


def frame_of(axis):
    """Two unit vectors ``e1, e2`` with ``e1 x e2 = axis`` (``axis`` a unit vector)."""
    a = np.asarray(axis, float)
    helper = np.eye(3)[np.argmin(np.abs(a))]
    e1 = np.cross(helper, a)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(a, e1)


def tube(p0, p1, radius, n=ROUND):
    """A closed cylinder from ``p0`` to ``p1``: two rims and the centres of its caps."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    axis = p1 - p0
    length = np.linalg.norm(axis)
    axis = axis / length if length > 0 else np.array([0.0, 0.0, 1.0])
    e1, e2 = frame_of(axis)
    s = 2 * np.pi * np.arange(n) / n
    ring = radius * (np.outer(np.cos(s), e1) + np.outer(np.sin(s), e2))
    vertices = np.vstack([p0 + ring, p1 + ring, p0, p1])
    faces = []
    for k in range(n):
        k1 = (k + 1) % n
        faces += [(k, k1, n + k1), (k, n + k1, n + k),          # the side
                  (2 * n, k1, k), (2 * n + 1, n + k, n + k1)]   # the caps
    return vertices, np.array(faces, dtype=np.int64)


def sphere(center, radius, n=SPHERE):
    """A UV sphere: ``n = (meridians, parallels)``."""
    m, p = n
    theta = np.pi * np.arange(1, p) / p                       # the parallels, poles apart
    phi = 2 * np.pi * np.arange(m) / m
    ring = np.stack([np.outer(np.sin(theta), np.cos(phi)), np.outer(np.sin(theta), np.sin(phi)),
                     np.outer(np.cos(theta), np.ones(m))], axis=-1).reshape(-1, 3)
    vertices = np.vstack([ring, [[0, 0, 1]], [[0, 0, -1]]]) * radius + np.asarray(center)
    top, bottom = len(ring), len(ring) + 1
    faces = []
    for j in range(m):
        j1 = (j + 1) % m
        faces.append((top, j, j1))
        faces.append((bottom, (p - 2) * m + j1, (p - 2) * m + j))
        for i in range(p - 2):
            a, b = i * m + j, i * m + j1
            faces += [(a, a + m, b + m), (a, b + m, b)]
    return vertices, np.array(faces, dtype=np.int64)


def box(center, size):
    """A box of edge lengths ``size`` along the axes."""
    half = 0.5 * np.asarray(size, float)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    vertices = corners * half + np.asarray(center)
    # corner index = 4 (x > 0) + 2 (y > 0) + (z > 0); each face two triangles, outward
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4),
             (1, 5, 7, 3)]
    faces = [(a, b, c) for a, b, c, d in quads] + [(a, c, d) for a, b, c, d in quads]
    return vertices, np.array(faces, dtype=np.int64)


def rod_radius(shape):
    """A rod's radius: its own, or 3 % of its length (at least a tenth of a millimetre)."""
    length = float(np.linalg.norm(np.asarray(shape["end"]) - np.asarray(shape["start"])))
    return float(shape.get("radius") or max(0.03 * length, 1e-4))


def shape_mesh(shape):
    """The mesh of a body's drawing shape in body axes (``None`` for a mesh file that
    cannot be read: ``viz.mesh_files`` warns once per file)."""
    c = np.asarray(shape.get("center", np.zeros(3)), float)
    if "rotation" in shape or shape["type"] == "mesh":
        mesh = _local_mesh(shape)
        if mesh is None:
            return None
        R = np.asarray(shape.get("rotation", np.eye(3)), float)
        return c + mesh[0] @ R.T, mesh[1]
    return _local_mesh(shape, c)


def _local_mesh(shape, c=None):
    """The mesh of ``shape`` centred on ``c`` (default the origin), before any rotation."""
    c = np.zeros(3) if c is None else c
    kind = shape["type"]
    if kind == "mesh":
        from .mesh_files import file_mesh
        mesh = file_mesh(shape["file"])
        if mesh is None:
            return None
        v, f = mesh
        scale = np.asarray(shape.get("scale", np.ones(3)), float)
        if np.prod(np.sign(scale)) < 0:           # a mirror: keep the faces outward
            f = f[:, ::-1]
        return v * scale, f
    if kind == "sphere":
        return sphere(c, shape["radius"])
    if kind == "box":
        return box(c, shape["size"])
    if kind == "rod":
        return tube(shape["start"], shape["end"], rod_radius(shape), 8)
    half = 0.5 * shape["length"] * np.asarray(shape["axis"], float)   # cylinder, disk
    return tube(c - half, c + half, shape["radius"])


def normals(vertices, faces):
    """Each face's unit normal (``(v1 - v0) x (v2 - v0)``, outward for these meshes)."""
    v = vertices[faces]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


def shade(rgb, vertices, faces, light, ambient=0.35):
    """Face colours ``(m, 3)``: ``rgb`` times ambient plus Lambert's diffuse term
    ``max(0, n . l)`` of each face's normal ``n`` and the light's direction ``l``."""
    light = np.asarray(light, float) / np.linalg.norm(light)
    lambert = np.clip(normals(vertices, faces) @ light, 0.0, 1.0)
    return np.clip(np.outer(ambient + (1 - ambient) * lambert, rgb), 0.0, 1.0)


#: the kinds a primitive may be, and the meaning of its ``size``
PRIMITIVES = {"sphere": "radius", "box": "edge lengths (3,)", "cylinder": "(radius, length)",
              "disk": "(radius, length)"}


def primitive_mesh(kind, pose, size):
    """The world mesh of a primitive: ``kind`` one of ``PRIMITIVES``, ``pose = (R, p)``
    (its axes and centre in the world; a cylinder's or disk's axis is its z), ``size`` as
    ``PRIMITIVES`` says."""
    R, p = (np.asarray(x, float) for x in pose)
    if kind == "sphere":
        v, f = sphere(np.zeros(3), float(np.ravel(size)[0]))
    elif kind == "box":
        v, f = box(np.zeros(3), size)
    elif kind in ("cylinder", "disk"):
        radius, length = size
        v, f = tube([0, 0, -0.5 * length], [0, 0, 0.5 * length], radius)
    else:
        raise ValueError(f"primitive kind {kind!r} is not one of {', '.join(PRIMITIVES)}")
    return p + v @ R.T, f

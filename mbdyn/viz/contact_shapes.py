"""Contact shapes (``System.add_shape``; docs/contact.md) in the pictures: light grey
wireframes of every shape a contact element of the model names -- a sphere's three great
circles, a box's edges, a capsule's or a cylinder's rims and generators (and a capsule's
end circles), a plane's square about its point with its normal, a cam's profile at both
ends of a short extrusion.
"""
from __future__ import annotations

import numpy as np

COLOUR = "#999999"


def _circle(centre, e1, e2, radius, n=32):
    s = np.linspace(0, 2 * np.pi, n + 1)
    return centre + radius * (np.outer(np.cos(s), e1) + np.outer(np.sin(s), e2))


def local_lines(shape, plane_size):
    """Polylines of a shape in its local axes (before its position and axes)."""
    ex, ey, ez = np.eye(3)
    o = np.zeros(3)
    a, b, c = shape.size
    if shape.kind == "sphere":
        return [_circle(o, u, v, a) for u, v in ((ex, ey), (ey, ez), (ez, ex))]
    if shape.kind == "box":
        corners = np.array([[sx * a, sy * b, sz * c] for sx in (-1, 1) for sy in (-1, 1)
                            for sz in (-1, 1)])
        edges = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4),
                 (1, 5), (2, 6), (3, 7)]
        return [corners[[i, j]] for i, j in edges]
    if shape.kind in ("capsule", "cylinder"):
        top, bottom = _circle(b * ez, ex, ey, a), _circle(-b * ez, ex, ey, a)
        out = [top, bottom] + [np.array([top[k], bottom[k]]) for k in range(0, 32, 8)]
        if shape.kind == "capsule":
            for end in (b, -b):
                out += [_circle(end * ez, ex, ez, a), _circle(end * ez, ey, ez, a)]
        return out
    if shape.kind == "plane":
        h = 0.5 * plane_size
        square = np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0], [-h, -h, 0]])
        return [square, np.array([o, 0.2 * h * ez])]
    from ..elements.contacts import cam_spline       # a cam: its profile, sampled
    knots, coefficients = cam_spline(*shape.profile)
    pts = []
    for k, cf in enumerate(coefficients):
        for s in np.linspace(0, knots[k + 1] - knots[k], 8, endpoint=False):
            phi, rad = knots[k] + s, np.polyval(cf, s)
            pts.append([rad * np.cos(phi), rad * np.sin(phi)])
    pts.append(pts[0])
    ring = np.column_stack([pts, np.zeros(len(pts))])
    depth = 0.1 * shape.bound
    return [ring + depth * ez, ring - depth * ez]


def contact_lines(model, kin):
    """``[(points, colour, width)]`` in world coordinates of the model's contact shapes
    at the kinematics ``kin``."""
    shapes = {}
    for el in getattr(model, "_force_elements", ()):
        if el.kind == "shape-contact":
            for s in el.params["shapes"]:
                shapes.setdefault(s.name, s)
    if not shapes:
        return []
    plane_size = 4 * max([s.bound for s in shapes.values()] + [0.05])
    out = []
    for s in shapes.values():
        if s.body == "ground":
            R, r = np.eye(3), np.zeros(3)
        else:
            i = model.frame_index(s.body)
            R, r = kin.R[i], kin.r[i]
        for pts in local_lines(s, plane_size):
            body = s.position + pts @ np.asarray(s.axes).T
            out.append((r + body @ R.T, COLOUR, 1.0))
    return out

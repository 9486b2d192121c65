"""Contact shapes (``System.add_shape``; docs/contact.md) in the pictures, as the extra
primitives of ``viz.drawing`` (shaded solids posed at each instant): a sphere, a box, a
cylinder, a capsule (a cylinder and its two end spheres); a plane on the ground is a
translucent ground plane of the scene (``ground_planes``); a plane on a body (a follower's
face) and a cam are drawn by their body's own drawing shape (an unbounded plane has no
size of its own to draw).
"""
from __future__ import annotations

import numpy as np

def _shapes(model):
    shapes = {}
    for el in getattr(model, "_force_elements", ()):
        if el.kind == "shape-contact":
            for s in el.params["shapes"]:
                shapes.setdefault(s.name, s)
    return list(shapes.values())


def _local(shape):
    """``[(kind, R (local axes), centre (local), size)]`` of one shape."""
    a, b, c = shape.size
    eye = np.eye(3)
    if shape.kind == "sphere":
        return [("sphere", eye, np.zeros(3), a)]
    if shape.kind == "box":
        return [("box", eye, np.zeros(3), (2 * a, 2 * b, 2 * c))]
    if shape.kind == "cylinder":
        return [("cylinder", eye, np.zeros(3), (a, 2 * b))]
    if shape.kind == "capsule":
        return [("cylinder", eye, np.zeros(3), (a, 2 * b)),
                ("sphere", eye, np.array([0, 0, b]), a), ("sphere", eye, np.array([0, 0, -b]), a)]
    return []               # a plane, a cam: a ground plane, or their body's drawing


def contact_primitives(model, kin):
    """``[(kind, (R, p), size)]`` in world axes of the model's contact shapes at the
    kinematics ``kin`` (``viz.drawing.extra_primitives``): the same list at every
    instant, poses changing."""
    shapes = _shapes(model)
    if not shapes:
        return []
    out = []
    for s in shapes:
        if s.body == "ground":
            R, r = np.eye(3), np.zeros(3)
        else:
            i = model.frame_index(s.body)
            R, r = kin.R[i], kin.r[i]
        axes = R @ np.asarray(s.axes)             # the shape's local axes in the world
        origin = r + R @ np.asarray(s.position)
        for kind, Rl, centre, size in _local(s):
            out.append((kind, (axes @ Rl, origin + axes @ centre), size))
    return out


def ground_planes(model):
    """``[(name, point, normal)]`` (world) of the contact shapes that are planes of the
    ground."""
    out = []
    for s in _shapes(model):
        if s.kind == "plane" and s.body == "ground":
            out.append((s.name, np.asarray(s.position, float), np.asarray(s.axes)[:, 2]))
    return out

"""Flexible bodies in the pictures: the deformed shape, scaled so that it shows.

A flexible body's elastic deflection at node ``i`` is ``Phi_i eta`` (body axes; the
reduced body's mode shapes at its nodes times the modal coordinates).  A beam is drawn
as a chain of cylinders between its nodes at ``x_i + s Phi_i eta``, posed at each
instant from the body frame's motion, as extra primitives of ``viz.drawing`` (the HTML
view and the GIF/MP4 draw them as every other shaded solid); a body from reduced data
(nodes in no particular order) as a small sphere at each node.  Deflections are small
against the body; the scale ``s`` makes the largest of the run ``DRAWN`` of the body's
length (never less than the true size: ``s >= 1``), rounded down to 1, 2 or 5 times a
power of ten, and the picture's title says it (``caption``).
"""
from __future__ import annotations

import numpy as np

#: the largest deflection drawn, as a fraction of the body's length
DRAWN = 0.1
#: a segment's radius, as a fraction of the body's length
RADIUS = 0.012
#: the deformed bodies' colour (their rigid drawing shapes are left out)
COLOUR = "#3a7ca5"


def _bodies(model):
    """``[(record, indices)]`` of the model's flexible bodies whose flexibility is on:
    the record and its modal coordinates' indices in the model's ``q``."""
    packs = {p.name for p in getattr(model, "_flex", ())}
    return [(model.flexible[name], [model.coordinate_index(c)
                                    for c in model.flexible[name].coordinates])
            for name in getattr(model, "flexible_bodies", ()) if name in packs]


def _length(nodes):
    return max(float(np.linalg.norm(nodes.max(axis=0) - nodes.min(axis=0))), 1e-9)


def deflections(record, indices, q):
    """Every node's elastic deflection ``Phi_i eta`` (N x 3, body axes) at the state ``q``
    (``indices``: the body's modal coordinates in ``q``)."""
    return record.reduced.modes[:, :3, :] @ np.asarray(q, float)[indices]


def deflection_scale(model, states):
    """The factor the pictures draw deflections with, over the states ``states`` (rows
    of ``q``): 1.0 without flexible bodies or deflection."""
    largest, length = 0.0, np.inf
    for rec, indices in _bodies(model):
        length = min(length, _length(rec.reduced.nodes))
        for q in states:
            largest = max(largest, float(np.abs(deflections(rec, indices, q)).max(initial=0.0)))
    if not largest > 0.0 or not np.isfinite(length):
        return 1.0
    wanted = DRAWN * length / largest
    if wanted <= 1.0:
        return 1.0
    power = 10.0 ** np.floor(np.log10(wanted))
    return float(max(m for m in (1.0, 2.0, 5.0) if m * power <= wanted) * power)


def caption(scale):
    """What a title adds for deflections drawn ``scale`` times their size."""
    return f"  (flexible deflections x{scale:g})" if scale != 1.0 else ""


def _segment_axes(e, hint):
    """Axes ``(3, 3)`` whose third column is the unit vector ``e`` (a cylinder's axis),
    the first perpendicular to ``e`` and to ``hint`` where it can be."""
    x = np.cross(hint, e)
    if np.linalg.norm(x) < 1e-6:
        x = np.cross([0.0, 0.0, 1.0] if abs(e[2]) < 0.9 else [1.0, 0.0, 0.0], e)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(e, x), e])


def flexible_primitives(model, kin, q, scale=1.0):
    """``[(kind, (R, p), size, colour)]`` in world axes of the flexible bodies at the state ``q``
    (kinematics ``kin``), deflections drawn ``scale`` times: the same kinds and sizes
    at every instant (``viz.drawing.extra_primitives``)."""
    out = []
    if q is None:
        return out
    for rec, indices in _bodies(model):
        nodes = rec.reduced.nodes.astype(float)
        i = model.frame_index(rec.name)
        R, r = kin.R[i], kin.r[i]
        world = r + (nodes + scale * deflections(rec, indices, q)) @ R.T
        radius = RADIUS * _length(nodes)
        if "beam" not in rec.spec:
            out += [("sphere", (np.eye(3), p), 2.0 * radius, COLOUR) for p in world]
            continue
        for k in range(len(nodes) - 1):
            a, b = world[k], world[k + 1]
            e = (b - a) / max(np.linalg.norm(b - a), 1e-300)
            rest = float(np.linalg.norm(nodes[k + 1] - nodes[k]))
            out.append(("cylinder", (_segment_axes(e, R[:, 1]), 0.5 * (a + b)),
                        (radius, rest), COLOUR))
    return out

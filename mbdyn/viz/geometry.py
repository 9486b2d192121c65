"""What a picture of a model shows at one instant: polylines, markers and labels in world
coordinates, from the bodies' shapes, or from what the model knows when a body has none.

Every body with mass is drawn as a sphere at its centre of mass, sized by its mass
(relative to the heaviest body), and every joint as a line from the parent frame's origin
to the child frame's origin and on to the child's centre of mass -- so every model draws
without edits.  Each frame's axes are drawn at its origin (x red, y green, z blue).
Shapes (``mbdyn.elements.bodies.make_shape``) are drawn as wireframes: a box by its
edges, a cylinder or disk by its two rims and four lines, a sphere by three great circles,
a rod as a thick line.  The joints that close loops are drawn in red, from each body's
origin to the joint's point on it (``loop_lines``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .contact_shapes import contact_lines

#: colours of a frame's x, y, z axes (red, green, blue)
AXES = ("#e41a1c", "#4daf4a", "#377eb8")
PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf")


@dataclass
class Scene3D:
    """One instant: ``lines`` ``[(points (k, 3), colour, width)]``, ``markers``
    ``[(name, position (3,), colour, size)]`` (one per body with mass: its centre of mass),
    ``trails`` ``{name: points (m, 3)}``."""
    t: float
    lines: list
    markers: list
    trails: dict


def _circle(center, axis, radius, n=24):
    a = np.asarray(axis, float)
    helper = np.eye(3)[np.argmin(np.abs(a))]
    e1 = np.cross(a, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    s = np.linspace(0, 2 * np.pi, n + 1)
    return center + radius * (np.outer(np.cos(s), e1) + np.outer(np.sin(s), e2))


def shape_lines(shape, R, r):
    """World polylines of a shape on a frame at ``r`` with rotation ``R``."""
    to_world = lambda p: r + np.asarray(p) @ R.T  # noqa: E731
    kind = shape["type"]
    c = shape.get("center", np.zeros(3))
    if kind == "rod":
        return [to_world(np.array([shape["start"], shape["end"]]))]
    if kind == "sphere":
        rad = shape["radius"]
        return [to_world(_circle(c, ax, rad)) for ax in np.eye(3)]
    if kind == "box":
        a, b, h = 0.5 * shape["size"]
        corners = np.array([[sx * a, sy * b, sz * h] for sx in (-1, 1) for sy in (-1, 1)
                            for sz in (-1, 1)]) + c
        edges = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4),
                 (1, 5), (2, 6), (3, 7)]
        return [to_world(corners[[i, j]]) for i, j in edges]
    # cylinder or disk: two rims and four generators
    axis = shape["axis"]
    half = 0.5 * shape["length"] * axis
    top = _circle(c + half, axis, shape["radius"], 32)
    bottom = _circle(c - half, axis, shape["radius"], 32)
    out = [to_world(top), to_world(bottom)]
    for k in range(0, 32, 8):
        out.append(to_world(np.array([top[k], bottom[k]])))
    return out


def model_geometry(model):
    """Static facts for drawing: per frame its shape (or None), colour, marker size, the
    parent index and the joint position."""
    bodies, joints, _ = model.elements
    lengths = [np.linalg.norm(b.com) for b in bodies] + [np.linalg.norm(j.position)
                                                          for j in joints]
    triad = 0.25 * max(max(lengths, default=0.0), 1e-3)
    masses = np.array([b.mass for b in bodies])
    biggest = masses.max() if masses.size and masses.max() > 0 else 1.0
    out = []
    for i, (b, j) in enumerate(zip(bodies, joints)):
        colour = (b.shape or {}).get("color") or PALETTE[i % len(PALETTE)]
        size = 6 + 10 * np.cbrt(b.mass / biggest) if b.mass > 0 else 0
        out.append({"name": b.name, "shape": b.shape, "color": colour, "size": float(size),
                    "com": b.com, "parent": int(model._parent[i]), "mass": b.mass,
                    "attached": j.kind != "free", "triad": triad})
    return out


def instant(model, geometry, q, u, t):
    """The ``Scene3D`` of the state ``(q, u)`` at ``t`` (trails left empty)."""
    kin = model.kinematics(q, u, t=t)
    lines, markers = [], []
    for i, g in enumerate(geometry):
        R, r = kin.R[i], kin.r[i]
        p = g["parent"]
        parent_origin = kin.r[p] if p >= 0 else np.zeros(3)
        if g["shape"] is not None:
            for pts in shape_lines(g["shape"], R, r):
                lines.append((pts, g["color"], 2.0 if g["shape"]["type"] != "rod" else 4.0))
        # the frame's axes (x red, y green, z blue) at its origin
        for k in range(3):
            lines.append((np.array([r, r + g["triad"] * R[:, k]]), AXES[k], 1.0))
        # the links: parent origin -> joint (this origin) -> centre of mass (a free joint
        # attaches nothing: no line to its parent)
        if g["attached"]:
            lines.append((np.array([parent_origin, r]), "#444444", 1.5))
        lines.append((np.array([r, kin.r_com[i]]), "#444444", 1.5))
        if g["mass"] > 0:
            markers.append((g["name"], kin.r_com[i].copy(), g["color"], g["size"]))
    if getattr(model, "has_loops", False):
        lines.extend(loop_lines(model, kin))
    lines.extend(contact_lines(model, kin))
    return Scene3D(float(t), lines, markers, {})


#: colour of the loop joints' links (the joints that close a loop)
LOOP_COLOUR = "#d62728"


def loop_lines(model, kin):
    """Each loop joint drawn in red: a line from each body's frame origin to the joint's
    point on it, and a distance constraint's rod between its two points (a coupling acts
    on coordinates and is not drawn)."""
    out = []
    for name in model.loop_joints:
        j = model.joint(name)
        if j.kind == "coupling":
            continue
        points = []
        for frame, s in ((j.parent, j.position), (j.child, j.child_position)):
            if frame == "ground":
                origin, point = np.zeros(3), np.asarray(s, float)
            else:
                i = model.frame_index(frame)
                origin, point = kin.r[i], kin.r[i] + kin.R[i] @ s
            out.append((np.array([origin, point]), LOOP_COLOUR, 2.5))
            points.append(point)
        if j.kind == "distance":
            out.append((np.array(points), LOOP_COLOUR, 3.0))
    return out


def sample_times(result, fps=30.0, speed=1.0, max_frames=None):
    """Frame times: real time (times ``speed``) at ``fps`` frames per second over the run;
    at most ``max_frames`` of them (the message gives the speed that fits)."""
    for name, value in (("speed", speed), ("fps", fps)):
        if not isinstance(value, (int, float, np.number)) or not 0 < value < np.inf:
            raise ModelError(f"{name} (--{name}) must be a positive, finite number, got "
                             f"{value!r}")
    t0, t1 = float(result.t[0]), float(result.t[-1])
    span = (t1 - t0) / speed * fps              # inf for a speed near the smallest float
    if max_frames is not None and not span + 1 <= max_frames:
        fitting = (t1 - t0) * fps / max(max_frames - 1, 1)
        need = f"{span + 1:.3g}" if np.isfinite(span) else "more than 1e308"
        raise ModelError(f"speed {speed:g} (--speed) at {fps:.3g} frames per second (--fps) "
                         f"would need {need} frames for the {t1 - t0:g} s of the run, more "
                         f"than {max_frames}; raise the speed to at least {fitting:.3g} or "
                         "lower the fps")
    n = int(np.floor(span + 1e-9)) + 1
    return t0 + np.arange(n) * speed / fps if n > 1 else np.array([t0])


def state_at(result, t):
    """The state at ``t`` by linear interpolation of the stored samples (quaternions
    renormalised): enough for a picture."""
    k = int(np.clip(np.searchsorted(result.t, t), 1, len(result.t) - 1)) if len(result.t) > 1 \
        else 0
    if len(result.t) == 1:
        return result.q[0].copy(), result.u[0].copy()
    t0, t1 = result.t[k - 1], result.t[k]
    w = 0.0 if t1 == t0 else (t - t0) / (t1 - t0)
    w = min(max(w, 0.0), 1.0)
    q = (1 - w) * result.q[k - 1] + w * result.q[k]
    u = (1 - w) * result.u[k - 1] + w * result.u[k]
    result.model.normalize_quaternions(q)
    return q, u


def frames(result, times, trail=90):
    """``Scene3D`` of every time in ``times``, with the trails of the centres of mass and of
    the run's output points (``[outputs.points]``) over the
    last ``trail`` frames (3 s of real-time playback: keeps an HTML view's size linear in
    its length)."""
    model = result.model
    geometry = model_geometry(model)
    out = []
    trail_points, trail_length = {}, int(trail)
    outputs = result.points or {}
    for t in times:
        q, u = state_at(result, t)
        sc = instant(model, geometry, q, u, t)
        for name, pos, _, _ in sc.markers:
            trail_points.setdefault(name, []).append(pos)
        for name, arr in outputs.items():        # the run's output points leave trails too
            pos = np.array([np.interp(t, result.t, arr[:, k]) for k in range(3)])
            trail_points.setdefault("point " + name, []).append(pos)
        sc.trails = {k: np.array(v[-trail_length:]) for k, v in trail_points.items()}
        out.append(sc)
    return out


def bounds(scenes):
    """A cube that holds every line and marker of the scenes: ``(centre, half-width)``."""
    pts = [pts for sc in scenes for pts, _, _ in sc.lines]
    pts += [pos[None, :] for sc in scenes for _, pos, _, _ in sc.markers]
    allp = np.vstack(pts) if pts else np.zeros((1, 3))
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    centre = 0.5 * (lo + hi)
    half = max(0.5 * float((hi - lo).max()), 1e-3) * 1.1
    return centre, half


def up_rotation(model):
    """A rotation whose third row is "up" (against gravity; z if there is none)."""
    g = np.asarray(model.gravity, float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.eye(3)[np.argmin(np.abs(up))]
    e1 = np.cross(helper, up)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(up, e1)
    return np.array([e1, e2, up])

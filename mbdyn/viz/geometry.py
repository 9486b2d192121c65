"""What a picture of a model shows at each instant, in world coordinates.

Every body with mass gets a marker at its centre of mass, sized by its mass (relative to
the heaviest body), and every joint a line from the parent frame's origin to the child
frame's origin and on to the child's centre of mass -- so every model draws without edits.
Each frame's axes are drawn at its origin (x red, y green, z blue).  Shapes
(``mbdyn.elements.bodies.make_shape``) are shaded solids (``viz.meshes``); force elements,
actuators, loop joints and ground planes as ``viz.drawing`` describes.  ``prepare`` poses
every frame at the picture's instants once; ``frames`` realises them as ``Scene3D``s
(matplotlib), ``viz.view_data`` sends the poses to the HTML view.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..elements.bodies import shapes_of
from ..errors import ModelError
from . import drawing as dr
from .flexible_shapes import caption, deflection_scale
from .meshes import shape_mesh

PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf")


@dataclass
class Scene3D:
    """One instant in world axes: ``lines`` ``[(points (k, 3), colour, width)]``,
    ``markers`` ``[(name, position (3,), colour, size)]`` (one per body with mass: its
    centre of mass), ``trails`` ``{name: points (m, 3)}``, ``solids`` ``[(vertices,
    faces, colour)]``, ``tags`` ``[(name, position, colour)]`` (bushings, bearings),
    ``planes`` ``[(name, vertices, faces)]`` and the scene's ``extent`` (centre,
    half-width) over the whole run."""
    t: float
    lines: list
    markers: list
    trails: dict
    solids: list = field(default_factory=list)
    tags: list = field(default_factory=list)
    planes: list = field(default_factory=list)
    extent: tuple = None
    caption: str = ""


def model_geometry(model):
    """Static facts for drawing: per frame its shape(s) (or None) and their ``meshes``
    ``[(vertices, faces, colour)]`` in body axes (a mesh file that cannot be read left
    out), colour, marker size, the parent index and the joint position."""
    bodies, joints, _ = model.elements
    lengths = [np.linalg.norm(b.com) for b in bodies] + [np.linalg.norm(j.position)
                                                          for j in joints]
    triad = 0.25 * max(max(lengths, default=0.0), 1e-3)
    masses = np.array([b.mass for b in bodies])
    biggest = masses.max() if masses.size and masses.max() > 0 else 1.0
    out = []
    flexible = set(getattr(model, "flexible_bodies", ()))
    for i, (b, j) in enumerate(zip(bodies, joints)):
        shapes = shapes_of(b)
        own = PALETTE[i % len(PALETTE)]
        colour = next((s["color"] for s in shapes if s.get("color")), None) or own
        size = 6 + 10 * np.cbrt(b.mass / biggest) if b.mass > 0 else 0
        meshes = [(*m, s.get("color") or own) for s in shapes
                  for m in [shape_mesh(s)] if m is not None
                  and b.name not in flexible]        # drawn deformed (viz.flexible_shapes)
        out.append({"name": b.name, "shape": b.shape, "color": colour, "size": float(size),
                    "com": np.asarray(b.com, float), "parent": int(model._parent[i]),
                    "mass": b.mass, "attached": j.kind != "free", "triad": triad,
                    "meshes": meshes})
    return out


@dataclass
class PosedRun:
    """A run posed for pictures: ``poses`` ``[(t, R (m, 3, 3), r (m, 3))]`` of every
    mover (the frames, then the extra primitives), the ``drawing``, the scene's ``centre``
    and ``half``-width, the output points' positions ``points`` ``{name: (n, 3)}`` and,
    when asked, the contact forces as ``arrows``: per pose an array ``(k, 2, 3)`` of
    segments from each touching point along its force (``Model.contact_forces``); ``box``
    the corners ``(lo, hi)`` of the box the mechanism fills over the run (its pieces and
    the output points; the ground planes left out); ``deflection_scale``: the factor
    the flexible bodies' deflections are drawn with (``viz.flexible_shapes``)."""
    model: object
    geometry: list
    drawing: dr.Drawing
    poses: list
    centre: np.ndarray
    half: float
    points: dict
    arrows: list = field(default_factory=list)
    box: tuple = None
    deflection_scale: float = 1.0


def _posed(model, kin, q=None, scale=1.0):
    prims = dr.extra_primitives(model, kin, q, scale)
    R = np.concatenate([kin.R, np.array([p[1][0] for p in prims]).reshape(-1, 3, 3)])
    r = np.concatenate([kin.r, np.array([p[1][1] for p in prims]).reshape(-1, 3)])
    return R, r, prims


def _box(d, poses, extra):
    """``(lo, hi)``: the corners of the box (along the world axes) that holds every piece
    at every pose, and the points ``extra``."""
    pts = [extra.reshape(-1, 3)]
    for _, R, r in poses:
        pts += [r[m] + v @ R[m].T for m, v, _, _ in d.solids]
        pts.append(np.array([dr.world(R, r, a) for _, _, ps in d.polylines for a in ps]
                            + [dr.world(R, r, a) for _, a, b in d.springs + d.dampers
                               for a in (a, b)]).reshape(-1, 3))
    allp = np.vstack(pts)
    if not len(allp):
        allp = np.zeros((1, 3))
    return allp.min(axis=0), allp.max(axis=0)


def _extent(d, poses, extra):
    """``(centre, half-width)`` of a cube holding every piece at every pose."""
    lo, hi = _box(d, poses, extra)
    return 0.5 * (lo + hi), max(0.5 * float((hi - lo).max()), 1e-3) * 1.1


def prepare(result, times, contact_forces=False):
    """Pose ``result`` at ``times``: a ``PosedRun`` (with the contact forces' arrows when
    ``contact_forces``)."""
    model = result.model
    geometry = model_geometry(model)
    poses, first, forces = [], None, []
    states = [state_at(result, t) for t in times]
    scale = deflection_scale(model, result.q)           # the whole run's: one per run
    for t, (q, u) in zip(times, states):
        R, r, prims = _posed(model, model.kinematics(q, u, t=t), q, scale)
        first = prims if first is None else first
        poses.append((float(t), R, r))
        if contact_forces:
            forces.append(model.contact_forces(q, u, t))
    points = {name: np.array([[np.interp(t, result.t, arr[:, k]) for k in range(3)]
                              for t in times]) for name, arr in (result.points or {}).items()}
    extra = np.vstack(list(points.values())) if points else np.zeros((0, 3))
    centre, half = _extent(dr.build(model, geometry, np.zeros(3), 1.0, first), poses, extra)
    d = dr.build(model, geometry, centre, half, first)
    for name, corners, _ in d.planes:         # a plane far from the motion stays in view
        centre, half = _extent(d, [], np.vstack([extra, corners.mean(axis=0)[None],
                                                 centre + half / 1.1, centre - half / 1.1]))
    return PosedRun(model, geometry, d, poses, centre, half, points, arrows(forces, half),
                    _box(d, poses, extra), scale)


#: the longest contact-force arrow, in the scene's half-width
ARROW = 0.35


def arrows(forces, half):
    """Segments ``(k, 2, 3)`` per pose from each point along its force, the largest force
    of the run drawn ``ARROW`` half-widths long."""
    peak = max([np.linalg.norm(f[:, 3:], axis=1).max() for f in forces if len(f)] + [0.0])
    scale = ARROW * half / peak if peak > 0 else 0.0
    return [np.stack([f[:, :3], f[:, :3] + scale * f[:, 3:]], axis=1) for f in forces]


def realise(d, t, R, r, arrows=()):
    """The ``Scene3D`` of drawing ``d`` with the movers at ``R``, ``r`` and the contact
    forces' ``arrows`` (segments; no trails)."""
    lines = [(np.array([dr.world(R, r, a) for a in pts]), colour, width)
             for colour, width, pts in d.polylines]
    lines += [(seg, dr.FORCE, 2.5) for seg in arrows]
    for _, a, b in d.springs:
        lines.append((dr.coil(dr.world(R, r, a), dr.world(R, r, b), d.sizes["coil"]),
                      dr.SPRING, 1.5))
    for _, a, b in d.dampers:
        body, rod = dr.damper(dr.world(R, r, a), dr.world(R, r, b))
        lines += [(body, dr.DAMPER, 7.0), (rod, dr.DAMPER, 2.5)]
    solids = [(r[m] + v @ R[m].T, f, colour) for m, v, f, colour in d.solids]
    markers = [(name, dr.world(R, r, a), colour, size) for name, a, colour, size in d.markers]
    tags = [(name, dr.world(R, r, a), colour) for name, a, colour in d.tags]
    return Scene3D(float(t), lines, markers, {}, solids, tags, list(d.planes))


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


def frames(result, times, trail=90, contact_forces=False):
    """``Scene3D`` of every time in ``times``, with the trails of the centres of mass and of
    the run's output points (``[outputs.points]``) over the last ``trail`` frames, and the
    contact forces as arrows when asked."""
    run = prepare(result, times, contact_forces)
    out, trail_points = [], {}
    for k, (t, R, r) in enumerate(run.poses):
        sc = realise(run.drawing, t, R, r, run.arrows[k] if run.arrows else ())
        sc.extent = (run.centre, run.half)
        sc.caption = caption(run.deflection_scale)
        for name, pos, _, _ in sc.markers:
            trail_points.setdefault(name, []).append(pos)
        for name, arr in run.points.items():     # the run's output points leave trails too
            trail_points.setdefault("point " + name, []).append(arr[k])
        sc.trails = {n: np.array(v[-int(trail):]) for n, v in trail_points.items()}
        out.append(sc)
    return out


def bounds(scenes):
    """The cube that holds the scenes: ``(centre, half-width)``."""
    if scenes and scenes[0].extent is not None:
        return scenes[0].extent
    pts = [pts for sc in scenes for pts, _, _ in sc.lines]
    pts += [pos[None, :] for sc in scenes for _, pos, _, _ in sc.markers]
    allp = np.vstack(pts) if pts else np.zeros((1, 3))
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    return 0.5 * (lo + hi), max(0.5 * float((hi - lo).max()), 1e-3) * 1.1


def up_rotation(model):
    """A rotation whose third row is "up" (against gravity; z if there is none)."""
    g = np.asarray(model.gravity, float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.eye(3)[np.argmin(np.abs(up))]
    e1 = np.cross(helper, up)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(up, e1)
    return np.array([e1, e2, up])

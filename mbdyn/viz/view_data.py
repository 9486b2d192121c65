"""The data of the HTML view: each solid's mesh once, and per frame only every mover's pose.

Numbers are sent as integers in the units a screen can show: lengths in ``unit`` (a power
of ten at most 1e-4 of the scene's half-width), quaternions in 1e-4 (a rotation to 2e-4
rad); a 1000-pixel view shows 2e-3 of the half-width per pixel, so nothing drawn moves by
a tenth of a pixel.  Frames are those of the animation (``fps`` of playback: the display
rate), times in milliseconds.  The page's script (``view.js``) rebuilds every line, coil and
solid from these (``viz.drawing`` describes them) and fits its camera to ``box`` (the
mechanism over the run), the world axes and the contact forces.  Texts a user named
(``title``, ``names``, the mounts' ``label``) are sent as typed: the page shows them
through ``textContent`` only, and the whole is written into it through
``escape.script_json``.
"""
from __future__ import annotations

import numpy as np

from . import drawing as dr
from .flexible_shapes import caption
from .geometry import up_rotation


def quaternions(R):
    """Unit quaternions ``(w, x, y, z)`` of rotation matrices ``(m, 3, 3)`` (Shepperd)."""
    R = np.asarray(R, float).reshape(-1, 3, 3)
    out = np.empty((len(R), 4))
    for k, m in enumerate(R):
        tr = np.trace(m)
        i = int(np.argmax([tr, m[0, 0], m[1, 1], m[2, 2]]))
        if i == 0:
            s = 2 * np.sqrt(1 + tr)
            q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s,
                 (m[1, 0] - m[0, 1]) / s]
        else:
            a, b, c = i - 1, i % 3, (i + 1) % 3
            s = 2 * np.sqrt(1 + m[a, a] - m[b, b] - m[c, c])
            q = [0.0] * 4
            q[0] = (m[c, b] - m[b, c]) / s
            q[1 + a], q[1 + b], q[1 + c] = 0.25 * s, (m[a, b] + m[b, a]) / s, \
                (m[a, c] + m[c, a]) / s
        out[k] = q
    return out * np.where(out[:, :1] < 0, -1.0, 1.0)


def _ints(x, unit):
    return np.rint(np.asarray(x, float) / unit).astype(np.int64).ravel().tolist()


def _at(a, unit):
    return [int(a[0])] + _ints(a[1], unit)


def eye_direction(up):
    """The camera's direction from the scene's centre (world axes): off the vertical plane
    that planar models move in -- from z when "up" is not z (a model in the x-y plane,
    gravity along -y) -- else from a corner."""
    if abs(up[2]) > 0.9:
        eye = np.array([1.4, -1.4, 0.9])
    else:
        eye = 1.7 * np.array([0.0, 0.0, 1.0]) + 0.5 * up + np.array([0.5, 0.0, 0.0])
    return eye / np.linalg.norm(eye)


def world_axes(centre, half, box):
    """The world axes drawn in the view: at the origin when it lies in the scene's cube,
    else at the low corner of ``box``; as long as the largest 1, 2 or 5 times a power of
    ten up to half the half-width."""
    origin = np.zeros(3) if np.all(np.abs(centre) <= half) else np.asarray(box[0], float)
    top = 0.5 * half
    power = 10.0 ** np.floor(np.log10(top))
    length = max(m * power for m in (1, 2, 5) if m * power <= top * (1 + 1e-9))
    return origin, float(length)


def view_data(run, title, speed, fps, trail):
    """The JSON-ready dict of a ``geometry.PosedRun``."""
    d, half = run.drawing, run.half
    unit = 10.0 ** -max(0, int(np.ceil(-np.log10(half))) + 4)
    poses = []
    for _, R, r in run.poses:
        poses += np.column_stack([np.rint(r / unit), np.rint(quaternions(R) * 1e4)]) \
            .astype(np.int64).ravel().tolist()
    markers = d.markers
    basis = up_rotation(run.model)
    origin, length = world_axes(run.centre, half, run.box)
    groups = {}
    for colour, width, pts in d.polylines:
        groups.setdefault((colour, width), []).append([_at(a, unit) for a in pts])
    return {
        "unit": unit, "movers": len(run.poses[0][1]), "fps": fps, "trail": int(trail),
        "times": [int(round(t * 1000)) for t, _, _ in run.poses], "poses": poses,
        "title": (str(title) + caption(run.deflection_scale)
                  + (f"  ({speed:g}x)" if speed != 1 else "")),
        "names": [n for n, _, _, _ in markers],
        "markers": [{"at": _at(a, unit), "color": c, "size": round(max(s * 0.6, 3), 1)}
                    for _, a, c, s in markers],
        "solids": [{"mover": m, "v": _ints(v, unit), "f": f.ravel().tolist(), "color": c}
                   for m, v, f, c in d.solids],
        "planes": [{"v": _ints(v, unit), "f": f.ravel().tolist(), "color": dr.PLANE}
                   for _, v, f in d.planes],
        "groups": [{"color": c, "width": w, "lines": lines}
                   for (c, w), lines in groups.items()],
        "springs": [[_at(a, unit), _at(b, unit)] for _, a, b in d.springs],
        "dampers": [[_at(a, unit), _at(b, unit)] for _, a, b in d.dampers],
        "tags": [{"at": _at(a, unit), "color": c, "label": n} for n, a, c in d.tags],
        "points": [_ints(arr, unit) for arr in run.points.values()],
        "arrows": [_ints(a, unit) for a in run.arrows],
        "sizes": {k: round(v / unit) for k, v in d.sizes.items()},
        "colors": {"spring": dr.SPRING, "damper": dr.DAMPER, "trail": "#aaaaaa",
                   "force": dr.FORCE},
        "box": [_ints(corner, unit) for corner in run.box],
        "basis": basis.tolist(), "eye": eye_direction(basis[2]).tolist(),
        "axes": {"origin": _ints(origin, unit), "length": round(length / unit),
                 "caption": f"{length:g} m", "colors": list(dr.AXES)},
    }

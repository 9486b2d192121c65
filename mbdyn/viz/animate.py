"""Animations of a run to a file: GIF (matplotlib and Pillow), MP4 (an ffmpeg that the
optional extra ``imageio-ffmpeg`` ships), or a self-contained HTML page (``viz.html``).

Playback is real time by default (``speed`` > 1 plays faster); frames are sampled at
``fps`` per second of playback from the stored results (states interpolated between
samples).  Bodies are drawn as shaded solids of their shapes, with the force elements,
actuators and ground planes (``viz.geometry``, ``viz.drawing``); centres of mass leave
trails, the time is shown.  The axes are the world's (x, y, z in metres, one scale), seen
with the world axis nearest to "up" (against gravity) drawn upwards.
"""
from __future__ import annotations

import numpy as np

from .. import files
from ..errors import ModelError
from ..escape import mathtext
from .drawing import PLANE
from .geometry import bounds, frames, prepare, sample_times, up_rotation
from .meshes import shade

FORMATS = (".gif", ".mp4", ".html")
MAX_FRAMES = 3000


def check_output(path):
    """The extension of a writable animation path; clear errors otherwise."""
    from .plots import _check_path
    ext = _check_path(path, FORMATS, "animation")
    if ext == ".mp4":
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            raise ModelError("MP4 needs the ffmpeg of the optional extra: pip install "
                             "\"mbdyn[video]\" (imageio-ffmpeg); or write a .gif or .html") \
                from None
    return ext


def animate(result, out, speed=1.0, fps=30.0, title=None, max_frames=MAX_FRAMES,
            contact_forces=False):
    """Write an animation of ``result`` to ``out`` (.gif, .mp4 or .html); returns the
    number of frames.  ``contact_forces``: draw each contact's force as an arrow from its
    touching point.  The file is written whole or not at all."""
    ext = check_output(out)
    for name, value in (("speed", speed), ("fps", fps)):
        if (isinstance(value, bool) or not isinstance(value, (int, float, np.number))
                or not (value > 0 and np.isfinite(value))):
            raise ModelError(f"{name} must be a positive number, got {value!r}")
    if ext == ".gif":
        # a GIF stores frame durations in whole centiseconds: make them exact
        fps = 100.0 / max(1, round(100.0 / fps))
    times = sample_times(result, fps, speed, max_frames)
    title = title or result.model.name
    with files.replacing(out) as tmp:     # a link at ``out`` is replaced, not followed
        if ext == ".html":
            from .html import write_html
            write_html(prepare(result, times, contact_forces), tmp, fps=fps, speed=speed,
                       title=title)
        else:
            _write_movie(result.model, frames(result, times, contact_forces=contact_forces),
                         tmp, ext, fps, speed, title)
    return len(times)


def snapshot(result, out, t=None, trail_frames=300, title=None, contact_forces=False):
    """A still picture (.png, .pdf, .svg) of the state at ``t`` (default the end), with the
    centres of mass' trails up to then (and the contact forces as arrows when asked);
    written whole or not at all."""
    from .plots import _check_path, _save
    _check_path(out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t_end = float(result.t[-1] if t is None else t)
    times = np.linspace(float(result.t[0]), t_end, max(2, trail_frames))
    scenes = frames(result, times, trail=trail_frames, contact_forces=contact_forces)
    fig, draw = _figure(result.model, scenes, title or result.model.name, 1.0)
    draw(len(scenes) - 1)
    _save(fig, out)
    plt.close(fig)


def view_angles(model):
    """``(vertical axis, elevation, azimuth, roll, light)``: the world axis nearest to "up"
    (against gravity) drawn upwards, seen from a corner -- or, when it is y (the textbook's
    planar models move in x-y), from the side of the x-y plane -- and the direction of a
    light over the viewer's shoulder (world axes) for the solids' shading."""
    up = up_rotation(model)[2]
    k = int(np.argmax(np.abs(up)))
    elev, azim = (15.0, 25.0) if k == 1 else (20.0, -60.0)
    e, a = np.radians(elev), np.radians(azim)
    eye = np.roll([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], k - 2)
    light = eye + 0.9 * np.sign(up[k]) * np.eye(3)[k]
    return "xyz"[k], elev, azim, (0.0 if up[k] > 0 else 180.0), light / np.linalg.norm(light)


def _draw_solids(ax, scene, light):
    from matplotlib.colors import to_rgb
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    for vertices, faces, colour in scene.solids:
        shades = shade(to_rgb(colour), vertices, faces, light)
        ax.add_collection3d(Poly3DCollection(vertices[faces], facecolors=shades,
                                             edgecolors="none", linewidths=0))
    for _, vertices, faces in scene.planes:
        ax.add_collection3d(Poly3DCollection(vertices[faces], facecolors=PLANE, alpha=0.3,
                                             edgecolors="none"))


def _figure(model, scenes, title, speed):
    """A 3D figure in world axes (x, y, z in metres, equal scales, "up" drawn upwards) and
    ``draw(k)`` showing scene k."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    centre, half = bounds(scenes)
    vertical, elev, azim, roll, light = view_angles(model)
    fig = plt.figure(figsize=(5.5, 5.5))
    ax = fig.add_subplot(projection="3d")

    def draw(k):
        ax.cla()
        sc = scenes[k]
        _draw_solids(ax, sc, light)
        for pts, colour, width in sc.lines:
            ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], color=colour, lw=width)
        for name, tr in sc.trails.items():
            ax.plot(tr[:, 0], tr[:, 1], tr[:, 2], color="0.6", lw=0.8)
        for name, p, colour in sc.tags:
            ax.scatter([p[0]], [p[1]], [p[2]], color=colour, marker="D", s=30,
                       depthshade=False)
        for name, p, colour, size in sc.markers:
            ax.scatter([p[0]], [p[1]], [p[2]], color=colour, s=0.5 * size ** 2,
                       depthshade=False, edgecolors="k", linewidths=0.4)
        for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
            setter(c - half, c + half)
        ax.set_box_aspect((1, 1, 1))
        ax.view_init(elev=elev, azim=azim, roll=roll, vertical_axis=vertical)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        ax.tick_params(labelsize=7)
        pace = f"  ({speed:g}x)" if speed != 1 else ""
        ax.set_title(f"{mathtext(title + sc.caption)}\nt = {sc.t:.3f} s{pace}", fontsize=9)
        return []
    return fig, draw


def _write_movie(model, scenes, path, ext, fps, speed, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import animation
    fig, draw = _figure(model, scenes, title, speed)
    anim = animation.FuncAnimation(fig, draw, frames=len(scenes), blit=False)
    if ext == ".gif":
        anim.save(path, writer=animation.PillowWriter(fps=fps))
    else:
        import imageio_ffmpeg
        matplotlib.rcParams["animation.ffmpeg_path"] = imageio_ffmpeg.get_ffmpeg_exe()
        anim.save(path, writer=animation.FFMpegWriter(fps=fps))
    plt.close(fig)

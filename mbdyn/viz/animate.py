"""Animations of a run to a file: GIF (matplotlib and Pillow), MP4 (an ffmpeg that the
optional extra ``imageio-ffmpeg`` ships), or a self-contained HTML page (``viz.html``).

Playback is real time by default (``speed`` > 1 plays faster); frames are sampled at
``fps`` per second of playback from the stored results (states interpolated between
samples).  Bodies are drawn with their shapes (``viz.geometry``), centres of mass leave
trails, the time is shown.  The world is turned so that "up" (against gravity) is drawn
upwards.
"""
from __future__ import annotations

import numpy as np

from .. import files
from ..errors import ModelError
from ..escape import mathtext
from .geometry import bounds, frames, sample_times, up_rotation

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


def animate(result, out, speed=1.0, fps=30.0, title=None, max_frames=MAX_FRAMES):
    """Write an animation of ``result`` to ``out`` (.gif, .mp4 or .html); returns the
    number of frames.  The file is written whole or not at all."""
    ext = check_output(out)
    for name, value in (("speed", speed), ("fps", fps)):
        if (isinstance(value, bool) or not isinstance(value, (int, float, np.number))
                or not (value > 0 and np.isfinite(value))):
            raise ModelError(f"{name} must be a positive number, got {value!r}")
    if ext == ".gif":
        # a GIF stores frame durations in whole centiseconds: make them exact
        fps = 100.0 / max(1, round(100.0 / fps))
    times = sample_times(result, fps, speed, max_frames)
    scenes = frames(result, times)
    title = title or result.model.name
    with files.replacing(out) as tmp:     # a link at ``out`` is replaced, not followed
        if ext == ".html":
            from .html import write_html
            write_html(result.model, scenes, tmp, fps=fps, speed=speed, title=title)
        else:
            _write_movie(result.model, scenes, tmp, ext, fps, speed, title)
    return len(scenes)


def snapshot(result, out, t=None, trail_frames=300, title=None):
    """A still picture (.png, .pdf, .svg) of the state at ``t`` (default the end), with the
    centres of mass' trails up to then; written whole or not at all."""
    from .plots import _check_path, _save
    _check_path(out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t_end = float(result.t[-1] if t is None else t)
    times = np.linspace(float(result.t[0]), t_end, max(2, trail_frames))
    scenes = frames(result, times, trail=trail_frames)
    fig, draw = _figure(result.model, scenes, title or result.model.name, 1.0)
    draw(len(scenes) - 1)
    _save(fig, out)
    plt.close(fig)


def _figure(model, scenes, title, speed):
    """A 3D figure and ``draw(k)`` showing scene k, "up" drawn upwards."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    Rv = up_rotation(model)
    centre, half = bounds(scenes)
    c = Rv @ centre
    fig = plt.figure(figsize=(5.5, 5.5))
    ax = fig.add_subplot(projection="3d")
    ax.set_box_aspect((1, 1, 1))

    def draw(k):
        ax.cla()
        sc = scenes[k]
        for pts, colour, width in sc.lines:
            p = pts @ Rv.T
            ax.plot(p[:, 0], p[:, 1], p[:, 2], color=colour, lw=width)
        for name, tr in sc.trails.items():
            p = tr @ Rv.T
            ax.plot(p[:, 0], p[:, 1], p[:, 2], color="0.6", lw=0.8)
        for name, pos, colour, size in sc.markers:
            p = Rv @ pos
            ax.scatter([p[0]], [p[1]], [p[2]], color=colour, s=size ** 2, depthshade=False)
        ax.set_xlim(c[0] - half, c[0] + half)
        ax.set_ylim(c[1] - half, c[1] + half)
        ax.set_zlim(c[2] - half, c[2] + half)
        ax.set_xlabel("[m]")
        pace = f"  ({speed:g}x)" if speed != 1 else ""
        ax.set_title(f"{mathtext(title)}\nt = {sc.t:.3f} s{pace}", fontsize=9)
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

"""``mbdyn animate MODEL --out FILE.gif|.mp4|.html``: simulate and animate.

    mbdyn animate MODEL [--case NAME] [--set PATH=VALUE ...] [--effects LIST]
                        [--t-end T] [--integrator NAME] [--rtol R] [--atol A] [--dt H]
                        [--out FILE] [--speed S] [--fps F]
"""
from __future__ import annotations

import os
import sys

from .common import (
    Progress,
    add_command,
    add_simulation_arguments,
    default_output,
    load,
    positive,
    title,
)


def register(subparsers):
    p = add_command(subparsers, "animate",
                    "Simulate the model with its [simulation] settings and write an "
                    "animation: real-time playback (--speed to change), bodies with their "
                    "shapes, trails of the centres of mass, the time shown.  .html is one "
                    "file that opens offline, with orbit/zoom, play/pause and a time slider.",
                    run)
    p.add_argument("--out", metavar="FILE", help=".gif, .mp4 (needs the video extra) or "
                                                 ".html (default STEM.gif)")
    p.add_argument("--speed", type=positive, default=1.0, help="playback speed (default 1: "
                                                            "real time)")
    p.add_argument("--fps", type=positive, default=30.0, help="frames per second (default 30)")
    p.add_argument("--contact-forces", action="store_true",
                   help="draw each contact's force as an arrow from its touching point")
    add_simulation_arguments(p)


def run(args):
    from ..viz.animate import animate, check_output
    if args.out:
        check_output(args.out)         # before the run: a bad request costs nothing
    scene = load(args)
    out = args.out or default_output(scene, ".gif")
    check_output(out)
    progress = Progress(scene.settings.get("t_end") or 0.0)
    result = scene.simulate(progress=progress)
    progress.close()
    n = animate(result, out, speed=args.speed, fps=args.fps, title=title(scene),
                contact_forces=args.contact_forces)
    sys.stdout.write(f"wrote {out} ({n} frames, {os.path.getsize(out) / 1e6:.2f} MB)\n")
    return 0

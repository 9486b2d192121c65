"""``mbdyn plot MODEL``: simulate and plot time series or a phase portrait.

    mbdyn plot MODEL [--case NAME] [--set PATH=VALUE ...] [--effects LIST]
                     [--t-end T] [--integrator NAME] [--rtol R] [--atol A] [--dt H]
                     [--series NAMES] [--phase X,Y] [--out FILE.png|.pdf|.svg]
"""
from __future__ import annotations

import sys

from .common import (
    Progress,
    add_command,
    add_simulation_arguments,
    default_output,
    load,
    title,
)


def register(subparsers):
    from ..viz import SERIES_HELP
    p = add_command(subparsers, "plot",
                    "Simulate the model with its [simulation] settings and plot series "
                    "against time (one axis per unit, events marked) or a phase portrait.", run)
    p.add_argument("--series", metavar="NAMES",
                   help="comma-separated: " + SERIES_HELP + " (default: the coordinates and "
                        "the energies when the file asks for them)")
    p.add_argument("--phase", metavar="X,Y", help="a phase portrait of two series")
    add_simulation_arguments(p)
    p.add_argument("--out", metavar="FILE", help="picture file: .png, .pdf or .svg (default "
                                                 "STEM.png in the current directory)")


def wanted_outputs(series):
    """The outputs a list of series names needs computed."""
    names = [s.strip() for s in (series or "").replace(";", ",").split(",") if s.strip()]
    out = []
    if any(n.startswith("energy") for n in names):
        out.append("energy")
    if any(n.startswith(("reaction", "effort")) for n in names):
        out.append("reactions")
    return tuple(out)


def plot_run(scene, result, series=None, phase=None, out=None):
    """Add the outputs the series need, then plot; returns the path written."""
    need = [o for o in wanted_outputs(",".join(filter(None, [series, phase])))
            if getattr(result, o if o == "energy" else "reactions") is None]
    if need:
        result.compute_outputs(tuple(need))
    path = out or default_output(scene, ".png")
    result.plot(series=series, phase=phase, out=path, title=title(scene))
    return path


def run(args):
    from ..viz.plots import _check_path
    if args.out:
        _check_path(args.out)          # before the run: a bad path costs nothing
    scene = load(args)
    progress = Progress(scene.settings.get("t_end") or 0.0)
    result = scene.simulate(progress=progress)
    progress.close()
    path = plot_run(scene, result, args.series, args.phase, args.out)
    sys.stdout.write(f"wrote {path}\n")
    return 0

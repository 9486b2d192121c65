"""Arguments and helpers shared by the ``mbdyn`` commands."""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
import warnings

from . import SUMMARIES
from ..io.errors import ModelFileError
from ..io.loader import load_model
from ..io.schema import parse_set_value


def finite(text):
    """argparse type: a finite number."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return v


def positive(text):
    """argparse type: a finite number > 0."""
    v = finite(text)
    if not v > 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not > 0")
    return v


def positive_int(text):
    """argparse type: a whole number >= 1."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not >= 1")
    return v


def add_command(subparsers, name, description, func, model_arguments=True):
    """The parser of the command ``name``: its one-line help from ``SUMMARIES``, its
    ``description``, ``MODEL [--case NAME] [--set PATH=VALUE ...] [--effects LIST]``
    unless ``model_arguments`` is false; ``func(args)`` runs it."""
    p = subparsers.add_parser(name, help=SUMMARIES[name], description=description)
    if model_arguments:
        add_model_arguments(p)
    p.set_defaults(func=func)
    return p


def add_model_arguments(parser):
    """``MODEL [--case NAME] [--set PATH=VALUE ...]``."""
    parser.add_argument("model", metavar="MODEL", help="model file (.toml) or URDF robot "
                                                        "(.urdf)")
    add_urdf_arguments(parser)
    parser.add_argument("--case", metavar="NAME",
                        help="apply the file's [cases.NAME] (default: model.default_case)")
    parser.add_argument("--set", dest="overrides", metavar="PATH=VALUE", action="append",
                        default=[],
                        help="override a value by its dotted path after the case, e.g. "
                             "parameters.b=0.3, initial.beta=pi/8, bodies.disk.mass=2 "
                             "(repeatable)")
    parser.add_argument("--effects", metavar="LIST",
                        help="switch effects off (-name) or on (+name) after the file's "
                             "[effects], e.g. --effects=-gravity,-bearing_left; names: gravity, "
                             "gyroscopic, every load and force element (mbdyn info lists them)")


def add_urdf_arguments(parser):
    """``--floating``, ``--accept-inertia``: a URDF robot's options (docs/urdf.md),
    shorthands of ``--set model.floating=true`` and ``--set model.accept_inertia=true``."""
    parser.add_argument("--floating", action="store_true",
                        help="URDF: the base hangs from the ground by a free joint 'root' "
                             "(default: fixed)")
    parser.add_argument("--accept-inertia", action="store_true",
                        help="URDF: accept inertias no body can have (a negative principal "
                             "moment set to 0, a broken triangle inequality), with a warning")
    parser.add_argument("--mesh-path", metavar="DIR", action="append", default=[],
                        help="URDF: a folder where package:// meshes of <visual> are looked "
                             "for, drawn by animate (repeatable; before the URDF's own "
                             "folder and its parents)")


def urdf_overrides(args):
    """``(path, value, origin)`` of ``--floating``, ``--accept-inertia`` and
    ``--mesh-path``, if given."""
    out = [(f"model.{key}", True, flag) for key, flag in
           (("floating", "--floating"), ("accept_inertia", "--accept-inertia"))
           if getattr(args, key, False)]
    folders = getattr(args, "mesh_path", None)
    if folders:
        out.append(("model.mesh_path", [os.path.abspath(f) for f in folders],
                    "--mesh-path " + " ".join(folders)))
    return out


#: the simulation options of every command that runs a model (run, plot, animate, sweep,
#: accuracy), defined once: ``(dotted path, flag, metavar, help)``; each is a shorthand of
#: ``--set PATH=VALUE`` applied after ``--case`` and ``--set`` (a number or an expression)
SIMULATION_FLAGS = (
    ("simulation.t_end", "--t-end", "T", "end time (s)"),
    ("simulation.integrator", "--integrator", "NAME", None),
    ("simulation.rtol", "--rtol", "R", "relative tolerance (adaptive integrators)"),
    ("simulation.atol", "--atol", "A", "absolute tolerance (adaptive integrators)"),
    ("simulation.dt", "--dt", "H", "step size (fixed-step integrators)"),
)


def add_simulation_arguments(parser, what="overrides the file's [simulation]"):
    """``--t-end --integrator --rtol --atol --dt`` (``SIMULATION_FLAGS``); their values
    are read as ``--set`` values (``overrides``, ``simulation_overrides``)."""
    from ..integrate.settings import FIXED_STEP, INTEGRATORS
    for _, flag, metavar, text in SIMULATION_FLAGS:
        if flag == "--integrator":
            parser.add_argument(flag, choices=INTEGRATORS, metavar=metavar,
                                help=f"one of {', '.join(INTEGRATORS)} ({', '.join(FIXED_STEP)}"
                                     f" are fixed-step and need --dt); {what}")
        else:
            parser.add_argument(flag, metavar=metavar, help=f"{text}; {what}")


def simulation_overrides(args):
    """``{dotted path: value}`` of the ``SIMULATION_FLAGS`` given (for ``sweep``'s fixed
    overrides)."""
    return {path: value for path, value, _ in _flag_values(
        args, [(p, f) for p, f, _, _ in SIMULATION_FLAGS])}


def _flag_values(args, flags):
    """``(path, value, origin)`` of each ``(path, flag)`` option given, its text read as
    a ``--set`` value."""
    out = []
    for path, flag in flags:
        value = getattr(args, flag.lstrip("-").replace("-", "_"), None)
        if value is None:
            continue
        try:
            parsed = parse_set_value(value) if isinstance(value, str) else value
        except ValueError as exc:
            raise ModelFileError(args.model, f"{flag} {value}", str(exc)) from None
        out.append((path, parsed, f"{flag} {value}"))
    return out


def overrides(args, flags=()):
    """``--set`` texts, then the ``(path, flag)`` options given (e.g. ``--dt``), as
    ``(path, value, origin)`` triples for ``load_model``."""
    return list(args.overrides) + _flag_values(args, flags) + urdf_overrides(args)


def load(args, flags=None, record_warnings=False):
    """The ``Scene`` of the command line's model, case and overrides (``flags``: the
    ``(path, flag)`` options to apply; default the ``SIMULATION_FLAGS`` the command
    has)."""
    if flags is None:
        flags = [(p, f) for p, f, _, _ in SIMULATION_FLAGS
                 if hasattr(args, f.lstrip("-").replace("-", "_"))]
    effects = getattr(args, "effects", None)
    if record_warnings:
        with warnings.catch_warnings(record=True):
            warnings.simplefilter("always")
            return load_model(args.model, case=args.case, overrides=overrides(args, flags),
                              effects=effects)
    return load_model(args.model, case=args.case, overrides=overrides(args, flags),
                      effects=effects)


def heading(scene):
    """``NAME (PATH, case CASE)``: the first line of a command's report."""
    return f"{scene.name} ({scene.path}{', case ' + scene.case if scene.case else ''})"


def title(scene):
    """``NAME (case CASE)``: a picture's title."""
    return f"{scene.name}{' (case ' + scene.case + ')' if scene.case else ''}"


def default_output(scene, suffix):
    """``STEM_CASE.SUFFIX`` (``STEM.SUFFIX`` without a case) in the current directory: where
    a picture or an animation goes when no path is given."""
    return os.path.splitext(os.path.basename(scene.path))[0] + (
        f"_{scene.case}" if scene.case else "") + suffix


def print_json(scene, fields):
    """One JSON object on stdout: the model's name and case, then ``fields``."""
    sys.stdout.write(json.dumps({"model": scene.name, "case": scene.case, **fields}) + "\n")


def fmt(x):
    """A number, briefly."""
    try:
        return f"{float(x):.6g}"
    except (TypeError, ValueError):
        return str(x)


class Progress:
    """``progress(t)`` for ``simulate``: after ``delay`` seconds of wall time, shows
    ``t`` and the percentage done on ``stream`` (stderr), refreshed every ``interval``
    seconds; only when the stream is a terminal (or ``force``)."""

    def __init__(self, t_end, stream=None, delay=2.0, interval=0.2, force=False,
                 clock=time.monotonic, t0=0.0):
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = force or bool(getattr(self.stream, "isatty", lambda: False)())
        self.t0, self.t_end = float(t0), float(t_end)
        self.delay, self.interval = delay, interval
        self.clock = clock
        self.start = clock()
        self.last = None
        self.shown = False

    def __call__(self, t):
        if not self.enabled:
            return
        now = self.clock()
        if now - self.start < self.delay:
            return
        if self.last is not None and now - self.last < self.interval:
            return
        self.last = now
        span = max(self.t_end - self.t0, 1e-300)
        pct = max(0.0, min(100.0, 100.0 * (float(t) - self.t0) / span))
        self.stream.write(f"\rmbdyn: t = {float(t):.6g} of {self.t_end:g} s ({pct:5.1f}%), "
                          f"{now - self.start:.0f} s elapsed")
        self.stream.flush()
        self.shown = True

    def close(self):
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()
            self.shown = False


def duration(seconds):
    """A duration, briefly: ``40 s``, ``15 min``, ``2.3 h``, ``4.1 days``."""
    if seconds < 100:
        return f"{seconds:.0f} s"
    if seconds < 6000:
        return f"{seconds / 60:.0f} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.2g} h"
    return f"{seconds / 86400:.2g} days"


class Estimate(Progress):
    """``progress(done, total)`` for a loop over ``total`` like items (``campbell``'s
    values).  Once ``sample`` items after the first are done (the first pays for imports
    and compilation), says on ``stream`` (stderr) how long the whole loop will take,
    extrapolated from them, if that is ``threshold`` seconds or more; then, on a terminal,
    shows the count and the time left every ``interval`` seconds."""

    def __init__(self, what, stream=None, sample=3, threshold=10.0, interval=0.5,
                 force=False, clock=time.monotonic):
        super().__init__(0.0, stream=stream, delay=0.0, interval=interval, force=force,
                         clock=clock)
        self.what, self.sample, self.threshold = what, sample, threshold
        self.first = None           # (done, time) after the first item
        self.long = False

    def __call__(self, done, total):
        now = self.clock()
        if self.first is None:
            self.first = (done, now)
            return
        d0, t0 = self.first
        if done - d0 == self.sample and done < total:
            rate = (now - t0) / (done - d0)
            whole = (now - self.start) + rate * (total - done)
            self.long = whole >= self.threshold
            if self.long:
                self.stream.write(f"mbdyn: {total} {self.what} will take about "
                                  f"{duration(whole)} ({rate:.3g} s each, timed over "
                                  f"{self.sample} of them); Ctrl-C stops\n")
                self.stream.flush()
        if not (self.enabled and self.long) or done - d0 < self.sample:
            return
        if self.last is not None and now - self.last < self.interval and done < total:
            return
        self.last = now
        left = (now - t0) / (done - d0) * (total - done)
        self.stream.write(f"\rmbdyn: {done} of {total} {self.what} "
                          f"({100.0 * done / total:5.1f}%), {duration(now - self.start)} "
                          f"elapsed, about {duration(left)} left   ")
        self.stream.flush()
        self.shown = True

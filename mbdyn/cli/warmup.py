"""``mbdyn warmup [--all]``: compile the numeric kernels ahead of time.

Runs the commands a user would, on small model files written to a temporary folder
(``warmup_models``), so that every kernel is compiled for the argument types real runs
pass and kept in numba's on-disk cache; later commands load them in a fraction of a
second.  Prints each route as it finishes: how many kernels it compiled and how long it
took (a route whose kernels an earlier one compiled costs little).  ``--all`` adds the
routes fewer first runs take: every fixed-step scheme on every layout, scipy's
integrators, batched sweeps, equilibrium and modes (Campbell diagrams use the same
kernels).  Exit code 0, or 1 if a route failed (named with its error).
"""
from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import time
import warnings

from . import SUMMARIES

FIXED = ("semi-implicit-euler", "euler", "rk4", "implicit-midpoint")
#: the model files of each layout, without and with force elements (the small tree also
#: with every kind, contacts between shapes among them: ``warmup_models``)
LAYOUTS = (("pendulum", "forces", "pendulum_forces"), ("chain", "chain_forces"),
           ("four_bar", "four_bar_forces"))


def _runs(models, integrators):
    return [["run", f"{{{m}}}", "--integrator", i] for m in models for i in integrators]


#: ``(name, what it compiles, in the main set?, command lines)``; ``{pendulum}`` etc. are
#: the paths of ``warmup_models.MODELS``.  A kernel is compiled once for each layout
#: (small tree, articulated bodies, closed loop), with or without force elements, and
#: integrator; the main set is what the shipped models run by default and with DOP853.
ROUTES = (
    ("jourdain", "a small tree (M u' = f): DOP853 and RK45 in compiled stretches, "
     "reactions, energy, points", True, _runs(["pendulum"], ["DOP853", "RK45"])),
    ("fixed-step", "semi-implicit Euler (the textbook's), Euler, RK4, implicit midpoint",
     True, _runs(["pendulum"], FIXED)),
    ("articulated", "6 or more speeds: the articulated-body route, a spherical joint "
     "(DOP853, semi-implicit Euler, RK4)", True,
     _runs(["chain"], ["DOP853", "semi-implicit-euler", "rk4"])),
    ("force elements", "springs, dampers, tables, bushing, bearing, contact, contacts "
     "between shapes, a stop, a compiled law, a PD actuator, a drive; a spring alone "
     "(no shape-contact kernel); on both routes (DOP853, semi-implicit Euler, RK4)", True,
     _runs(["forces", "pendulum_forces"], ["DOP853", "semi-implicit-euler", "rk4"])
     + _runs(["chain_forces"], ["DOP853", "semi-implicit-euler"])),
    ("closed loop", "a four-bar: constrained accelerations, projection, the loop's "
     "reactions; with a force element (DOP853, RK4)", True,
     _runs(["four_bar", "four_bar_forces"], ["DOP853", "rk4"])),
    ("fixed-step, all", "every fixed-step scheme on every layout", False,
     _runs([m for group in LAYOUTS for m in group], FIXED)),
    ("scipy integrators", "Radau, BDF, LSODA: the packed right-hand side", False,
     _runs(["pendulum"], ["Radau", "BDF", "LSODA"])
     + _runs(["forces", "chain", "chain_forces"], ["Radau"])),
    ("batched sweeps", "members advanced together, on every layout", False,
     [["sweep", f"{{{m}}}", "--grid", f"initial_speeds.{s}=0:1:2", "--integrator", "rk4",
       "--batched", "--json"]
      for m, s in (("pendulum", "theta1"), ("forces", "x"), ("chain", "j0"),
                   ("chain_forces", "j0"), ("four_bar", "crank"),
                   ("four_bar_forces", "crank"))]),
    ("modes", "equilibrium, linearisation and modes, on every layout", False,
     [["equilibrium", "{pendulum}"], ["modes", "{pendulum}"],
      ["modes", "{forces}", "--at", "initial"], ["modes", "{chain}", "--at", "initial"],
      ["modes", "{four_bar}"]]),
)


def register(subparsers):
    p = subparsers.add_parser("warmup", help=SUMMARIES["warmup"], description=(
        "Compile the numeric kernels ahead of time (numba keeps them on disk), so that "
        "no later command waits for a compile: the main routes (small trees, the "
        "articulated route, the compiled integrators, force elements, closed loops); "
        "--all every route.  Prints what each route compiled and the time it took."))
    p.add_argument("--all", action="store_true", help="also every fixed-step scheme on "
                   "every layout, scipy's integrators, batched sweeps, equilibrium and "
                   "modes")
    p.set_defaults(func=warmup)


def _run_quietly(argv):
    """Run one command line with its output and warnings silenced (an error is raised);
    returns its exit code."""
    from . import build_parser
    args = build_parser(argv[0]).parse_args(argv)
    with open(os.devnull, "w") as devnull, contextlib.redirect_stdout(devnull), \
            contextlib.redirect_stderr(devnull), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return args.func(args) or 0


def run_route(lines, paths):
    """Run a route's command lines; returns ``(kernels compiled, wall s, CPU s, error)``."""
    from .compiling import Watch
    start, cpu = time.perf_counter(), time.process_time()
    error = None
    with Watch(notice=False, live=False) as watch:
        for line in lines:
            argv = [word.format(**paths) for word in line]
            try:
                code = _run_quietly(argv)
            except Exception as exc:            # named, and the other routes go on
                code, error = 1, f"{type(exc).__name__}: {exc}"
            if code:
                error = error or f"exit code {code}"
                error = f"`mbdyn {' '.join(argv)}`: {error}"
                break
    return (len(watch.compiled), time.perf_counter() - start, time.process_time() - cpu,
            error)


def warmup(args):
    from .warmup_models import MODELS
    out = sys.stdout
    routes = [r for r in ROUTES if r[2] or args.all]
    out.write(f"mbdyn warmup: the kernels of {len(routes)} routes, compiled where numba's "
              "cache lacks them (kept on disk for later commands)\n")
    out.flush()
    failed = 0
    total = [0, 0.0, 0.0]
    with tempfile.TemporaryDirectory(prefix="mbdyn-warmup-") as tmp:
        paths = {}
        for stem, text in MODELS.items():
            paths[stem] = os.path.join(tmp, f"{stem}.toml")
            with open(paths[stem], "w", encoding="utf-8") as f:
                f.write(text)
        for name, what, _, lines in routes:
            n, wall, cpu, error = run_route(lines, paths)
            total = [total[0] + n, total[1] + wall, total[2] + cpu]
            done = f"{n} kernels compiled" if n else "cached"
            sys.stdout.write(f"  {name:<18} {done:<20} {wall:6.1f} s  ({what})\n")
            if error:
                failed += 1
                sys.stdout.write(f"    failed: {error}\n")
            sys.stdout.flush()
    sys.stdout.write(f"  {'total':<18} {str(total[0]) + ' kernels compiled':<20} "
                     f"{total[1]:6.1f} s  (CPU {total[2]:.1f} s)\n")
    return 1 if failed else 0

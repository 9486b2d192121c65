"""``mbdyn run MODEL``: simulate a model file; summary, ``--json`` or ``--out DIR``."""
from __future__ import annotations

import json
import sys
import warnings

from .. import limits
from ..errors import ModelWarning, SimulationError
from ..io.loader import METHODS
from ..io.results import _jsonable, summary, write_results
from ..integrate.settings import FIXED_STEP
from .common import (SIMULATION_FLAGS, Progress, add_command,
                     add_simulation_arguments, fmt, heading, load, positive)

#: options that are shorthands of --set simulation.KEY=VALUE: the shared ones
#: (``common.SIMULATION_FLAGS``), then run's own
FLAGS = tuple((p, f) for p, f, _, _ in SIMULATION_FLAGS) + (
    ("simulation.method", "--method"), ("simulation.max_steps", "--max-steps"),
    ("simulation.max_samples", "--max-samples"),
    ("simulation.max_wall_time", "--max-wall-time"))


def register(subparsers):
    p = add_command(subparsers, "run", "Simulate a model file with its [simulation] "
                    "settings; options override them (after --case and --set).", run)
    add_simulation_arguments(p)
    p.add_argument("--method", choices=METHODS, help="formulation: " + ", ".join(METHODS))
    p.add_argument("--max-steps", metavar="N", help="step budget of the run (default "
                   f"{limits.MAX_STEPS}); see docs/reliability.md")
    p.add_argument("--max-samples", metavar="N", help="stored samples at most (default "
                   f"{limits.MAX_SAMPLES}); beyond, give output_dt")
    p.add_argument("--max-wall-time", metavar="S", help="stop the run after S seconds of "
                   "wall time (default: no limit)")
    p.add_argument("--error-estimate", action="store_true",
                   help="run again at half the step (fixed-step) or at rtol/100, atol/100 "
                        "(adaptive) and report the difference per coordinate")
    p.add_argument("--warn-threshold", metavar="F", type=positive,
                   help="warn when the energy drift, the quaternion drift or the error "
                        f"estimate (relative) exceeds F (default {limits.WARN_THRESHOLD:g})")
    p.add_argument("--out", metavar="DIR", help="write STEM.csv (named columns) and "
                                                "STEM.json (metadata) into DIR")
    p.add_argument("--json", action="store_true",
                   help="print one JSON object (the summary) and nothing else on stdout")
    p.add_argument("--plot", metavar="FILE",
                   help="also plot the coordinates (and energies) into FILE (.png, .pdf, .svg)")


def run(args):
    if args.plot:
        from ..viz.plots import _check_path
        _check_path(args.plot)         # before the run: a bad path costs nothing
    scene = load(args, FLAGS)
    if args.dt is not None and scene.settings["integrator"] not in FIXED_STEP:
        warnings.warn(f"--dt is ignored: the adaptive integrator "
                      f"{scene.settings['integrator']} chooses its own steps (choose a "
                      f"fixed-step --integrator: {', '.join(FIXED_STEP)})", ModelWarning)
    progress = Progress(scene.settings.get("t_end") or 0.0)
    try:
        result = scene.simulate(progress=progress, error_estimate=args.error_estimate)
    except SimulationError as exc:
        progress.close()
        if args.out and exc.result is not None and len(exc.result.t):
            write_results(args.out, scene, exc.result, status="failed", error=str(exc))
        if scene.settings["integrator"] in FIXED_STEP:
            raise SimulationError(f"{exc} (with the fixed-step integrator "
                                  f"{scene.settings['integrator']!r} this may be the scheme, "
                                  "not the model: try a smaller --dt or an adaptive "
                                  "--integrator such as DOP853)", exc.result) from exc
        raise
    progress.close()
    worth = result.quality(args.warn_threshold)
    for message in worth["warnings"]:
        warnings.warn(message, ModelWarning)
    paths = (list(write_results(args.out, scene, result, extra={"quality": _jsonable(worth)}))
             if args.out else [])
    if args.plot:
        from .plot import plot_run
        paths.append(plot_run(scene, result, out=args.plot))
    if args.json:
        sys.stdout.write(json.dumps(summary(scene, result, worth)) + "\n")
    else:
        report(scene, result, paths, worth)
    return 0


def report(scene, result, paths, worth=None):
    s = summary(scene, result, worth)
    st = result.stats
    out = sys.stdout
    out.write(heading(scene) + "\n")
    step = f", dt = {fmt(st.get('dt'))}" if st.get("dt") and st.get("integrator") in (
        "euler", "semi-implicit-euler", "rk4") else \
        f", rtol = {fmt(st.get('rtol'))}, atol = {fmt(st.get('atol'))}"
    out.write(f"  integrator {s['stats']['integrator']}, method {s['stats']['method']}{step}\n")
    out.write(f"  t = {fmt(result.t[0])} .. {fmt(s['t_final'])} s: {s['stats']['steps']} steps, "
              f"{s['stats']['rhs_evaluations']} right-hand sides, "
              f"{s['stats']['wall_time_s']:.3g} s wall time\n")
    terminal = {e.name: e.terminal for e in scene.events}
    if s["events"]:
        for e in s["events"]:
            tag = " (terminal: the run stops)" if terminal.get(e["name"]) else ""
            out.write(f"  event {e['name']} at t = {fmt(e['t'])} s{tag}\n")
    elif scene.events:
        out.write("  events: none occurred\n")
    out.write("  final state:\n")
    names = list(s["q"].items()) + list(s["u"].items())
    width = max((len(n) for n, _ in names), default=1)
    for n, v in names:
        out.write(f"    {n:<{width}} = {fmt(v)}\n")
    if s["energy"]:
        e0, e1 = s["energy"]["initial"], s["energy"]["final"]
        out.write(f"  energy T + V: initial {fmt(e0)} J, final {fmt(e1)} J\n")
    quality_lines(out, s["quality"])
    if s.get("loops"):
        lp = s["loops"]
        out.write(f"  loops: mobility {lp.get('mobility')}, constraint drift "
                  f"{fmt(lp.get('constraint_drift', 0.0))} (positions), "
                  f"{fmt(lp.get('constraint_drift_velocity', 0.0))} (velocities)\n")
        if lp.get("reactions_not_unique"):
            out.write("  reactions not unique (minimum-norm values): " + "; ".join(
                f"{j} {', '.join(c)}" for j, c in lp["reactions_not_unique"].items()) + "\n")
        if lp.get("singular_configuration"):
            sc = lp["singular_configuration"]
            out.write(f"  singular configuration passed at t = {fmt(sc['t'])} s (rank "
                      f"{sc['rank']})\n")
    for p in paths:
        out.write(f"  wrote {p}\n")


def quality_lines(out, worth):
    """What the run is worth: the energy balance drift, the quaternion drift, the error
    estimate; a figure above the threshold is marked (its warning went to stderr)."""
    def mark(v):
        return "  ** above the warning threshold **" if v is not None and v > worth[
            "threshold"] else ""
    drift = worth["energy_drift"]
    out.write("  energy balance drift: " + (
        "not computed (loads, drives or force elements: add energy = true to [outputs])"
        if drift is None else f"{drift:.3g} ({100 * drift:.3g} % of the energy scale)"
        + mark(drift)) + "\n")
    if worth["quaternion_drift"] is not None:
        out.write(f"  quaternion drift: {worth['quaternion_drift']:.3g}"
                  f"{mark(worth['quaternion_drift'])}\n")
    est = worth["error_estimate"]
    if est is None:
        return
    if est.get("failed"):
        out.write(f"  error estimate: not available ({est['failed']})\n")
        return
    out.write(f"  error estimate (difference from the same run at {est['against']}), "
              f"largest {100 * (est['relative'] or 0):.3g} % of its scale "
              f"({est['worst']}){mark(est['relative'])}:\n")
    width = max(len(n) for n in est["difference"])
    for n, v in est["difference"].items():
        out.write(f"    {n:<{width}} {fmt(v)}\n")

"""``mbdyn accuracy MODEL``: what accuracy costs in time -- a work-precision study."""
from __future__ import annotations

import json
import math
import sys

from ..analysis.accuracy import DEFAULT_INTEGRATORS, TOLERANCES, accuracy_study
from ..errors import ModelError
from ..escape import legend_label, mathtext
from ..files import check_target, replacing
from ..integrate.settings import INTEGRATORS
from .common import add_command, add_simulation_arguments, load, positive, positive_int


def register(subparsers):
    p = add_command(subparsers, "accuracy",
                    "Integrate the model with a reference (DOP853 at 1e-13, cross-checked by "
                    "Radau), then with each integrator over a sweep of tolerances (adaptive) "
                    "or step sizes (fixed-step); report error (max over time), energy drift, "
                    "wall time and right-hand-side evaluations.", run)
    add_simulation_arguments(p, "of the study: --integrator X is --integrators X, --rtol R "
                                "--tolerances R (each with atol R/1000 unless --atol), --dt H "
                                "--steps H")
    p.add_argument("--integrators", metavar="LIST",
                   help="comma-separated, from " + ", ".join(INTEGRATORS)
                        + f" (default {','.join(DEFAULT_INTEGRATORS)})")
    p.add_argument("--tolerances", metavar="LIST",
                   help="comma-separated tolerances of the adaptive sweep (default "
                        f"{TOLERANCES[0]:g} ... {TOLERANCES[-1]:g})")
    p.add_argument("--steps", metavar="LIST",
                   help="comma-separated step sizes of the fixed-step sweep (default: "
                        "t_end/200 down to t_end/60000, aligned with the error samples)")
    p.add_argument("--repeats", type=positive_int, default=3, metavar="N",
                   help="timing repeats per run; the median is reported (default 3)")
    p.add_argument("--budget", type=positive, default=10.0, metavar="S",
                   help="stop an integrator's sweep after a run slower than S seconds "
                        "(default 10)")
    p.add_argument("--json", action="store_true", help="print one JSON object and nothing else")
    p.add_argument("--plot", metavar="FILE",
                   help="write a log-log work-precision diagram (error against wall time; "
                        "needs matplotlib)")


def _floats(text, what):
    try:
        values = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise ModelError(f"--{what}: {text!r} is not a comma-separated list of numbers") from None
    if not values or any(not v > 0 for v in values):
        raise ModelError(f"--{what}: give positive numbers, got {text!r}")
    return values


def _one_or_many(args, one, many):
    """The value of the option ``one`` (a shared simulation flag) or ``many`` (the study's
    list), not both."""
    a, b = getattr(args, one.lstrip("-")), getattr(args, many.lstrip("-"))
    if a is not None and b is not None:
        raise ModelError(f"{one} and {many}: give one of the two ({one} X is {many} X)")
    return a if a is not None else b


def _settings(args):
    """``(integrators, tolerances, steps, atol)`` of the study from its options."""
    integrators = DEFAULT_INTEGRATORS
    names = _one_or_many(args, "--integrator", "--integrators")
    if names:
        integrators = tuple(x.strip() for x in names.split(",") if x.strip())
        unknown = [x for x in integrators if x not in INTEGRATORS]
        if unknown:
            raise ModelError(f"--integrators: unknown {', '.join(unknown)}; choose from "
                             f"{', '.join(INTEGRATORS)}")
    tolerances = _one_or_many(args, "--rtol", "--tolerances")
    tolerances = _floats(tolerances, "tolerances") if tolerances else TOLERANCES
    steps = _one_or_many(args, "--dt", "--steps")
    steps = _floats(steps, "steps") if steps else None
    atol = _floats(args.atol, "atol")[0] if args.atol else None
    return integrators, tolerances, steps, atol


def run(args):
    if args.plot:                      # before the study: a bad path costs nothing
        check_target(args.plot, (".png", ".pdf", ".svg"), "picture", "--plot")
        _require_matplotlib()
    scene = load(args, [("simulation.t_end", "--t-end")])   # the others choose the runs
    t_end = scene.settings.get("t_end")
    if not t_end:
        raise ModelError(f"{scene.path}: simulation.t_end is not set; pass --t-end T")
    if not (math.isfinite(t_end) and t_end > 0):
        raise ModelError(f"--t-end {t_end}: give a positive, finite end time")
    if not (math.isfinite(args.budget) and args.budget > 0):
        raise ModelError(f"--budget {args.budget}: give a positive number of seconds")
    integrators, tolerances, steps, atol = _settings(args)

    def progress(run):
        if not args.json and sys.stderr.isatty():
            sys.stderr.write(f"\rmbdyn: {run.integrator} {run.setting:.2g} done        ")
            sys.stderr.flush()
    study = accuracy_study(scene.model, scene.q0, scene.u0, float(t_end),
                           integrators=integrators, tolerances=tolerances, steps=steps,
                           events=scene.events, repeats=max(1, args.repeats),
                           time_budget_s=args.budget,
                           method=scene.settings.get("method", "jourdain"), progress=progress,
                           atol=atol)
    if not args.json and sys.stderr.isatty():
        sys.stderr.write("\n")
    if args.plot:
        plot(study, args.plot, title=f"{scene.name}" + (f", case {scene.case}" if scene.case
                                                         else ""))
    failed = [r for r in study.runs if r.failed]
    if failed and args.json:      # the schema has no field for it: say it on stderr
        sys.stderr.write("mbdyn: warning: " + "; ".join(
            f"{r.integrator} at {r.setting:g} {r.failed}" for r in failed)
            + " (their error is null)\n")
    if args.json:
        sys.stdout.write(json.dumps(study.as_dict(), allow_nan=False) + "\n")
    else:
        sys.stdout.write(study.table() + "\n")
        if args.plot:
            sys.stdout.write(f"wrote {args.plot}\n")
    return 0


def _require_matplotlib():
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise ModelError("--plot needs matplotlib: pip install 'mbdyn[plot]' "
                         "(or pip install matplotlib)") from None


def plot(study, path, title=""):
    """Log-log work-precision diagram: error against wall time, one line per integrator."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 5))
    for name in dict.fromkeys(r.integrator for r in study.runs):
        runs = [r for r in study.runs if r.integrator == name and r.failed is None
                and r.error > 0 and r.error != float("inf")]
        if runs:
            ax.loglog([r.wall_time_s for r in runs], [r.error for r in runs], "o-",
                      label=legend_label(name), markersize=4)
    if study.error_estimate > 0:
        ax.axhline(study.error_estimate, color="gray", linestyle=":",
                   label="reference's error estimate")
    ax.set_xlabel("wall time [s] (median)")
    ax.set_ylabel("max coordinate error over the run")
    ax.set_title(mathtext(f"work-precision: {title}, t = 0 .. {study.t_end:g} s"))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with replacing(path) as tmp:            # a link at ``path`` is replaced
        fig.savefig(tmp, dpi=110)
    plt.close(fig)

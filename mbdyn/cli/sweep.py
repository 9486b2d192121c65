"""``mbdyn sweep MODEL``: run a model file over a grid of overrides; a table of results.

The work is ``mbdyn.analysis.sweep``; this module only reads the command line."""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys

from .. import limits
from ..analysis.schedulers import check_spec
from ..analysis.sweep import DEFAULT_QUANTITIES, parse_grid, sweep
from ..analysis.sweeps.quantities import column_of
from ..errors import ModelError
from ..escape import spreadsheet_cell
from ..files import check_target
from ..io.schema import parse_set_value
from ..viz.sweep_plots import FORMATS as PICTURES
from .common import (
    add_command,
    add_simulation_arguments,
    add_urdf_arguments,
    fmt,
    positive,
    positive_int,
    simulation_overrides,
    urdf_overrides,
)


def register(subparsers):
    p = add_command(subparsers, "sweep",
                    "Run MODEL once per member of a grid of overrides by dotted path and "
                    "keep quantities of each run in a table (CSV).  Ranges: START:STOP:N "
                    "(N points, ends included), START:STOP:N:log, or a list [a, b, \"pi/4\"].",
                    run, model_arguments=False)
    p.add_argument("model", metavar="MODEL", help="model file (.toml) or URDF robot (.urdf)")
    add_urdf_arguments(p)
    p.add_argument("--grid", metavar="PATH=VALUES", action="append", default=[],
                   help="one axis of the grid, e.g. parameters.Mz=-0.03:-0.001:8 or "
                        "initial.theta=[0.1, 0.2] (repeatable: every combination)")
    p.add_argument("--case", metavar="NAME", action="append",
                   help="case(s) to run (repeatable: an outer loop); default the file's")
    p.add_argument("--set", dest="fixed", metavar="PATH=VALUE", action="append", default=[],
                   help="override for every member, e.g. simulation.integrator=rk4")
    add_simulation_arguments(p, "for every member, after --set")
    p.add_argument("--quantity", "-q", dest="quantities", metavar="Q", action="append",
                   help="what to keep per member: final, events, t_final, energy_drift, "
                        "steps, rhs_evaluations, max:X, min:X, absmax:X, mean:X, std:X "
                        f"(default: {', '.join(DEFAULT_QUANTITIES)})")
    p.add_argument("--scheduler", default="serial", metavar="WHERE", type=scheduler_spec,
                   help="serial (default), processes, dask (a local Dask cluster) or "
                        "tcp://HOST:PORT (an existing Dask scheduler)")
    p.add_argument("--scheduler-timeout", type=positive, metavar="S",
                   help="the longest wait on a tcp:// scheduler: connecting, each result, "
                        f"each check that it answers (default {limits.SCHEDULER_TIMEOUT:g} s)")
    p.add_argument("--workers", type=positive_int, metavar="N", help="local worker processes")
    p.add_argument("--batched", action="store_true",
                   help="advance members in one compiled call (fixed-step, no events)")
    p.add_argument("--out", metavar="FILE", help="the table (.csv, or .parquet with pyarrow); "
                                                 "rows are written as members finish")
    p.add_argument("--resume", action="store_true",
                   help="keep the finished rows of --out and run only the rest")
    p.add_argument("--plot", metavar="QUANTITY",
                   help="a line (one grid axis) or heat map (two) of a table column, named "
                        "as in the table (absmax.theta) or as -q took it (absmax:theta); "
                        "written beside --out as .png (or to --plot-file)")
    p.add_argument("--plot-file", metavar="PNG", help="where --plot writes")
    p.add_argument("--json", action="store_true",
                   help="print the table as one JSON object {column: [values]} and nothing "
                        "else on stdout (the progress counter and a long sweep's estimate go "
                        "to stderr)")


def _fixed(items):
    out = {}
    for item in items:
        if "=" not in item:
            raise ModelError(f"--set {item}: expected PATH=VALUE, e.g. simulation.dt=1e-3")
        path, value = item.split("=", 1)
        out[path.strip()] = parse_set_value(value)
    return out


def scheduler_spec(text):
    """argparse type: a scheduler name or a well-formed address (nothing is connected)."""
    try:
        check_spec(text)
    except ModelError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def _check_outputs(out, plot_file):
    """Every output checked before any member runs (format, not a folder, a writable
    folder; matplotlib for a plot): nothing is lost to a bad name after the work."""
    if out:
        os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
        check_target(out, (".csv", ".parquet"), "table", "--out")
    if plot_file:
        check_target(plot_file, PICTURES, "picture", "--plot-file")
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            raise ModelError("--plot needs matplotlib: pip install \"mbdyn[plot]\" (or "
                             "pip install matplotlib)") from None


def _json_value(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def run(args):
    if args.resume and not args.out:
        raise ModelError("--resume needs --out FILE (the table to complete)")
    if args.out and not args.out.endswith((".csv", ".parquet")):
        raise ModelError(f"--out {args.out}: the table is written as .csv (or .parquet); "
                         "name the file so")
    if not args.grid:
        raise ModelError("give at least one --grid PATH=VALUES (e.g. "
                         "--grid parameters.Mz=-0.03:-0.001:8)")
    grid = parse_grid(args.grid)
    args.plot = column_of(args.plot) if args.plot else None      # -q absmax:X -> absmax.X
    plot_file = args.plot_file or (args.out.rsplit(".", 1)[0] + f"_{args.plot}.png"
                                   if args.plot and args.out else None)
    if args.plot and not plot_file:
        raise ModelError("--plot needs --out FILE or --plot-file PNG")
    _check_outputs(args.out, plot_file)
    result = sweep(args.model, grid, tuple(args.quantities or DEFAULT_QUANTITIES),
                   cases=args.case, fixed={**_fixed(args.fixed), **simulation_overrides(args),
                                           **{p: v for p, v, _ in urdf_overrides(args)}},
                   scheduler=args.scheduler,
                   workers=args.workers, out=args.out, resume=args.resume,
                   batched=args.batched, progress=None,
                   require_columns=[args.plot] if args.plot else [],
                   scheduler_timeout=args.scheduler_timeout)
    if args.plot:
        from ..viz.sweep_plots import plot_sweep
        plot_sweep(result, args.plot, plot_file, axes=list(grid))
    if args.json:
        table = {c: [_json_value(r[c]) for r in result.rows] for c in result.columns}
        sys.stdout.write(json.dumps(table) + "\n")
        return 0
    bad = [r for r in result.rows if r["status"] != "ok"]
    st = result.stats
    sys.stdout.write(f"{len(result.rows)} members ({st['ran']} run now, {len(bad)} not ok) "
                     f"on {st['scheduler']}{' batched' if st['batched'] else ''} in "
                     f"{fmt(st['wall_time_s'])} s\n")
    for r in bad[:10]:
        sys.stdout.write(f"  member {r['member']}: {r['status']}: {r['error']}\n")
    if args.out:
        sys.stdout.write(f"  wrote {result.path}\n")
    if args.plot:
        sys.stdout.write(f"  wrote {plot_file}\n")
    if not args.out and not args.plot:
        _print_table(result)
    return 0


def _print_table(result):
    """The table as CSV on stdout (briefly: 6 digits), text cells escaped as in every CSV
    mbdyn writes (never a spreadsheet formula), numbers as numbers."""
    writer = csv.writer(sys.stdout, lineterminator="\n")
    writer.writerow([spreadsheet_cell(c) for c in result.columns])
    for r in result.rows:
        writer.writerow([spreadsheet_cell(v) if isinstance(v, str) else
                         fmt(v) if isinstance(v, float) else str(v)
                         for v in (r[c] for c in result.columns)])

"""``mbdyn campbell MODEL --parameter NAME --values START:STOP:N``: modes against a parameter.

    mbdyn campbell MODEL --parameter NAME --values START:STOP:N [--case NAME]
                         [--set PATH=VALUE ...] [--effects LIST] [--orders 1,2]
                         [--whirl Y,Z ...] [--at equilibrium|initial] [--fixed NAMES]
                         [--not-spin] [--plot FILE] [--json]
"""
from __future__ import annotations

import sys

from .common import Estimate, add_command, load, print_json
from .vibration_args import add_vibration_arguments, names, value_range, whirl_pairs


def register(subparsers):
    p = add_command(subparsers, "campbell",
                    "Equilibrium, linearisation and modes at each value of a parameter; modes "
                    "tracked by shape (MAC); critical speeds and the onset of instability.", run)
    p.add_argument("--parameter", required=True, metavar="NAME",
                   help="a name in the file's [parameters], e.g. Omega")
    p.add_argument("--values", required=True, metavar="START:STOP:N",
                   help="START:STOP:N, START:STOP:Nlog, or a comma-separated list")
    p.add_argument("--orders", default="1", metavar="N,N",
                   help="spin-line orders for critical speeds (default 1)")
    p.add_argument("--at", choices=("equilibrium", "initial"), default="equilibrium")
    p.add_argument("--not-spin", action="store_true",
                   help="the parameter is not the spin speed (no spin lines, no critical "
                        "speeds)")
    p.add_argument("--plot", metavar="FILE", help="write the diagram (.png, .pdf, .svg)")
    add_vibration_arguments(p)


def run(args):
    from ..analysis.campbell import campbell
    from ..errors import ModelError
    from ..files import check_target
    if args.plot:                        # before the work: a bad path costs nothing
        check_target(args.plot, (".png", ".pdf", ".svg"), "picture", "--plot")
    scene = load(args)
    try:
        orders = [int(o) for o in names(args.orders)]
    except ValueError:
        raise ModelError(f"--orders {args.orders!r}: give integers, e.g. 1,2") from None
    if not orders or any(o < 1 for o in orders):
        raise ModelError(f"--orders {args.orders!r}: give whole numbers >= 1, e.g. 1,2")
    estimate = Estimate("values")
    try:
        cb = campbell(scene, args.parameter, value_range(args.values), orders=orders,
                      whirl=whirl_pairs(args), at=args.at, fixed=names(args.fixed),
                      spin_is_parameter=not args.not_spin, progress=estimate)
    finally:
        estimate.close()
    if args.plot:
        cb.plot(args.plot, orders=orders)
    if args.json:
        print_json(scene, {"campbell": cb.to_dict()})
        return 0
    sys.stdout.write(f"{scene.name}: modes against {args.parameter}\n{cb.table()}\n")
    if args.plot:
        sys.stdout.write(f"diagram written to {args.plot}\n")
    return 0

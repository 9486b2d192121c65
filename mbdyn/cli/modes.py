"""``mbdyn modes MODEL``: linearise and list natural frequencies, damping and shapes.

    mbdyn modes MODEL [--case NAME] [--set PATH=VALUE ...] [--effects LIST]
                      [--at equilibrium|initial] [--route numeric|symbolic]
                      [--fixed NAMES] [--whirl Y,Z ...] [--t T] [--json]
                      [--independent NAMES]

A closed mechanism is linearised in independent coordinates (chosen by pivoted QR of the
constraint Jacobian, or named by ``--independent``); each mode lists how the dependent
coordinates move with them.
"""
from __future__ import annotations

import sys

from .common import add_command, heading, load, positive, positive_int, print_json
from .vibration_args import add_vibration_arguments, names, whirl_pairs


def register(subparsers):
    p = add_command(subparsers, "modes",
                    "Linearise the model about its equilibrium (or its initial state) into "
                    "M x'' + (D + G) x' + (K + N) x = 0 and list its modes and stability.", run)
    p.add_argument("--at", choices=("equilibrium", "initial"), default="equilibrium",
                   help="operating point (default: the equilibrium near the initial state)")
    p.add_argument("--route", choices=("numeric", "symbolic"), default="numeric",
                   help="derivatives by central differences (default) or from the closed-form "
                        "equations")
    p.add_argument("--matrices", action="store_true", help="also print M, D, G, K, N")
    p.add_argument("--animate", metavar="FILE", help="animate a mode shape about the "
                   "operating point: .gif, .mp4 or .html")
    p.add_argument("--mode", type=positive_int, default=1, metavar="K",
                   help="which mode --animate draws (1 = the lowest, as listed)")
    p.add_argument("--amplitude", type=positive, default=0.1,
                   help="--animate's amplitude in the tangent coordinates (rad or m)")
    p.add_argument("--independent", metavar="NAMES", default="",
                   help="closed loops: the independent coordinates (comma-separated); "
                        "default: chosen by pivoted QR of the constraint Jacobian")
    add_vibration_arguments(p)


def run(args):
    import numpy as np

    from ..analysis.equilibrium import equilibrium
    from ..analysis.linearize import linearize
    from ..analysis.modes import modes
    if args.animate:
        from ..viz.animate import check_output
        check_output(args.animate)     # before the work: a bad path costs nothing
    scene = load(args)
    model = scene.model
    q, u = scene.q0, scene.u0
    eq = None
    if args.at == "equilibrium":
        eq = equilibrium(model, q, u, t=args.t, fixed=names(args.fixed))
        q = eq.q
    lin = linearize(model, q, u, t=args.t, route=args.route,
                    independent=names(args.independent) or None)
    md = modes(lin, whirl=whirl_pairs(args))
    if args.animate:
        from ..errors import ModelError
        from ..viz.modeshape import animate_mode
        if not 1 <= args.mode <= len(md):
            raise ModelError(f"--mode {args.mode}: the model has modes 1 to {len(md)}")
        animate_mode(lin, md[args.mode - 1], args.animate, amplitude=args.amplitude)
        sys.stderr.write(f"mbdyn: wrote {args.animate}\n")
    if args.json:
        print_json(scene, {"at": args.at, "equilibrium": eq.to_dict() if eq else None,
                           "linearization": lin.to_dict(), **md.to_dict()})
        return 0
    w = sys.stdout.write
    w(f"{heading(scene)}: linearised at the {args.at} state by the {args.route} route"
      + (f" (error estimate {lin.error:.1e})" if lin.route == "numeric" else "") + "\n")
    w(f"  coordinates: {', '.join(lin.names)}\n")
    if lin.basis is not None:
        dependent = [n for n in lin.coordinates if n not in lin.names]
        w(f"  closed loops: independent coordinates {', '.join(lin.names)}; "
          f"{', '.join(dependent)} follow on the constraints\n")
    if args.matrices:
        with np.printoptions(precision=6, suppress=False, linewidth=100):
            for k in ("M", "D", "G", "K", "N"):
                w(f"  {k} =\n{getattr(lin, k)}\n")
    w(md.table() + "\n")
    return 0

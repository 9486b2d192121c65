"""``mbdyn equilibrium MODEL``: a static or steady equilibrium near the initial state.

    mbdyn equilibrium MODEL [--case NAME] [--set PATH=VALUE ...] [--effects LIST]
                            [--fixed NAMES] [--t T] [--json]
"""
from __future__ import annotations

import sys

from .common import add_command, fmt, heading, load, print_json
from .vibration_args import add_vibration_arguments, names


def register(subparsers):
    p = add_command(subparsers, "equilibrium",
                    "Find the configuration where the generalized forces vanish at the "
                    "initial speeds (zero unless the file gives spin speeds), starting from "
                    "the initial coordinates.", run)
    add_vibration_arguments(p, whirl=False)


def run(args):
    from ..analysis.equilibrium import equilibrium
    scene = load(args)
    eq = equilibrium(scene.model, scene.q0, scene.u0, t=args.t, fixed=names(args.fixed))
    if args.json:
        print_json(scene, {"equilibrium": eq.to_dict()})
        return 0
    w = sys.stdout.write
    w(heading(scene) + "\n")
    w(f"  equilibrium by {eq.method}: {eq.iterations} iterations, residual "
      f"{fmt(eq.residual)}, Jacobian condition {fmt(eq.condition)}\n")
    if eq.time_dependent:
        w("  (the equations depend on time here: this is the equilibrium at t only)\n")
    if eq.independent:
        w(f"  closed loops: solved in the independent coordinates "
          f"{', '.join(eq.independent)}, the others on the constraints\n")
    width = max(len(n) for n in scene.model.coordinates)
    for n, v in zip(scene.model.coordinates, eq.q):
        w(f"    {n:<{width}} = {fmt(v)}\n")
    return 0

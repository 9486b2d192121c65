"""``mbdyn eom MODEL``: the equations of motion of a model file in closed form.

    mbdyn eom MODEL [--case NAME] [--set PATH=VALUE ...]
                    [--method newton-euler|jourdain|lagrange] [--steps] [--solve]
                    [--frames own|inertial] [--simplify compact|expand|none|trigsimp]
                    [--format text|latex|markdown|json]

``--steps`` prints the derivation the way the textbook writes its solutions (frames,
transformation matrices, positions, angular velocities and accelerations in each body's own
frame, velocities and accelerations of the centres of mass, masses, momenta, forces,
reactions or Jacobians or energies, then the equations); ``--solve`` solves them for the
accelerations (and, by Newton-Euler, for every reaction component).  ``--format json`` prints
one object (see ``mbdyn.symbolic.report``) whose expression strings ``sympy.sympify`` reads
back with the model's names as symbols.  A model with loop joints gets its constraint
equations ``phi(q, t) = 0``, their Jacobian, ``gamma`` and the equations with the
multipliers ``M u' = f + G^T lambda`` in every format (``mbdyn.symbolic.loops``).
"""
from __future__ import annotations

import json
import sys

from .. import limits
from ..symbolic.derive import derive
from ..symbolic.methods import METHODS
from ..symbolic.simplify import MODES
from ..symbolic.walk import FRAMES

FORMATS = ("text", "latex", "markdown", "json")


def register(subparsers):
    from .common import add_command
    p = add_command(subparsers, "eom",
                    "Derive a model's equations of motion with sympy by Newton-Euler (with "
                    "the joint reactions), Newton-Euler-Jourdain or Lagrange; print them, "
                    "optionally with the textbook's derivation steps and solved for the "
                    "accelerations and reactions.", eom)
    add_eom_arguments(p)


def add_eom_arguments(p):
    p.add_argument("--method", choices=METHODS, default="jourdain",
                   help="formulation (default jourdain)")
    p.add_argument("--steps", action="store_true",
                   help="print the derivation step by step, as the textbook does")
    p.add_argument("--solve", action="store_true",
                   help="solve for the accelerations (and, by newton-euler, the reactions); "
                        "practical for a few degrees of freedom")
    p.add_argument("--frames", choices=FRAMES, default="own",
                   help="write vectors in each body's own frame (default, compact) or in the "
                        "inertial frame")
    p.add_argument("--simplify", choices=MODES, default="compact",
                   help="simplification (default compact: expansion and sin^2+cos^2=1 where "
                        "it shortens; trigsimp is slow)")
    p.add_argument("--format", choices=FORMATS, default="text", dest="format",
                   help="output format (default text)")


def render(derivation, fmt="text", steps=False):
    """The text ``mbdyn eom`` prints for a derivation."""
    if fmt == "json":
        return json.dumps(derivation.to_dict(steps=steps), indent=2) + "\n"
    if fmt == "latex":
        return derivation.to_latex(steps=steps)
    if fmt == "markdown":
        return derivation.to_markdown(steps=steps)
    return derivation.to_text(steps=steps)


def eom(args, out=None):
    from .common import load
    out = out if out is not None else sys.stdout
    scene = load(args)
    d = derive(scene.model, args.method, frames=args.frames, simplify=args.simplify,
               solve=args.solve, max_nodes=limits.MAX_EQUATION_NODES)
    out.write(render(d, args.format, args.steps))
    return 0

"""Are two derivations the same equations?  Symbolically for small models, numerically for all.

``same_expression(a, b)`` decides ``a == b`` for rational functions of sines and cosines:
it brings ``a - b`` over one denominator, expands sums of angles (``expand_trig``) and
reduces every ``sin(x)**2`` to ``1 - cos(x)**2``, after which a zero difference is a literal
0.  That is a decision procedure for polynomials in ``sin``/``cos`` of independent angles, and
much faster than ``simplify``.

``compare_numerically`` evaluates ``M`` and ``f`` of a derivation (or the accelerations,
or the reactions) at random states and compares them with the numeric engine's.
"""
from __future__ import annotations

import numpy as np
import sympy

from .simplify import operations


def _canonical_trig(expr):
    expr = sympy.expand(sympy.expand_trig(expr))
    for _ in range(64):
        mapping = {}
        for p in expr.atoms(sympy.Pow):
            b, e = p.args
            if isinstance(b, sympy.sin) and e.is_Integer and e >= 2:
                k = int(e)
                mapping[p] = b ** (k % 2) * (1 - sympy.cos(b.args[0]) ** 2) ** (k // 2)
        if not mapping:
            break
        expr = sympy.expand(expr.xreplace(mapping))
    return expr


def same_expression(a, b):
    """True if ``a`` and ``b`` are the same function (see the module docstring)."""
    diff = sympy.together(sympy.sympify(a) - sympy.sympify(b))
    num, _ = sympy.fraction(diff)
    return _canonical_trig(num) == 0


def same_matrix(A, B):
    A, B = sympy.Matrix(A), sympy.Matrix(B)
    return A.shape == B.shape and all(same_expression(x, y) for x, y in zip(A, B))


def random_states(model, n=5, seed=1, scale=1.0):
    """``n`` random ``(q, u, t)`` with unit quaternions."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = model.default_coordinates() + rng.uniform(-scale, scale, model.nq)
        model.normalize_quaternions(q)
        u = rng.uniform(-scale, scale, model.nu)
        out.append((q, u, float(rng.uniform(0, 2))))
    return out


def compare_numerically(derivation, states=None, what=("mass_matrix", "forcing")):
    """Largest relative difference between the derivation and the numeric engine over
    ``states`` (default: five random ones) for each of ``what``: ``mass_matrix``,
    ``forcing``, ``accelerations`` and ``reactions`` (world components, as
    ``Model.reactions``).  A closed mechanism's accelerations and reactions are taken at
    the engine's multipliers (``Model.multipliers``; give states on the mechanism)."""
    model = derivation.model
    states = random_states(model) if states is None else states
    loops = derivation.constraints is not None
    out = {}
    for name in what:
        worst = 0.0
        fn = derivation.numeric(name)
        for q, u, t in states:
            lam = model.multipliers(q, u, t)[1] if loops and name in (
                "accelerations", "reactions") else None
            if name == "mass_matrix":
                a, b = fn(q, u, t), model.mass_matrix(q, t)
            elif name == "forcing":
                a, b = fn(q, u, t), model.forcing(q, u, t)
            elif name == "accelerations":
                a, b = fn(q, u, t, multipliers=lam), model.forward_dynamics(q, u, t)
            else:
                ref = model.reactions(q, u, t)
                kin = model.kinematics(q, u, t=t)
                a, b = [], []
                values = np.asarray(fn(q, u, t, multipliers=lam), dtype=float).reshape(-1, 6)
                for joint, vals in zip(model.joints, values):
                    i = model.frame_index(model.joint(joint).child)
                    R = np.eye(3) if derivation.frames == "inertial" else kin.R[i]
                    a.extend(np.concatenate([R @ vals[:3], R @ vals[3:]]))
                    b.extend(np.concatenate(ref[joint]))
                a, b = np.array(a), np.array(b)
            a, b = np.atleast_1d(a), np.atleast_1d(b)
            scale = max(np.abs(b).max(initial=0.0), 1e-300)
            worst = max(worst, float(np.abs(a - b).max(initial=0.0) / scale))
        out[name] = worst
    return out


def compare_methods(derivations):
    """Symbolic check that derivations (of one model) give the same ``M`` and ``f``:
    ``{(method_a, method_b): True/False}``."""
    out = {}
    ds = list(derivations)
    for i in range(len(ds)):
        for j in range(i + 1, len(ds)):
            a, b = ds[i], ds[j]
            out[(a.method, b.method)] = (same_matrix(a.mass_matrix, b.mass_matrix)
                                         and same_matrix(a.forcing, b.forcing))
    return out


__all__ = ["same_expression", "same_matrix", "random_states", "compare_numerically",
           "compare_methods", "operations"]

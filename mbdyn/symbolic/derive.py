"""``derive``: the equations of motion of a model in closed form, by one of three methods.

    d = mb.derive(model, method="newton-euler", solve=True)
    d.mass_matrix, d.forcing          # M(q), f(q, u, t) of M u' = f (sympy matrices)
    d.accelerations                   # {speed name: expression of u'} (solve=True)
    d.reactions                       # {joint: [Fx, Fy, Fz, Mx, My, Mz]} (newton-euler, solve)
    d.constraints                     # closed loops: phi, Phi_q, G, gamma, lambda (else None)
    d.constrained_equations()         # M u' = f + G^T lambda and G u' = gamma, as sympy.Eq
    d.steps()                         # the derivation, step by step, as the textbook does it
    print(d.to_text(steps=True))      # or to_latex(), to_markdown(), to_dict() / to_json()

Reactions are the force and the moment the parent exerts on the child at the child frame's
origin, in the child frame's own components (``frames="own"``, the default) or in inertial
components (``frames="inertial"``).

A model with loop joints (``mbdyn.symbolic.loops``): ``M`` and ``f`` are the tree's, and the
loops add ``G^T lambda`` to ``f`` (``M u' = f + G^T lambda``, ``G u' = gamma``); by
Newton-Euler the multipliers' forces and moments act on the bodies (the reactions include
them); ``solve=True`` gives the accelerations in terms of the multipliers.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field

import sympy

from .. import limits
from ..errors import ModelError
from .loops import add_multiplier_loads, loop_equations
from .methods import FORMULATIONS, METHODS
from .simplify import (MODES, diff, finish_matrix, operations, operations_after_cse,
                       replace_shared, tree_size)
from .solve import solve_linear, substitute_rates
from .walk import FRAMES, Walk, too_large

#: results (M and f together) up to this many nodes get the final tidying (``finish``)
FINISH_BUDGET = 5000


def _as_model(model_or_system):
    return _model_of(model_or_system)


def _model_of(model_or_system):
    from ..compiled.model import Model
    if isinstance(model_or_system, Model):
        return model_or_system
    if hasattr(model_or_system, "compile") and hasattr(model_or_system, "add_joint"):
        return model_or_system.compile()
    if hasattr(model_or_system, "model"):          # a loaded scene
        return model_or_system.model
    raise ModelError(f"derive needs a System, a compiled Model or a loaded scene, got "
                     f"{type(model_or_system).__name__}")


def _quotient(num, den, limit=3000):
    """``num / den`` with the factors they share cancelled (when they are small enough for
    ``sympy.cancel`` to be quick)."""
    if den == 1:
        return num
    from .simplify import tree_size
    if tree_size(num) + tree_size(den) > limit:
        return num / den
    n, d = sympy.factor_terms(num), sympy.factor_terms(den)
    g = sympy.gcd_terms(sympy.Integer(1) * n / d)
    try:
        c = sympy.cancel(num / den)
    except Exception:
        c = g
    return min((g, c, num / den), key=tree_size)


@dataclass
class Derivation:
    """The equations of motion of a model by one method (sympy objects); see ``derive``."""
    model: object
    method: str
    frames: str
    simplify: str
    walk: Walk
    equations: object
    mass_matrix: sympy.Matrix
    forcing: sympy.Matrix
    accelerations: dict | None = None
    reactions: dict | None = None
    denominator: sympy.Expr | None = None
    stats: dict = field(default_factory=dict)
    constraints: object = None          # loops.LoopEquations of a closed mechanism

    # ------------------------------------------------------------------ basic views
    @property
    def symbols(self):
        return self.walk.sym

    @property
    def coordinates(self):
        return tuple(self.model.coordinates)

    @property
    def speeds(self):
        return tuple(self.model.speeds)

    @property
    def rates(self):
        """Symbols of the speed rates ``u'`` in ``speeds`` order."""
        return tuple(self.walk.sym.ud)

    @property
    def kinematic_equations(self):
        """``{coordinate symbol: rate expression}``: ``q' = N(q) u``."""
        return dict(self.walk.qdot)

    def equations_of_motion(self):
        """The rows of ``M u' = f`` as ``sympy.Eq`` (left: ``M u'``, right: ``f``)."""
        ud = sympy.Matrix(self.rates)
        lhs = self.mass_matrix * ud
        return [sympy.Eq(lhs[k], self.forcing[k]) for k in range(len(ud))]

    def constrained_equations(self):
        """A closed mechanism's equations with the multipliers, as ``sympy.Eq``: the rows
        of ``M u' = f + G^T lambda`` (by Lagrange ``d/dt dL/dq' - dL/dq = Q + Phi_q^T
        lambda``: left ``M q'' - f + Q``, right ``Q + Phi_q^T lambda``), then those of
        ``G u' = gamma``.  A tree's are ``equations_of_motion()``."""
        c = self.constraints
        if c is None:
            return self.equations_of_motion()
        ud = sympy.Matrix(self.rates)
        lhs = self.mass_matrix * ud
        rhs = self.forcing + c.constraint_forces()
        if self.method == "lagrange":
            Q = self.equations.details["generalized_forces"]
            lhs, rhs = lhs - self.forcing + Q, Q + c.constraint_forces()
        acc = c.G * ud
        return ([sympy.Eq(lhs[k], rhs[k], evaluate=False) for k in range(len(ud))]
                + [sympy.Eq(acc[k], c.gamma[k], evaluate=False) for k in range(len(c.rows))])

    def names(self):
        """``{name: Symbol}`` of every parameter, coordinate, speed, rate and ``t`` (and
        multiplier, for a closed mechanism)."""
        out = dict(self.walk.sym.table)
        out.update((s.name, s) for s in self.walk.constants)   # flexible bodies' invariants
        if self.constraints is not None:
            out.update((s.name, s) for s in self.constraints.multipliers)
        return out

    def subs(self, values):
        """A copy with ``values`` substituted in the equations (and solutions), keys given
        as names (``"theta2"``), plain ``sympy.Symbol("theta2")`` or the derivation's own
        symbols.  The derivation's symbols are real (``Symbol(name, real=True)``), which a
        plain symbol is not equal to, so ``mass_matrix.subs({Symbol("theta2"): 0})`` would
        change nothing; this method maps by name, and refuses unknown names."""
        import dataclasses
        table = {**self.walk.sym.table, **{s.name: s for s in self.walk.constants}}
        mapping = {}
        for key, value in dict(values).items():
            name = key if isinstance(key, str) else getattr(key, "name", None)
            if name not in table:
                raise ModelError(f"subs: {key!r} is not a name of this derivation; its names "
                                 f"are {', '.join(table)}")
            mapping[table[name]] = value
        sub = lambda e: e.xreplace(mapping) if hasattr(e, "xreplace") else e  # noqa: E731
        return dataclasses.replace(
            self, mass_matrix=sub(self.mass_matrix), forcing=sub(self.forcing),
            accelerations=None if self.accelerations is None else
            {k: sub(v) for k, v in self.accelerations.items()},
            reactions=None if self.reactions is None else
            {k: (sub(v) if not isinstance(v, (tuple, list)) else type(v)(sub(x) for x in v))
             for k, v in self.reactions.items()},
            constraints=None if self.constraints is None else self.constraints.subs(mapping))

    # ------------------------------------------------------------------ numbers
    def numeric(self, what="mass_matrix"):
        """A function ``(q, u, t=0, parameters=None, multipliers=None)`` -> numpy array of
        ``mass_matrix``, ``forcing``, ``accelerations`` (in ``speeds`` order) or
        ``reactions`` (joints in model order, six components each) -- for checks, not for
        speed (see ``codegen``).  A closed mechanism's accelerations and reactions hold the
        multipliers: give their values (``Model.multipliers``) in ``constraints.rows``
        order."""
        import numpy as np
        from .evaluate import evaluate
        sym = self.walk.sym
        if what == "accelerations":
            if self.accelerations is None:
                raise ModelError("derive(..., solve=True) first")
            expr = sympy.Matrix([self.accelerations[s] for s in self.speeds])
        elif what == "reactions":
            if self.reactions is None:
                raise ModelError("derive(..., method='newton-euler', solve=True) first")
            expr = sympy.Matrix([[e for e in self.reactions[j]] for j in self.model.joints])
        else:
            expr = getattr(self, what)
        shape = expr.shape
        flat = list(expr)
        params = dict(self.model.parameters)
        lam = self.constraints.multipliers if self.constraints is not None else ()

        def evaluate_at(q, u, t=0.0, parameters=None, multipliers=None):
            vals = {sym.t: float(t)}
            vals.update({s: float(x) for s, x in zip(sym.q, q)})
            vals.update({s: float(x) for s, x in zip(sym.u, u)})
            p = dict(params, **(parameters or {}))
            vals.update({s: float(p[n]) for n, s in sym.params.items()})
            vals.update(self.walk.constants)         # flexible bodies' invariants
            if lam and multipliers is None and what in ("accelerations", "reactions"):
                raise ModelError(f"model {self.model.name!r}: its {what} hold the loop "
                                 "joints' multipliers; pass multipliers=... "
                                 "(Model.multipliers(q, u, t)[1])")
            vals.update({s: float(x) for s, x in zip(lam, multipliers if multipliers
                                                     is not None else ())})
            return np.array(evaluate(flat, vals), dtype=float).reshape(shape).squeeze()
        return evaluate_at

    # ------------------------------------------------------------------ reports
    def steps(self):
        """The derivation as the textbook writes it: a list of ``Step``."""
        from .steps import build_steps
        return build_steps(self)

    def to_dict(self, steps=False):
        """The ``mbdyn eom --format json`` object (expression strings parseable by
        ``sympy.sympify`` with the model's names as symbols)."""
        from .report import as_dict
        return as_dict(self, steps=steps)

    def to_json(self, steps=False, indent=2):
        return json.dumps(self.to_dict(steps=steps), indent=indent)

    def to_text(self, steps=False):
        from .report import as_text
        return as_text(self, steps=steps)

    def to_latex(self, steps=False):
        from .report import as_latex
        return as_latex(self, steps=steps)

    def to_markdown(self, steps=False):
        from .report import as_markdown
        return as_markdown(self, steps=steps)

    def __repr__(self):
        return (f"<Derivation {self.model.name!r} by {self.method}: {len(self.speeds)} speeds, "
                f"{self.stats.get('operations', '?')} operations>")


def derive(model_or_system, method="jourdain", *, frames="own", simplify="compact",
           solve=False, measure=True, max_nodes=None):
    """Derive the equations of motion of a model in closed form.

    ``method``: ``"newton-euler"`` (per-body equations with the joint reactions as unknowns),
    ``"jourdain"`` (``M = sum J^T m J``, reactions eliminated) or ``"lagrange"`` (from the
    kinetic and potential energies and the generalized forces of the loads).  ``frames``:
    write each body's vectors in its own frame (``"own"``, compact) or in the inertial
    frame (``"inertial"``).  ``simplify``: ``"compact"`` (default), ``"expand"``,
    ``"none"`` or ``"trigsimp"`` (see ``mbdyn.symbolic.simplify``).  ``solve``: also solve
    for the accelerations (and, for newton-euler, every reaction component) in closed form
    -- practical for a few degrees of freedom.  ``measure``: count the operations of ``M``
    and ``f`` before and after cse into ``stats`` (before cse only up to
    ``limits.MAX_EQUATION_NODES`` parse-tree nodes: counting is as slow as printing).
    ``max_nodes``: refuse equations (and solutions) whose parse tree, written out, would
    have more nodes -- a chain's grows by 2 to 5 per link -- as soon as the walk or the
    formulation shows it (``mbdyn eom`` passes ``limits.MAX_EQUATION_NODES``).
    """
    if method not in METHODS:
        raise ModelError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
    if frames not in FRAMES:
        raise ModelError(f"unknown frames {frames!r}; use one of {', '.join(FRAMES)}")
    if simplify not in MODES:
        raise ModelError(f"unknown simplify {simplify!r}; use one of {', '.join(MODES)}")
    if max_nodes is not None and (isinstance(max_nodes, bool) or not isinstance(
            max_nodes, int) or max_nodes < 1):
        raise ModelError(f"derive: max_nodes must be a whole number >= 1 (or None), got "
                         f"{max_nodes!r}")
    model = _as_model(model_or_system)
    start = time.perf_counter()
    shorter = "" if method == "jourdain" and not solve else \
        ", or use the jourdain method without solving (the shortest form)"
    walk = Walk(model, frames=frames, simplify=simplify, max_nodes=max_nodes)
    t_walk = time.perf_counter()
    eq, loops = _formulate(walk, method)
    size = sum(tree_size(e) for e in eq.M) + sum(tree_size(e) for e in eq.f)
    if max_nodes is not None and size > max_nodes:
        raise too_large(model, f"M and f by {method}", size, max_nodes, shorter)
    if size <= FINISH_BUDGET:               # small results: expand, reduce and tidy them
        M = finish_matrix(eq.M, simplify, units=walk.units)
        f = finish_matrix(eq.f, simplify, units=walk.units)
    else:                                   # large ones stay in the walk's nested form
        M, f = eq.M, eq.f
    if loops is not None:
        loops.tidy(simplify, walk.units, FINISH_BUDGET)
        if max_nodes is not None:           # the constraints are printed with M and f
            size = loops.size()
            if size > max_nodes:
                raise too_large(model, "the constraint equations, their Jacobian and gamma",
                                size, max_nodes)
    t_eq = time.perf_counter()
    d = Derivation(model, method, frames, simplify, walk, eq, M, f, constraints=loops)
    if solve:
        _solve(d, eq, loops, simplify, walk.units)
        solved = sum(tree_size(e) for e in d.accelerations.values()) + sum(
            tree_size(e) for comps in (d.reactions or {}).values() for e in comps)
        if max_nodes is not None and solved > max_nodes:
            raise too_large(model, "the solved accelerations" + (" and reactions" if
                            d.reactions else ""), solved, max_nodes, shorter)
    end = time.perf_counter()
    d.stats = {"derive_s": end - start, "walk_s": t_walk - start, "equations_s": t_eq - t_walk,
               "solve_s": end - t_eq}
    if measure:
        if sum(tree_size(e) for e in M) + sum(tree_size(e) for e in f) \
                <= limits.MAX_EQUATION_NODES:
            d.stats["operations"] = operations(M) + operations(f)
        d.stats["operations_after_cse"] = operations_after_cse([M, f])
    return d


def _formulate(walk, method):
    """``(equations, loops)``: the method's ``M`` and ``f``, and a closed mechanism's
    ``LoopEquations`` (None for a tree); by Newton-Euler the multipliers' forces act on the
    bodies (their reactions include them), then leave ``f``."""
    loops = loop_equations(walk)
    if loops is not None and method == "newton-euler":
        add_multiplier_loads(walk, loops)
    eq = FORMULATIONS[method](walk)
    if loops is not None and method == "newton-euler":
        _split_multipliers(eq, loops)
    return eq, loops


def _solve(d, eq, loops, simplify, units):
    """``d.accelerations`` (in terms of the multipliers of a closed mechanism) and, by
    Newton-Euler, ``d.reactions``, in closed form over the common denominator."""
    M, f = d.mass_matrix, d.forcing
    rhs = f if loops is None else f + loops.constraint_forces()
    nums, den = solve_linear(M, rhs, simplify, units)
    d.denominator = den
    d.accelerations = {s: _quotient(n, den) for s, n in zip(d.model.speeds, nums)}
    if d.method != "newton-euler":
        return
    d.reactions = {}
    for joint in d.model.joints:
        AF, bF, AM, bM = eq.details["reactions"].linear(joint)
        comps = []
        for A, b in ((AF, bF), (AM, bM)):
            for r in range(3):
                if b[r] == 0 and all(a == 0 for a in A[r, :]):
                    comps.append(sympy.Integer(0))
                    continue
                num = substitute_rates(A[r, :], b[r], nums, den, simplify, units)
                comps.append(_quotient(num, den))
        d.reactions[joint] = comps


def _split_multipliers(eq, loops):
    """Newton-Euler with the multipliers' loads on the bodies: ``f`` without them, and
    their generalized forces (``G^T`` as Newton-Euler projects them) in
    ``eq.details["constraint_forces"]``."""
    lam = loops.multipliers
    eq.details["constraint_forces"] = sympy.Matrix(
        eq.f.rows, len(lam), lambda r, c: diff(eq.f[r], lam[c]))
    eq.f = replace_shared(eq.f, {x: sympy.Integer(0) for x in lam}).applyfunc(loops.walk.s)

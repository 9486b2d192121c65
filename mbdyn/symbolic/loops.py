"""Closed loops in closed form: step 3's constraint equations, their Jacobian and the
multipliers' terms of the equations of motion.

Every loop joint is written as the numeric kernels write it (``compiled.constraint_packing``,
``kernels.constraints``): a few primitive constraints between a point or vector fixed in
its parent frame ``p`` and one fixed in its child ``c``, in world components, with the
walk's positions and rotations of the frames::

    POINT   P_c - P_p = 0                          3 rows  (revolute, spherical, fixed,
                                                             universal)
    PERP    a . b = 0, a fixed in p, b in c        1 row   (revolute, cylindrical: the axis
                                                             against two normals; prismatic,
                                                             fixed: e2.f3, e3.f1, e1.f2;
                                                             universal: the two axes)
    SLIDE   (P_c - P_p) . n = 0, n fixed in p      1 row   (prismatic, cylindrical)
    DIST    (|P_c - P_p|^2 - L^2) / 2 = 0          1 row   (distance)
    COUPLE  q_a - ratio q_b - offset = 0           1 row   (coupling)

rows labelled as ``Model.constraint_rows`` ("D.x", "D.perp1" ...).  Then
``Phi_q = d phi / d q``; the speed form ``G = Phi_q N(q)`` (``q' = N(q) u``; ``G = Phi_q``
where the speeds are the coordinates' rates), so that ``d phi / dt = G u + phi_t``
(``phi_t``: the drives' part); ``gamma = -(d/dt (G u + phi_t))`` at ``u' = 0``, so that
the accelerations satisfy ``G u' = gamma``; one multiplier ``lambda_k`` a row, and the
equations of motion ``M(q) u' = f(q, u, t) + G^T lambda`` (by Lagrange
``d/dt dL/dq' - dL/dq = Q + Phi_q^T lambda``).  The multipliers mean what
``Model.multipliers`` returns: a point's force, a perpendicularity's moment, a rod's
tension over its length, a coupling's effort, as the parent exerts them on the child.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy

from .simplify import FINISH_LIMIT, diff, finish_matrix, free_symbols, tree_size
from .step_record import LATEX_NAMES
from .symbols import (axis_vector, canonical, cross, exact, exact_vector,
                      orientation_matrix)

Z3 = sympy.zeros(3, 1)


@dataclass
class Primitive:
    """One primitive constraint of a loop joint (world vectors, for the trace and for the
    multipliers' wrenches)."""
    kind: str                # "POINT", "PERP", "SLIDE", "DIST" or "COUPLE"
    joint: str
    rows: tuple              # row indices into LoopEquations.rows
    parent: str = ""
    child: str = ""
    points: tuple = ()       # (s_p, s_c): the points in the frames' own components
    world: tuple = ()        # (P_p, P_c) in world components
    vector: object = None    # PERP: b x a; SLIDE: n (world)
    coupled: tuple = ()      # COUPLE: (follower joint, leader joint, ratio)


@dataclass
class LoopEquations:
    """The constraint equations of a model's loop joints in closed form (see the module
    docstring): ``rows`` (labels), ``joints`` (the loop joint of each row), ``phi`` (m x 1),
    ``jacobian`` (``Phi_q``, m x nq), ``G`` (m x nu), ``phi_t`` (m x 1), ``multipliers``
    (a ``lambda`` symbol a row), ``gamma`` (computed when first asked for)."""
    walk: object
    rows: tuple
    joints: tuple
    phi: sympy.Matrix
    jacobian: sympy.Matrix
    G: sympy.Matrix
    phi_t: sympy.Matrix
    multipliers: tuple
    primitives: list = field(default_factory=list)
    _gamma: object = None
    _finish: tuple | None = None        # (mode, units) of the printed results' tidying

    @property
    def speed_form(self):
        """True where ``G`` differs from ``Phi_q`` (quaternion joints: ``u != q'``)."""
        return self.G is not self.jacobian

    @property
    def gamma(self):
        """``G u' = gamma``: minus the constraints' second time derivative at ``u' = 0``."""
        if self._gamma is None:
            walk = self.walk
            psi = self.G * sympy.Matrix(walk.sym.u) + self.phi_t if walk.sym.u else self.phi_t
            self._gamma = psi.applyfunc(lambda e: walk.s(-_rate_at_rest(walk, e)))
            if self._finish is not None:
                self._gamma = finish_matrix(self._gamma, *self._finish)
        return self._gamma

    def size(self):
        """Parse-tree nodes of ``phi``, ``Phi_q``, ``G`` and ``gamma`` written out."""
        mats = [self.phi, self.jacobian, self.gamma] + ([self.G] if self.speed_form else [])
        return sum(tree_size(e) for M in mats for e in M)

    def tidy(self, mode, units=(), budget=5000):
        """The last touch for printing (``simplify.finish``: sums of angles contracted,
        terms grouped), on equations up to ``budget`` parse-tree nodes; ``gamma`` too
        when it is derived."""
        if sum(tree_size(e) for M in (self.phi, self.jacobian) for e in M) > budget:
            return
        same = self.G is self.jacobian
        self.phi, self.jacobian, self.phi_t = (finish_matrix(M, mode, units=units) for M in
                                               (self.phi, self.jacobian, self.phi_t))
        self.G = self.jacobian if same else finish_matrix(self.G, mode, units=units)
        self._finish = (mode, FINISH_LIMIT, units)

    def constraint_forces(self):
        """``G^T lambda``: the generalized forces of the multipliers (nu x 1)."""
        lam = sympy.Matrix(self.multipliers)
        return (self.G.T * lam).applyfunc(self.walk.s)

    def subs(self, mapping):
        """A copy with ``mapping`` (``{symbol: value}``) put in every matrix (``gamma``
        derived first, from the unsubstituted equations)."""
        import dataclasses
        sub = lambda M: M.xreplace(mapping)  # noqa: E731
        return dataclasses.replace(self, phi=sub(self.phi), jacobian=sub(self.jacobian),
                                   G=sub(self.G), phi_t=sub(self.phi_t),
                                   _gamma=sub(self.gamma))

    def numeric(self, what="phi"):
        """A function ``(q, u=None, t=0, parameters=None)`` -> numpy array of ``phi``,
        ``jacobian``, ``G``, ``phi_t`` or ``gamma`` (for checks)."""
        from .evaluate import evaluate
        expr = getattr(self, what)
        sym, shape, flat = self.walk.sym, expr.shape, list(expr)
        params = dict(self.walk.model.parameters)

        def at(q, u=None, t=0.0, parameters=None):
            vals = {sym.t: float(t)}
            vals.update({s: float(x) for s, x in zip(sym.q, q)})
            vals.update({s: float(x) for s, x in zip(sym.u, np.zeros(len(sym.u))
                                                     if u is None else u)})
            p = dict(params, **(parameters or {}))
            vals.update({s: float(p[n]) for n, s in sym.params.items()})
            return np.array(evaluate(flat, vals), dtype=float).reshape(shape)
        return at


def _rate_at_rest(walk, expr):
    """``d expr / dt`` along ``q' = N(q) u`` and explicit ``t``, the speeds held."""
    out = sympy.Integer(0)
    for s in sorted(free_symbols(expr), key=lambda x: x.name):
        if s in walk.qdot:
            out += diff(expr, s) * walk.qdot[s]
        elif s == walk.sym.t:
            out += diff(expr, s)
    return out


# ---------------------------------------------------------------------------- geometry
def _value(walk, joint, key, numeric):
    raw = joint.symbolic.get(key) if isinstance(joint.symbolic, dict) else None
    if raw is None:
        return exact(numeric)
    return canonical(sympy.sympify(raw), walk.sym.table)


def _vector_of(walk, joint, key, numeric):
    raw = joint.symbolic.get(key) if isinstance(joint.symbolic, dict) else None
    return exact_vector(numeric if raw is None else raw, walk.sym.table)


def _axis(walk, joint, key):
    raw = joint.symbolic.get(key) if isinstance(joint.symbolic, dict) else None
    return axis_vector(raw if raw is not None else getattr(joint, key), walk.sym.table)


def _orientation(walk, joint, key):
    raw = joint.symbolic.get(key) if isinstance(joint.symbolic, dict) else None
    return orientation_matrix(raw, getattr(joint, key), walk.sym.table)


def perpendiculars(axis, numeric_axis):
    """Two unit vectors completing ``axis`` to a right-handed triad, with the helper axis
    the numeric layer picks (``constraint_packing.perpendiculars``)."""
    helper = sympy.zeros(3, 1)
    helper[int(np.argmin(np.abs(numeric_axis)))] = 1
    b1 = cross(axis, helper)
    norm = sympy.sqrt(sympy.simplify((b1.T * b1)[0]))
    b1 = (b1 / norm).applyfunc(sympy.simplify)
    return b1, cross(axis, b1).applyfunc(sympy.simplify)


# ---------------------------------------------------------------------------- the rows
def _body_rows(walk, j, first):
    """``(labels, expressions, primitives)`` of a loop joint between two bodies."""
    s = walk.s
    sp, sc = _vector_of(walk, j, "position", j.position), \
        _vector_of(walk, j, "child_position", j.child_position)
    Cp, Cc = _orientation(walk, j, "orientation"), _orientation(walk, j, "child_orientation")
    Rp, Rc = walk._R_world(j.parent), walk._R_world(j.child)
    Pp, Pc = walk._world_point(j.parent, sp), walk._world_point(j.child, sc)
    d = s(Pc - Pp)
    labels, exprs, prims = [], [], []

    def add(kind, rows, values, vector=None):
        idx = tuple(range(first + len(labels), first + len(labels) + len(rows)))
        labels.extend(f"{j.name}.{r}" for r in rows)
        exprs.extend(values)
        prims.append(Primitive(kind, j.name, idx, j.parent, j.child, (sp, sc), (Pp, Pc),
                               vector))

    def perp(a_body, b_body, label):
        a, b = s(Rp * a_body), s(Rc * b_body)
        add("PERP", (label,), [s((a.T * b)[0])], s(cross(b, a)))

    kind = j.kind
    if kind in ("revolute", "cylindrical", "prismatic", "universal"):
        axis = _axis(walk, j, "axis")
        n1, n2 = perpendiculars(axis, j.axis)
    if kind in ("revolute", "spherical", "fixed", "universal"):
        add("POINT", ("x", "y", "z"), list(d))
    if kind in ("revolute", "cylindrical"):
        perp(Cp * axis, Cc * n1, "perp1")
        perp(Cp * axis, Cc * n2, "perp2")
    if kind in ("prismatic", "fixed"):
        for a, b, label in ((1, 2, "rx"), (2, 0, "ry"), (0, 1, "rz")):
            perp(Cp[:, a], Cc[:, b], label)
    if kind in ("prismatic", "cylindrical"):
        for n, label in ((n1, "slide1"), (n2, "slide2")):
            nw = s(Rp * (Cp * n))
            add("SLIDE", (label,), [s((d.T * nw)[0])], nw)
    if kind == "universal":
        perp(Cp * axis, Cc * _axis(walk, j, "axis2"), "cross")
    if kind == "distance":
        L = _value(walk, j, "length", j.length)
        add("DIST", ("length",), [s(((d.T * d)[0] - L ** 2) / 2)])
    return labels, exprs, prims


def _coupling_row(walk, j, first):
    q = {}
    for role in ("follower", "leader"):
        q[role] = walk.joint_values[getattr(j, role)][0][0]
    ratio = _value(walk, j, "ratio", j.ratio)
    offset = _value(walk, j, "offset", j.offset)
    prim = Primitive("COUPLE", j.name, (first,), coupled=(j.follower, j.leader, ratio))
    return [j.name], [walk.s(q["follower"] - ratio * q["leader"] - offset)], [prim]


def _multiplier_symbols(rows, table):
    out = []
    for label in rows:
        name = "lambda_" + label.replace(".", "_")
        while name in table:
            name += "_"
        sym = sympy.Symbol(name, real=True)
        LATEX_NAMES[sym] = r"\lambda_{\text{" + label.replace("_", r"\_") + "}}"
        out.append(sym)
    return tuple(out)


def loop_equations(walk):
    """The ``LoopEquations`` of the walk's model, or None for a tree."""
    model = walk.model
    names = tuple(getattr(model, "loop_joints", ()))
    if not names:
        return None
    labels, exprs, prims, owners = [], [], [], []
    for name in names:
        j = model.joint(name)
        rows = (_coupling_row if j.kind == "coupling" else _body_rows)(walk, j, len(labels))
        labels.extend(rows[0])
        exprs.extend(rows[1])
        prims.extend(rows[2])
        owners.extend([name] * len(rows[0]))
    sym = walk.sym
    phi = sympy.Matrix(len(exprs), 1, exprs)
    jac = sympy.Matrix(len(exprs), len(sym.q), lambda r, c: walk.s(diff(phi[r], sym.q[c])))
    G = jac
    if any(not (walk.qdot.get(q) == u) for q, u in zip(sym.q, sym.u)) or \
            len(sym.q) != len(sym.u):
        N = sympy.Matrix(len(sym.q), len(sym.u),
                         lambda r, c: diff(walk.qdot[sym.q[r]], sym.u[c]))
        G = (jac * N).applyfunc(walk.s)
    phi_t = phi.applyfunc(lambda e: walk.s(diff(e, sym.t)))
    lam = _multiplier_symbols(labels, sym.table)
    return LoopEquations(walk, tuple(labels), tuple(owners), phi, jac, G, phi_t, lam, prims)


# ---------------------------------------------------------------------------- wrenches
def add_multiplier_loads(walk, eqs):
    """The multipliers' loads on the walk's frames (for Newton-Euler's free-body
    diagrams): each primitive's force and moment on its child, the opposite on its parent,
    as ``Model.multipliers`` means them; their generalized forces are ``G^T lambda``."""
    lam = eqs.multipliers
    for p in eqs.primitives:
        name = f"{p.joint} (multipliers)"
        if p.kind == "COUPLE":
            follower, leader, ratio = p.coupled
            _joint_effort(walk, name, follower, lam[p.rows[0]])
            _joint_effort(walk, name, leader, -ratio * lam[p.rows[0]])
            continue
        F = N = Z3
        if p.kind == "POINT":
            F = sympy.Matrix([lam[r] for r in p.rows])
        elif p.kind == "PERP":
            N = p.vector * lam[p.rows[0]]
        elif p.kind == "SLIDE":
            F = p.vector * lam[p.rows[0]]
        else:
            F = walk.s(p.world[1] - p.world[0]) * lam[p.rows[0]]
        walk._add_wrench(name, p.child, F, N, p.points[1])
        # the parent's share where its virtual power is -lambda^T G u at every q: at its own
        # point (a point, a rod), at the child's point (a slide: the plane turns with it)
        at = walk._own_point(p.parent, p.world[1]) if p.kind == "SLIDE" else p.points[0]
        walk._add_wrench(name, p.parent, -F, -N, at)


def _joint_effort(walk, name, joint_name, effort):
    """An effort along a 1-DoF tree joint: a torque pair (revolute) or a force pair at the
    child's origin (prismatic), as ``force_elements.joint_spring_damper`` applies it."""
    joint = walk.model.joint(joint_name)
    axis_w = walk.s(walk._R_world(joint.child) * walk._joint_geometry(joint)[0])
    if joint.kind == "revolute":
        walk._add_wrench(name, joint.child, Z3, effort * axis_w, Z3)
        walk._add_wrench(name, joint.parent, Z3, -effort * axis_w, Z3)
    else:
        walk._add_wrench(name, joint.child, effort * axis_w, Z3, Z3)
        if joint.parent != "ground":
            walk._add_wrench(name, joint.parent, -effort * axis_w, Z3,
                             walk.by_name[joint.child].rho_p)

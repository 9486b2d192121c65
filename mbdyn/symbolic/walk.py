"""The kinematic walk with sympy: steps 1-11 of the textbook for every frame of a model.

For each frame, parents first: the transformation matrix from its parent, the position
vectors, the absolute angular velocity and acceleration, the velocity and acceleration of
its origin and of its centre of mass, the Jacobians of rotation and translation, and the
applied forces and moments reduced to the centre of mass -- the same quantities as
``mbdyn.kernels.kinematics`` computes numerically, as expressions.

Every vector of frame ``i`` is written in one *basis*: with ``frames="own"`` (default, the
textbook's advice) in frame ``i``'s own axes, where the body's inertia tensor is constant and
the expressions are shortest; with ``frames="inertial"`` in the inertial axes (the "one
frame" style whose expressions grow with every sum of angles).  The recursion is the same::

    w_i   = X w_p + X_c w_rel
    al_i  = X al_p + (X w_p) x (X_c w_rel) + X_c d/dt(w_rel)
    v_i   = X v_p + (X w_p) x rho + v_rel
    a_i   = X a_p + (X al_p) x rho + (X w_p) x ((X w_p) x rho) + 2 (X w_p) x v_rel + a_rel
    v_G   = v_i + w_i x c,     a_G = a_i + al_i x c + w_i x (w_i x c)

with ``X`` the change of basis from the parent's basis (``T`` of the joint for ``own``,
identity for ``inertial``), ``X_c`` from the child's own axes (identity / ``R_i``), and
``rho``, ``v_rel``, ``a_rel`` the joint's offset and relative motion in the new basis.

Conventions follow ``mbdyn.kernels.joints``: a joint frame J0 is fixed in the parent at
``position`` with orientation ``C`` (``P s = C J0 s``); ``Rrel`` maps child to J0
components; the textbook's transformation matrix is ``T = (C Rrel)^T`` (``B s = T P s``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy

from ..errors import ModelError
from .simplify import (compact, compact_matrix, diff, free_symbols, replace_shared,
                       tree_size)
from .symbols import (Symbols, axis_vector, canonical, cross, exact, exact_matrix,
                      exact_vector, orientation_matrix, quaternion_matrix,
                      rotation_about_axis, rotation_about_coordinate_axis)

FRAMES = ("own", "inertial")

E3 = sympy.eye(3)
Z3 = sympy.zeros(3, 1)


@dataclass
class FrameMotion:
    """Everything the walk knows about one frame (vectors in ``basis`` components)."""
    index: int
    name: str
    joint: object            # the Joint record
    parent: str
    basis: str               # "B<i>" label of the components used, or "I"
    T: sympy.Matrix          # joint transformation matrix B s = T P s
    Rrel: sympy.Matrix       # J0 <- B
    C: sympy.Matrix          # P <- J0
    rho_p: sympy.Matrix      # parent origin -> this origin, parent components
    com: sympy.Matrix        # origin -> centre of mass, own components
    mass: sympy.Expr
    inertia: sympy.Matrix    # about the centre of mass, own axes
    w_rel: sympy.Matrix      # relative angular velocity, own components
    omega: sympy.Matrix
    alpha: sympy.Matrix
    r: sympy.Matrix          # position of the origin from the inertial origin
    v: sympy.Matrix
    a: sympy.Matrix
    r_G: sympy.Matrix
    v_G: sympy.Matrix
    a_G: sympy.Matrix
    JR: sympy.Matrix         # d omega / d u   (3 x nu)
    JT: sympy.Matrix         # d v_G / d u     (3 x nu)
    gravity: sympy.Matrix    # gravitational acceleration in basis components
    X_child: sympy.Matrix    # basis <- own axes
    w_rel_basis: sympy.Matrix = None   # relative angular velocity of the joint, basis comps
    v_rel_basis: sympy.Matrix = None   # relative velocity of the joint, basis comps
    force: sympy.Matrix = None     # applied force (gravity + loads), basis components
    moment: sympy.Matrix = None    # applied moment about the centre of mass
    loads: list = field(default_factory=list)   # (name, F, N, point) basis comps / own point
    children: list = field(default_factory=list)

    @property
    def has_inertia(self):
        return self.mass != 0 or any(e != 0 for e in self.inertia)

    @property
    def inertia_basis(self):
        X = self.X_child
        return self.inertia if X is E3 else X * self.inertia * X.T

    @property
    def com_basis(self):
        return self.com if self.X_child is E3 else self.X_child * self.com


def _joint_values(joint, sym, qi, ui):
    """Coordinates, speeds and speed rates of a joint: symbols, or its drive's expressions."""
    if joint.drive is not None:
        expr = joint.symbolic.get("drive") if isinstance(joint.symbolic, dict) else None
        if expr is None:
            expr = joint.drive.expression
        if expr is None:
            raise ModelError(f"joint {joint.name!r}: its drive is given as Python functions; a "
                             "symbolic derivation needs it as a sympy expression of mb.t "
                             "(e.g. drive=Omega*mb.t)")
        expr = canonical(sympy.sympify(expr), sym.table)
        return [expr], [expr.diff(sym.t)], [expr.diff(sym.t, 2)], True
    if not joint.nu:
        return [], [], [], False
    return (sym.q[qi:qi + joint.nq], sym.u[ui:ui + joint.nu], sym.ud[ui:ui + joint.nu], False)


def joint_motion(joint, axis, qj, uj):
    """Symbolic ``Rrel`` (J0 <- B), offset ``d`` (J0), relative angular velocity (B comps)
    and relative velocity (J0 comps) of a joint; see ``mbdyn.kernels.joints``."""
    kind = joint.kind
    if kind == "fixed":
        return E3, Z3, Z3, Z3
    if kind == "revolute":
        return rotation_about_axis(axis, qj[0]), Z3, axis * uj[0], Z3
    if kind == "prismatic":
        return E3, axis * qj[0], Z3, axis * uj[0]
    if kind == "euler":
        s0, s1, s2 = joint.sequence
        R0 = rotation_about_coordinate_axis(s0, qj[0])
        R1 = rotation_about_coordinate_axis(s1, qj[1])
        R2 = rotation_about_coordinate_axis(s2, qj[2])
        e = [E3[:, k] for k in range(3)]
        w = R2.T * (R1.T * e[s0]) * uj[0] + R2.T * e[s1] * uj[1] + e[s2] * uj[2]
        return R0 * R1 * R2, Z3, w, Z3
    if kind == "spherical":
        return quaternion_matrix(*qj), Z3, sympy.Matrix(uj), Z3
    if kind == "free":
        return (quaternion_matrix(*qj[3:7]), sympy.Matrix(qj[0:3]), sympy.Matrix(uj[3:6]),
                sympy.Matrix(uj[0:3]))
    raise ModelError(f"joint {joint.name!r}: unknown kind {kind!r}")


def _cross_columns(r, A):
    """``r x`` every column of ``A`` (3 x n)."""
    out = sympy.zeros(3, A.cols)
    for k in range(A.cols):
        a = A[:, k]
        if any(e != 0 for e in a):
            out[:, k] = cross(r, a)
    return out


def quaternion_rates(qj, w):
    """``q' = 1/2 q (x) (0, w)``, ``w`` in child components."""
    a, b, c, d = qj
    return [(-b * w[0] - c * w[1] - d * w[2]) / 2, (a * w[0] - d * w[1] + c * w[2]) / 2,
            (d * w[0] + a * w[1] - b * w[2]) / 2, (-c * w[0] + b * w[1] + a * w[2]) / 2]


def too_large(model, what, size, limit, remedy=""):
    """The error for equations too large to write out (``derive(..., max_nodes=...)``)."""
    return ModelError(
        f"model {model.name!r}: {what} would have {size:.3g} parts written out (parse-tree "
        f"nodes, a shared part counted where it occurs), more than {limit} "
        "(limits.MAX_EQUATION_NODES; each link of a chain multiplies the size by 2 to 5): "
        f"derive fewer links{remedy}; in Python, mb.derive keeps the shared form and has no "
        "such bound")


class Walk:
    """The symbolic kinematics and applied loads of a compiled model.

    ``frames``: ``"own"`` or ``"inertial"`` (see the module docstring); ``simplify``: one of
    ``mbdyn.symbolic.simplify.MODES``.  ``motions`` lists a ``FrameMotion`` per frame in
    topological order; ``qdot`` maps each coordinate symbol to its rate (the kinematic
    equations ``q' = N(q) u``).  ``max_nodes``: refuse (``too_large``) once the frames'
    angular velocities and accelerations and centre-of-mass accelerations written out
    exceed this size (the equations are larger still).
    """

    def __init__(self, model, frames="own", simplify="compact", max_nodes=None):
        if frames not in FRAMES:
            raise ModelError(f"unknown frames {frames!r}; use one of {', '.join(FRAMES)}")
        self.model = model
        self.frames = frames
        self.simplify = simplify
        self.sym = sym = Symbols(model)
        bodies, joints, loads = model.elements
        self.bodies, self.joints, self.loads = bodies, joints, loads
        self.gravity = self._gravity()
        self.qdot = {}
        self.u_to_ud = dict(zip(sym.u, sym.ud))
        self.zero_ud = {s: 0 for s in sym.ud}
        self.motions = []
        self.by_name = {}
        self.joint_values = {}
        self.units = []                     # unit quaternions: their squares sum to 1
        qi = ui = walked = 0
        for i, (body, joint) in enumerate(zip(bodies, joints)):
            qj, uj, udj, driven = _joint_values(joint, sym, qi, ui)
            self.joint_values[joint.name] = (qj, uj, udj, driven)
            if not driven and joint.nu:
                if joint.kind == "spherical":
                    self.units.append(tuple(qj))
                    for s, r in zip(qj, quaternion_rates(qj, uj)):
                        self.qdot[s] = r
                elif joint.kind == "free":
                    self.units.append(tuple(qj[3:]))
                    for s, r in zip(qj[:3], uj[:3]):
                        self.qdot[s] = r
                    for s, r in zip(qj[3:], quaternion_rates(qj[3:], uj[3:])):
                        self.qdot[s] = r
                else:
                    for s, r in zip(qj, uj):
                        self.qdot[s] = r
                qi += joint.nq
                ui += joint.nu
            m = self._walk_frame(i, body, joint, qj, uj)
            if max_nodes is not None:       # stop at the first frame past the bound
                walked += sum(tree_size(e) for v in (m.omega, m.alpha, m.a_G) for e in v)
                if walked > max_nodes:
                    raise too_large(model, f"the kinematics of the frames down to "
                                    f"{body.name!r} alone", walked, max_nodes)
            self.motions.append(m)
            self.by_name[body.name] = m
            if joint.parent in self.by_name:
                self.by_name[joint.parent].children.append(m)
        self._apply_loads()
        self._apply_forces()

    # ------------------------------------------------------------------ helpers
    def s(self, expr):
        """Simplify a scalar or matrix with the walk's mode."""
        if isinstance(expr, sympy.MatrixBase):
            return compact_matrix(expr, self.simplify, units=self.units)
        return compact(expr, self.simplify, units=self.units)

    def D(self, expr):
        """Total time derivative along the motion: ``q' = N(q) u``, ``u' = ud`` (symbols) and
        explicit ``t`` (drives, loads)."""
        if isinstance(expr, sympy.MatrixBase):
            return expr.applyfunc(self.D)
        if not isinstance(expr, sympy.Basic):
            return sympy.Integer(0)
        out = sympy.Integer(0)
        for s in sorted(free_symbols(expr), key=lambda x: x.name):
            if s in self.qdot:
                out += diff(expr, s) * self.qdot[s]
            elif s in self.u_to_ud:
                out += diff(expr, s) * self.u_to_ud[s]
            elif s == self.sym.t:
                out += diff(expr, s)
        return out

    def jacobian(self, vec):
        """``d vec / d u`` over the free speeds (3 x nu)."""
        u = self.sym.u
        if not u:
            return sympy.zeros(vec.rows, 0)
        return sympy.Matrix(vec.rows, len(u), lambda r, c: diff(vec[r], u[c]))

    def bias(self, expr):
        """``expr`` at zero speed rates (velocity-product part of an acceleration)."""
        return replace_shared(expr, self.zero_ud)

    def _gravity(self):
        m = self.model
        if m.gravity_symbolic is not None:
            return exact_vector(m.gravity_symbolic, self.sym.table)
        return exact_vector(m.gravity, self.sym.table)

    def _body_values(self, body):
        table = self.sym.table
        sy = body.symbolic if isinstance(body.symbolic, dict) else {}
        mass = sy.get("mass", body.mass)
        mass = canonical(mass, table) if isinstance(mass, sympy.Basic) else exact(mass)
        com = exact_vector(sy.get("com", body.com), table)
        raw = sy.get("inertia")
        if raw is None:
            inertia = exact_matrix(body.inertia, table)
        else:
            arr = np.asarray(raw, dtype=object)
            if arr.shape == (3,):
                inertia = sympy.diag(*exact_vector(arr, table))
            elif arr.shape == ():
                inertia = E3 * canonical(sympy.sympify(raw), table)
            else:
                inertia = exact_matrix(arr, table)
        return mass, com, inertia

    def _joint_geometry(self, joint):
        table = self.sym.table
        sy = joint.symbolic if isinstance(joint.symbolic, dict) else {}
        if "axis" in sy:
            axis = axis_vector(sy["axis"], table)
        else:
            axis = exact_vector(joint.axis, table)
            if any(a != 0 for a in axis) and not sympy.simplify((axis.T * axis)[0] - 1) == 0:
                axis = (axis / sympy.sqrt((axis.T * axis)[0])).applyfunc(sympy.nsimplify)
        position = exact_vector(sy.get("position", joint.position), table)
        C = orientation_matrix(sy.get("orientation"), joint.orientation, table)
        return axis, position, C

    # ------------------------------------------------------------------ the walk
    def _walk_frame(self, i, body, joint, qj, uj):
        s = self.s
        axis, position, C = self._joint_geometry(joint)
        Rrel, d, w_rel, v_rel_j = joint_motion(joint, axis, qj, uj)
        Rrel = s(Rrel)
        w_rel = s(w_rel)
        T = s((C * Rrel).T)
        rho_p = s(position + C * d)
        mass, com, inertia = self._body_values(body)
        parent = self.by_name.get(joint.parent)
        own = self.frames == "own"
        if parent is None:                      # the ground: at rest
            wp = alp = vp = ap = rp = Z3
            gp = self.gravity
            Rp = E3
        else:
            wp, alp, vp, ap, rp, gp = (parent.omega, parent.alpha, parent.v, parent.a,
                                       parent.r, parent.gravity)
            Rp = parent.X_child
        if own:
            X = T                                # parent basis -> this basis
            Xp = T                               # parent's own axes -> this basis
            Xc = E3                              # own axes -> basis
        else:
            X = E3
            Xp = Rp
            Xc = s(Rp * C * Rrel)
        wp_b = s(X * wp)
        alp_b = s(X * alp)
        rho = s(Xp * rho_p)
        w_rel_b = w_rel if Xc is E3 else s(Xc * w_rel)
        v_rel = s(Xp * (C * v_rel_j))
        a_rel = s(Xp * (C * self.D(v_rel_j)))
        omega = s(wp_b + w_rel_b)
        dw_rel = self.D(w_rel) if Xc is E3 else Xc * self.D(w_rel)
        alpha = s(alp_b + cross(wp_b, w_rel_b) + dw_rel)
        r = s(X * rp + rho)
        v = s(X * vp + cross(wp_b, rho) + v_rel)
        a = s(X * ap + cross(alp_b, rho) + cross(wp_b, cross(wp_b, rho)) + 2 * cross(wp_b, v_rel)
              + a_rel)
        c = com if Xc is E3 else s(Xc * com)
        r_G = s(r + c)
        v_G = s(v + cross(omega, c))
        a_G = s(a + cross(alpha, c) + cross(omega, cross(omega, c)))
        g = s(X * gp)
        # Jacobians recursively, as the numeric kernel does: inherit the parent's columns
        # (rotated into this basis, the translation one moved along rho), add this joint's
        JR_p = parent.JR if parent is not None else sympy.zeros(3, len(self.sym.u))
        JO_p = parent.JO if parent is not None else sympy.zeros(3, len(self.sym.u))
        JR = X * JR_p
        JO = X * JO_p - _cross_columns(rho, JR)
        for u in (uj if not self._driven(joint) else ()):
            col = self.sym.u.index(u)
            JR[:, col] += w_rel_b.diff(u)
            JO[:, col] += v_rel.diff(u)
        JR = self.s(JR)
        JO = self.s(JO)
        JT = self.s(JO - _cross_columns(c, JR))
        basis = f"B{i + 1}" if own else "I"
        fm = FrameMotion(i, body.name, joint, joint.parent, basis, T, Rrel, C, rho_p, com,
                         mass, inertia, w_rel, omega, alpha, r, v, a, r_G, v_G, a_G, JR, JT,
                         g, Xc, w_rel_b, v_rel)
        fm.JO = JO
        return fm

    def _driven(self, joint):
        return self.joint_values[joint.name][3]

    def absolute_T(self, name):
        """The transformation matrix ``B s = T I s`` of a frame from the inertial frame."""
        cache = self.__dict__.setdefault("_absT", {})
        if name not in cache:
            m = self.by_name[name]
            parent = m.parent
            Tp = E3 if parent not in self.by_name else self.absolute_T(parent)
            cache[name] = self.s(m.T * Tp)
        return cache[name]

    def to_basis(self, m, vec, in_body):
        """A load vector given in body (own) or world components, in ``m``'s basis."""
        if in_body:
            return vec if m.X_child is E3 else self.s(m.X_child * vec)
        return self.s(self.absolute_T(m.name) * vec) if self.frames == "own" else vec

    def _load_vector(self, load, what):
        table = self.sym.table
        sy = load.symbolic if isinstance(load.symbolic, dict) else {}
        val = sy.get(what, getattr(load, what))
        if callable(val):
            names = ", ".join(self.model.coordinates + self.model.speeds)
            raise ModelError(f"load {load.name!r}: its {what} is a Python function; a symbolic "
                             "derivation needs constants or sympy expressions of t and the "
                             f"coordinates/speeds ({names})")
        vec = exact_vector(val, table)
        allowed = set(self.sym.table.values()) - set(self.sym.ud)
        bad = sorted(s.name for e in vec for s in e.free_symbols if s not in allowed)
        if bad:
            raise ModelError(f"load {load.name!r}: its {what} uses {', '.join(bad)}, which are "
                             "neither parameters, t, coordinates nor speeds of the model")
        return vec

    def _apply_loads(self):
        for m in self.motions:
            m.force = self.s(m.mass * m.gravity)
            m.moment = sympy.zeros(3, 1)
        for load in self.loads:
            m = self.by_name[load.body]
            F = self.to_basis(m, self._load_vector(load, "force"), load.in_body)
            N = self.to_basis(m, self._load_vector(load, "moment"), load.in_body)
            point = exact_vector(load.symbolic.get("point", load.point)
                                 if isinstance(load.symbolic, dict) else load.point,
                                 self.sym.table)
            lever = point - m.com if m.X_child is E3 else m.X_child * (point - m.com)
            m.loads.append((load.name, F, N, point))
            m.force = self.s(m.force + F)
            m.moment = self.s(m.moment + N + cross(lever, F))

    # ------------------------------------------------------------------ force elements
    def _param(self, el, key):
        value = el.symbolic.get(key, el.params[key])
        if isinstance(value, sympy.Basic):
            return canonical(value, self.sym.table)
        return exact(value)

    def _world_point(self, frame, point):
        """World position of a point fixed on ``frame`` (own components)."""
        if frame == "ground":
            return point
        m = self.by_name[frame]
        if self.frames == "own":
            return self.s(self.absolute_T(frame).T * (m.r + point))
        return self.s(m.r + m.X_child * point)

    def _add_wrench(self, name, frame, F_world, N_world, point):
        """Element ``name``'s force (world components) at ``point`` (own components) and
        moment on ``frame``, into its applied loads."""
        if frame == "ground":
            return
        m = self.by_name[frame]
        F = self.to_basis(m, F_world, False)
        N = self.to_basis(m, N_world, False)
        m.loads.append((name, F, N, point))
        lever = point - m.com if m.X_child is E3 else m.X_child * (point - m.com)
        m.force = self.s(m.force + F)
        m.moment = self.s(m.moment + N + cross(lever, F))

    def _R_world(self, frame):
        """Rotation matrix (own -> world components) of a frame; the identity for ground."""
        if frame == "ground":
            return E3
        if self.frames == "own":
            return self.absolute_T(frame).T
        return self.by_name[frame].X_child

    def _omega_world(self, frame):
        if frame == "ground":
            return Z3
        m = self.by_name[frame]
        return self.s(self.absolute_T(frame).T * m.omega) if self.frames == "own" else m.omega

    def _own_point(self, frame, p_world):
        """Own components (from the frame origin) of a world point."""
        if frame == "ground":
            return p_world
        return self.s(self._R_world(frame).T * (p_world - self._world_point(frame, Z3)))

    def _spin(self, name):
        """The speed a bearing's coefficients depend on: a speed symbol, or a driven joint's
        prescribed rate."""
        for j in self.joints:
            qj, uj, _, driven = self.joint_values[j.name]
            if j.nu == 1 and (name == j.name or name in j.coordinates or name in j.speeds):
                return uj[0]
        raise ModelError(f"unknown spin speed {name!r}")

    def _coefficient(self, el, key):
        """A bearing coefficient: a number, or a table as a named function of the spin speed
        (``kxx_bearing(spin)``) that evaluates by the table's interpolation."""
        value = el.params[key]
        if hasattr(value, "block"):                     # a Table
            from sympy.utilities.lambdify import implemented_function
            fn = implemented_function(f"{key}_{el.name}", value)
            return fn(self._spin(el.params["speed"]))
        return self._param(el, key)

    def _apply_forces(self):
        """Force elements as body wrenches, in closed form: a spring-damper's tension along
        the line of its points, a joint spring-damper's effort on its coordinate, a bushing's
        6x6 law, a bearing's eight coefficients (tabulated ones as named functions of the
        spin speed), a contact's Hunt-Crossley force and regularised friction."""
        for el in getattr(self.model, "_force_elements", ()):
            p = el.params
            tabulated = [k for k in ("force_table", "damping_table") if p.get(k) is not None]
            if tabulated:
                raise ModelError(f"force {el.name!r}: the symbolic layer writes linear springs "
                                 "and dampers in closed form, not tabulated laws; switch it off "
                                 f"to derive the rest (--effects=-{el.name})")
            vec = lambda key: exact_vector(el.symbolic.get(key, p[key]), self.sym.table)  # noqa
            law = p.get("law")
            if law is not None and law.expression is None:
                raise ModelError(f"force {el.name!r}: its law is a Python function; the symbolic "
                                 "layer needs it as an expression of x and v (or switch it off: "
                                 f"--effects=-{el.name})")
            if el.kind == "spring-damper":
                k, c, F0 = (self._param(el, key) for key in ("stiffness", "damping", "preload"))
                pa, pb = vec("point_a"), vec("point_b")
                a, b = el.frames
                d = self._world_point(b, pb) - self._world_point(a, pa)
                L = sympy.sqrt((d.T * d)[0])
                x = L - self._param(el, "free_length")
                T = (self._law(law, x, self.D(L)) if law is not None
                     else F0 + k * x + c * self.D(L))
                f = d * (T / L)
                self._add_wrench(el.name, a, f, Z3, pa)
                self._add_wrench(el.name, b, -f, Z3, pb)
            elif el.kind == "joint-spring-damper":
                k, c, F0 = (self._param(el, key) for key in ("stiffness", "damping", "preload"))
                joint = next(j for j in self.joints if j.name == p["joint"])
                qj, uj, _, driven = self.joint_values[joint.name]
                x = qj[0] - self._param(el, "rest")
                tau = -(self._law(law, x, uj[0]) if law is not None else F0 + k * x + c * uj[0])
                m = self.by_name[joint.child]
                axis = self._joint_geometry(joint)[0]
                # the axis in world components: joint frame J0 = child axes along the axis
                axis_w = self.s(self._R_world(joint.child) * axis)
                if joint.kind == "revolute":
                    self._add_wrench(el.name, joint.child, Z3, tau * axis_w, Z3)
                    self._add_wrench(el.name, joint.parent, Z3, -tau * axis_w, Z3)
                else:
                    self._add_wrench(el.name, joint.child, tau * axis_w, Z3, Z3)
                    if joint.parent != "ground":
                        self._add_wrench(el.name, joint.parent, -tau * axis_w, Z3, m.rho_p)
            elif el.kind == "bushing":
                a, b = el.frames
                pa, pb = vec("point_a"), vec("point_b")
                Ra = self._R_world(a)
                pbw = self._world_point(b, pb)
                x = self.s(Ra.T * (pbw - self._world_point(a, pa)))
                Rrel = self.s(Ra.T * self._R_world(b))
                theta = sympy.Matrix([Rrel[2, 1] - Rrel[1, 2], Rrel[0, 2] - Rrel[2, 0],
                                      Rrel[1, 0] - Rrel[0, 1]]) / 2
                xd = self.s(self.D(x))
                thd = self.s(Ra.T * (self._omega_world(b) - self._omega_world(a)))
                K = sympy.Matrix(6, 6, [exact(v) for v in np.ravel(p["stiffness"])])
                C = sympy.Matrix(6, 6, [exact(v) for v in np.ravel(p["damping"])])
                w6 = -(K * x.col_join(theta) + C * xd.col_join(thd))
                f, mo = self.s(Ra * w6[:3, 0]), self.s(Ra * w6[3:, 0])
                self._add_wrench(el.name, b, f, mo, pb)
                self._add_wrench(el.name, a, -f, -mo, self._own_point(a, pbw))
            elif el.kind == "bearing":
                a, b = el.frames
                Rb = self._R_world(b)
                e1, e2 = self.s(Rb * vec("e1")), self.s(Rb * vec("e2"))
                pa = vec("point")
                paw = self._world_point(a, pa)
                d = paw - self._world_point(b, vec("center"))
                x, y = (e1.T * d)[0], (e2.T * d)[0]
                xd, yd = self.D(x), self.D(y)
                kxx, kxy, kyx, kyy, cxx, cxy, cyx, cyy = (
                    self._coefficient(el, c) for c in ("kxx", "kxy", "kyx", "kyy", "cxx",
                                                        "cxy", "cyx", "cyy"))
                fx = -(kxx * x + kxy * y + cxx * xd + cxy * yd)
                fy = -(kyx * x + kyy * y + cyx * xd + cyy * yd)
                f = self.s(e1 * fx + e2 * fy)
                self._add_wrench(el.name, a, f, Z3, pa)
                self._add_wrench(el.name, b, -f, Z3, self._own_point(b, paw))
            else:                                           # contact
                a = el.frames[0]
                n = vec("plane_normal")
                radius = self._param(el, "radius")
                centre = self._world_point(a, vec("center"))
                if p["shape"] == "disk":
                    ax = self._R_world(a) * vec("axis")
                    side = -n + (n.T * ax)[0] * ax
                    pc = centre + radius * side / sympy.sqrt((side.T * side)[0])
                else:
                    pc = centre - radius * n
                pc = self.s(pc)
                delta = -((pc - vec("plane_point")).T * n)[0]
                own = self._own_point(a, pc)
                vc = self._world_velocity(a) + self._omega_world(a).cross(
                    pc - self._world_point(a, Z3))
                vn = (vc.T * n)[0]
                k = self._param(el, "stiffness")
                ex = self._param(el, "exponent")
                chc = exact(p["damping_factor"])
                fn = sympy.Max(0, k * delta ** ex * (1 - chc * vn))
                vt = vc - vn * n
                ft = -self._param(el, "friction") * fn / sympy.sqrt(
                    (vt.T * vt)[0] + self._param(el, "slip_speed") ** 2)
                f = (fn * n + ft * vt).applyfunc(
                    lambda e: sympy.Piecewise((e, delta > 0), (0, True)))
                self._add_wrench(el.name, a, f, Z3, own)

    def _law(self, law, x, v):
        """A law's expression with the elongation ``x`` and its rate ``v`` put in."""
        e = law.expression
        e = e.xreplace({s: (x if s.name == "x" else v) for s in e.free_symbols
                        if s.name in ("x", "v")})
        return canonical(e, self.sym.table)

    def _world_velocity(self, frame):
        """World velocity of a frame's origin."""
        m = self.by_name[frame]
        return self.s(self.absolute_T(frame).T * m.v) if self.frames == "own" else m.v

    # ------------------------------------------------------------------ for the methods
    def point_jacobians(self, m, point):
        """Jacobians of translation of a point fixed on frame ``m`` (own components) and of
        rotation, basis components."""
        p = point if m.X_child is E3 else m.X_child * point
        vP = m.v + cross(m.omega, p)
        return self.jacobian(vP), m.JR

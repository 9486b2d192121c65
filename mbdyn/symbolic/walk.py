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


import numpy as np
import sympy

from ..errors import ModelError
from .flexible import CHAIN, chain_values
from .flexible import attach as attach_flexible
from .flexible import check as check_flexible
from .force_elements import apply_forces, reflected_inertia
from .frames import (FrameMotion, _cross_columns, _joint_values, joint_motion,
                     quaternion_rates)
from .simplify import (compact, compact_matrix, diff, free_symbols, replace_shared,
                       tree_size)
from .symbols import (Symbols, axis_vector, canonical, cross, exact, exact_matrix,
                      exact_vector, orientation_matrix)

FRAMES = ("own", "inertial")

E3 = sympy.eye(3)
Z3 = sympy.zeros(3, 1)


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
        if getattr(model, "flexible_bodies", ()):
            check_flexible(model)           # before any work: what it cannot write
        self.model = model
        self.frames = frames
        self.simplify = simplify
        self.sym = sym = Symbols(model)
        flexible = getattr(model, "flexible_bodies", ())
        bodies, joints, loads = model.tree.elements if flexible else model.elements
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
        chains = chain_values(self)         # node frames' chains: moved by the modes
        for i, (body, joint) in enumerate(zip(bodies, joints)):
            qj, uj, udj, driven = chains.get(joint.name) or _joint_values(joint, sym, qi, ui)
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
        apply_forces(self)
        attach_flexible(self)               # flexible bodies' terms (``symbolic.flexible``)

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
        return mass, com, inertia + reflected_inertia(self.model, body.name)

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
        JR, JO, JT = self._jacobians(parent, joint, uj, X, rho, w_rel_b, v_rel, c)
        basis = f"B{i + 1}" if own else "I"
        fm = FrameMotion(i, body.name, joint, joint.parent, basis, T, Rrel, C, rho_p, com,
                         mass, inertia, w_rel, omega, alpha, r, v, a, r_G, v_G, a_G, JR, JT,
                         g, Xc, w_rel_b, v_rel)
        fm.JO = JO
        return fm

    def _jacobians(self, parent, joint, uj, X, rho, w_rel_b, v_rel, c):
        """``(JR, JO, JT)`` of a frame recursively, as the numeric kernel does: the parent's
        columns (rotated into this basis, the translation one moved along ``rho``) plus
        this joint's; ``JO`` of the origin, ``JT`` of the centre of mass (at ``c``)."""
        JR_p = parent.JR if parent is not None else sympy.zeros(3, len(self.sym.u))
        JO_p = parent.JO if parent is not None else sympy.zeros(3, len(self.sym.u))
        JR = X * JR_p
        JO = X * JO_p - _cross_columns(rho, JR)
        for u in self.speeds_of(joint, uj):
            col = self.sym.u.index(u)
            JR[:, col] += w_rel_b.diff(u)
            JO[:, col] += v_rel.diff(u)
        JR = self.s(JR)
        JO = self.s(JO)
        return JR, JO, self.s(JO - _cross_columns(c, JR))

    def _driven(self, joint):
        return self.joint_values[joint.name][3]

    def speeds_of(self, joint, uj):
        """The free speeds a joint's relative motion is linear in: its own, none for a
        drive, the modal rates for a node frame's chain joint (``symbolic.flexible``)."""
        driven = self._driven(joint)
        if driven == CHAIN:
            return sorted(free_symbols(uj[0]) & set(self.sym.u), key=self.sym.u.index)
        return () if driven else uj

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

    # ------------------------------------------------------------------ world quantities
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

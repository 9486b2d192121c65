"""A frame's motion as the symbolic walk writes it (``FrameMotion``), and each joint kind's
formulas in closed form: the joint's coordinates and speeds as symbols (or its drive), its
relative rotation, offset and relative velocities, and the quaternion rates.  Conventions
as in ``mbdyn.kernels.joints``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy

from ..errors import ModelError
from .symbols import (canonical, cross, quaternion_matrix, rotation_about_axis,
                      rotation_about_coordinate_axis)

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

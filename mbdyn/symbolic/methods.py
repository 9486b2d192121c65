"""The equations of motion by three methods, from the same symbolic walk.

Each method takes a ``Walk`` and returns ``Equations``: the mass matrix ``M`` and forcing
``f`` of ``M(q) u' = f(q, u, t)`` over the free speeds, plus what that method produces on
the way (the per-body Newton-Euler equations and the reactions; the energies and generalized
forces of Lagrange).  The three ``M``/``f`` pairs are equal as functions; their expressions
differ in form, which is the point of deriving them side by side.

* ``newton_euler`` -- step 12: for every body, leaves first, Newton ``sum F = m a_G`` and
  Euler about the frame origin ``sum M_O = I alpha + w x I w + c x m a_G`` with the joint
  reaction (force and moment the parent exerts on the child at the child's origin) as the
  unknown; the reaction's components along the joint's free directions vanish (a joint
  transmits no force or moment along its motion), which gives one equation of motion per
  speed; the others are the reaction components.
* ``jourdain`` -- step 13: ``sum_i J_T,i^T (F_i - m_i a_i) + J_R,i^T (M_i - I_i alpha_i -
  w_i x I_i w_i) = 0``, so ``M = sum J_T^T m J_T + J_R^T I J_R`` and ``f`` the rest at
  ``u' = 0``.
* ``lagrange`` -- ``d/dt dT/dq' - dT/dq + dV/dq = Q`` with ``T`` the kinetic energy, ``V``
  the gravitational potential and ``Q`` the generalized forces of the model's loads.  It
  needs ``u = q'``, so joints with quaternions (spherical, free) are refused.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy

from ..compiled.layout import reaction_basis
from ..errors import ModelError
from .flexible import CHAIN
from .simplify import diff
from .symbols import cross, exact_vector

METHODS = ("newton-euler", "jourdain", "lagrange")


@dataclass
class Equations:
    method: str
    M: sympy.Matrix
    f: sympy.Matrix
    details: dict = field(default_factory=dict)


def _symmetric(entries, n):
    M = sympy.zeros(n, n)
    for (r, c), e in entries.items():
        M[r, c] = e
        M[c, r] = e
    return M


def _free_columns(m):
    """Columns of the free speeds the frame's Jacobians depend on."""
    cols = set()
    for J in (m.JR, m.JT):
        for c in range(J.cols):
            if any(J[r, c] != 0 for r in range(3)):
                cols.add(c)
    return sorted(cols)


def jourdain(walk):
    """Newton-Euler-Jourdain: ``M = sum JT^T m JT + JR^T I JR``, ``f = sum JT^T (F - m a0)
    + JR^T (N - I alpha0 - w x I w)`` with ``a0``, ``alpha0`` the accelerations at ``u' = 0``."""
    s = walk.s
    nu = len(walk.sym.u)
    Mraw = {}
    f = [sympy.Integer(0)] * nu
    per_body = []
    for m in walk.motions:
        if not m.has_inertia and not m.loads:    # a massless frame adds only its loads
            continue
        I = m.inertia_basis
        aG0 = walk.bias(m.a_G)
        al0 = walk.bias(m.alpha)
        Iw = I * m.omega
        fT = s(m.force - m.mass * aG0)
        fR = s(m.moment - I * al0 - cross(m.omega, Iw))
        per_body.append((m.name, fT, fR))
        cols = _free_columns(m)
        IJ = {c: I * m.JR[:, c] for c in cols}
        for a in cols:
            f[a] += (m.JT[:, a].T * fT)[0] + (m.JR[:, a].T * fR)[0]
            for b in cols:
                if b < a:
                    continue
                val = m.mass * (m.JT[:, a].T * m.JT[:, b])[0] + (m.JR[:, a].T * IJ[b])[0]
                Mraw[(a, b)] = Mraw.get((a, b), 0) + val
    for body in walk.flexible:              # floating-frame bodies: B^T M_b B, B^T Q
        Mb, fb = body.jourdain()
        for a in range(nu):
            f[a] += fb[a]
            for b in range(a, nu):
                if Mb[a, b] != 0:
                    Mraw[(a, b)] = Mraw.get((a, b), 0) + Mb[a, b]
    M = _symmetric({k: s(v) for k, v in Mraw.items()}, nu)
    return Equations("jourdain", M, sympy.Matrix(nu, 1, [s(e) for e in f]),
                     {"effective_loads": per_body})


def _projectors(walk, m):
    """Projectors onto the reaction subspace (force, moment), basis components."""
    P = [sympy.zeros(3, 3), sympy.zeros(3, 3)]
    for fo, mo in reaction_basis(m.joint):
        for k, vec in enumerate((fo, mo)):
            if any(vec):
                d = exact_vector(vec, walk.sym.table)
                d = d if m.X_child.is_Identity else m.X_child * d
                P[k] += d * d.T
    return [walk.s(p) for p in P]


def _cross_columns(r, A):
    """``r x`` every column of ``A`` (3 x n)."""
    return sympy.Matrix.hstack(*[cross(r, A[:, c]) for c in range(A.cols)]) if A.cols \
        else sympy.zeros(3, 0)


def newton_euler(walk):
    """Newton-Euler with reactions: per-body equations, leaves to root, solved for each
    joint's reaction; the free-direction components give ``M u' = f``.

    Everything is linear in the speed rates ``u'``, so each reaction is carried as
    ``A u' + b`` (``A`` built from the Jacobians, ``b`` from the velocity products and the
    applied loads): ``M`` and ``f`` are read off the free-direction rows without
    differentiating the (nested) expressions.
    """
    s = walk.s
    sym = walk.sym
    nu = len(sym.u)
    wrench = {}
    bodies = []
    rows, pushes = {}, []
    ud = sympy.Matrix(sym.ud) if nu else sympy.zeros(0, 1)
    for m in reversed(walk.motions):
        I = m.inertia_basis
        c = m.com_basis
        aG0 = walk.bias(m.a_G)
        al0 = walk.bias(m.alpha)
        AF = m.mass * m.JT
        bF = m.mass * aG0 - m.force
        AM = I * m.JR + _cross_columns(c, AF)
        bM = I * al0 + cross(m.omega, I * m.omega) - m.moment + cross(c, bF)
        if m.name in walk.flexible_by_frame:     # a floating frame's rigid rows
            AF, bF, AM, bM = walk.flexible_by_frame[m.name].wrench(m)
        child_terms = []
        for ch in m.children:
            cAF, cbF, cAM, cbM = wrench[ch.name]
            X = ch.T.T if walk.frames == "own" else sympy.eye(3)
            rho = ch.rho_p if walk.frames == "own" else m.X_child * ch.rho_p
            XAF, XbF = X * cAF, X * cbF
            AF += XAF
            bF += XbF
            AM += X * cAM + _cross_columns(rho, XAF)
            bM += X * cbM + cross(rho, XbF)
            child_terms.append((ch.joint.name, X, rho))
        AF, bF, AM, bM = s(AF), s(bF), s(AM), s(bM)
        wrench[m.name] = (AF, bF, AM, bM)
        maG = s(m.mass * m.a_G)
        euler_G = s(I * m.alpha + cross(m.omega, I * m.omega))
        bodies.append({"body": m.name, "joint": m.joint.name, "basis": m.basis,
                       "m_aG": maG, "euler_G": euler_G, "force": m.force,
                       "moment": m.moment, "com": c, "children": child_terms})
        _free_direction_rows(walk, m, (AF, bF, AM, bM), rows, pushes)
    bodies.reverse()
    for body in walk.flexible:              # and its modal rows
        for r, a, b in body.modal_rows():
            rows[r] = (a, b)
    for r, (a, b) in pushes:
        rows[r] = (rows[r][0] + a, rows[r][1] + b)
    M = sympy.zeros(nu, nu)
    f = sympy.zeros(nu, 1)
    for r, (a, b) in rows.items():
        for c in range(nu):
            M[r, c] = s(a[0, c])
        f[r] = s(-b)
    return Equations("newton-euler", M, f, {"bodies": bodies,
                                            "reactions": _Reactions(walk, wrench, ud)})


def _free_direction_rows(walk, m, wrench, rows, pushes):
    """The equations of motion at frame ``m``'s joint: no reaction along its free
    directions (``rows[r] = (a, b)``, the row ``a u' + b = 0`` of speed ``r``); a node
    frame's chain joint's effort along its coordinate pushes the modes instead
    (``pushes``: added to the modal rows, ``D^T tau``)."""
    AF, bF, AM, bM = wrench
    qj, uj, udj, driven = walk.joint_values[m.joint.name]
    chain = driven == CHAIN
    if (driven and not chain) or not uj:
        return
    for u in walk.speeds_of(m.joint, uj):
        dF = m.v_rel_basis.applyfunc(lambda e: diff(e, u))
        dM = m.w_rel_basis.applyfunc(lambda e: diff(e, u))
        row = (dF.T * AF + dM.T * AM, (dF.T * bF)[0] + (dM.T * bM)[0])
        r = walk.sym.u.index(u)
        if chain:
            pushes.append((r, row))
        else:
            rows[r] = row


class _Reactions:
    """Each joint's reaction (force, moment), computed when first asked for: projected
    onto the directions the joint transmits, as ``A u' + b`` (``linear``) or as one
    expression (``[joint]``)."""

    def __init__(self, walk, wrench, ud):
        self.walk, self.wrench, self.ud = walk, wrench, ud
        self._linear = {}

    def linear(self, joint):
        if joint not in self._linear:
            s = self.walk.s
            m = self.walk.by_name[self.walk.model.joint(joint).child]
            AF, bF, AM, bM = self.wrench[m.name]
            PF, PM = _projectors(self.walk, m)
            if PF != sympy.eye(3):
                AF, bF = s(PF * AF), s(PF * bF)
            if PM != sympy.eye(3):
                AM, bM = s(PM * AM), s(PM * bM)
            self._linear[joint] = (AF, bF, AM, bM)
        return self._linear[joint]

    def __getitem__(self, joint):
        AF, bF, AM, bM = self.linear(joint)
        s = self.walk.s
        return s(AF * self.ud + bF), s(AM * self.ud + bM)

    def __iter__(self):
        return iter(self.walk.model.joints)

    def items(self):
        return [(j, self[j]) for j in self]


def lagrange(walk):
    """Lagrange's equations of the second kind with ``u = q'``."""
    s = walk.s
    sym = walk.sym
    for j in walk.joints:
        if j.drive is None and j.kind in ("spherical", "free"):
            raise ModelError(f"joint {j.name!r} ({j.kind}): Lagrange's equations need the "
                             "speeds to be the coordinate rates, and a quaternion joint's "
                             "speeds are angular velocities; use method='jourdain' or "
                             "'newton-euler', or an euler joint")
    q = [c for c in sym.q]
    u = sym.u
    Tkin = sympy.Integer(0)
    V = sympy.Integer(0)
    Q = sympy.zeros(len(u), 1)
    parts = []
    for m in walk.motions:
        if m.has_inertia:
            I = m.inertia_basis
            Tm = s(m.mass * (m.v_G.T * m.v_G)[0] / 2 + (m.omega.T * I * m.omega)[0] / 2)
            Vm = s(-m.mass * (m.gravity.T * m.r_G)[0])
            Tkin += Tm
            V += Vm
            parts.append((m.name, Tm, Vm))
        for name, F, N, point in m.loads:
            JTp, JR = walk.point_jacobians(m, point)
            Q += JTp.T * F + JR.T * N
    for body in walk.flexible:              # 1/2 w^T M_b w, weight and strain, the rest
        Tb, Vb, Qb = body.energies()
        Tkin, V, Q = Tkin + Tb, V + Vb, Q + Qb
        parts.append((body.name, Tb, Vb))
    Tkin, V = s(Tkin), s(V)
    Q = Q.applyfunc(s)
    n = len(u)
    dTdu = [s(diff(Tkin, x)) for x in u]
    M = sympy.zeros(n, n)
    f = sympy.zeros(n, 1)
    for k in range(n):
        p = dTdu[k]
        for j in range(k, n):
            M[k, j] = M[j, k] = s(diff(p, u[j]))
        rest = -sum((diff(p, q[j]) * u[j] for j in range(n)), sympy.Integer(0)) - diff(p, sym.t)
        f[k] = s(Q[k] - diff(V, q[k]) + diff(Tkin, q[k]) + rest)
    return Equations("lagrange", M, f, {"kinetic": Tkin, "potential": V,
                                        "generalized_forces": Q, "bodies": parts,
                                        "momenta": dTdu})


FORMULATIONS = {"newton-euler": newton_euler, "jourdain": jourdain, "lagrange": lagrange}

"""Flexible bodies in the symbolic layer: a floating-frame body's terms in closed form,
its inertia invariants and modal matrices as named symbols.

The tree is walked as for rigid models, with each flexible body a massless frame
(``FlexibleModel.tree``); its frame's motion gives, in the body's own components, the
velocity ``v`` of the frame origin, the angular velocity ``omega``, their Jacobians and
the accelerations at ``u' = 0``.  With the modal coordinates ``eta`` (the model's
coordinates ``BODY_m1 ...``) and rates ``eta'``, the body's speeds and mass matrix are

    w = (v, omega, eta'),      M_b(eta) = [[m I,  -S~,  S1 ], [S~,  J,  Cr], [S1^T, Cr^T, M_ee]]

    S(eta)  = S0 + S1 eta                             first moment (S1 = C_t: the coupling)
    J(eta)  = J0 + eta_k J1_k + sum_{k<=l} eta_k eta_l J2_kl      inertia about the origin
    Cr(eta) = Cr0 + eta_k Cr1_k                       rotation-elastic coupling (C_r)

(``mbdyn.flexible.invariants``; ``J2_kl`` here is the symmetric coefficient of
``eta_k eta_l``).  Every entry is a symbol named ``BODY_NAME_indices`` (components ``x``,
``y``, ``z``, modes ``1 .. n``: ``beam_S1_y_2``, ``beam_J2_1_2_xy``, ``beam_Kee_1_1``),
an entry below 1e-11 of the largest of its matrix an exact 0; their values are in
``constants`` (``Derivation.numeric`` reads them).  The forces: the quadratic velocity
vector ``Q_v`` (centrifugal, Coriolis, gyroscopic: Kirchhoff's form), the weight
``(m g, S x g, S1^T g)`` (body components), the elastic and damping forces ``-K_ee eta -
D_ee eta'``, a rotor's ``-Omega G_ee eta'`` and, with ``geometric_stiffening``,
``-((omega_y^2 + omega_z^2) Kc + (a_x - g_x) Ka) eta``.  Jourdain adds ``B^T M_b B`` and
``B^T (Q - M_b w'_bias)`` (``B = dw/du``); Newton-Euler takes the rigid rows as the
body's wrench at its frame and the modal rows as equations; Lagrange takes the kinetic
energy ``1/2 w^T M_b w``, the potential ``-g . (m r + S) + 1/2 eta^T K_ee eta`` and the
other forces as generalized forces (so its ``Q_v`` is derived, not written).

Small models only: at most ``limits.MAX_SYMBOLIC_MODES`` modes a body, no joints, loads
or force elements at its nodes (its frame origin only), the gyroscopic effect on, and no
axial stiffening where the frame's axial acceleration depends on the accelerations (the
matrix ``u'`` solves would not be symmetric); each refused with its remedy.
"""
from __future__ import annotations

import itertools

import numpy as np
import sympy

from .. import limits
from ..errors import ModelError
from .symbols import cross

AXES = "xyz"
#: the flag ``Walk.joint_values`` holds for a node frame's chain joint (its coordinate a
#: row of the modes at the node times ``eta``: moved, like a drive, but by the modes)
CHAIN = "chain"
#: an invariant's entry below this fraction of the largest of its matrix is an exact 0
ZERO = 1e-11


def _skew(a):
    return sympy.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


class _Names:
    """Symbols of one body's invariants and their values: ``constants`` ``{Symbol:
    value}``, ``matrices`` ``{label: sympy.Matrix of the symbols}`` (for the reports)."""

    def __init__(self, body, taken):
        self.body, self.taken = body, taken
        self.constants, self.matrices, self.meanings = {}, {}, {}

    def symbol(self, name, value):
        full = f"{self.body}_{name}"
        if full in self.taken:
            raise ModelError(f"flexible body {self.body!r}: the symbolic layer names its "
                             f"invariant {full!r}, which is already a name of the model; "
                             "rename the parameter, coordinate or body")
        s = sympy.Symbol(full, real=True)
        self.taken.add(full)
        self.constants[s] = float(value)
        return s

    def matrix(self, label, values, rows, cols, symmetric=False, skew=False, meaning=""):
        """A matrix of symbols ``label_row_col`` (zeros exact); ``symmetric``/``skew``:
        one symbol per pair; ``meaning`` for the reports."""
        values = np.atleast_2d(np.asarray(values, float))
        big = np.abs(values).max(initial=0.0)
        out = sympy.zeros(*values.shape)
        for i, j in itertools.product(range(values.shape[0]), range(values.shape[1])):
            if (symmetric or skew) and j < i:
                out[i, j] = out[j, i] if symmetric else -out[j, i]
                continue
            v = values[i, j]
            if abs(v) <= ZERO * big or (skew and i == j):
                continue
            sep = "" if rows[i].isalpha() and cols[j].isalpha() else "_"
            index = rows[i] + sep + cols[j] if rows[i] else cols[j]
            out[i, j] = self.symbol(f"{label}_{index}", v)
        self.matrices[label] = out
        if meaning:
            self.meanings[label] = meaning
        return out

    def vector(self, label, values, rows):
        """A column of symbols ``label_row`` (zeros exact)."""
        values = np.asarray(values, float)
        big = np.abs(values).max(initial=0.0)
        out = sympy.Matrix([0 if abs(v) <= ZERO * big else self.symbol(f"{label}_{r}", v)
                            for v, r in zip(values, rows)])
        self.matrices[label] = out
        return out


def _symmetric_parts(fb):
    """``{(k, l): (3, 3)}`` for ``k <= l``: the symmetric coefficient of ``eta_k eta_l``
    in ``J(eta)`` (``J2_kl + J2_lk`` for ``k < l``, ``J2_kk``)."""
    J2 = fb.invariants.inertia_2
    return {(k, l): (J2[k, l] if k == l else J2[k, l] + J2[l, k])
            for k in range(fb.n) for l in range(k, fb.n)}


class FlexibleBodyTerms:
    """One flexible body in the walk: its named invariants, its speeds ``w``, ``B``, the
    bias accelerations, ``M_b(eta)`` and the forces ``Q`` (module docstring)."""

    def __init__(self, walk, fb, taken):
        # long: the named invariants of the docstring, matrix by matrix
        model, sym = walk.model, walk.sym
        self.name, self.n, self.walk = fb.name, fb.n, walk
        rec = model.flexible[fb.name]
        k0, u0 = model.coordinates.index(rec.coordinates[0]), model.speeds.index(rec.speeds[0])
        self.eta = sympy.Matrix(sym.q[k0:k0 + fb.n])
        self.eta_dot = sympy.Matrix(sym.u[u0:u0 + fb.n])
        modes = [str(k + 1) for k in range(fb.n)]
        inv = fb.invariants
        nm = walk.chain_names.get(fb.name) or _Names(fb.name, taken)
        self.names = nm
        self.m = nm.symbol("m", inv.mass)
        nm.matrices["m"] = sympy.Matrix([[self.m]])
        self.S0 = nm.vector("S0", inv.first_moment, AXES)
        self.S1 = nm.matrix("S1", inv.modal_first_moment, AXES, modes)
        J0 = nm.matrix("J0", inv.inertia, AXES, AXES, symmetric=True)
        self.J = J0 + sum((self.eta[k] * nm.matrix(f"J1_{k + 1}", inv.inertia_1[k], AXES,
                                                   AXES, symmetric=True)
                           for k in range(fb.n)), sympy.zeros(3, 3))
        for (k, l), part in _symmetric_parts(fb).items():
            self.J += self.eta[k] * self.eta[l] * nm.matrix(
                f"J2_{k + 1}_{l + 1}", part, AXES, AXES, symmetric=True)
        self.Cr = nm.matrix("Cr0", inv.coupling, AXES, modes) + sum(
            (self.eta[k] * nm.matrix(f"Cr1_{k + 1}", inv.coupling_1[k], AXES, modes)
             for k in range(fb.n)), sympy.zeros(3, fb.n))
        sym_ = np.allclose(fb.mass, fb.mass.T, rtol=0, atol=ZERO * np.abs(fb.mass).max())
        self.Mee = nm.matrix("Mee", fb.mass, modes, modes, symmetric=sym_)
        self.Kee = nm.matrix("Kee", fb.stiffness, modes, modes, symmetric=_is_sym(fb.stiffness))
        self.Dee = nm.matrix("Dee", fb.damping, modes, modes, symmetric=_is_sym(fb.damping))
        self.stiffening = bool(model.stiffening)
        if self.stiffening:
            self.Kc = nm.matrix("Kc", fb.centrifugal, modes, modes,
                                symmetric=_is_sym(fb.centrifugal))
            self.Ka = nm.matrix("Ka", fb.axial, modes, modes, symmetric=_is_sym(fb.axial))
        self.Omega = None
        if fb.spin:
            self.Omega = nm.symbol("Omega", fb.spin)
            self.Gee = nm.matrix("Gee", fb.gyroscopic, modes, modes, skew=True)
        self._motion(walk.by_name[fb.name])

    def _motion(self, m):
        """``w``, ``B``, the bias ``(a_0, alpha, 0)`` and gravity in body components."""
        walk, s = self.walk, self.walk.s
        XT = None if walk.frames == "own" else m.X_child.T
        body = (lambda v: v) if XT is None else (lambda v: s(XT * v))
        self.motion, self.XT = m, XT
        self.v, self.omega = body(m.v), body(m.omega)
        self.w = sympy.Matrix.vstack(self.v, self.omega, self.eta_dot)
        self.B = walk.jacobian(self.w)
        self.bias = sympy.Matrix.vstack(body(walk.bias(m.a)), body(walk.bias(m.alpha)),
                                        sympy.zeros(self.n, 1))
        self.g = body(m.gravity)
        self.r = body(m.r)

    # ---------------------------------------------------------------- the body's terms
    @property
    def S(self):
        return self.S0 + self.S1 * self.eta

    def mass_matrix(self):
        """``M_b(eta)`` ((6 + n) square)."""
        if getattr(self, "_Mb", None) is None:
            self._Mb = self._mass_matrix()
        return self._Mb

    def _mass_matrix(self):
        n, S = self.n, self.S
        M = sympy.zeros(6 + n, 6 + n)
        M[:3, :3] = self.m * sympy.eye(3)
        M[:3, 3:6], M[3:6, :3] = -_skew(S), _skew(S)
        M[:3, 6:], M[6:, :3] = self.S1, self.S1.T
        M[3:6, 3:6], M[3:6, 6:], M[6:, 3:6] = self.J, self.Cr, self.Cr.T
        M[6:, 6:] = self.Mee
        return M

    def quadratic_velocity_vector(self):
        """``Q_v`` (6 + n): ``mbdyn.flexible.invariants.quadratic_velocity_vector``."""
        w, ed, eta = self.omega, self.eta_dot, self.eta
        dJ = [self.J.diff(e) for e in eta]
        dCr = [self.Cr.diff(e) for e in eta]
        Jdot = sum((ed[k] * dJ[k] for k in range(self.n)), sympy.zeros(3, 3))
        Q_t = -cross(w, cross(w, self.S)) - 2 * cross(w, self.S1 * ed)
        Q_r = -cross(w, self.J * w) - Jdot * w - cross(w, self.Cr * ed)
        Cr_dot = sum((ed[k] * dCr[k] for k in range(self.n)), sympy.zeros(3, self.n))
        Q_e = sympy.Matrix([(w.T * dJ[k] * w)[0] / 2 + (w.T * dCr[k] * ed)[0]
                            - (w.T * Cr_dot[:, k])[0] for k in range(self.n)])
        return sympy.Matrix.vstack(Q_t, Q_r, Q_e)

    def modal_forces(self):
        """The forces on the modal coordinates no potential gives: damping, a rotor's
        gyroscopic term and the geometric stiffening (``n``)."""
        Q = -self.Dee * self.eta_dot
        if self.Omega is not None:
            Q -= self.Omega * self.Gee * self.eta_dot
        if self.stiffening:
            a_x = self.bias[0] - self.g[0]
            Q -= ((self.omega[1] ** 2 + self.omega[2] ** 2) * self.Kc + a_x * self.Ka) \
                * self.eta
        return Q

    def forces(self):
        """``Q`` (6 + n): ``Q_v``, the weight, the elastic and the other modal forces."""
        if getattr(self, "_Q", None) is None:
            self._Q = self._forces()
        return self._Q

    def _forces(self):
        g = self.g
        Q = self.quadratic_velocity_vector()
        Q[:3, 0] += self.m * g
        Q[3:6, 0] += cross(self.S, g)
        Q[6:, 0] += self.S1.T * g - self.Kee * self.eta + self.modal_forces()
        return Q

    # ---------------------------------------------------------------- per method
    def jourdain(self):
        """``(B^T M_b B, B^T (Q - M_b w'_bias))`` over the model's speeds."""
        s, Mb = self.walk.s, self.mass_matrix()
        MbB = Mb * self.B
        return ((self.B.T * MbB).applyfunc(s),
                (self.B.T * (self.forces() - Mb * self.bias)).applyfunc(s))

    def wrench(self, m):
        """``(AF, bF, AM, bM)``: the wrench the body needs at its frame origin, ``A u' +
        b`` (force and moment, the walk's basis), less the loads applied to its frame
        (the loop multipliers' by Newton-Euler): its floating frame's rigid rows."""
        s, Mb = self.walk.s, self.mass_matrix()
        rigid = Mb[:6, :] * self.B
        rest = Mb[:6, :] * self.bias - self.forces()[:6, 0]
        X = (lambda v: v) if self.XT is None else (lambda v: self.XT.T * v)
        return (s(X(rigid[:3, :])), s(X(rest[:3, 0]) - m.force),
                s(X(rigid[3:, :])), s(X(rest[3:, 0]) - m.moment))

    def modal_rows(self):
        """``[(speed index, a (1 x nu), b)]``: the modal equations ``a u' + b = 0``."""
        s, Mb = self.walk.s, self.mass_matrix()
        A = Mb[6:, :] * self.B
        b = Mb[6:, :] * self.bias - self.forces()[6:, 0]
        first = self.walk.sym.u.index(self.eta_dot[0])
        return [(first + k, A[k, :].applyfunc(s), s(b[k])) for k in range(self.n)]

    def energies(self):
        """``(T, V, Q)``: kinetic and potential energy, and the other modal forces as
        generalized forces over the model's speeds (Lagrange)."""
        s = self.walk.s
        T = s((self.w.T * self.mass_matrix() * self.w)[0] / 2)
        V = s(-(self.m * (self.g.T * self.r)[0] + (self.g.T * self.S)[0])
              + (self.eta.T * self.Kee * self.eta)[0] / 2)
        Q = sympy.zeros(len(self.walk.sym.u), 1)
        first = self.walk.sym.u.index(self.eta_dot[0])
        Q[first:first + self.n, 0] = self.modal_forces().applyfunc(s)
        return T, V, Q


def _is_sym(A):
    return bool(np.allclose(A, A.T, rtol=0, atol=ZERO * max(np.abs(A).max(), 1e-300)))


def chain_values(walk):
    """``{joint: (q, u, u', CHAIN)}`` of the node frames' chain joints
    (``elements.flexible_nodes``): each coordinate ``D_j eta``, its rate ``D_j eta'`` and
    acceleration ``D_j eta''``, the entries of ``D`` (the mode shapes at the node, as the
    numeric ``StateMap`` has them) named ``BODY_NODE_c_k`` (the chain coordinate's name,
    then the mode) with their values in ``walk.constants``."""
    model, sym = walk.model, walk.sym
    walk.constants, walk.taken, walk.chain_names = {}, set(sym.table), {}
    out = {}
    for nf in getattr(model, "node_frames", ()):
        rec = model.flexible[nf.body]
        k0, u0 = model.coordinates.index(rec.coordinates[0]), model.speeds.index(rec.speeds[0])
        eta, rate = sym.q[k0:k0 + rec.n_modes], sym.u[u0:u0 + rec.n_modes]
        accel = sym.ud[u0:u0 + rec.n_modes]
        names = walk.chain_names.setdefault(nf.body, _Names(nf.body, walk.taken))
        for joint, row in zip(nf.joints, nf.rows):
            coordinate = model.tree.joint(joint).coordinates[0]
            D = names.matrix(coordinate[len(nf.body) + 1:], np.reshape(row, (1, -1)), [""],
                             [str(k + 1) for k in range(row.size)],
                             meaning=f"node frame {nf.name}: {coordinate} per mode")
            q, u, ud = ((D * sympy.Matrix(v))[0] for v in (eta, rate, accel))
            out[joint] = ([q], [u], [ud], CHAIN)
        walk.constants.update(names.constants)
    return out


def attach(walk):
    """The walk's ``flexible`` terms (``FlexibleBodyTerms`` per body), the modal
    coordinates' kinematic equations ``eta' = u`` and the invariants' values
    ``walk.constants``; what the symbolic layer cannot write is refused, named."""
    model = walk.model
    walk.flexible, walk.flexible_by_frame = [], {}
    if not getattr(model, "flexible_bodies", ()):
        return
    taken = walk.taken
    for fb in model._flex:
        body = FlexibleBodyTerms(walk, fb, taken)
        for e, ed in zip(body.eta, body.eta_dot):
            walk.qdot[e] = ed
        _check_axial(model, body)
        walk.flexible.append(body)
        walk.constants.update(body.names.constants)
    walk.flexible_by_frame = {b.name: b for b in walk.flexible}


def check(model):
    """Refuse the flexible models the symbolic layer does not write (module docstring)."""
    where = f"model {model.name!r}: the symbolic layer"
    for fb in model._flex:
        if fb.n > limits.MAX_SYMBOLIC_MODES:
            raise ModelError(f"{where} writes flexible bodies of at most "
                             f"{limits.MAX_SYMBOLIC_MODES} modes in closed form "
                             f"(limits.MAX_SYMBOLIC_MODES); {fb.name!r} has {fb.n}: give it "
                             f"modes = {limits.MAX_SYMBOLIC_MODES} or fewer")
    if model._flex_elements:
        pk = model._flex_elements[0]
        raise ModelError(f"{where} does not write loads and force elements at flexible "
                         f"bodies yet ({pk.what} {pk.record.name!r}); switch it off "
                         f"(--effects=-{pk.record.name}) or use the numeric routes")
    if not model.tree.gyroscopic:
        raise ModelError(f"{where} writes flexible bodies with the gyroscopic effect on "
                         "only; derive without -gyroscopic")


def _check_axial(model, body):
    if body.stiffening and any(e != 0 for e in body.Ka) and any(
            e != 0 for e in body.B[0, :]):
        raise ModelError(
            f"model {model.name!r}: flexible body {body.name!r}: the geometric stiffening's "
            "axial term reads the frame's axial acceleration, which here depends on the "
            "accelerations (the matrix u' solves is then not symmetric): not written in "
            "closed form; derive with --effects=-geometric_stiffening")

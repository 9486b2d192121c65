"""The Newton-Euler equations with reaction unknowns of a model with flexible bodies,
assembled as one system and solved by LU (numpy): a route of its own to ``u'`` and the
reactions, beside the Jourdain route (``flexible_dynamics``), which it does not call.

Equations (rows):

* six per frame of the tree (``kernels.dynamics.newton_euler_system``: Newton at the
  centre of mass, Euler about it, world components), the node frames' massless chains
  among them.  A flexible body, a massless frame of the tree, takes the *rigid rows* of
  its floating-frame equations there: the momentum and angular momentum of the whole
  deformable body about its frame origin, ``R (M_b[:6] w' - Q[:6]) = F + reactions``,
  with ``w' = B u_x' + (a_0, alpha)_bias`` (body components, ``B`` the body's map of the
  extended speeds) and ``Q`` its quadratic velocity vector, weight and the loads at its
  nodes (``mbdyn.flexible.invariants``);
* the *modal rows* of every flexible body, ``M_b[6:] w' - Q[6:] + D^T tau = 0``:
  ``Q[6:]`` holds the elastic, damping, gyroscopic (rotors) and stiffening forces, and
  ``tau`` the efforts of its node frames' chain joints (what the body exerts on the
  chain along each chain coordinate, whose motion is ``D eta``): a joint at a node
  pushes the modal coordinates through them;
* with loops, ``G_r u' = U_r^T gamma`` for the kept directions of ``G = U S V^T``
  (``G_r = S_r V_r^T``, ``flexible_loops``).

Unknowns (columns): the model's ``u'`` (the tree's speeds through the constant map
``u_x' = P u'``, ``compiled.flexible_states``), the reaction components of every tree
joint (``compiled.layout.reaction_basis``; a driven joint's effort among them), each
chain joint's effort ``tau`` along its coordinate, and with loops the multipliers in the
kept directions, ``lam = U_r mu`` (the multipliers orthogonal to every self-balanced set
``G^T z = 0``: the minimum-norm multipliers, as the Jourdain route's).  The system is
square: ``6 n + modal + r`` rows and columns.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, NonFiniteError, SingularMassMatrixError
from ..flexible.invariants import (cross3, floating_frame_mass_matrix,
                                   quadratic_velocity_vector, skew)
from ..kernels import constraints as kcon
from ..kernels import dynamics as kd
from . import flexible_loops as loops_rows
from .flexible_forces import wrenches

#: the routes this module is (both the same dense system: the elimination in tree order
#: of the rigid route has no floating-frame bodies)
METHODS = ("newton-euler", "newton-euler-dense")

#: the side of an element each wrench of ``flexible_forces.wrenches`` acts on (as
#: ``flexible_reactions.SIDES``): a bushing's first wrench is on its second side
SIDES = {"load": (0,), "spring-damper": (0, 1), "bushing": (1, 0), "bearing": (0, 1)}

#: kinds of the tree's joints (``kernels.joints``): a chain joint is one of these
PRISMATIC, REVOLUTE = "prismatic", "revolute"


@dataclass(frozen=True)
class Solution:
    """``u'`` (the model's speeds), the tree joints' reaction components ``react``
    (``tree._reaction_slices``), the chain joints' efforts ``tau`` and the loop joints'
    multipliers ``lam`` (``None`` without loops)."""
    ud: np.ndarray
    react: np.ndarray
    tau: np.ndarray
    lam: np.ndarray | None


def forward_dynamics(model, q, u, t=0.0):
    """``u'`` by the Newton-Euler system with reaction unknowns (module docstring)."""
    return solve(model, q, u, t).ud


def newton_euler(model, q, u, t=0.0, dense=False):
    """``(u', {joint: (F, M)})``: the accelerations and every joint's reaction (tree joints
    at their origin, loop joints at their point on the child; world components), both
    from one solve of the system (``dense`` is accepted for the rigid models' signature:
    there is one system)."""
    sol = solve(model, q, u, t)
    return sol.ud.copy(), reactions_of(model, sol)


def _state(model, q, u):
    try:
        q, u = np.asarray(q, dtype=float), np.asarray(u, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"model {model.name!r}: q and u must be arrays of numbers "
                         f"(q: {model.nq} coordinates, u: {model.nu} speeds)") from None
    if q.shape != (model.nq,) or u.shape != (model.nu,):
        raise ModelError(f"model {model.name!r} expects q of length {model.nq} and u of "
                         f"length {model.nu}, got {q.shape} and {u.shape}")
    return q, u


def solve(model, q, u, t=0.0):
    """The ``Solution`` at ``(q, u, t)``."""
    q, u = _state(model, q, u)
    rows = _loop_rows(model, q, u, t) if model.has_loops else None
    K, rhs, sizes = _system(model, q, u, t, rows)
    if not (np.all(np.isfinite(K)) and np.all(np.isfinite(rhs))):
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the Newton-Euler equations "
                             "came out non-finite (check the state, masses and stiffness)")
    try:
        x = np.linalg.solve(K, rhs)
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(
            f"model {model.name!r}, t={t:.6g}: the Newton-Euler system with reactions is "
            "singular (a massless frame on a free joint, or the loops lock the "
            "mechanism)", []) from None
    nu, nr, nc = sizes
    lam = None if rows is None else rows[0] @ x[nu + nr + nc:]
    return Solution(x[:nu], x[nu:nu + nr], x[nu + nr:nu + nr + nc], lam)


def _loop_rows(model, q, u, t):
    """``(U_r, G_r, U_r^T gamma)``: the kept directions of the loops' rows (evaluated
    before the tree's kinematics of the system: they evaluate the tree themselves)."""
    _, _, G, gamma = loops_rows.constraint_terms(model, q, u, t)
    Ur, sr, Vtr, _ = loops_rows._kept(G, model)
    return Ur, sr[:, None] * Vtr, Ur.T @ gamma


def _system(model, q, u, t, rows):
    """``(K, rhs, (nu, n_reactions, n_chain))`` of the module docstring."""
    # long: one system assembled in its blocks, each a few lines, in the order of the text
    tree = model.tree
    qx, ux = model._extended(q, u)
    nqt, nut, n = tree.nq, tree.nu, tree.n_frames
    omegas, F, N, Qel = _kinematics_and_loads(model, qx, ux, t)
    A, b = tree._dense_system()
    kd.newton_euler_system(tree._mass, tree._com, tree._inertia, tree._parent, tree._R,
                           tree._r, tree._w, tree._alpha, tree._a, tree._JR, tree._JT,
                           tree._anc_ptr, tree._anc_idx, F, N, tree._react_joint,
                           tree._react_force, tree._react_moment, A, b, tree._scratch)
    P = model._map.P if model._map is not None else np.eye(model._nux)
    chains = _chains(model)
    nu, nr, nc = model.nu, A.shape[1] - nut, len(chains)
    nm, r = model._nux - nut, 0 if rows is None else rows[1].shape[0]
    size = 6 * n + nm + r
    if nu + nr + nc + r != size:
        raise ModelError(f"model {model.name!r}: the Newton-Euler system has {size} rows "
                         f"and {nu + nr + nc + r} unknowns")
    K, rhs = np.zeros((size, size)), np.zeros(size)
    K[:6 * n, :nu] = A[:, :nut] @ P[:nut]
    K[:6 * n, nu:nu + nr] = A[:, nut:]
    rhs[:6 * n] = b
    for fb in model._flex:
        lhs, f = _body_rows(model, fb, qx, ux, omegas[fb.frame], Qel[fb.name])
        i, m = fb.frame, 6 * n + fb.u.start - nut
        R, c = tree._R[i], tree._R[i] @ tree._com[i]
        force, moment = R @ lhs[:3], R @ lhs[3:6]
        K[6 * i:6 * i + 3, :nu] += force @ P
        K[6 * i + 3:6 * i + 6, :nu] += (moment - skew(c) @ force) @ P
        rhs[6 * i:6 * i + 3] += R @ f[:3]
        rhs[6 * i + 3:6 * i + 6] += R @ f[3:6] - cross3(c, R @ f[:3])
        K[m:m + fb.n, :nu] = lhs[6:] @ P
        rhs[m:m + fb.n] = f[6:]
    for k, (child, parent, kind, axis, D_row) in enumerate(chains):
        col = nu + nr + k
        _joint_column(tree, child, parent, kind, axis, K[:6 * n, col])
        K[6 * n:6 * n + nm, col] = D_row
    if rows is not None:
        Ur, Gr, gamma_r = rows
        K[:6 * n, nu + nr + nc:] = -_multiplier_loads(tree) @ Ur
        K[6 * n + nm:, :nu] = Gr
        rhs[6 * n + nm:] = gamma_r
    return K, rhs, (nu, nr, nc)


def _kinematics_and_loads(model, qx, ux, t):
    """The tree's motion at the extended state with ``u_x' = 0`` (its full Jacobians and
    bias accelerations in its workspace, the velocity products dropped with the
    gyroscopic effect off, after the loads have read the true velocities):
    ``(omegas, F, N, Qel)``, each frame's true angular velocity in its own components
    (the stiffening reads it whatever the switch), the tree's applied loads with the
    elements' wrenches on rigid bodies added, and each flexible body's generalized
    element forces (``_element_loads``)."""
    tree = model.tree
    tree._kinematics_kernel(qx[:tree.nq], ux[:tree.nu], t)
    omegas = np.einsum("nji,nj->ni", tree._R, tree._w)
    F, N = tree._F.copy(), tree._N.copy()
    Qel = _element_loads(model, qx, ux, t, F, N)
    tree._drop_velocity_products()
    return omegas, F, N, Qel


def _element_loads(model, qx, ux, t, F, N):
    """The loads and force elements at points of flexible bodies: their wrenches on rigid
    frames added to ``F``, ``N`` (world, about the centres of mass), and per flexible body
    ``{name: Q_el}`` (6 + k, body components, moments about the frame origin): a force
    ``F`` and moment ``N`` at a point rigidly moved by the node ``(x_p, Phi_p, Psi_p)``
    give ``(F_b, x_p(eta) x F_b + N_b', Phi_p^T F_b + Psi_p^T N_b')``, with ``N_b'`` the
    moment about the node's point (``F`` may act off it: a bushing's far side)."""
    tree = model.tree
    out = {fb.name: np.zeros(6 + fb.n) for fb in model._flex}
    for pk in model._flex_elements:
        for k, ((p, *_), f, n) in zip(SIDES[pk.what], wrenches(model, pk, qx, ux, t,
                                                                 jacobians=False)[0]):
            sd = pk.sides[k]
            if sd.flex is None:
                _add(tree, sd.frame, p, f, n, F, N)
                continue
            i, pt, eta = sd.frame, sd.point, qx[sd.flex.q]
            RT = tree._R[i].T
            xb = pt.x + pt.Phi @ eta
            fb_, nb = RT @ f, RT @ n + cross3(RT @ (p - tree._r[i]) - xb, RT @ f)
            out[sd.flex.name] += np.concatenate([fb_, cross3(xb, fb_) + nb,
                                                 pt.Phi.T @ fb_ + pt.Psi.T @ nb])
    return out


def _add(tree, frame, p, f, n, F, N):
    """The force ``f`` at the world point ``p`` and the moment ``n`` added to the tree
    frame ``frame``'s applied loads (about its centre of mass; the ground: nothing)."""
    if frame < 0:
        return
    c = tree._r[frame] + tree._R[frame] @ tree._com[frame]
    F[frame] += f
    N[frame] += n + cross3(p - c, f)


def _body_rows(model, fb, qx, ux, omega, Qel):
    """``(L, f)`` of the body's floating-frame equations ``L u_x' = f`` (6 + k rows over
    the extended speeds, body components, moments about the frame origin): ``L = M_b B``
    (plus the stiffening's part in the frame's axial acceleration), ``f = Q - M_b w'_bias``
    with ``Q`` the quadratic velocity vector, the weight, the elastic, damping, rotor and
    stiffening forces and the elements' ``Qel``; the joints' wrenches are the unknowns."""
    tree, inv = model.tree, fb.invariants
    i, n = fb.frame, fb.n
    RT = tree._R[i].T
    eta, eta_dot = qx[fb.q], ux[fb.u]
    Mb = floating_frame_mass_matrix(inv, eta)
    Mb[6:, 6:] = fb.mass
    B = np.zeros((6 + n, model._nux))
    B[:3, :tree.nu], B[3:6, :tree.nu] = RT @ tree._JT[i], RT @ tree._JR[i]
    B[6:, fb.u] = np.eye(n)
    bias = np.concatenate([RT @ tree._a[i], RT @ tree._alpha[i]])
    g = RT @ tree.gravity
    Q = Qel.copy()
    if tree.gyroscopic and omega.any():
        Q += quadratic_velocity_vector(inv, eta, eta_dot, omega)
    Q[:3] += inv.mass * g
    Q[3:6] += cross3(inv.first_moment + inv.modal_first_moment @ eta, g)
    Q[6:] += inv.modal_first_moment.T @ g - fb.stiffness @ eta - fb.damping @ eta_dot
    if fb.spin:
        Q[6:] -= fb.spin * (fb.gyroscopic @ eta_dot)
    L = Mb @ B
    if model.stiffening:
        Kg = (omega[1] ** 2 + omega[2] ** 2) * fb.centrifugal + (bias[0] - g[0]) * fb.axial
        Q[6:] -= Kg @ eta
        L[6:] += np.outer(fb.axial @ eta, B[0])
    return L, Q - Mb[:, :6] @ bias


def _chains(model):
    """The node frames' chain joints, in the rows of ``D`` (``compiled.flexible_states``):
    ``[(child frame, parent frame, kind, axis, D row)]``."""
    if model._map is None:
        return []
    tree, out, k = model.tree, [], 0
    for nf in model.node_frames:
        for name in nf.joints:
            j = tree._joint[name]
            out.append((tree.frame_index(j.child), tree.frame_index(j.parent), j.kind,
                        np.asarray(j.axis, float), model._map.D[k]))
            k += 1
    return out


def _joint_column(tree, child, parent, kind, axis, col):
    """A unit effort along a 1-DoF joint's coordinate (a force along a prismatic axis, a
    moment about a revolute one), on its child at the child's origin and the opposite on
    its parent, in the rows of the tree's Newton-Euler equations (as
    ``newton_euler_system`` writes a reaction component's column)."""
    e = tree._R[child] @ axis
    Fk, Nk = (e, np.zeros(3)) if kind == PRISMATIC else (np.zeros(3), e)
    c = tree._R[child] @ tree._com[child]
    col[6 * child:6 * child + 3] -= Fk
    col[6 * child + 3:6 * child + 6] -= Nk - cross3(c, Fk)
    if parent >= 0:
        lever = tree._r[child] - tree._r[parent] - tree._R[parent] @ tree._com[parent]
        col[6 * parent:6 * parent + 3] += Fk
        col[6 * parent + 3:6 * parent + 6] += Nk + cross3(lever, Fk)


def _multiplier_loads(tree):
    """``(6 n, m)``: the loads (``F``, ``N`` per frame, as the rows of the system read
    them) of each unit loop multiplier (``kernels.constraints.constraint_wrenches``)."""
    con_int, con_data = tree._con[0], tree._con[1]
    m, n = tree._con[4].shape[0], tree.n_frames
    out = np.zeros((6 * n, m))
    prim = np.empty((con_int.shape[0], 6))
    for k in range(m):
        F, N, unit = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(m)
        unit[k] = 1.0
        kcon.constraint_wrenches(con_int, con_data, tree._parent, tree._kind, tree._axis,
                                 tree._R, tree._r, unit, F, N, tree._com, prim)
        out[:, k] = np.concatenate([F, N], axis=1).ravel()
    return out


def reactions_of(model, sol, frame="world"):
    """``{joint: (F, M)}`` of the model's joints from a ``Solution`` (the tree's workspace
    still at its state): the tree joints' reaction components on their bases, the loop
    joints' multipliers as their primitives' wrenches; world or child components."""
    tree = model.tree
    out = {}
    for name in model.joints:
        s, i = tree._reaction_slices[name], tree.frame_index(tree._joint[name].child)
        R = tree._R[i]
        out[name] = (R @ (tree._react_force[s].T @ sol.react[s]),
                     R @ (tree._react_moment[s].T @ sol.react[s]))
    if sol.lam is not None:
        con_int, con_data = tree._con[0], tree._con[1]
        prim, n = np.empty((con_int.shape[0], 6)), tree.n_frames
        kcon.constraint_wrenches(con_int, con_data, tree._parent, tree._kind, tree._axis,
                                 tree._R, tree._r, np.ascontiguousarray(sol.lam),
                                 np.zeros((n, 3)), np.zeros((n, 3)), tree._com, prim)
        loops = {}
        for k, owner in enumerate(tree._prim_joint):
            loops[owner] = loops.get(owner, 0.0) + prim[k]
        for name in model.reaction_joints[len(model.joints):]:
            w = loops.get(name, np.zeros(6))
            out[name] = (np.array(w[:3]), np.array(w[3:]))
    if frame == "child":
        for name, (f, m) in out.items():
            R = _child_rotation(model, name)
            out[name] = (R.T @ f, R.T @ m)
    return out


def _child_rotation(model, name):
    tree = model.tree
    child = (tree._joint[name].child if name in tree._joint
             else tree._loop_joint[name].child)
    return np.eye(3) if child == "ground" else tree._R[tree.frame_index(child)]

"""Reactions of the joints of a model with flexible bodies: the force and moment each
joint's parent exerts on its child, by Newton-Euler inverse dynamics from the leaves to
the root (the tree's ``kernels.dynamics.joint_wrenches``) after the Jourdain route's
accelerations (and, with loops, its multipliers).

A flexible body is a massless frame in the tree; its own Newton-Euler equations are the
rigid rows of its floating-frame equations (``mbdyn.flexible.invariants``): the external
wrench it needs, at its frame origin in body components,

    W = M_b[:6] (a_0, alpha, eta'') - Q_v[:6] - (m g, c(eta) x g)

(the elastic and damping forces are internal: they act on the modal rows only).  Loads
and force elements at its nodes supply part of ``W``; the joints (its parent's, and those
of the children hung from its node frames, which pass their wrenches through the chains'
massless frames) the rest.  So the tree's inverse dynamics is run with the body's
applied load ``-(W - W_elements)`` at its frame, the elements' other sides on the rigid
bodies they join, and the loop multipliers' loads (``kernels.constraints``): every
joint's wrench follows, the chains' and the drives' efforts among them.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..flexible.invariants import cross3, quadratic_velocity_vector
from ..kernels import constraints as kcon
from ..kernels import dynamics as kd
from ..kernels.loop_solve import RANK_TOLERANCE
from . import flexible_newton_euler
from .flexible_dynamics import body_matrix, split
from .flexible_forces import wrenches
from .loop_reactions import UNIQUE_TOLERANCE

METHODS = ("auto", "jourdain", "newton-euler", "newton-euler-dense")


def reactions(model, q, u, t=0.0, method="auto", frame="world"):
    """``{joint: (F, M)}`` of the model's joints (tree joints at their origin, loop
    joints at their point on the child), world components or the child frame's
    (``frame="child"``); ``method``: ``"auto"`` and ``"jourdain"``: the Jourdain route's
    accelerations, then inverse dynamics (module docstring); ``"newton-euler"`` (or
    ``"-dense"``): the system with reaction unknowns (``flexible_newton_euler``)."""
    if frame not in ("world", "child"):
        raise ModelError(f"unknown frame {frame!r} for reactions; use 'world' or 'child'")
    if method not in METHODS:
        raise ModelError(f"model {model.name!r} has flexible bodies: reactions take method "
                         f"{', '.join(repr(m) for m in METHODS)}, not {method!r}")
    q, u = split(model, q, u)
    if method in flexible_newton_euler.METHODS:
        return flexible_newton_euler.reactions_of(
            model, flexible_newton_euler.solve(model, q, u, t), frame)
    if model.has_loops:
        ud, lam = model.multipliers(q, u, t)
    else:
        ud, lam = model.forward_dynamics(q, u, t), None
    tree, loops = _joint_wrenches(model, q, u, ud, lam, t)
    out = {name: (tree[i, :3].copy(), tree[i, 3:].copy()) for name, i in _tree_rows(model)}
    for name in model.reaction_joints[len(model.joints):]:
        w = loops.get(name, np.zeros(6))
        out[name] = (np.array(w[:3]), np.array(w[3:]))
    if frame == "child":
        for name, (f, m) in out.items():
            R = _child_rotation(model, name)
            out[name] = (R.T @ f, R.T @ m)
    return out


def _tree_rows(model):
    """``(joint, tree frame index)`` of the model's tree joints (the chains' left out)."""
    tree = model.tree
    return [(name, tree.frame_index(tree._joint[name].child)) for name in model.joints]


def _child_rotation(model, name):
    tree = model.tree
    child = (tree._joint[name].child if name in tree._joint
             else tree._loop_joint[name].child)
    return np.eye(3) if child == "ground" else tree._R[tree.frame_index(child)]


def _joint_wrenches(model, q, u, ud, lam, t):
    """The tree's joint wrenches (frames x 6) and the loop joints' ``{name: (6,)}`` for
    the motion ``(q, u, u')`` and the multipliers ``lam`` (``None`` without loops)."""
    tree = model.tree
    qx, ux = model._extended(q, u)
    udx = ud if model._map is None else model._map.P @ ud
    nqt, nut = tree.nq, tree.nu
    tree._kinematics_kernel(qx[:nqt], ux[:nut], t, udx[:nut])
    tree._drop_velocity_products()
    F, N = tree._F.copy(), tree._N.copy()
    _flexible_loads(model, qx, ux, udx, F, N, t)
    loops = {}
    if lam is not None:
        con_int, con_data = tree._con[0], tree._con[1]
        prim = np.empty((con_int.shape[0], 6))
        kcon.constraint_wrenches(con_int, con_data, tree._parent, tree._kind, tree._axis,
                                 tree._R, tree._r, np.ascontiguousarray(lam), F, N,
                                 tree._com, prim)
        for k, owner in enumerate(tree._prim_joint):
            loops[owner] = loops.get(owner, 0.0) + prim[k]
    out = np.empty((tree.n_frames, 6))
    kd.joint_wrenches(tree._mass, tree._com, tree._inertia, tree._parent, tree._R, tree._r,
                      tree._w, tree._alpha, tree._a, F, N, out)
    return out, loops


def _flexible_loads(model, qx, ux, udx, F, N, t):
    """Into the tree's applied loads ``F``, ``N`` (world, at the centres of mass): each
    flexible body's ``-(W - W_elements)`` at its frame, and the force elements' and loads'
    wrenches at flexible bodies' points on the rigid bodies they join (module
    docstring); the tree's kinematics at the extended state are in its workspace."""
    tree = model.tree
    for fb in model._flex:
        i, eta, eta_dot = fb.frame, qx[fb.q], ux[fb.u]
        R = tree._R[i]
        wdot = np.concatenate([R.T @ tree._a[i], R.T @ tree._alpha[i], udx[fb.u]])
        Mb = body_matrix(fb, eta)
        omega = R.T @ tree._w[i]
        W = Mb[:6] @ wdot
        if tree.gyroscopic and omega.any():
            W -= quadratic_velocity_vector(fb.invariants, eta, eta_dot, omega)[:6]
        g = R.T @ tree.gravity
        inv = fb.invariants
        W[:3] -= inv.mass * g
        W[3:] -= cross3(inv.first_moment + inv.modal_first_moment @ eta, g)
        F[i] -= R @ W[:3]
        N[i] -= R @ W[3:]
    for pk in model._flex_elements:
        for side, ((p, *_), f, n) in zip(SIDES[pk.what], wrenches(model, pk, qx, ux, t,
                                                                    jacobians=False)[0]):
            _add(tree, pk.sides[side].frame, p, f, n, F, N)


#: the side of the element (``Packed.sides``) each wrench ``flexible_forces.wrenches``
#: returns acts on: a bushing's first wrench is on its second side, then the opposite on
#: its first side's material point there; a bearing's second on its housing
SIDES = {"load": (0,), "spring-damper": (0, 1), "bushing": (1, 0), "bearing": (0, 1)}


def _add(tree, frame, p, f, n, F, N):
    """The force ``f`` at the world point ``p`` and the moment ``n`` added to the tree
    frame ``frame``'s applied loads (about its centre of mass; the ground: nothing)."""
    if frame < 0:
        return
    c = tree._r[frame] + tree._R[frame] @ tree._com[frame]
    F[frame] += f
    N[frame] += n + cross3(p - c, f)


def reaction_uniqueness(model, q, t=0.0):
    """``{joint: [6 bools]}``: which reaction components (force, moment, world) the
    motion determines at ``q``; False where a self-balanced set of loop loads ``z``
    (``G^T z = 0``, ``G`` over the model's speeds, modal ones included) changes them."""
    G = model.constraint_jacobian(q, t)
    names = model.reaction_joints
    unique = {name: np.ones(6, bool) for name in names}
    if not G.size:
        return unique
    U, sv, _ = np.linalg.svd(G, full_matrices=True)
    rank = int(np.sum(sv > RANK_TOLERANCE * sv[0])) if sv.size and sv[0] > 0 else 0
    tree = model.tree
    n = tree.n_frames
    for z in U[:, rank:].T:
        F, N, zero = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
        con_int, con_data = tree._con[0], tree._con[1]
        prim = np.empty((con_int.shape[0], 6))
        kcon.constraint_wrenches(con_int, con_data, tree._parent, tree._kind, tree._axis,
                                 tree._R, tree._r, np.ascontiguousarray(z), F, N, tree._com,
                                 prim)
        out = np.empty((n, 6))
        kd.joint_wrenches(np.zeros(n), tree._com, tree._inertia, tree._parent, tree._R,
                          tree._r, zero, zero, zero, F, N, out)
        for name, i in _tree_rows(model):
            unique[name] &= np.abs(out[i]) <= UNIQUE_TOLERANCE
        loops = {}
        for k, owner in enumerate(tree._prim_joint):
            loops[owner] = loops.get(owner, 0.0) + prim[k]
        for name in names[len(model.joints):]:
            unique[name] &= np.abs(loops.get(name, np.zeros(6))) <= UNIQUE_TOLERANCE
    return unique

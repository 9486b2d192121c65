"""Reactions of a closed mechanism: the force and moment each joint's parent exerts on its
child -- tree joints at their origin, loop joints at their point on the child -- and which
of their components the motion determines.

With redundant constraints the multipliers are not unique: any ``z`` with ``G^T z = 0``
(a self-balanced set of loop loads, such as two revolutes of a planar loop squeezing
the links along their axes) can be added without changing the motion.  The multipliers
reported are the minimum-norm ones (``kernels.constrained``); a reaction component that
changes along such a ``z`` is flagged as not unique (``reaction_uniqueness``).
"""
from __future__ import annotations

import numpy as np

from ..kernels import constraints as kcon
from ..kernels import dynamics as kd
from ..kernels.loop_solve import RANK_TOLERANCE

#: a reaction component that moves less than this per unit self-balanced multiplier set
#: is unique (N, or N m for moments)
UNIQUE_TOLERANCE = 1e-8


def reaction_joints(model):
    """Names of the joints with a reaction: the tree's, then the loop joints' (a
    coupling has none: its effort is its multiplier, ``Model.multipliers``)."""
    return model.joints + tuple(n for n in model.loop_joints
                                if model._loop_joint[n].kind != "coupling")


def _wrenches(model, lam, F, N, w, alpha, a):
    """Tree joints' wrenches ``(n, 6)`` and loop joints' ``{name: (6,)}`` for the loads
    ``F``, ``N`` plus those of the multipliers ``lam``, with the frames' motion given."""
    con_int, con_data = model._con[0], model._con[1]
    prim = np.empty((con_int.shape[0], 6))
    kcon.constraint_wrenches(con_int, con_data, model._parent, model._kind, model._axis,
                             model._R, model._r, lam, F, N, model._com,
                             prim)
    tree = np.empty((model.n_frames, 6))
    kd.joint_wrenches(model._mass, model._com, model._inertia, model._parent, model._R,
                      model._r, w, alpha, a, F, N, tree)
    loops = {}
    for m, owner in enumerate(model._prim_joint):
        loops[owner] = loops.get(owner, 0.0) + prim[m]
    return tree, loops


def loop_reactions(model, q, u, t=0.0, frame="world"):
    """``{joint: (F, M)}`` of every tree and loop joint of a closed mechanism (world or
    child-frame components), the multipliers being the minimum-norm ones."""
    ud, lam = model.multipliers(q, u, t)
    model._kinematics_kernel(q, u, t, ud)
    model._drop_velocity_products()
    tree, loops = _wrenches(model, lam, model._F, model._N, model._w, model._alpha, model._a)
    out = {name: (tree[i, :3].copy(), tree[i, 3:].copy())
           for i, name in enumerate(model.joints)}
    for name in reaction_joints(model)[len(model.joints):]:
        w = loops.get(name, np.zeros(6))
        out[name] = (np.array(w[:3]), np.array(w[3:]))
    if frame == "child":
        for name, (f, m) in out.items():
            R = child_rotation(model, name)
            out[name] = (R.T @ f, R.T @ m)
    return out


def child_rotation(model, joint):
    child = (model._joint[joint].child if joint in model._joint
             else model._loop_joint[joint].child)
    return np.eye(3) if child == "ground" else model._R[model.frame_index(child)]


def reaction_uniqueness(model, q, t=0.0):
    """``{joint: [6 bools]}``: which components (force x, y, z, moment x, y, z, world) of
    each joint's reaction the motion determines at ``q``; False where a self-balanced set
    of loop loads changes it (redundant constraints)."""
    G = model.constraint_jacobian(q, t)
    names = reaction_joints(model)
    unique = {name: np.ones(6, bool) for name in names}
    if not G.size:
        return unique
    U, sv, _ = np.linalg.svd(G, full_matrices=True)
    rank = int(np.sum(sv > RANK_TOLERANCE * sv[0])) if sv.size and sv[0] > 0 else 0
    n = model.n_frames
    zero = np.zeros((n, 3))
    for z in U[:, rank:].T:
        F, N = np.zeros((n, 3)), np.zeros((n, 3))
        # (a contiguous copy: the kernel is compiled for contiguous multipliers)
        tree, loops = _wrenches(model, np.ascontiguousarray(z), F, N, zero, zero, zero)
        for i, name in enumerate(model.joints):
            unique[name] &= np.abs(tree[i]) <= UNIQUE_TOLERANCE
        for name in names[len(model.joints):]:
            unique[name] &= np.abs(loops.get(name, np.zeros(6))) <= UNIQUE_TOLERANCE
    return unique

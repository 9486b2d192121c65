"""The Newton-Euler equations with reaction unknowns for a closed mechanism: the tree's
dense system (``kernels.dynamics.newton_euler_system``: per frame three Newton and three
Euler equations, unknowns ``u'`` and the components each tree joint transmits) with the
loop joints' multipliers as more unknowns -- each one's loads entering the bodies' equations
-- and their constraint equations ``G u' = gamma`` as more rows, as the textbook extends
step 3.  Solved by least squares (minimum norm): with redundant constraints the
reactions are not unique, the accelerations are.
"""
from __future__ import annotations

import numpy as np

from ..kernels import constrained as kc
from ..kernels import constraints as kcon
from ..kernels.loop_solve import RANK_TOLERANCE
from ..kernels import dynamics as kd
from .constrained import groups


def _system(model, F, N, A, b):
    kd.newton_euler_system(model._mass, model._com, model._inertia, model._parent,
                           model._R, model._r, model._w, model._alpha, model._a,
                           model._JR, model._JT, model._anc_ptr, model._anc_idx,
                           F, N, model._react_joint, model._react_force,
                           model._react_moment, A, b, model._scratch)


def loop_newton_euler(model, q, u, t=0.0):
    """``(u', tree reaction components, loop multipliers)`` of the extended system."""
    q, u = model._kinematics_kernel(q, u, t)
    model._drop_velocity_products()
    tree, _, state, _, motion, _ = groups(model)
    kc.constraint_state(tree, state, motion, model._con, model._scratch)
    con_int, con_data, _, _, G, gamma = model._con[:6]
    A, b = model._dense_system()
    F0, N0 = model._F.copy(), model._N.copy()
    _system(model, F0, N0, A, b)
    A0, b0 = A.copy(), b.copy()
    m, nu, size = G.shape[0], model.nu, A0.shape[0]
    K = np.zeros((size + m, size + m))
    K[:size, :size] = A0
    prim = np.empty((con_int.shape[0], 6))
    for k in range(m):                    # each multiplier's loads, through the same system
        F, N, unit = F0.copy(), N0.copy(), np.zeros(m)
        unit[k] = 1.0
        kcon.constraint_wrenches(con_int, con_data, model._parent, model._kind, model._axis,
                             model._R, model._r, unit, F, N,
                                 model._com, prim)
        _system(model, F, N, A, b)
        K[:size, size + k] = -(b - b0)
    K[size:, :nu] = G
    rhs = np.concatenate([b0, gamma])
    x = np.linalg.lstsq(K, rhs, rcond=RANK_TOLERANCE)[0]
    if not np.all(np.isfinite(x)):
        model._check_finite(q, u, t, x, "the Newton-Euler solution")
    return x[:nu].copy(), x[nu:size].copy(), x[size:].copy()


def loop_newton_euler_reactions(model, q, u, t=0.0):
    """``(u', {joint: (F, M)})`` by the extended Newton-Euler system (world components)."""
    ud, lam_tree, lam = loop_newton_euler(model, q, u, t)
    out = model._reactions_from(lam_tree)
    con_int, con_data = model._con[0], model._con[1]
    prim = np.empty((con_int.shape[0], 6))
    n = model.n_frames
    kcon.constraint_wrenches(con_int, con_data, model._parent, model._kind, model._axis,
                             model._R, model._r, lam, np.zeros((n, 3)),
                             np.zeros((n, 3)), model._com, prim)
    loops = {}
    for k, owner in enumerate(model._prim_joint):
        loops[owner] = loops.get(owner, 0.0) + prim[k]
    for name in model.reaction_joints[len(model.joints):]:
        out[name] = (np.array(loops[name][:3]), np.array(loops[name][3:]))
    return ud, out

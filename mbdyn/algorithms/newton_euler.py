"""The Newton-Euler equations with reaction unknowns (per frame three Newton and three
Euler equations; unknowns ``u'`` and the components each joint transmits): eliminated in
tree order (O(n), ``kernels.articulated``) or assembled as one dense 6n system and solved
by LU, as the textbook writes it.
"""
from __future__ import annotations


import numpy as np

from ..kernels import dynamics as kd
from ..kernels import packed as kp


def _lu_solve(A, b):
    """``x`` of ``A x = b`` as numba's compiled ``np.linalg.solve`` gives it, bit for bit:
    LAPACK's ``dgesv`` from scipy (the library numba calls); NaN or Inf in ``A`` or ``b``
    and a singular ``A`` raise ``numpy.linalg.LinAlgError``, as there."""
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))):
        raise np.linalg.LinAlgError("Array must not contain infs or NaNs.")
    if not b.shape[0]:
        return b.copy()
    from scipy.linalg.lapack import dgesv
    _, _, x, info = dgesv(A, b)
    if info > 0:
        raise np.linalg.LinAlgError("Matrix is singular to machine precision.")
    return x


def tree_order(model, q, u, t):
    """The Newton-Euler equations eliminated in tree order, in one compiled call: ``u'``
    in ``model._ud``, the reaction components in ``model._lam``, every joint's wrench in
    ``model._W`` (world components, about the child's origin); a failure raised, named."""
    q, u = model._state(q, u)
    if model._python_inputs:
        model._fill_inputs(q, u, t)
    try:
        status = kp.newton_euler_tree_packed(*model._packed, q, u)
    except ZeroDivisionError:
        raise model._division_by_zero(q, t) from None
    if status >= 0:
        model._raise_singular(q, t, status)
    if status == -2:
        model._check_finite(q, u, t, np.concatenate([model._ud, model._lam]),
                            "the Newton-Euler solution")


def solve(model, q, u, t, dense=False):
    """The Newton-Euler unknowns ``[u', reactions]`` (a new array): eliminated in tree
    order (``kernels.articulated``), or, with ``dense``, the system of
    ``kernels.dynamics.newton_euler_system`` solved by LU (from Python: it needs no
    compiled entry point beyond the kinematics a run has compiled anyway)."""
    if not dense:
        tree_order(model, q, u, t)
        return np.concatenate([model._ud, model._lam])
    q, u = model._state(q, u)
    try:
        # the steps of newton_euler_solution with kernels a run compiles anyway, and
        # the LU solve from Python: no fused entry point of its own to compile
        A, b = model._dense_system()          # (and the full Jacobians, before the walk)
        model._kinematics_kernel(q, u, t)
        model._drop_velocity_products()
        kd.newton_euler_system(model._mass, model._com, model._inertia, model._parent,
                               model._R, model._r, model._w, model._alpha, model._a,
                               model._JR, model._JT, model._anc_ptr, model._anc_idx,
                               model._F, model._N, model._react_joint,
                               model._react_force, model._react_moment, A, b,
                               model._scratch)
        x = _lu_solve(A, b)
        finite = bool(np.all(np.isfinite(x)))
    except np.linalg.LinAlgError:     # singular, or fed NaN/Inf: tell which
        model._jourdain_terms(q, u, t)
        for out in (model._f, np.diag(model._M)):
            if not np.all(np.isfinite(out)):
                model._check_finite(q, u, t, out, "the Newton-Euler equations")
        model._raise_singular(q, t, None)
    if not finite:                    # NaN or Inf somewhere: find and report it
        model._check_finite(q, u, t, x, "the Newton-Euler solution")
    return x


def newton_euler(model, q, u, t=0.0, dense=False):
    """Solve the Newton-Euler equations with reaction unknowns, eliminated in tree
    order (O(n)) or, with ``dense=True``, assembled as one 6n system and solved by LU
    (the textbook's literal form).

    Returns ``(ud, reactions)``; ``reactions`` as in ``Model.reactions``.
    """
    x = model._newton_euler(q, u, t, dense=dense)
    return x[:model.nu].copy(), model._reactions_from(x[model.nu:])


def reactions_from(model, lam):
    out = {}
    for i, name in enumerate(model.joints):
        s = model._reaction_slices[name]
        R = model._R[i]
        force = R @ (model._react_force[s].T @ lam[s])
        moment = R @ (model._react_moment[s].T @ lam[s])
        out[name] = (force, moment)
    return out

"""The compiled evaluations of a model with flexible bodies, called from Python: its
``u'``, ``M``, ``f`` and, with loops, the multipliers and the projection, by the model's
compiled function (``kernels.flexible_entry``) on the arrays of
``compiled.flexible_packing.FlexibleKernels`` (``model._kernels``).  The same equations as
``flexible_dynamics`` and ``flexible_loops`` (numpy), which stay as their reference and
serve the models the compiled function does not take (contacts between shapes).

Before a call the model's state goes into the extended joint space: the tree's drives,
loads and laws given as Python functions are evaluated by the tree as always (at the
tree's state, the node frames' chains from ``eta``), copied there, then the model's free
coordinates and speeds scattered over them; the loads at flexible bodies given as
functions are written into the elements' numbers.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, NonFiniteError, SingularMassMatrixError
from ..kernels import flexible_entry as kfe
from . import flexible_dynamics as numpy_route
from . import flexible_loops as numpy_loops
from .constrained import positions_not_closed, speeds_not_closed
from .flexible_dynamics import split


def load_state(model, q, u, t):
    """The model's ``(q, u)`` at ``t`` into the kernels' extended joint space (module
    docstring); returns the checked ``(q, u)``."""
    q, u = split(model, q, u)
    kern, tree = model._kernels, model.tree
    qf, uf, udf = kern.qfull, kern.ufull, kern.udfull
    if tree._python_inputs or kern.load_functions:
        qx, ux = model._extended(q, u)        # the model's state for load functions
        if tree._python_inputs:
            tree._fill(qx[:tree.nq], ux[:tree.nu], t)
            qf[:kern.nqf] = tree._qfull
            uf[:kern.nuf] = tree._ufull
            udf[:kern.nuf] = tree._udfull
        edata = kern.flex[8]
        for at, fn in kern.load_functions:
            edata[at:at + 3] = _load_value(fn, t, *model._model_state(qx, ux))
    qf[kern.free_q] = q
    uf[kern.free_u] = u
    udf[kern.free_u] = 0.0
    return q, u


def _load_value(fn, t, q, u):
    val = np.asarray(fn(t, q, u), dtype=float).reshape(-1)
    if val.shape != (3,):
        raise ModelError(f"a load at a flexible body returned {val.size} values at t={t}; "
                         "it must return three")
    return val


def _call(model, q, io, mode, t):
    try:
        return int(kfe.call(model._kernels.ready(), io, mode))
    except ZeroDivisionError:
        raise model._division_by_zero(q, t) from None


def forward_dynamics(model, q, u, t=0.0, method="jourdain"):
    """``u'`` of ``A u' = f`` (with loops, of the constrained system), compiled."""
    model.formulation(method)
    if model.has_loops:
        return constrained_accelerations(model, q, u, t)[0]
    if not model._kernels.supported:
        return numpy_route.forward_dynamics(model, q, u, t, method)
    q, u = load_state(model, q, u, t)
    ud = np.empty(model.nu)
    _check(model, _call(model, q, ud, kfe.ACCEL, t), q, u, t)
    return ud


def _check(model, status, q, u, t, loops=False):
    if status == -2 or (status >= 0 and not _finite_terms(model)):
        model._require_finite(q, u, t)
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the equations of motion "
                             "came out non-finite (check the state, masses and stiffness)")
    if status >= 0:
        raise SingularMassMatrixError(
            f"model {model.name!r}, t={t:.6g}: the mass matrix is singular"
            + (" on the motions the loop constraints allow" if loops else ""), [])


def _finite_terms(model):
    flex = model._kernels.flex
    return bool(np.all(np.isfinite(flex[14])) and np.all(np.isfinite(flex[15])))


def terms(model, q, u, t=0.0):
    """``(M, f, A)`` (new arrays) as ``flexible_dynamics.terms``, compiled."""
    if not model._kernels.supported:
        return numpy_route.terms(model, q, u, t)
    q, u = load_state(model, q, u, t)
    _call(model, q, np.empty(model.nu), kfe.TERMS, t)
    flex = model._kernels.flex
    return flex[13].copy(), flex[15].copy(), flex[14].copy()


def mass_matrix(model, q, t=0.0):
    """The symmetric mass matrix ``M(q)`` (nu x nu) of the tree and its flexible bodies."""
    return terms(model, q, np.zeros(model.nu), t)[0]


def forcing(model, q, u, t=0.0):
    """The right-hand side ``f(q, u, t)`` of ``A u' = f``."""
    return terms(model, q, u, t)[1]


def constrained_accelerations(model, q, u, t=0.0):
    """``(u', lam)`` of the closed mechanism at the state (``flexible_loops``), compiled."""
    if not model._kernels.supported:
        return numpy_loops.constrained_accelerations(model, q, u, t)
    q, u = load_state(model, q, u, t)
    ud = np.empty(model.nu)
    _check(model, _call(model, q, ud, kfe.ACCEL, t), q, u, t, loops=True)
    return ud, model.tree._con[6].copy()


def multipliers(model, q, u, t=0.0):
    """``(u', lam)``: the accelerations and the minimum-norm multipliers."""
    if not model.has_loops:
        raise ModelError(f"model {model.name!r} has no loop joints (no constraints)")
    return constrained_accelerations(model, q, u, t)


def project(model, q, u, t=0.0):
    """``(q, u)`` moved onto the loop constraints (``flexible_loops.project``), compiled."""
    if not model.has_loops:
        raise ModelError(f"model {model.name!r} has no loop joints (no constraints)")
    if not model._kernels.supported:
        return numpy_loops.project(model, q, u, t)
    q, u = load_state(model, q, u, t)
    y = np.concatenate([q, u])
    steps = _call(model, q, y, kfe.PROJECT, t)
    tree = model.tree
    if steps == -1:
        raise positions_not_closed(model, t, tree._con[2])
    if steps == -2:
        raise speeds_not_closed(model, t, tree._con[3])
    return y[:model.nq].copy(), y[model.nq:].copy()

"""The Newton-Euler-Jourdain form ``M(q) u' = f(q, u, t)``: the mass matrix (composite
rigid bodies) and the forcing, by the kernels a run compiles anyway or by one packed call,
and the check at compile that the system at rest is solvable.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import NonFiniteError
from ..kernels import dynamics as kd
from ..kernels import entries as ke
from .inputs import plain as _plain
from .inputs import F64, ND
from .inputs import empty as _empty
from .inputs import freeze as _freeze
from .recycling import FREE as _FREE
from .recycling import refcount as _refcount
from .recycling import spares
from ..kernels import packed as kp


def jourdain_terms(model, q, u, t):
    model._full_workspace()
    q, u = model._kinematics_kernel(q, u, t)
    model._drop_velocity_products()
    kd.jourdain_terms(model._mass, model._com, model._inertia, model._has_inertia, model._R,
                      model._r, model._w, model._alpha, model._a, model._JR, model._JT,
                      model._anc_ptr, model._anc_idx, model._parent, model._F, model._N,
                      model._M, model._f, model._scratch)
    return q, u


def mass_matrix(model, q, t=0.0):
    """The Jourdain mass matrix ``M(q)`` (nu x nu, symmetric), by composite rigid bodies
    in one compiled call (``kernels.inverse``: each joint's motion subspace, no full
    Jacobians, O(n depth)) on the merged tree (``compiled.merging``)."""
    call = model._c_mass_matrix
    if call is not None:                 # one C call (kernels.fastcall); None: not taken
        M = call(q)
        if M is not None:
            return M
    call = model._fast_mass_matrix
    if call is not None and type(q) is ND and q.dtype is F64 and q.ndim == 1:
        # an array of the compiled type (inputs.fits): its entry, no dispatch (freeze)
        kernel, fb, ib, shape, spare = call
        M = spare[0]       # a result the caller let go of, as it was made (recycling)
        if _refcount(M) != _FREE or M.dtype is not F64 or not M.flags.writeable:
            M = spare[1]
            if _refcount(M) != _FREE or M.dtype is not F64 or not M.flags.writeable:
                spare[0] = M             # both held or altered: a new one
                M = spare[1] = _empty(shape)
        try:
            if kernel(fb, ib, q, M) == -1:
                return M
        except ZeroDivisionError:
            pass                     # a failure, or another size: the checked route
    M = np.empty((model.nu, model.nu))
    status = None
    entry = _mass_matrix_entry()
    fb, ib = model._dynamics[:2]
    if not model._python_inputs and _plain(q, model.nq):
        try:                                 # a float64 array as it comes: no conversion
            status = entry(fb, ib, q, M)
        except ZeroDivisionError:
            pass
    u = np.zeros(model.nu)
    if status is None:                       # convert, check, say what is wrong
        q = np.require(model._state(q, u)[0], float, "CW")  # the entry's type
        if model._python_inputs:             # the drives' coordinates at t
            model._fill_inputs(q, u, t)
        try:
            status = entry(fb, ib, q, M)
        except ZeroDivisionError:
            raise model._division_by_zero(q, t) from None
    if status == -2:
        model._require_finite(q, u, t)
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the mass matrix came out "
                             "non-finite (check masses, inertias and drives)")
    if not model._python_inputs:
        _freeze(model, "mass matrix", entry, (fb, ib), (q, M), M.shape, spares(M.shape))
    return M


def _mass_matrix_entry():
    """The mass matrix's entry compiled for its one signature (``kernels.entries``):
    ``(fb, ib, q, M)``, the low-level call's too, so the two compile it once."""
    return ke.entry(ke.mass_matrix, ke.MASS_MATRIX_SIGNATURE)


def mass_matrix_by(model, q, t, terms):
    """``mass_matrix`` with the Jourdain terms computed by ``terms``: the packed,
    one-call route (``_jourdain_packed``) or the kernels a run compiles anyway
    (``_jourdain_terms``; for the checks of a run, whose first start must not compile
    the packed entry point).  The same kernels either way: the same numbers."""
    terms(q, np.zeros(model.nu), t)
    # the sum is finite exactly when every entry is (short of overflow, which the
    # exact test below then clears): a third of the cost of isfinite().all()
    if not math.isfinite(model._M.sum()) and not np.all(np.isfinite(model._M)):
        model._require_finite(q, np.zeros(model.nu), t)
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the mass matrix came out "
                             "non-finite (check masses, inertias and drives)")
    return model._M.copy()


def forcing(model, q, u, t=0.0):
    """The right-hand side ``f(q, u, t)`` of ``M u' = f``: applied, gyroscopic and
    velocity-product terms projected by the Jacobians."""
    q, u = model._jourdain_packed(q, u, t)
    if not np.all(np.isfinite(model._f)):      # a NaN in the state: say so; else as it came
        model._require_finite(q, u, t)
    return model._f.copy()


def jourdain_packed(model, q, u, t):
    """``M`` and ``f`` into the workspace by one compiled call on the packed buffers
    (``kernels.packed.jourdain_accelerations_packed``, which solves for ``u'`` too: a
    small part of its cost, and no extra compiled entry point)."""
    q, u = model._state(q, u)
    model._full_workspace()
    if model._python_inputs:
        model._fill_inputs(q, u, t)
    try:
        kp.jourdain_accelerations_packed(*model._dynamics_full, q, u)
    except ZeroDivisionError:
        raise model._division_by_zero(q, t) from None
    return q, u


#: up to this many speeds (robots, humanoids) the check at rest factors ``M`` by the
#: kernels every run compiles for its conditioning report, even where runs take the
#: articulated route, whose packed entry point would otherwise be compiled for the check
#: alone (a second of a first run); above it, compiling allocates no full Jacobians
CHECK_BY_CHOLESKY = 40


def check_at_rest(model, q, t=0.0):
    """Raise what ``forward_dynamics(q, 0, t)`` raises -- ``SingularMassMatrixError``
    or ``NonFiniteError`` -- by the same Cholesky solve of ``M u' = f``, called on the
    terms ``mass_matrix`` computes; returns nothing.  Used when a system is compiled:
    this way the check needs no compiled entry point of its own (a first run compiles
    less)."""
    q, u = model._state(q, np.zeros(model.nu))
    if model.formulation("auto") == "articulated" and model.nu > CHECK_BY_CHOLESKY:
        # O(n) where runs take that route anyway: the Cholesky factor of M costs O(n^3)
        # (minutes at 10,000 speeds); a failure is reported exactly as below
        model.forward_dynamics(q, u, t, method="articulated")
        return
    model._jourdain_terms(q, u, t)
    pivot = kd.cholesky_solve(model._M, model._f, model._L, model._ud)
    if pivot >= 0:
        model._raise_singular(q, t, pivot)
    model._check_finite(q, u, t, model._ud, "the accelerations")

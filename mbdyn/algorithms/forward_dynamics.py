"""Forward dynamics, ``u'`` from ``(q, u, t)``, by each route: ``M u' = f`` (Jourdain), the
articulated-body algorithm, the Newton-Euler system with reactions eliminated in tree
order or assembled dense; the choice ``"auto"`` makes; and the state derivative
``[q', u']`` in one compiled call.
"""
from __future__ import annotations


import numpy as np

from ..errors import ModelError
from ..kernels import packed as kp
from .inputs import F64, ND
from .inputs import freeze as _freeze
from .inputs import plain as _plain
from .c_entries import pending
from .constrained import fast_call as closed_fast_call
from .route_hook import loop_route
from .loop_newton_euler import loop_newton_euler


#: formulations of the forward dynamics: ``M(q) u' = f`` (Jourdain, composite-rigid-body
#: mass matrix and Cholesky), the articulated-body algorithm (O(n)), the Newton-Euler
#: system with reaction unknowns eliminated in tree order (O(n)) and the same system as the
#: textbook writes it, assembled dense and solved by LU
METHODS = ("jourdain", "articulated", "newton-euler", "newton-euler-dense")


#: "auto" takes the articulated-body route from this many free speeds on (below it the
#: mass matrix and its Cholesky factor are as cheap or cheaper: at 4 speeds the two cost
#: the same, at 6 the articulated bodies 7-11 % less; docs/performance.md)
ARTICULATED_FROM = 6


def forward_dynamics(model, q, u, t=0.0, method="auto"):
    """Speed rates ``u'``: from ``M(q) u' = f(q, u, t)`` (``method="jourdain"``), by the
    articulated-body algorithm (``"articulated"``), or from the Newton-Euler system with
    reactions, eliminated in tree order (``"newton-euler"``) or assembled dense and
    solved by LU (``"newton-euler-dense"``).  All four solve the same equations;
    ``"auto"`` (the default) takes the fastest at the model's size (``formulation``,
    docs/performance.md)."""
    call = model._c_forward.get(method)
    if call is not None:                 # one C call (kernels.fastcall); None: not taken
        ud = call(q, u)
        if ud is not None:
            return ud
    call = model._fast_calls.get(method)
    if (call is not None and type(q) is ND and type(u) is ND and q.dtype is F64
            and u.dtype is F64 and q.ndim == 1 and u.ndim == 1):
        # arrays of the compiled type (inputs.fits): its entry, no dispatch (freeze)
        kernel, fb, ib, forces, ud = call
        try:
            if kernel(fb, ib, forces, q, u) == -1:
                return ud.copy()
        except ZeroDivisionError:
            pass                     # a failure, or another size: the checked route
    if model._con is not None and method in ("auto", "jourdain", "articulated"):
        # closed loops: G u' = gamma, by the mass matrix or the articulated bodies
        route = loop_route(model, method)
        ud = closed_fast_call(model, q, u, route)
        if ud is not None:
            return ud
        return model._constrained_accelerations(q, u, t, route)
    route = model._auto_route if method == "auto" else method
    if model._con is not None and route in ("newton-euler", "newton-euler-dense"):
        return loop_newton_euler(model, q, u, t)[0]
    if route in ("jourdain", "articulated"):
        return _accelerations(model, q, u, t, route, method)
    method = route
    if method in ("newton-euler", "newton-euler-dense"):
        return model._newton_euler(q, u, t, dense=method == "newton-euler-dense")[:model.nu]
    raise ModelError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")


def _accelerations(model, q, u, t, method, key=None):
    """``u'`` by one packed kernel into a new array: float64 arrays as they come, anything
    else converted and checked first.  After a call that succeeded, a model without
    inputs written in Python calls the kernel's compiled entry from then on
    (``_fast_calls`` under the ``method`` asked for, ``key``), with no dispatch, for
    arrays that pass ``inputs.fits``."""
    if method == "jourdain":
        kernel = model._jourdain_kernel
        if kernel is None:                       # its arrays not yet allocated
            model._full_workspace()
            kernel = model._jourdain_kernel
        packed, ud = model._dynamics_full, model._ud          # (fb, ib, forces)
    else:                                        # on the merged tree (compiled.merging)
        kernel = kp.articulated_accelerations_packed
        packed, ud = model._dynamics, model._dynamics_ud    # (fb, ib, forces)
    status = None
    if not model._python_inputs and _plain(q, model.nq) and _plain(u, model.nu):
        try:
            status = kernel(*packed, q, u)
        except ZeroDivisionError:
            pass
    if status is None:                           # convert, check, say what is wrong
        q, u = model._state(q, u)
        q, u = np.require(q, float, "CW"), np.require(u, float, "CW")  # one compiled type
        if model._python_inputs:
            model._fill_inputs(q, u, t)
        try:
            status = kernel(*packed, q, u)
        except ZeroDivisionError:
            raise model._division_by_zero(q, t) from None
    if status >= 0:
        model._raise_singular(q, t, status)
    if status == -2:
        model._check_finite(q, u, t, ud, "the accelerations")
    if key is not None and not model._python_inputs:
        _freeze(model, key, kernel, packed, (q, u), ud)
        if method == "articulated" and model._c_forward.get(key) is None:
            # and one C call once called often (c_entries); kept through later checked calls
            model._c_forward[key] = pending(
                model, "articulated", packed,
                lambda owner, entry: owner._c_forward.update({key: entry}))
    return ud.copy()


def formulation(model, method="auto"):
    """The per-call route ``method`` stands for: ``"auto"`` is ``"jourdain"`` for fewer
    than ``ARTICULATED_FROM`` free speeds, else ``"articulated"`` (measured crossover,
    docs/performance.md); any other name is checked and returned."""
    if model._con is not None and method in ("auto", "jourdain", "articulated"):
        # closed loops: by the mass matrix, or the articulated bodies from
        # LOOP_ARTICULATED_FROM free speeds on (kernels.constrained, loop_articulated)
        return loop_route(model, method)
    if method == "auto":
        return "jourdain" if model.nu < ARTICULATED_FROM else "articulated"
    if method not in METHODS:
        raise ModelError(f"unknown method {method!r}; use 'auto' or one of "
                         f"{', '.join(METHODS)}")
    return method


def state_derivative(model, t, y, method="auto"):
    """``[q', u']`` for the state ``y = [q, u]`` in one compiled call: ``q' = N(q) u``
    (``coordinate_rates``) and ``u'`` as ``forward_dynamics`` gives it (``method``:
    ``"auto"``, ``"jourdain"`` or ``"articulated"``).  Returns a new array."""
    route = loop_route(model, method) if model._con is not None else None
    if method == "auto":
        method = model._auto_route
    try:
        y = np.asarray(y, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"model {model.name!r}: the state y must be {model.nq + model.nu} "
                         f"numbers (q then u), got {y!r}") from None
    if y.shape != (model.nq + model.nu,):
        raise ModelError(f"model {model.name!r} expects a state of length "
                         f"{model.nq + model.nu} (q then u), got shape {y.shape}")
    if model._con is not None:
        ydot = np.empty(model.nq + model.nu)
        q, u = y[:model.nq], y[model.nq:]
        ydot[model.nq:] = model._constrained_accelerations(q, u, t, route)
        ydot[:model.nq] = model.coordinate_rates(q, u)
        return ydot
    if method == "jourdain":
        kernel = model._jourdain_rates
        if kernel is None:
            model._full_workspace()
            kernel = model._jourdain_rates
    elif method == "articulated":               # on the merged tree (compiled.merging)
        kernel = kp.state_derivative_articulated_packed
    else:
        raise ModelError(f"state_derivative: unknown method {method!r}; use 'jourdain' "
                         "or 'articulated'")
    if model._python_inputs:
        model._fill_inputs(y[:model.nq], y[model.nq:], t)
    ydot = np.empty(model.nq + model.nu)
    packed = model._dynamics if method == "articulated" else model._packed
    try:
        status = kernel(*packed, y, ydot)
    except ZeroDivisionError:
        raise model._division_by_zero(y[:model.nq], t) from None
    if status >= 0:
        model._raise_singular(y[:model.nq], t, status)
    if status == -2:
        rates = [c + "'" for c in model.coordinates] + [s + "'" for s in model.speeds]
        model._check_finite(y[:model.nq], y[model.nq:], t, ydot, "the state derivative",
                           rates)
    return ydot

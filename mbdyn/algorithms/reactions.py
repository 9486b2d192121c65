"""Reactions and inverse dynamics: the force and moment each joint's parent exerts on its
child (at the joint origin, world or child components), the efforts that make a given
motion, and the drive efforts of driven joints.
"""
from __future__ import annotations


import numpy as np

from ..errors import ModelError
from ..kernels import dynamics as kd
from ..kernels import inverse as ki
from .inputs import plain as _plain
from .forward_dynamics import ARTICULATED_FROM, METHODS
from .inputs import F64, ND
from .inputs import empty as _empty
from .inputs import freeze as _freeze
from .loop_newton_euler import loop_newton_euler_reactions
from .newton_euler import tree_order
from .recycling import FREE as _FREE
from .recycling import refcount as _refcount
from .recycling import spares
from .loop_reactions import child_rotation, loop_reactions


def reactions(model, q, u, t=0.0, method="auto", frame="world"):
    """Force and moment each joint's parent exerts on its child, reduced to the joint
    origin (the child frame's origin): ``{joint: (F[3], M[3])}``, in world components
    (``frame="world"``) or in the child frame's own components (``frame="child"``, as
    the textbook writes reactions).

    ``method="newton-euler"`` solves the system with reaction unknowns in tree order
    (``"newton-euler-dense"``: the dense 6n system); ``"jourdain"`` and
    ``"articulated"`` compute the accelerations by that route and then the joint
    wrenches by inverse dynamics from the leaves to the root.  ``"auto"``: the dense
    system below ``ARTICULATED_FROM`` speeds (it needs no compiled kernel beyond those
    a run has, so a first run compiles less), tree order from there on.
    """
    if frame not in ("world", "child"):
        raise ModelError(f"unknown frame {frame!r} for reactions; use 'world' or 'child'")
    if model._con is not None:        # closed loops: with the loop joints' multipliers
        if method in ("newton-euler", "newton-euler-dense"):
            out = loop_newton_euler_reactions(model, q, u, t)[1]
            if frame == "child":
                out = {name: (child_rotation(model, name).T @ f,
                              child_rotation(model, name).T @ m)
                       for name, (f, m) in out.items()}
            return out
        return loop_reactions(model, q, u, t, frame)
    if method == "auto":
        method = "newton-euler-dense" if model.nu < ARTICULATED_FROM else "newton-euler"
    if method in ("newton-euler", "newton-euler-dense"):
        out = model.newton_euler(q, u, t, dense=method == "newton-euler-dense")[1]
    elif method in ("jourdain", "articulated"):
        ud = model.forward_dynamics(q, u, t, method=method)
        model._kinematics_kernel(q, u, t, ud)
        model._drop_velocity_products()
        w = np.empty((model.n_frames, 6))
        kd.joint_wrenches(model._mass, model._com, model._inertia, model._parent, model._R,
                          model._r, model._w, model._alpha, model._a, model._F, model._N, w)
        out = {name: (w[i, :3].copy(), w[i, 3:].copy()) for i, name in enumerate(model.joints)}
    else:
        raise ModelError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
    if frame == "child":
        out = {name: (model._R[i].T @ f, model._R[i].T @ m)
               for i, (name, (f, m)) in enumerate(out.items())}
    return out


def reaction_array(model, q, u, t=0.0, frame="world"):
    """The reactions as one array, a row per joint in ``Model.joints`` order: ``[Fx, Fy,
    Fz, Mx, My, Mz]``, what the parent exerts on the child about the joint origin (world
    components, or the child's with ``frame="child"``) -- ``reactions`` without its
    dictionaries, by the Newton-Euler equations in tree order (one compiled call; the
    loop joints' multipliers for a closed mechanism)."""
    if frame not in ("world", "child"):
        raise ModelError(f"unknown frame {frame!r} for reactions; use 'world' or 'child'")
    if model._con is not None:
        out = reactions(model, q, u, t, frame=frame)
        return np.array([np.concatenate(out[name]) for name in model.joints])
    tree_order(model, q, u, t)
    w = model._W.copy()
    if frame == "child":
        R = model._R
        w[:, :3] = np.einsum("nji,nj->ni", R, w[:, :3])
        w[:, 3:] = np.einsum("nji,nj->ni", R, w[:, 3:])
    return w


def _rates(model, u_dot):
    """``u'`` as a contiguous float array of the model's speeds, checked."""
    try:
        ud = np.require(u_dot, float, "CW")
    except (TypeError, ValueError):
        raise ModelError(f"model {model.name!r}: u_dot must be {model.nu} numbers, got "
                         f"{u_dot!r}") from None
    if ud.shape != (model.nu,):
        raise ModelError(f"model {model.name!r}: u_dot needs {model.nu} values, got "
                         f"{ud.size}")
    return ud


def effort_array(model, q, u, u_dot, t=0.0):
    """The generalized forces the actuators must add on each free speed to make the
    motion ``(q, u, u')``: ``Q = M u' - f``, one array in ``Model.speeds`` order (a torque
    on a revolute joint's speed, a force on a prismatic one) -- ``inverse_dynamics``'s
    efforts without its dictionaries, by the recursive Newton-Euler algorithm in one
    compiled call on the merged tree (O(n), ``compiled.merging``; a closed mechanism by
    ``M u' - f`` of its tree)."""
    call = model._c_efforts
    if call is not None:                 # one C call (kernels.fastcall); None: not taken
        tau = call(q, u, u_dot)
        if tau is not None:
            return tau
    call = model._fast_efforts
    if (call is not None and type(q) is ND and type(u) is ND and type(u_dot) is ND
            and q.dtype is F64 and u.dtype is F64 and u_dot.dtype is F64
            and q.ndim == 1 and u.ndim == 1 and u_dot.ndim == 1):
        # arrays of the compiled type (inputs.fits): its entry, no dispatch (freeze)
        kernel, fb, ib, forces, nu, spare = call
        tau = spare[0]       # a result the caller let go of, as it was made (recycling)
        if _refcount(tau) != _FREE or tau.dtype is not F64 or not tau.flags.writeable:
            tau = spare[1]
            if _refcount(tau) != _FREE or tau.dtype is not F64 or not tau.flags.writeable:
                spare[0] = tau             # both held or altered: a new one
                tau = spare[1] = _empty(nu)
        try:
            if kernel(fb, ib, forces, q, u, u_dot, tau) == -1:
                return tau
        except ZeroDivisionError:
            pass                     # a failure, or another size: the checked route
    return _efforts(model, model._dynamics, q, u, u_dot, t, "efforts")


def _efforts(model, packed, q, u, u_dot, t, key=None):
    """``effort_array`` on the packed tree ``packed``: the merged one, or the full one
    (``model._dynamics_full``), whose joint wrenches ``model._W`` then holds.  After a
    call that succeeded, a model without inputs written in Python calls the kernel
    by its compiled entry from then on, under ``key`` (``inputs.freeze``)."""
    tau = np.empty(model.nu)
    status = None
    if (model._con is None and not model._python_inputs and _plain(q, model.nq)
            and _plain(u, model.nu) and _plain(u_dot, model.nu)):
        try:                             # float64 arrays as they come: no conversion
            status = ki.inverse_dynamics_packed(*packed, q, u, u_dot, tau)
        except ZeroDivisionError:
            pass
    if status is None:                   # convert, check, say what is wrong
        q, u = model._state(q, u)
        ud = _rates(model, u_dot)
        if model._con is not None:
            return model.mass_matrix(q, t) @ ud - model.forcing(q, u, t)
        q, u = np.require(q, float, "CW"), np.require(u, float, "CW")  # the entry's types
        if model._python_inputs:
            model._fill_inputs(q, u, t)
        try:
            status = ki.inverse_dynamics_packed(*packed, q, u, ud, tau)
        except ZeroDivisionError:
            raise model._division_by_zero(q, t) from None
    if status == -2:
        model._check_finite(q, u, t, tau, "the inverse dynamics")
    if key is not None and not model._python_inputs and model._con is None:
        _freeze(model, key, ki.inverse_dynamics_packed, packed,
                (q, u, np.require(u_dot, float, "CW"), tau), model.nu, spares(model.nu))
    return tau


def inverse_dynamics(model, q, u, u_dot, t=0.0, frame="world"):
    """The efforts and reactions that make the motion ``(q, u, u')``: returns
    ``(efforts, reactions)`` -- ``efforts`` ``{speed name: generalized force}`` the
    actuators must add on each free speed, ``Q = M u' - f`` (a torque on a revolute
    joint's speed, a force on a prismatic one), and ``reactions`` ``{joint: (F, M)}``
    as ``Model.reactions`` gives them, the joints transmitting those efforts too.
    ``effort_array`` gives the efforts alone as an array, faster."""
    if frame not in ("world", "child"):
        raise ModelError(f"unknown frame {frame!r} for reactions; use 'world' or 'child'")
    Q = _efforts(model, model._dynamics_full, q, u, u_dot, t)   # the full tree: every joint
    if model._con is None:
        w = model._W                     # the joint wrenches of that motion
    else:
        q, u = model._state(q, u)
        model._kinematics_kernel(q, u, t, _rates(model, u_dot))
        model._drop_velocity_products()
        w = np.empty((model.n_frames, 6))
        kd.joint_wrenches(model._mass, model._com, model._inertia, model._parent, model._R,
                          model._r, model._w, model._alpha, model._a, model._F, model._N, w)
    R = model._R
    if frame == "child":
        reactions = {name: (R[i].T @ w[i, :3], R[i].T @ w[i, 3:])
                     for i, name in enumerate(model.joints)}
    else:
        reactions = {name: (w[i, :3].copy(), w[i, 3:].copy())
                     for i, name in enumerate(model.joints)}
    return dict(zip(model.speeds, Q.tolist())), reactions


def inverse_dynamics_along(model, t, q, u, u_dot=None, frame="world"):
    """``inverse_dynamics`` along a trajectory: ``t`` (n,), ``q`` (n, nq), ``u``
    (n, nu) and ``u_dot`` (n, nu; default the time derivative of ``u`` by second-order
    finite differences, ``numpy.gradient``).  Returns ``(efforts (n, nu), {joint:
    (n, 6)})`` -- force then moment, as ``reactions``."""
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float).reshape(len(t), model.nq)
    u = np.asarray(u, dtype=float).reshape(len(t), model.nu)
    if u_dot is None:
        if len(t) < 3:
            raise ModelError("inverse_dynamics_along: give u_dot, or at least three "
                             "samples to differentiate u")
        u_dot = np.gradient(u, t, axis=0, edge_order=2)
    u_dot = np.asarray(u_dot, dtype=float).reshape(len(t), model.nu)
    efforts = np.empty((len(t), model.nu))
    reactions = {j: np.empty((len(t), 6)) for j in model.joints}
    if model._con is not None or frame != "world":
        for k in range(len(t)):
            e, r = model.inverse_dynamics(q[k], u[k], u_dot[k], t[k], frame)
            efforts[k] = list(e.values())
            for j, (fo, mo) in r.items():
                reactions[j][k, :3], reactions[j][k, 3:] = fo, mo
        return efforts, reactions
    wrenches = np.empty((len(t), model.n_frames, 6))
    for k in range(len(t)):              # one compiled call a sample, no dictionaries
        efforts[k] = _efforts(model, model._dynamics_full, q[k], u[k], u_dot[k], t[k])
        wrenches[k] = model._W
    for i, j in enumerate(model.joints):
        reactions[j][:] = wrenches[:, i]
    return efforts, reactions


def drive_efforts(model, q, u, t=0.0):
    """Force or torque each driven joint needs to impose its motion: ``{joint: value}``
    (the reaction component along the joint axis, in the axis' sense)."""
    reac = model.reactions(q, u, t)
    out = {}
    for name, *_ in model._driven:
        j = model._joint[name]
        i = model._frame_index[j.child]
        axis_world = model._R[i] @ j.axis
        f, m = reac[name]
        out[name] = float(axis_world @ (m if j.kind == "revolute" else f))
    return out

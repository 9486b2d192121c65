"""One-call evaluations of the equations of motion (kinematics + loads + formulation + solve).

Fusing the steps into one compiled call keeps the Python overhead of a right-hand side to a
single dispatch.  The arguments are the compiled model's static arrays (``tree``, ``body``),
the joint-space state with drives filled in, the load values and a workspace whose last
array, ``scratch`` (``scratch_size`` floats), holds every temporary: the evaluations
allocate nothing and run uncounted (``views.UNCOUNTED``).
"""
import numpy as np
from numba import njit

from .articulated import ARTICULATED_WORK, articulated_body
from .articulated_reactions import joint_wrenches_tree, reaction_components
from .dynamics import (applied_loads, cholesky_solve, jourdain_terms, jourdain_work,
                       newton_euler_system)
from .force_function import apply_forces
from .forces import FORCE_WORK
from .kinematics import KINEMATICS_WORK, walk
from .motion import MOTION_WORK, motion
from .views import UNCOUNTED, c_view
from .internal import internal


def scratch_size(n, nu, nuf):
    """Floats of ``scratch`` an evaluation of ``n`` frames, ``nu`` free speeds and ``nuf``
    joint-space speeds needs.  The steps use it one after another from its start, except
    the speeds ``drop_velocity_products`` keeps across a second kinematic pass (after the
    kinematics' part)."""
    return max(KINEMATICS_WORK + nuf, FORCE_WORK, jourdain_work(n, nu),
               ARTICULATED_WORK + 6 * n)


@njit(cache=True, inline="always")
def outcome(pivot, ud):
    """A route's return value after its solve: the pivot that failed (>= 0), -2 when
    ``u'`` came out non-finite, else -1."""
    if pivot >= 0:
        return pivot
    for k in range(ud.shape[0]):
        if not np.isfinite(ud[k]):
            return -2
    return -1


@njit(**UNCOUNTED)
def kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                         mass, com, gravity, qfull, ufull, udfull,
                         load_body, load_point, load_force, load_moment, load_in_body,
                         forces, force_data, switches,
                         R, r, w, v, alpha, a, JR, JT, S, F, N, scratch):
    """Motion of every frame, then the applied loads ``F``, ``N``: gravity, point loads
    and force elements.  ``forces``: the force table and the compiled function that
    applies it (``force_function``: of one type for every model, so that this kernel is
    compiled once whether a model has force elements or not)."""
    walk(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx, qfull, ufull,
         udfull, R, r, w, v, alpha, a, JR, JT, S, scratch)
    loads_at(parent, axis, mass, com, gravity, qfull, ufull, load_body, load_point,
             load_force, load_moment, load_in_body, forces, force_data, R, r, w, v, F, N,
             scratch)


@internal(**UNCOUNTED)
def loads_at(parent, axis, mass, com, gravity, qfull, ufull, load_body, load_point,
             load_force, load_moment, load_in_body, forces, force_data, R, r, w, v, F, N,
             scratch):
    """The applied loads ``F``, ``N`` of the motion in ``R .. v``: gravity, point loads and
    the force elements (``forces``: the force table and the function that applies it,
    ``force_function``; None for a caller that has no force elements)."""
    applied_loads(mass, com, gravity, R, r, load_body, load_point, load_force, load_moment,
                  load_in_body, F, N, scratch)
    if forces is not None:
        force_int, how = forces
        if force_int.shape[0]:
            apply_forces(how, force_int, force_data, parent, axis, com, qfull, ufull, R, r,
                         w, v, F, N, force_data[0:0], scratch)


@internal(**UNCOUNTED)
def motion_and_loads(tree, body, state, loads, kin, scratch):
    """``kinematics_and_loads`` for the per-call entries, with the kinematics of
    ``motion.motion`` (no full Jacobians; ``S``) and, with the gyroscopic effect switched
    off, the motion again with every speed zero after the loads (as
    ``drop_velocity_products``).  The groups as ``articulated_accelerations``'s (``tree``:
    its first nine arrays)."""
    parent, kind, axis, seq, pos, C, qoff, uoff = tree[:8]
    mass, com, gravity = body[0], body[1], body[4]
    qfull, ufull, udfull = state
    (load_body, load_point, load_force, load_moment, load_in_body, forces, force_data,
     switches) = loads
    R, r, w, v, alpha, a, _, _, S, F, N = kin
    motion(parent, kind, axis, seq, pos, C, qoff, uoff, qfull, ufull, udfull, R, r, w, v,
           alpha, a, S, scratch, 1)
    loads_at(parent, axis, mass, com, gravity, qfull, ufull, load_body, load_point,
             load_force, load_moment, load_in_body, forces, force_data, R, r, w, v, F, N,
             scratch)
    if switches[0] == 0:
        nuf = ufull.shape[0]
        saved = c_view(scratch, MOTION_WORK, (nuf,))
        for k in range(nuf):
            saved[k] = ufull[k]
            ufull[k] = 0.0
        motion(parent, kind, axis, seq, pos, C, qoff, uoff, qfull, ufull, udfull, R, r, w,
               v, alpha, a, S, scratch, 1)
        for k in range(nuf):
            ufull[k] = saved[k]


@njit(inline="always", **UNCOUNTED)
def drop_velocity_products(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                           qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S, scratch):
    """The ``gyroscopic`` effect switched off: the motion again with every speed zero, so
    that the bias accelerations keep only the prescribed (drive) accelerations and
    ``w x I w`` vanishes; the applied loads computed before keep the true velocities.
    Inlined into the evaluations (a compiled function of its own would be machine-coded
    again, with the kinematics it calls, in every caller); Python calls it too."""
    nuf = ufull.shape[0]
    saved = c_view(scratch, KINEMATICS_WORK, (nuf,))
    for k in range(nuf):
        saved[k] = ufull[k]
        ufull[k] = 0.0
    walk(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx, qfull, ufull,
         udfull, R, r, w, v, alpha, a, JR, JT, S, scratch)
    for k in range(nuf):
        ufull[k] = saved[k]


# The two accelerations below take their arrays in groups (tuples, as ``packed._views``
# returns them) and are inlined into their callers: a call of some forty arrays costs a
# tenth of a small model's evaluation, and Python compiles a call of more than 30
# arguments as a call with ``*args``, which numba cannot inline.

@njit(inline="always", **UNCOUNTED)
def jourdain_accelerations(tree, body, state, loads, motion, jourdain, scratch):
    """Kinematics, loads, ``M`` and ``f``, then ``ud = M^-1 f`` by Cholesky.  The groups:
    ``tree`` (``parent .. anc_idx``), ``body`` (``mass, com, inertia, has_inertia,
    gravity``), ``state`` (``qfull, ufull, udfull``), ``loads`` (``load_body ..
    switches``), ``motion`` (``R, r, w, v, alpha, a, JR, JT, S, F, N``), ``jourdain`` (``M, f,
    L, ud``).

    Returns -1 on success, the index of the speed where the Cholesky factorisation broke
    down, or -2 when ``ud`` holds NaN or Inf.
    """
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx = tree
    mass, com, inertia, has_inertia, gravity = body
    qfull, ufull, udfull = state
    (load_body, load_point, load_force, load_moment, load_in_body, forces, force_data,
     switches) = loads
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion
    M, f, L, ud = jourdain
    kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                         mass, com, gravity, qfull, ufull, udfull,
                         load_body, load_point, load_force, load_moment, load_in_body,
                         forces, force_data, switches, R, r, w, v, alpha, a, JR, JT, S, F,
                         N, scratch)
    if switches[0] == 0:
        drop_velocity_products(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr,
                               anc_idx, qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S,
                               scratch)
    jourdain_terms(mass, com, inertia, has_inertia, R, r, w, alpha, a, JR, JT, anc_ptr,
                   anc_idx, parent, F, N, M, f, scratch)
    pivot = cholesky_solve(M, f, L, ud)
    return outcome(pivot, ud)


@internal(cache=True)
def newton_euler_solution(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                          mass, com, inertia, gravity, qfull, ufull, udfull,
                          load_body, load_point, load_force, load_moment, load_in_body,
                          forces, force_data, switches,
                          react_joint, react_force, react_moment,
                          R, r, w, v, alpha, a, JR, JT, S, F, N, A, b, scratch):
    """Kinematics, loads, the Newton-Euler system with reactions, solved by LU.

    Returns the unknowns ``x = [ud, lambda]`` (a new array).
    """
    kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                         mass, com, gravity, qfull, ufull, udfull,
                         load_body, load_point, load_force, load_moment, load_in_body,
                         forces, force_data, switches, R, r, w, v, alpha, a, JR, JT, S, F,
                         N, scratch)
    if switches[0] == 0:
        drop_velocity_products(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr,
                               anc_idx, qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S,
                               scratch)
    newton_euler_system(mass, com, inertia, parent, R, r, w, alpha, a, JR, JT, anc_ptr, anc_idx,
                        F, N, react_joint, react_force, react_moment, A, b, scratch)
    return np.linalg.solve(A, b)


@njit(inline="always", **UNCOUNTED)
def articulated_accelerations(tree, body, state, loads, motion, work, ud, scratch):
    """Kinematics, loads, then ``ud`` by the articulated-body algorithm: O(n).  The groups
    as ``jourdain_accelerations``'s, except ``body`` (``mass, com, inertia, gravity``) and
    ``work`` (``IA, pA, cb, U, Dl, acc``, the algorithm's workspace).

    ``tree`` ends with empty ancestor lists ``anc_ptr``, ``anc_idx``: the kinematics then
    write each frame's own Jacobian columns into ``S`` only, all the algorithm reads, and
    skip the full Jacobians (n x 3 x nu floats each, O(n depth) work; they may be
    unallocated).  Returns -1 on success, the speed where a degree of freedom has no
    inertia, or -2 when ``ud`` holds NaN or Inf.
    """
    parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx = tree
    mass, com, inertia, gravity = body
    qfull, ufull, udfull = state
    (load_body, load_point, load_force, load_moment, load_in_body, forces, force_data,
     switches) = loads
    R, r, w, v, alpha, a, JR, JT, S, F, N = motion
    IA, pA, cb, U, Dl, acc = work
    kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                         mass, com, gravity, qfull, ufull, udfull,
                         load_body, load_point, load_force, load_moment, load_in_body,
                         forces, force_data, switches, R, r, w, v, alpha, a, JR, JT, S, F,
                         N, scratch)
    if switches[0] == 0:
        drop_velocity_products(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr,
                               anc_idx, qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT, S,
                               scratch)
    pivot = articulated_body(mass, com, inertia, parent, kind, ucol, R, r, w, alpha, a, S, F,
                             N, IA, pA, cb, U, Dl, acc, ud, scratch)
    return outcome(pivot, ud)


@internal(**UNCOUNTED)
def newton_euler_tree(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                      mass, com, inertia, gravity, qfull, ufull, udfull,
                      load_body, load_point, load_force, load_moment, load_in_body,
                      forces, force_data, switches, react_joint, react_force, react_moment,
                      R, r, w, v, alpha, a, JR, JT, S, F, N, IA, pA, cb, U, Dl, acc, wrench, ud,
                      lam, scratch):
    """The Newton-Euler equations with reaction unknowns solved in tree order: speed rates
    ``ud`` and reaction components ``lam`` (as ``newton_euler_solution``'s ``x``), in O(n).
    Returns as ``articulated_accelerations`` (-2 also for non-finite reactions)."""
    pivot = articulated_accelerations(
        (parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx),
        (mass, com, inertia, gravity), (qfull, ufull, udfull),
        (load_body, load_point, load_force, load_moment, load_in_body, forces, force_data,
         switches), (R, r, w, v, alpha, a, JR, JT, S, F, N), (IA, pA, cb, U, Dl, acc), ud,
        scratch)
    if pivot != -1:
        return pivot
    joint_wrenches_tree(parent, r, IA, pA, acc, wrench, scratch)
    reaction_components(R, react_joint, react_force, react_moment, wrench, lam)
    for k in range(lam.shape[0]):
        if not np.isfinite(lam[k]):
            return -2
    return -1

"""Compiled fixed-step integration loops over the Jourdain right-hand side.

A Python loop spends most of a small model's step in interpreter overhead; these loops run
whole stretches of steps in one compiled call.  They serve models whose loads are
constants (callable loads need Python) -- drives are allowed, their values being
precomputed at every stage time by the caller.

Schemes (codes): 0 explicit Euler, 1 semi-implicit (symplectic) Euler -- velocities first,
then positions with the new velocities, the textbook's scheme --, 2 classic RK4,
3 implicit midpoint (symmetric, preserves quadratic invariants such as a quaternion's norm;
solved by a simplified Newton iteration whose finite-difference matrix is kept over steps,
``kernels.implicit_midpoint``).  Quaternions are projected onto the unit sphere after every
step.

Status codes returned: 0 done, 1 non-finite state or acceleration, 2 mass matrix not
positive definite, 3 implicit midpoint's Newton iteration did not converge.
"""
import numpy as np
from numba import njit
from .events import step_ends_stretch
from .implicit_midpoint import implicit_midpoint_step, newton_scratch
from .routes import finish_step
from .state_rate import coordinate_rates_into, copy_into, state_rate, state_rate_call
from .views import UNCOUNTED

EULER, SEMI_IMPLICIT_EULER, RK4, IMPLICIT_MIDPOINT = 0, 1, 2, 3
SCHEMES = {"euler": EULER, "semi-implicit-euler": SEMI_IMPLICIT_EULER, "rk4": RK4,
           "implicit-midpoint": IMPLICIT_MIDPOINT}
# stage times of each scheme as fractions of the step (drives are evaluated there)
STAGES = (0.0, 0.5, 1.0)


# Each scheme's step (inlined into the loops: no compiled layer of its own) has the same
# arguments: the step size, the state ``y`` and the slot
# ``yn`` for the next one, the drives' stage values ``drives`` (``drive_table[n]``), the
# model's arrays, scratch vectors ``k1 .. k4``, ``tmp`` and matrix ``J``, and the counter
# ``nfev``.  Each returns a status code (0 done).

@njit(cache=True, inline="always")
def euler_step(h, y, yn, drives, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
               loads, ws, k1, k2, k3, k4, tmp, J, nfev):
    """Explicit Euler."""
    st = state_rate(y, drives[0], nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
                    ws, k1, nfev)
    if st:
        return st
    for i in range(y.shape[0]):
        yn[i] = y[i] + h * k1[i]
    return 0


@njit(cache=True, inline="always")
def semi_implicit_euler_step(h, y, yn, drives, nq, slots, free_q, free_u, drive_q, drive_u,
                             tree, body, loads, ws, k1, k2, k3, k4, tmp, J, nfev):
    """Semi-implicit (symplectic) Euler: velocities first, then positions with them."""
    ny = y.shape[0]
    st = state_rate(y, drives[0], nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
                    ws, k1, nfev)
    if st:
        return st
    for i in range(nq, ny):
        yn[i] = y[i] + h * k1[i]           # velocities first
    for i in range(nq):
        tmp[i] = y[i]
    for i in range(nq, ny):
        tmp[i] = yn[i]
    coordinate_rates_into(tmp, nq, slots, k2)              # positions with the new velocities
    for i in range(nq):
        yn[i] = y[i] + h * k2[i]
    return 0


@njit(cache=True, inline="always")
def rk4_step(h, y, yn, drives, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
             loads, ws, k1, k2, k3, k4, tmp, J, nfev):
    """Classic fourth-order Runge-Kutta (its four stages call ``state_rate_call``: one
    compiled function, not four inlined copies)."""
    ny = y.shape[0]
    st = state_rate_call(y, drives[0], nq, slots, free_q, free_u, drive_q, drive_u, tree,
                         body, loads, ws, k1, nfev)
    for i in range(ny):
        tmp[i] = y[i] + 0.5 * h * k1[i]
    st = st or state_rate_call(tmp, drives[1], nq, slots, free_q, free_u, drive_q, drive_u,
                               tree, body, loads, ws, k2, nfev)
    for i in range(ny):
        tmp[i] = y[i] + 0.5 * h * k2[i]
    st = st or state_rate_call(tmp, drives[1], nq, slots, free_q, free_u, drive_q, drive_u,
                               tree, body, loads, ws, k3, nfev)
    for i in range(ny):
        tmp[i] = y[i] + h * k3[i]
    st = st or state_rate_call(tmp, drives[2], nq, slots, free_q, free_u, drive_q, drive_u,
                               tree, body, loads, ws, k4, nfev)
    if st:
        return st
    for i in range(ny):
        yn[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    return 0


def loop_scratch(ny, scheme):
    """The scratch space of one call of a loop of ``scheme`` (a code of ``SCHEMES``) on a
    state of ``ny`` entries: ``(k1, k2, k3, k4, tmp, J, H, piv, work)``, the steps'
    vectors, and the matrix ``J``, the inverse ``H``, the pivots and the work vectors of
    the implicit midpoint rule's Newton iteration (``implicit_midpoint.newton_scratch``;
    empty for the explicit schemes).  A new one for each call: the implicit midpoint
    rule starts each call with no inverse kept (``piv[ny] = 0``).  Allocated here, by
    the caller: the loops are compiled without reference counting (no array of theirs is
    allocated or freed)."""
    n = ny if scheme == IMPLICIT_MIDPOINT else 0
    return (np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny),
            np.empty((n, n))) + newton_scratch(n)


#: the loops' compile options: uncounted (their arrays are the caller's, ``loop_scratch``),
#: so no count is kept for any array they view -- their compile about 0.5 s shorter than
#: with counting and ``views.untracked`` views -- and releasing the GIL
LOOP = dict(UNCOUNTED, nogil=True)


# One compiled loop per scheme, so that a run compiles only its own scheme's step (a loop
# over all four would compile all of them: about 9 s of a first run).  The loops differ
# only in the step they call.  They release the GIL (``nogil``): batched ensembles run
# them on threads (``kernels.batched``).  After each step they check the run's event conditions
# (``kernels.events``; ``times[n]``: the time after step ``n``) and return early, status 0,
# after a step where a terminal one crossed zero or one is not finite.  Unless ``dout`` is
# empty, ``dout[n]`` receives ``y'`` at the start of step ``n`` (``k1``, which every step
# computes anyway): the derivatives of the cubic Hermite dense output (``samples``).

@njit(**LOOP)
def euler_loop(h, y0, drive_table, nq, slots, quats, free_q, free_u, drive_q, drive_u,
               tree, body, loads, ws, out, dout, nfev, times, events, scratch):
    """Run ``out.shape[0] - 1`` steps of size ``h`` of explicit Euler from ``y0``;
    ``out[k]`` is the state after k steps.  ``drive_table[k, s]`` holds the drives'
    ``(q, q', q'')`` at stage time ``t_k + STAGES[s] h``; ``nfev[0]`` counts
    right-hand-side evaluations; ``scratch``: ``loop_scratch(y0.size, EULER)``.  Returns
    ``(steps done, status)``."""
    copy_into(y0, out[0])
    k1, k2, k3, k4, tmp, J = scratch[:6]
    check_events = events[3].shape[0] > 0
    for n in range(out.shape[0] - 1):
        st = euler_step(h, out[n], out[n + 1], drive_table[n], nq, slots, free_q, free_u,
                        drive_q, drive_u, tree, body, loads, ws, k1, k2, k3, k4, tmp, J, nfev)
        if st:
            return n, st
        if dout.shape[0]:
            copy_into(k1, dout[n])              # y' at the step's start, for dense output
        st = finish_step(out[n + 1], drive_table[n][2], nq, slots, quats, free_q, free_u,
                         drive_q, drive_u, tree, loads, ws)
        if st:
            return n, st
        if check_events and step_ends_stretch(events, times[n], out[n + 1], n):
            return n + 1, 0
    return out.shape[0] - 1, 0


@njit(**LOOP)
def semi_implicit_euler_loop(h, y0, drive_table, nq, slots, quats, free_q, free_u, drive_q,
                             drive_u, tree, body, loads, ws, out, dout, nfev, times, events,
                             scratch):
    """``euler_loop`` with semi-implicit Euler."""
    copy_into(y0, out[0])
    k1, k2, k3, k4, tmp, J = scratch[:6]
    check_events = events[3].shape[0] > 0
    for n in range(out.shape[0] - 1):
        st = semi_implicit_euler_step(h, out[n], out[n + 1], drive_table[n], nq, slots,
                                      free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
                                      k1, k2, k3, k4, tmp, J, nfev)
        if st:
            return n, st
        if dout.shape[0]:
            copy_into(k1, dout[n])              # y' at the step's start, for dense output
        st = finish_step(out[n + 1], drive_table[n][2], nq, slots, quats, free_q, free_u,
                         drive_q, drive_u, tree, loads, ws)
        if st:
            return n, st
        if check_events and step_ends_stretch(events, times[n], out[n + 1], n):
            return n + 1, 0
    return out.shape[0] - 1, 0


@njit(**LOOP)
def rk4_loop(h, y0, drive_table, nq, slots, quats, free_q, free_u, drive_q, drive_u, tree,
             body, loads, ws, out, dout, nfev, times, events, scratch):
    """``euler_loop`` with RK4."""
    copy_into(y0, out[0])
    k1, k2, k3, k4, tmp, J = scratch[:6]
    check_events = events[3].shape[0] > 0
    for n in range(out.shape[0] - 1):
        st = rk4_step(h, out[n], out[n + 1], drive_table[n], nq, slots, free_q, free_u,
                      drive_q, drive_u, tree, body, loads, ws, k1, k2, k3, k4, tmp, J, nfev)
        if st:
            return n, st
        if dout.shape[0]:
            copy_into(k1, dout[n])              # y' at the step's start, for dense output
        st = finish_step(out[n + 1], drive_table[n][2], nq, slots, quats, free_q, free_u,
                         drive_q, drive_u, tree, loads, ws)
        if st:
            return n, st
        if check_events and step_ends_stretch(events, times[n], out[n + 1], n):
            return n + 1, 0
    return out.shape[0] - 1, 0


@njit(**LOOP)
def implicit_midpoint_loop(h, y0, drive_table, nq, slots, quats, free_q, free_u, drive_q,
                           drive_u, tree, body, loads, ws, out, dout, nfev, times, events,
                           scratch):
    """``euler_loop`` with the implicit midpoint rule (``kernels.implicit_midpoint``: its
    iteration matrix kept over the loop's steps; ``k1`` left holding ``y'`` at the step's
    start, as the other schemes leave it)."""
    copy_into(y0, out[0])
    k1, k2, k3, k4, tmp, J, H, piv, work = scratch
    check_events = events[3].shape[0] > 0
    for n in range(out.shape[0] - 1):
        drives = drive_table[n]
        st = implicit_midpoint_step(out[n], out[max(n - 1, 0)], out[max(n - 2, 0)], min(n, 2),
                                    h, drives[0], drives[1], nq, slots, free_q, free_u,
                                    drive_q, drive_u, tree, body, loads, ws, out[n + 1], k1,
                                    k3, k2, tmp, k4, J, H, piv, work, nfev)
        if st:
            return n, st
        if dout.shape[0]:
            copy_into(k1, dout[n])              # y' at the step's start, for dense output
        st = finish_step(out[n + 1], drives[2], nq, slots, quats, free_q, free_u, drive_q,
                         drive_u, tree, loads, ws)
        if st:
            return n, st
        if check_events and step_ends_stretch(events, times[n], out[n + 1], n):
            return n + 1, 0
    return out.shape[0] - 1, 0


#: the compiled loop of each scheme code
LOOPS = {EULER: euler_loop, SEMI_IMPLICIT_EULER: semi_implicit_euler_loop, RK4: rk4_loop,
         IMPLICIT_MIDPOINT: implicit_midpoint_loop}

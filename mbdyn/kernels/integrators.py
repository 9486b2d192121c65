"""Compiled fixed-step integration loops over the Jourdain right-hand side.

A Python loop spends most of a small model's step in interpreter overhead; these loops run
whole stretches of steps in one compiled call.  They serve models whose loads are
constants (callable loads need Python) -- drives are allowed, their values being
precomputed at every stage time by the caller.

Schemes (codes): 0 explicit Euler, 1 semi-implicit (symplectic) Euler -- velocities first,
then positions with the new velocities, the textbook's scheme --, 2 classic RK4,
3 implicit midpoint (symmetric, preserves quadratic invariants such as a quaternion's norm;
solved by Newton's method with a finite-difference Jacobian).  Quaternions are projected
onto the unit sphere after every step.

Status codes returned: 0 done, 1 non-finite state or acceleration, 2 mass matrix not
positive definite, 3 implicit midpoint's Newton iteration did not converge.
"""
import numpy as np
from numba import njit
from .events import step_ends_stretch
from .joints import coordinate_rates
from .routes import accelerations, finish_step
from .views import untracked

EULER, SEMI_IMPLICIT_EULER, RK4, IMPLICIT_MIDPOINT = 0, 1, 2, 3
SCHEMES = {"euler": EULER, "semi-implicit-euler": SEMI_IMPLICIT_EULER, "rk4": RK4,
           "implicit-midpoint": IMPLICIT_MIDPOINT}
# stage times of each scheme as fractions of the step (drives are evaluated there)
STAGES = (0.0, 0.5, 1.0)


@njit(cache=True, inline="always")
def _rates(y, nq, slots, out):
    """``q' = N(q) u`` into ``out[:nq]``."""
    coordinate_rates(y[:nq], y[nq:], slots, out[:nq])


@njit(cache=True, inline="always")
def _rhs(y, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
         ydot, nfev):
    """``ydot = [N(q) u, M^-1 f]`` at the stage whose drive values are ``drive_vals``;
    counts the evaluation in ``nfev[0]``."""
    nfev[0] += 1
    qfull, ufull, udfull = ws[0], ws[1], ws[2]
    nu = y.shape[0] - nq
    for k in range(nq):
        qfull[free_q[k]] = y[k]
    for k in range(nu):
        ufull[free_u[k]] = y[nq + k]
        udfull[free_u[k]] = 0.0
    for d in range(drive_q.shape[0]):
        qfull[drive_q[d]] = drive_vals[d, 0]
        ufull[drive_u[d]] = drive_vals[d, 1]
        udfull[drive_u[d]] = drive_vals[d, 2]
    pivot = accelerations(tree, body, loads, ws, ydot[nq:])
    if pivot >= 0:
        return 2
    _rates(y, nq, slots, ydot)
    for k in range(ydot.shape[0]):
        if not np.isfinite(ydot[k]):
            return 1
    return 0


@njit(cache=True, inline="always")
def _copy(src, dst):
    """``dst[:] = src`` element by element (an array assignment makes numba compile its
    shape-mismatch message: string formatting, seconds of a first run)."""
    for k in range(src.shape[0]):
        dst[k] = src[k]


# Each scheme's step (inlined into the loops: no compiled layer of its own) has the same
# arguments: the step size, the state ``y`` and the slot
# ``yn`` for the next one, the drives' stage values ``drives`` (``drive_table[n]``), the
# model's arrays, scratch vectors ``k1 .. k4``, ``tmp`` and matrix ``J``, and the counter
# ``nfev``.  Each returns a status code (0 done).

@njit(cache=True, inline="always")
def euler_step(h, y, yn, drives, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
               loads, ws, k1, k2, k3, k4, tmp, J, nfev):
    """Explicit Euler."""
    st = _rhs(y, drives[0], nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
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
    st = _rhs(y, drives[0], nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
              ws, k1, nfev)
    if st:
        return st
    for i in range(nq, ny):
        yn[i] = y[i] + h * k1[i]           # velocities first
    for i in range(nq):
        tmp[i] = y[i]
    for i in range(nq, ny):
        tmp[i] = yn[i]
    _rates(tmp, nq, slots, k2)              # positions with the new velocities
    for i in range(nq):
        yn[i] = y[i] + h * k2[i]
    return 0


@njit(cache=True, inline="always")
def rk4_step(h, y, yn, drives, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
             loads, ws, k1, k2, k3, k4, tmp, J, nfev):
    """Classic fourth-order Runge-Kutta."""
    ny = y.shape[0]
    st = _rhs(y, drives[0], nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
              ws, k1, nfev)
    for i in range(ny):
        tmp[i] = y[i] + 0.5 * h * k1[i]
    st = st or _rhs(tmp, drives[1], nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
                    loads, ws, k2, nfev)
    for i in range(ny):
        tmp[i] = y[i] + 0.5 * h * k2[i]
    st = st or _rhs(tmp, drives[1], nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
                    loads, ws, k3, nfev)
    for i in range(ny):
        tmp[i] = y[i] + h * k3[i]
    st = st or _rhs(tmp, drives[2], nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
                    loads, ws, k4, nfev)
    if st:
        return st
    for i in range(ny):
        yn[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    return 0


@njit(cache=True, inline="always")
def midpoint_step(h, y, yn, drives, nq, slots, free_q, free_u, drive_q, drive_u,
                            tree, body, loads, ws, k1, k2, k3, k4, tmp, J, nfev):
    """Implicit midpoint (``implicit_midpoint_step`` with the common arguments; ``k1``
    left holding ``y'`` at the step's start, as the other schemes leave it)."""
    return implicit_midpoint_step(y, h, drives[0], drives[1], nq, slots, free_q, free_u,
                                  drive_q, drive_u, tree, body, loads, ws, yn, k1, k3, k2,
                                  tmp, J, nfev)


@njit(cache=True, inline="always")
def _scratch(ny):
    """The steps' scratch space: ``k1 .. k4``, ``tmp`` and ``J``."""
    return (np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny),
            np.empty((ny, ny)))


# One compiled loop per scheme, so that a run compiles only its own scheme's step (a loop
# over all four would compile all of them: about 9 s of a first run).  The loops differ
# only in the step they call.  They release the GIL (``nogil``): batched ensembles run
# them on threads (``kernels.batched``).  After each step they check the run's event conditions
# (``kernels.events``; ``times[n]``: the time after step ``n``) and return early, status 0,
# after a step where a terminal one crossed zero or one is not finite.  Unless ``dout`` is
# empty, ``dout[n]`` receives ``y'`` at the start of step ``n`` (``k1``, which every step
# computes anyway): the derivatives of the cubic Hermite dense output (``samples``).

@njit(cache=True, nogil=True)
def euler_loop(h, y0, drive_table, nq, slots, quats, free_q, free_u, drive_q, drive_u,
               tree, body, loads, ws, out, dout, nfev, times, events):
    """Run ``out.shape[0] - 1`` steps of size ``h`` of explicit Euler from ``y0``;
    ``out[k]`` is the state after k steps.  ``drive_table[k, s]`` holds the drives'
    ``(q, q', q'')`` at stage time ``t_k + STAGES[s] h``; ``nfev[0]`` counts
    right-hand-side evaluations.  Returns ``(steps done, status)``."""
    _copy(y0, out[0])
    k1, k2, k3, k4, tmp, J = _scratch(y0.shape[0])
    tree, body, loads, ws = untracked(tree), untracked(body), untracked(loads), untracked(ws)
    out, drive_table = untracked(out), untracked(drive_table)
    check_events = events[3].shape[0] > 0
    for n in range(out.shape[0] - 1):
        st = euler_step(h, out[n], out[n + 1], drive_table[n], nq, slots, free_q, free_u,
                        drive_q, drive_u, tree, body, loads, ws, k1, k2, k3, k4, tmp, J, nfev)
        if st:
            return n, st
        if dout.shape[0]:
            _copy(k1, dout[n])              # y' at the step's start, for dense output
        st = finish_step(out[n + 1], drive_table[n][2], nq, slots, quats, free_q, free_u,
                         drive_q, drive_u, tree, loads, ws)
        if st:
            return n, st
        if check_events and step_ends_stretch(events, times[n], out[n + 1], n):
            return n + 1, 0
    return out.shape[0] - 1, 0


@njit(cache=True, nogil=True)
def semi_implicit_euler_loop(h, y0, drive_table, nq, slots, quats, free_q, free_u, drive_q,
                             drive_u, tree, body, loads, ws, out, dout, nfev, times, events):
    """``euler_loop`` with semi-implicit Euler."""
    _copy(y0, out[0])
    k1, k2, k3, k4, tmp, J = _scratch(y0.shape[0])
    tree, body, loads, ws = untracked(tree), untracked(body), untracked(loads), untracked(ws)
    out, drive_table = untracked(out), untracked(drive_table)
    check_events = events[3].shape[0] > 0
    for n in range(out.shape[0] - 1):
        st = semi_implicit_euler_step(h, out[n], out[n + 1], drive_table[n], nq, slots,
                                      free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
                                      k1, k2, k3, k4, tmp, J, nfev)
        if st:
            return n, st
        if dout.shape[0]:
            _copy(k1, dout[n])              # y' at the step's start, for dense output
        st = finish_step(out[n + 1], drive_table[n][2], nq, slots, quats, free_q, free_u,
                         drive_q, drive_u, tree, loads, ws)
        if st:
            return n, st
        if check_events and step_ends_stretch(events, times[n], out[n + 1], n):
            return n + 1, 0
    return out.shape[0] - 1, 0


@njit(cache=True, nogil=True)
def rk4_loop(h, y0, drive_table, nq, slots, quats, free_q, free_u, drive_q, drive_u, tree,
             body, loads, ws, out, dout, nfev, times, events):
    """``euler_loop`` with RK4."""
    _copy(y0, out[0])
    k1, k2, k3, k4, tmp, J = _scratch(y0.shape[0])
    tree, body, loads, ws = untracked(tree), untracked(body), untracked(loads), untracked(ws)
    out, drive_table = untracked(out), untracked(drive_table)
    check_events = events[3].shape[0] > 0
    for n in range(out.shape[0] - 1):
        st = rk4_step(h, out[n], out[n + 1], drive_table[n], nq, slots, free_q, free_u,
                      drive_q, drive_u, tree, body, loads, ws, k1, k2, k3, k4, tmp, J, nfev)
        if st:
            return n, st
        if dout.shape[0]:
            _copy(k1, dout[n])              # y' at the step's start, for dense output
        st = finish_step(out[n + 1], drive_table[n][2], nq, slots, quats, free_q, free_u,
                         drive_q, drive_u, tree, loads, ws)
        if st:
            return n, st
        if check_events and step_ends_stretch(events, times[n], out[n + 1], n):
            return n + 1, 0
    return out.shape[0] - 1, 0


@njit(cache=True, nogil=True)
def implicit_midpoint_loop(h, y0, drive_table, nq, slots, quats, free_q, free_u, drive_q,
                           drive_u, tree, body, loads, ws, out, dout, nfev, times, events):
    """``euler_loop`` with the implicit midpoint rule."""
    _copy(y0, out[0])
    k1, k2, k3, k4, tmp, J = _scratch(y0.shape[0])
    tree, body, loads, ws = untracked(tree), untracked(body), untracked(loads), untracked(ws)
    out, drive_table = untracked(out), untracked(drive_table)
    check_events = events[3].shape[0] > 0
    for n in range(out.shape[0] - 1):
        st = midpoint_step(h, out[n], out[n + 1], drive_table[n], nq, slots, free_q, free_u,
                           drive_q, drive_u, tree, body, loads, ws, k1, k2, k3, k4, tmp, J,
                           nfev)
        if st:
            return n, st
        if dout.shape[0]:
            _copy(k1, dout[n])              # y' at the step's start, for dense output
        st = finish_step(out[n + 1], drive_table[n][2], nq, slots, quats, free_q, free_u,
                         drive_q, drive_u, tree, loads, ws)
        if st:
            return n, st
        if check_events and step_ends_stretch(events, times[n], out[n + 1], n):
            return n + 1, 0
    return out.shape[0] - 1, 0


#: the compiled loop of each scheme code
LOOPS = {EULER: euler_loop, SEMI_IMPLICIT_EULER: semi_implicit_euler_loop, RK4: rk4_loop,
         IMPLICIT_MIDPOINT: implicit_midpoint_loop}


@njit(cache=True)
def implicit_midpoint_step(y, h, drive_start, drive_vals, nq, slots, free_q, free_u, drive_q,
                           drive_u, tree, body, loads, ws, yn, f0, fm, fp, ym, J, nfev):
    """``yn = y + h F((y + yn)/2)`` by Newton's method; the Jacobian of F by forward
    differences at the explicit predictor's midpoint, kept for the step's iterations.
    ``f0``: ``y'`` at the step's start (drive values ``drive_start``), the predictor's."""
    ny = y.shape[0]
    st = _rhs(y, drive_start, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
              ws, f0, nfev)
    if st:
        return st
    for i in range(ny):
        ym[i] = y[i] + 0.5 * h * f0[i]
    st = _rhs(ym, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
              ws, fm, nfev)
    if st:
        return st
    for i in range(ny):
        yn[i] = y[i] + h * fm[i]                    # predictor: explicit midpoint
    # J = I - h/2 dF/dy at the predictor's midpoint
    for j in range(ny):
        eps = 1.4901161193847656e-08 * max(1.0, abs(ym[j]))
        old = ym[j]
        ym[j] = old + eps
        st = _rhs(ym, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
                  loads, ws, fp, nfev)
        ym[j] = old
        if st:
            return st
        for i in range(ny):
            J[i, j] = -0.5 * h * (fp[i] - fm[i]) / eps
        J[j, j] += 1.0
    G = np.empty(ny)
    for it in range(30):
        for i in range(ny):
            ym[i] = 0.5 * (y[i] + yn[i])
        st = _rhs(ym, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
                  loads, ws, fm, nfev)
        if st:
            return st
        for i in range(ny):
            G[i] = yn[i] - y[i] - h * fm[i]
        dy = np.linalg.solve(J, G)
        size = 0.0
        scale = 0.0
        for i in range(ny):
            yn[i] -= dy[i]
            size = max(size, abs(dy[i]))
            scale = max(scale, abs(yn[i]))
        if size <= 1e-14 * max(1.0, scale):
            return 0
    return 3

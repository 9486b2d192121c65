"""The implicit midpoint rule's step, ``yn = y + h F((y + yn)/2)``, solved by a
quasi-Newton iteration whose matrix is kept from step to step.

The residual is ``G(yn) = yn - y - h F((y + yn)/2)``; Newton's matrix ``I - h/2 dF/dy``
by forward differences costs one evaluation of ``F`` per state, an iteration one.  Here
the inverse ``H`` of that matrix is formed once and then kept over steps, corrected after
every iteration by Broyden's ("good") update from the residuals' change, so that it
follows the Jacobian as the motion and the time move on.  It is formed afresh only when
the iteration stops contracting fast (its rate ``theta = |dy_k| / |dy_k-1|`` over
``REFRESH_RATE``), fails, or has not converged in ``STALE_ITERATIONS``.  A step starts
from the quadratic through the last three states (the explicit midpoint rule when they
are not at hand).  The answer is the same root of the same equation, converged to the
same tolerance as by Newton's method; only the path to it differs (Hairer & Wanner,
*Solving Ordinary Differential Equations II*, IV.8, the simplified Newton iteration and
its convergence rate; Dennis & Schnabel, *Numerical Methods for Unconstrained
Optimization and Nonlinear Equations*, 8.1, Broyden's update).
"""
import numpy as np
from numba import njit
from .state_rate import copy_into
from .state_rate import state_rate_call as _rate
from .internal import internal

#: a kept matrix whose iteration contracts more slowly than this is formed again
REFRESH_RATE = 0.25
#: iterations allowed with a kept matrix (a fresh one gets ``FRESH_ITERATIONS``)
STALE_ITERATIONS = 6
FRESH_ITERATIONS = 30
#: converged when the last correction is below this times ``max(1, |yn|)`` (max norms):
#: what is left is about ``theta`` times less, near the rounding of ``yn`` as after Newton
NEWTON_TOL = 1e-14


@njit(cache=True, inline="always")
def lu_factor(A, piv):
    """Factor ``A`` in place as ``P A = L U`` (partial pivoting; ``piv[k]``: the row
    swapped with row ``k`` at step ``k``).  Returns -1, or the column whose pivot is
    exactly zero (a singular matrix)."""
    n = A.shape[0]
    for k in range(n):
        p = k
        big = abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > big:
                big = abs(A[i, k])
                p = i
        piv[k] = p
        if big == 0.0:
            return k
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        inv = 1.0 / A[k, k]
        for i in range(k + 1, n):
            l_ = A[i, k] * inv
            A[i, k] = l_
            if l_ != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= l_ * A[k, j]
    return -1


@njit(cache=True, inline="always")
def lu_apply(LU, piv, x):
    """``x = A^-1 x`` in place with ``lu_factor``'s ``LU`` and ``piv`` of ``A``."""
    n = x.shape[0]
    for k in range(n):
        p = piv[k]
        if p != k:
            x[k], x[p] = x[p], x[k]
    for i in range(n):
        s = x[i]
        for j in range(i):
            s -= LU[i, j] * x[j]
        x[i] = s
    for i in range(n - 1, -1, -1):
        s = x[i]
        for j in range(i + 1, n):
            s -= LU[i, j] * x[j]
        x[i] = s / LU[i, i]


def newton_scratch(ny):
    """What ``implicit_midpoint_step`` keeps over steps besides the matrix ``J`` it
    factors: the inverse ``H``, the pivots ``piv`` (``piv[ny]`` is 1 while ``H`` holds an
    inverse) and four work vectors; allocated by the loop's caller
    (``integrators.loop_scratch``)."""
    return np.empty((ny, ny)), np.zeros(ny + 1, np.int64), np.empty((4, ny))


@internal(cache=True)
def implicit_midpoint_step(y, y1, y2, back, h, drive_start, drive_vals, nq, slots, free_q,
                           free_u, drive_q, drive_u, tree, body, loads, ws, yn, f0, fm, fp,
                           ym, pred, J, H, piv, work, nfev):
    """One step from ``y`` into ``yn``; ``y1``, ``y2``: the states one and two steps back
    (``back`` of them are real), for the predictor; ``f0``: left holding ``y'`` at the
    step's start (drive values ``drive_start``).  ``J`` (scratch), ``H``, ``piv``, ``work``
    (``newton_scratch``): as the previous step left them.  Returns a status: 0, a
    failed evaluation's, or 3 (no convergence with a fresh matrix, or a singular one)."""
    ny = y.shape[0]
    st = _rate(y, drive_start, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
               f0, nfev)
    if st:
        return st
    if back >= 2 and piv[ny] == 1:                 # the quadratic through the last states
        for i in range(ny):
            pred[i] = 3.0 * (y[i] - y1[i]) + y2[i]
    else:                                          # the explicit midpoint rule
        st = _explicit_midpoint(y, h, f0, drive_vals, nq, slots, free_q, free_u, drive_q,
                                drive_u, tree, body, loads, ws, ym, fm, pred, nfev)
        if st:
            return st
    copy_into(pred, yn)
    fresh = piv[ny] == 0
    renew, secant = fresh, False
    prev, left = -1.0, FRESH_ITERATIONS if fresh else STALE_ITERATIONS
    while left > 0:
        for i in range(ny):
            ym[i] = 0.5 * (y[i] + yn[i])
        st = _rate(ym, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
                   ws, fm, nfev)
        if st and not fresh:                      # a kept matrix led astray: start again
            renew, fresh = True, True
            copy_into(pred, yn)
            continue
        if st:
            return st
        if renew:
            st = _newton_inverse(ym, fm, h, drive_vals, nq, slots, free_q, free_u, drive_q,
                                 drive_u, tree, body, loads, ws, fp, J, H, piv, nfev)
            if st:
                return st
            renew, fresh, secant, prev, left = False, True, False, -1.0, FRESH_ITERATIONS
        size, scale = _correct(y, yn, fm, h, H, fp, work, secant)
        secant = True
        tol = NEWTON_TOL * max(1.0, scale)
        if size <= tol:
            return 0
        if prev > 0.0:
            theta = size / prev
            if theta > REFRESH_RATE and not fresh:
                renew, fresh = True, True
                if theta >= 1.0:
                    copy_into(pred, yn)
                continue
        prev, left = size, left - 1
        if left == 0 and not fresh:
            renew, fresh, left = True, True, 1
    return 3


@njit(cache=True, inline="always")
def _explicit_midpoint(y, h, f0, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u,
                       tree, body, loads, ws, ym, fm, pred, nfev):
    """``pred = y + h F(y + h/2 f0)``; returns the evaluation's status."""
    for i in range(y.shape[0]):
        ym[i] = y[i] + 0.5 * h * f0[i]
    st = _rate(ym, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
               fm, nfev)
    for i in range(y.shape[0]):
        pred[i] = y[i] + h * fm[i]
    return st


@njit(cache=True, inline="always")
def _correct(y, yn, fm, h, H, g, work, secant):
    """One quasi-Newton correction ``yn -= H G(yn)`` (``fm = F((y + yn)/2)``; the
    residual into ``g``), after Broyden's update of ``H`` by the previous correction when
    ``secant`` (``work[0]``: the previous residual, ``work[1]``: the previous correction,
    both kept for the next).  Returns the correction's size and ``yn``'s (max norms)."""
    ny = y.shape[0]
    g_old, step = work[0], work[1]
    for i in range(ny):
        g[i] = yn[i] - y[i] - h * fm[i]
    if secant:
        for i in range(ny):
            g_old[i] = g[i] - g_old[i]
        broyden_update(H, step, g_old, work[2], work[3])
    copy_into(g, g_old)
    size, scale = 0.0, 0.0
    for i in range(ny):
        d = 0.0
        for j in range(ny):
            d += H[i, j] * g[j]
        step[i] = -d
        yn[i] -= d
        size = max(size, abs(d))
        scale = max(scale, abs(yn[i]))
    return size, scale


@njit(cache=True, inline="always")
def broyden_update(H, s, dg, a, b):
    """Broyden's good update of the inverse ``H`` for the step ``s`` that changed the
    residual by ``dg``: ``H += (s - H dg) (s^T H) / (s^T H dg)`` (skipped when the
    denominator vanishes); ``a``, ``b``: scratch."""
    n = s.shape[0]
    den = 0.0
    for i in range(n):
        ai, bi = 0.0, 0.0
        for j in range(n):
            ai += H[i, j] * dg[j]
            bi += H[j, i] * s[j]
        a[i], b[i] = ai, bi
    for i in range(n):
        den += s[i] * a[i]
    if den == 0.0 or not np.isfinite(den):
        return
    for i in range(n):
        c = (s[i] - a[i]) / den
        for j in range(n):
            H[i, j] += c * b[j]


@njit(cache=True, inline="always")
def _newton_inverse(ym, fm, h, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree,
                    body, loads, ws, fp, J, H, piv, nfev):
    """``H = (I - h/2 dF/dy)^-1`` at ``ym`` (``fm = F(ym)``), the derivative by forward
    differences, factored in ``J`` (``piv[ny]`` set to 1).  Returns a status: 0, a failed
    evaluation's, 3 (a singular matrix)."""
    ny = ym.shape[0]
    piv[ny] = 0
    for j in range(ny):
        eps = 1.4901161193847656e-08 * max(1.0, abs(ym[j]))
        old = ym[j]
        ym[j] = old + eps
        st = _rate(ym, drive_vals, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads,
                   ws, fp, nfev)
        ym[j] = old
        if st:
            return st
        for i in range(ny):
            J[i, j] = -0.5 * h * (fp[i] - fm[i]) / eps
        J[j, j] += 1.0
    if lu_factor(J, piv) >= 0:
        return 3
    for j in range(ny):                            # H's columns: J^-1 e_j
        for i in range(ny):
            fp[i] = 1.0 if i == j else 0.0
        lu_apply(J, piv, fp)
        for i in range(ny):
            H[i, j] = fp[i]
    piv[ny] = 1
    return 0

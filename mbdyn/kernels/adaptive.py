"""Compiled embedded Runge-Kutta pairs with step-size control, over the Jourdain right-hand
side: Dormand-Prince 5(4) ("RK45") and Dormand-Prince 8(5,3) ("DOP853").

One call runs a *stretch*: up to ``max_accept`` accepted steps, each with its embedded error
estimate and the standard controller (Hairer, Norsett & Wanner, *Solving Ordinary
Differential Equations I*, II.4 and II.10), the same as scipy's ``RK45`` and ``DOP853``:

* error norm: the root mean square of ``err_i / (atol + rtol max(|y_i|, |y_new_i|))``; for
  DOP853 the 5th- and 3rd-order estimates combined as ``|h| e5^2 / sqrt(n (e5^2 + e3^2/100))``;
* accepted when the norm is below 1; the next step scaled by
  ``0.9 norm^(-1/(p+1))`` (``p`` the estimator's order, 4 or 7), between 0.2 and 10 times,
  never up right after a rejection; a step below ten roundoffs of ``t`` fails.

Dense output (Hairer's continuous extensions): a polynomial in ``x = (t - t_old)/h``,
``y_old + x (F0 + (1-x)(F1 + x (F2 + (1-x)(F3 + ...))))`` with ``F0 = y_new - y_old``,
``F1 = h f_old - F0``, ``F2 = F0 - h f_new - F1`` and the rest ``h D K`` (4th order for
RK45 from its seven stages, 7th order for DOP853 after three more stages).

The model must have no Python-function loads; its drives come as programs of
``kernels.programs`` (``drives = (ops, consts, starts)``), evaluated at each stage time.
The pairs' coefficients are in ``kernels.tableaus``.
Status codes: 0 done (stretch full or ``t_end`` reached), 1 non-finite derivative, 2 mass
matrix not positive definite (both at the stage time and state left in ``fail``), 4 step
size below the roundoff of ``t``.
"""
import numpy as np
from numba import njit

from .events import step_ends_stretch
from .integrators import _rhs
from .programs import STACK, drive_values
from .tableaus import DOP853, RK45, TABLEAUS, Tableau  # noqa: F401 (re-exported)
from .views import untracked

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0


def initial_step(fun, y0, f0, span, max_step, order, rtol, atol):
    """A first step size from the size of ``y0``, ``f0`` and a difference estimate of the
    second derivative (Hairer, Norsett & Wanner, II.4); ``fun(h, y)`` is the derivative at
    ``t0 + h``; at most ``span`` and ``max_step``."""
    scale = atol + np.abs(y0) * rtol
    rms = lambda x: np.sqrt(np.mean(x * x))
    d0, d1 = rms(y0 / scale), rms(f0 / scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, span)
    f1 = fun(h0, y0 + h0 * f0)
    d2 = rms((f1 - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return min(100 * h0, h1, span, max_step)


@njit(cache=True, inline="always")
def _stage(t, y, ops, consts, starts, stack, dv, nq, slots, free_q, free_u, drive_q, drive_u,
           tree, body, loads, ws, ydot, nfev):
    """The right-hand side at time ``t`` (drives evaluated there) and state ``y``."""
    if dv.shape[0]:
        drive_values(ops, consts, starts, t, stack, dv)
    return _rhs(y, dv, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
                ydot, nfev)


@njit(cache=True, inline="always")
def _combine(y, h, A, s, K, out):
    """``out = y + h sum_j<s A[s, j] K[j]`` (the state at stage ``s``)."""
    n = y.shape[0]
    for i in range(n):
        acc = 0.0
        for j in range(s):
            a = A[s, j]
            if a != 0.0:
                acc += a * K[j, i]
        out[i] = y[i] + h * acc


@njit(cache=True, inline="always")
def _dense_coefficients(A, C, D, stages, t_old, y_old, y_new, h, K, F, tmp, ops, consts, starts,
                        stack, dv, nq, slots, free_q, free_u, drive_q, drive_u, tree, body,
                        loads, ws, fail, nfev):
    """``F`` (rows of the dense polynomial) of the step ``y_old -> y_new`` whose stages are
    ``K[:stages]``; computes the extra stages ``K[stages:]`` first (DOP853: three)."""
    for s in range(stages, K.shape[0]):
        _combine(y_old, h, A, s, K, tmp)
        st = _stage(t_old + C[s] * h, tmp, ops, consts, starts, stack, dv, nq, slots, free_q,
                    free_u, drive_q, drive_u, tree, body, loads, ws, K[s], nfev)
        if st:
            fail[0] = t_old + C[s] * h
            fail[1:] = tmp
            return st
    n = y_old.shape[0]
    f_new = K[stages - 1]
    for i in range(n):
        dy = y_new[i] - y_old[i]
        F[0, i] = dy
        F[1, i] = h * K[0, i] - dy
        F[2, i] = dy - h * f_new[i] - F[1, i]
    for r in range(D.shape[0]):
        for i in range(n):
            acc = 0.0
            for j in range(K.shape[0]):
                d = D[r, j]
                if d != 0.0:
                    acc += d * K[j, i]
            F[3 + r, i] = h * acc
    return 0


@njit(cache=True, inline="always")
def _dense_value(F, y_old, x, out):
    """The dense polynomial at ``x = (t - t_old) / h`` into ``out``."""
    n = y_old.shape[0]
    m = F.shape[0]
    for i in range(n):
        acc = 0.0
        for r in range(m - 1, -1, -1):
            acc += F[r, i]
            acc *= x if r % 2 == 0 else 1.0 - x
        out[i] = y_old[i] + acc


@njit(cache=True, inline="always")
def _error_norm(kind, E, E3, K, y, y_new, h, h_abs, rtol, atol, stages):
    """The error norm of the step ``y -> y_new`` of size ``h`` from its stages ``K`` (see
    the module docstring): below 1 the step is accepted."""
    n = y.shape[0]
    if kind == RK45:
        total = 0.0
        for i in range(n):
            scale = atol + max(abs(y[i]), abs(y_new[i])) * rtol
            acc = 0.0
            for j in range(stages):
                acc += E[j] * K[j, i]
            e = h * acc / scale
            total += e * e
        return np.sqrt(total / n)
    e5 = 0.0
    e3 = 0.0
    for i in range(n):
        scale = atol + max(abs(y[i]), abs(y_new[i])) * rtol
        a5 = 0.0
        a3 = 0.0
        for j in range(stages):
            a5 += E[j] * K[j, i]
            a3 += E3[j] * K[j, i]
        e5 += (a5 / scale) ** 2
        e3 += (a3 / scale) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return h_abs * e5 / np.sqrt((e5 + 0.01 * e3) * n)


@njit(cache=True)
def rk_stretch(kind, A, B, C, E, E3, D, t, t_end, y, f, h_abs, rtol, atol, max_step,
               max_accept, t_eval, i_eval, samples, ops, consts, starts, nq, slots, quats,
               free_q, free_u, drive_q, drive_u, tree, body, loads, ws, out_t, out_y, out_h,
               out_nfev, out_ieval, out_K, fail, nfev, events):
    """Up to ``max_accept`` accepted steps from ``(t, y)`` (``f`` its derivative, ``h_abs``
    the proposed step) towards ``t_end``.  Accepted step ``k``: ``out_t[k]``,
    ``out_y[k]``, its size ``out_h[k]``, the evaluations so far ``out_nfev[k]``, the
    samples so far ``out_ieval[k]``; its stages in ``out_K[k]`` when ``out_K`` has rows
    (the last row when it has fewer: ``out_K`` of one row keeps the last step's stages).
    Output times ``t_eval[i_eval:]`` passed are sampled on the dense output into
    ``samples``.  ``y``, ``f`` end as the last accepted state and its derivative.
    ``events``: the event conditions (``kernels.events``), checked after every step; the
    stretch ends early after a step where one crossed zero or is not finite.
    On failure ``fail`` holds the stage's time, then its state.  Returns
    ``(accepted, status, h_abs, i_eval)``; ``quats`` is unused (no projection: the drift is
    reported, as with scipy's solvers)."""
    # long: one accepted step -- stages, error norm, step-size control, dense sampling --
    # inside two loops whose early returns carry (accepted, status, h_abs, i_eval) out; the
    # pieces with a job of their own are the inlined helpers above.
    n = y.shape[0]
    stages = B.shape[0] + 1
    # untracked aliases of the model's arrays: views of them cost no reference counting
    tree, body, loads, ws = untracked(tree), untracked(body), untracked(loads), untracked(ws)
    K = np.empty((A.shape[0], n))
    y_new = np.empty(n)
    tmp = np.empty(n)
    F = np.empty((3 + D.shape[0], n))
    stack = np.empty(STACK)
    dv = np.empty((drive_q.shape[0], 3))
    keep_stages = out_K.shape[0]
    check_events = events[3].shape[0] > 0
    exponent = -1.0 / (5.0 if kind == RK45 else 8.0)
    accepted = 0
    while accepted < max_accept and t < t_end:
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        rejected = False
        while True:
            if h_abs < min_step:
                return accepted, 4, h_abs, i_eval
            t_new = t + h_abs
            if t_new > t_end:
                t_new = t_end
            h = t_new - t
            h_abs = abs(h)
            for i in range(n):
                K[0, i] = f[i]
            st = 0
            for s in range(1, stages - 1):
                _combine(y, h, A, s, K, tmp)
                st = _stage(t + C[s] * h, tmp, ops, consts, starts, stack, dv, nq, slots,
                            free_q, free_u, drive_q, drive_u, tree, body, loads, ws, K[s],
                            nfev)
                if st:
                    fail[0] = t + C[s] * h
                    fail[1:] = tmp
                    return accepted, st, h_abs, i_eval
            for i in range(n):
                acc = 0.0
                for j in range(stages - 1):
                    acc += B[j] * K[j, i]
                y_new[i] = y[i] + h * acc
            st = _stage(t_new, y_new, ops, consts, starts, stack, dv, nq, slots, free_q,
                        free_u, drive_q, drive_u, tree, body, loads, ws, K[stages - 1], nfev)
            if st:
                fail[0] = t_new
                fail[1:] = y_new
                return accepted, st, h_abs, i_eval
            norm = _error_norm(kind, E, E3, K, y, y_new, h, h_abs, rtol, atol, stages)
            if norm < 1.0:
                if norm == 0.0:
                    factor = MAX_FACTOR
                else:
                    factor = min(MAX_FACTOR, SAFETY * norm ** exponent)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            if np.isnan(norm):
                h_abs *= MIN_FACTOR
            else:
                h_abs *= max(MIN_FACTOR, SAFETY * norm ** exponent)
            rejected = True
        # accepted: sample the output times passed, then move on
        if i_eval < t_eval.shape[0] and t_eval[i_eval] <= t_new:
            st = _dense_coefficients(A, C, D, stages, t, y, y_new, h, K, F, tmp, ops, consts,
                                     starts, stack, dv, nq, slots, free_q, free_u, drive_q,
                                     drive_u, tree, body, loads, ws, fail, nfev)
            if st:
                return accepted, st, h_abs, i_eval
            while i_eval < t_eval.shape[0] and t_eval[i_eval] <= t_new:
                _dense_value(F, y, (t_eval[i_eval] - t) / h, samples[i_eval])
                i_eval += 1
        if keep_stages:
            row = min(accepted, keep_stages - 1)
            for s in range(stages):
                for i in range(n):
                    out_K[row, s, i] = K[s, i]
        for i in range(n):
            y[i] = y_new[i]
            f[i] = K[stages - 1, i]
        t = t_new
        out_t[accepted] = t
        out_y[accepted] = y
        out_h[accepted] = h
        out_nfev[accepted] = nfev[0]
        out_ieval[accepted] = i_eval
        accepted += 1
        if check_events and step_ends_stretch(events, t, y, accepted - 1):
            break
    return accepted, 0, h_abs, i_eval


@njit(cache=True)
def dense_step(A, C, D, stages, t_old, y_old, y_new, h, K_step, ops, consts, starts, nq,
               slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws, nfev):
    """The dense polynomial ``F`` of one accepted step from its stages ``K_step``
    (``out_K[k]`` of ``rk_stretch``); returns ``(F, status)``."""
    n = y_old.shape[0]
    K = np.zeros((A.shape[0], n))
    K[:stages] = K_step[:stages]
    F = np.empty((3 + D.shape[0], n))
    tmp = np.empty(n)
    fail = np.empty(n + 1)
    st = _dense_coefficients(A, C, D, stages, t_old, y_old, y_new, h, K, F, tmp, ops, consts,
                             starts, np.empty(STACK), np.empty((drive_q.shape[0], 3)), nq,
                             slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
                             fail, nfev)
    return F, st


def dense_values(F, y_old, x):
    """The dense polynomial at the fractions ``x`` (array) of the step: ``(len(x), n)``."""
    x = np.atleast_1d(np.asarray(x, dtype=float))[:, None]
    acc = np.zeros((x.shape[0], F.shape[1]))
    for r in range(F.shape[0] - 1, -1, -1):
        acc += F[r]
        acc *= x if r % 2 == 0 else 1.0 - x
    return y_old + acc

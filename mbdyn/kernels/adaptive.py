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
Status codes: 0 done (stretch full or ``t_end`` reached), 1 non-finite derivative, 2 mass
matrix not positive definite (both at the stage time and state left in ``fail``), 4 step
size below the roundoff of ``t``.
"""
# long: the embedded Runge-Kutta pairs' tableaus (data) and the compiled stretch that uses
# them stay in one file: numba's cache is invalidated per source file, and a kernel must
# not outlive a change of the coefficients it was compiled with.
import numpy as np
from numba import njit

from .events import step_ends_stretch
from .routes import closed, finish_step
from .state_rate import state_rate
from .programs import STACK, drive_values
from .views import CACHED, UNCOUNTED

RK45, DOP853 = 0, 1
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0

# ----------------------------------------------------------------- Dormand-Prince 5(4)
# Dormand & Prince (1980), J. Comp. Appl. Math. 6, 19-26; dense output of Shampine (1986)
# in the form of Hairer's DOPRI5.
_DP5_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
_DP5_A = np.zeros((7, 7))
_DP5_A[1, :1] = [1 / 5]
_DP5_A[2, :2] = [3 / 40, 9 / 40]
_DP5_A[3, :3] = [44 / 45, -56 / 15, 32 / 9]
_DP5_A[4, :4] = [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729]
_DP5_A[5, :5] = [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656]
_DP5_A[6, :6] = [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
_DP5_B = _DP5_A[6, :6].copy()               # 5th order; its last stage is f(t + h, y_new)
_DP5_BHAT = np.array([5179 / 57600, 0.0, 7571 / 16695, 393 / 640, -92097 / 339200,
                      187 / 2100, 1 / 40])   # the embedded 4th-order weights (7 stages)
_DP5_E = np.append(_DP5_B, 0.0) - _DP5_BHAT
_DP5_D = np.array([[-12715105075 / 11282082432, 0.0, 87487479700 / 32700410799,
                    -10690763975 / 1880347072, 701980252875 / 199316789632,
                    -1453857185 / 822651844, 69997945 / 29380423]])

# ----------------------------------------------------------------- Dormand-Prince 8(5,3)
# Hairer, Norsett & Wanner, Solving ODEs I (2nd ed.), II.10, and their code DOP853:
# 12 stages, the 13th is f(t + h, y_new); stages 14-16 only for the dense output.
_DOP_C = np.array([
    0.0, 0.526001519587677318785587544488e-01, 0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510, 0.281649658092772603273242802490,
    0.333333333333333333333333333333, 0.25, 0.307692307692307692307692307692,
    0.651282051282051282051282051282, 0.6, 0.857142857142857142857142857142, 1.0, 1.0,
    0.1, 0.2, 0.777777777777777777777777777778])
_DOP_A = np.zeros((16, 16))
# (stage, {earlier stage: coefficient}) -- the nonzero entries of each row
for _s, _row in (
        (1, {0: 5.26001519587677318785587544488e-2}),
        (2, {0: 1.97250569845378994544595329183e-2, 1: 5.91751709536136983633785987549e-2}),
        (3, {0: 2.95875854768068491816892993775e-2, 2: 8.87627564304205475450678981324e-2}),
        (4, {0: 2.41365134159266685502369798665e-1, 2: -8.84549479328286085344864962717e-1,
             3: 9.24834003261792003115737966543e-1}),
        (5, {0: 3.7037037037037037037037037037e-2, 3: 1.70828608729473871279604482173e-1,
             4: 1.25467687566822425016691814123e-1}),
        (6, {0: 3.7109375e-2, 3: 1.70252211019544039314978060272e-1,
             4: 6.02165389804559606850219397283e-2, 5: -1.7578125e-2}),
        (7, {0: 3.70920001185047927108779319836e-2, 3: 1.70383925712239993810214054705e-1,
             4: 1.07262030446373284651809199168e-1, 5: -1.53194377486244017527936158236e-2,
             6: 8.27378916381402288758473766002e-3}),
        (8, {0: 6.24110958716075717114429577812e-1, 3: -3.36089262944694129406857109825,
             4: -8.68219346841726006818189891453e-1, 5: 2.75920996994467083049415600797e1,
             6: 2.01540675504778934086186788979e1, 7: -4.34898841810699588477366255144e1}),
        (9, {0: 4.77662536438264365890433908527e-1, 3: -2.48811461997166764192642586468,
             4: -5.90290826836842996371446475743e-1, 5: 2.12300514481811942347288949897e1,
             6: 1.52792336328824235832596922938e1, 7: -3.32882109689848629194453265587e1,
             8: -2.03312017085086261358222928593e-2}),
        (10, {0: -9.3714243008598732571704021658e-1, 3: 5.18637242884406370830023853209,
              4: 1.09143734899672957818500254654, 5: -8.14978701074692612513997267357,
              6: -1.85200656599969598641566180701e1, 7: 2.27394870993505042818970056734e1,
              8: 2.49360555267965238987089396762, 9: -3.0467644718982195003823669022}),
        (11, {0: 2.27331014751653820792359768449, 3: -1.05344954667372501984066689879e1,
              4: -2.00087205822486249909675718444, 5: -1.79589318631187989172765950534e1,
              6: 2.79488845294199600508499808837e1, 7: -2.85899827713502369474065508674,
              8: -8.87285693353062954433549289258, 9: 1.23605671757943030647266201528e1,
              10: 6.43392746015763530355970484046e-1}),
        # the 8th-order weights b (stage 12 is at t + h, y_new)
        (12, {0: 5.42937341165687622380535766363e-2, 5: 4.45031289275240888144113950566,
              6: 1.89151789931450038304281599044, 7: -5.8012039600105847814672114227,
              8: 3.1116436695781989440891606237e-1, 9: -1.52160949662516078556178806805e-1,
              10: 2.01365400804030348374776537501e-1, 11: 4.47106157277725905176885569043e-2}),
        (13, {0: 5.61675022830479523392909219681e-2, 6: 2.53500210216624811088794765333e-1,
              7: -2.46239037470802489917441475441e-1, 8: -1.24191423263816360469010140626e-1,
              9: 1.5329179827876569731206322685e-1, 10: 8.20105229563468988491666602057e-3,
              11: 7.56789766054569976138603589584e-3, 12: -8.298e-3}),
        (14, {0: 3.18346481635021405060768473261e-2, 5: 2.83009096723667755288322961402e-2,
              6: 5.35419883074385676223797384372e-2, 7: -5.49237485713909884646569340306e-2,
              10: -1.08347328697249322858509316994e-4, 11: 3.82571090835658412954920192323e-4,
              12: -3.40465008687404560802977114492e-4, 13: 1.41312443674632500278074618366e-1}),
        (15, {0: -4.28896301583791923408573538692e-1, 5: -4.69762141536116384314449447206,
              6: 7.68342119606259904184240953878, 7: 4.06898981839711007970213554331,
              8: 3.56727187455281109270669543021e-1, 12: -1.39902416515901462129418009734e-3,
              13: 2.9475147891527723389556272149, 14: -9.15095847217987001081870187138})):
    for _j, _v in _row.items():
        _DOP_A[_s, _j] = _v
_DOP_B = _DOP_A[12, :12].copy()
# error estimators over the 13 stages: 5th order (e5) and 3rd order (e3 = b - bhat3)
_DOP_E5 = np.zeros(13)
for _j, _v in {0: 0.1312004499419488073250102996e-1, 5: -0.1225156446376204440720569753e+1,
               6: -0.4957589496572501915214079952, 7: 0.1664377182454986536961530415e+1,
               8: -0.3503288487499736816886487290, 9: 0.3341791187130174790297318841,
               10: 0.8192320648511571246570742613e-1,
               11: -0.2235530786388629525884427845e-1}.items():
    _DOP_E5[_j] = _v
_DOP_E3 = np.append(_DOP_B, 0.0)
_DOP_E3[0] -= 0.244094488188976377952755905512
_DOP_E3[8] -= 0.733846688281611857341361741547
_DOP_E3[11] -= 0.220588235294117647058823529412e-1
# dense output: the coefficients of F3 .. F6 over the 16 stages
_DOP_D = np.zeros((4, 16))
for _r, _row in enumerate((
        {0: -0.84289382761090128651353491142e+1, 5: 0.56671495351937776962531783590,
         6: -0.30689499459498916912797304727e+1, 7: 0.23846676565120698287728149680e+1,
         8: 0.21170345824450282767155149946e+1, 9: -0.87139158377797299206789907490,
         10: 0.22404374302607882758541771650e+1, 11: 0.63157877876946881815570249290,
         12: -0.88990336451333310820698117400e-1, 13: 0.18148505520854727256656404962e+2,
         14: -0.91946323924783554000451984436e+1, 15: -0.44360363875948939664310572000e+1},
        {0: 0.10427508642579134603413151009e+2, 5: 0.24228349177525818288430175319e+3,
         6: 0.16520045171727028198505394887e+3, 7: -0.37454675472269020279518312152e+3,
         8: -0.22113666853125306036270938578e+2, 9: 0.77334326684722638389603898808e+1,
         10: -0.30674084731089398182061213626e+2, 11: -0.93321305264302278729567221706e+1,
         12: 0.15697238121770843886131091075e+2, 13: -0.31139403219565177677282850411e+2,
         14: -0.93529243588444783865713862664e+1, 15: 0.35816841486394083752465898540e+2},
        {0: 0.19985053242002433820987653617e+2, 5: -0.38703730874935176555105901742e+3,
         6: -0.18917813819516756882830838328e+3, 7: 0.52780815920542364900561016686e+3,
         8: -0.11573902539959630126141871134e+2, 9: 0.68812326946963000169666922661e+1,
         10: -0.10006050966910838403183860980e+1, 11: 0.77771377980534432092869265740,
         12: -0.27782057523535084065932004339e+1, 13: -0.60196695231264120758267380846e+2,
         14: 0.84320405506677161018159903784e+2, 15: 0.11992291136182789328035130030e+2},
        {0: -0.25693933462703749003312586129e+2, 5: -0.15418974869023643374053993627e+3,
         6: -0.23152937917604549567536039109e+3, 7: 0.35763911791061412378285349910e+3,
         8: 0.93405324183624310003907691704e+2, 9: -0.37458323136451633156875139351e+2,
         10: 0.10409964950896230045147246184e+3, 11: 0.29840293426660503123344363579e+2,
         12: -0.43533456590011143754432175058e+2, 13: 0.96324553959188282948394950600e+2,
         14: -0.39177261675615439165231486172e+2, 15: -0.14972683625798562581422125276e+3})):
    for _j, _v in _row.items():
        _DOP_D[_r, _j] = _v


class Tableau:
    """One pair's constants as the kernels take them: ``kind``, stage matrix ``A`` (rows
    past the step's stages are the dense output's extra stages), weights ``B``, error
    weights ``E`` (and ``E3`` for DOP853), dense-output rows ``D``, the number of stages of
    a step (the last of them being ``f(t + h, y_new)``), the error estimator's order."""

    def __init__(self, kind, A, B, C, E, E3, D, stages, order):
        self.kind, self.A, self.B, self.C, self.E, self.E3, self.D = kind, A, B, C, E, E3, D
        self.stages, self.order = stages, order

    def arrays(self):
        return self.kind, self.A, self.B, self.C, self.E, self.E3, self.D


TABLEAUS = {
    "RK45": Tableau(RK45, _DP5_A, _DP5_B, _DP5_C, _DP5_E, np.zeros(7), _DP5_D, 7, 4),
    "DOP853": Tableau(DOP853, _DOP_A, _DOP_B, _DOP_C, _DOP_E5, _DOP_E3, _DOP_D, 13, 7),
}


@njit(**UNCOUNTED)
def stage(t, y, ops, consts, starts, stack, dv, nq, slots, free_q, free_u, drive_q, drive_u,
          tree, body, loads, ws, ydot, nfev):
    """The right-hand side at time ``t`` (drives evaluated there) and state ``y``: every
    stage of ``rk_stretch`` and of ``dense_step``, and, called from Python with the same
    argument types (so compiled once for both), a run's first derivatives
    (``integrate.compiled_adaptive``).  A function of its own, not inlined into each
    stage's place: numba compiled the right-hand side five times over in ``rk_stretch``
    (13 s of its first run instead of 8), and the call costs nothing measurable."""
    if dv.shape[0]:
        drive_values(ops, consts, starts, t, stack, dv)
    return state_rate(y, dv, nq, slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
                      ydot, nfev)


@njit(cache=True, inline="always")
def _failed(t, y, fail):
    """``fail = [t, y]``: a failing stage's time and state (element by element: an array
    assignment makes numba compile its shape-mismatch message, seconds of a first run)."""
    fail[0] = t
    for i in range(y.shape[0]):
        fail[1 + i] = y[i]


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
        st = stage(t_old + C[s] * h, tmp, ops, consts, starts, stack, dv, nq, slots, free_q,
                    free_u, drive_q, drive_u, tree, body, loads, ws, K[s], nfev)
        if st:
            _failed(t_old + C[s] * h, tmp, fail)
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


def stretch_scratch(A, D, n, drives):
    """The scratch of one ``rk_stretch`` call (a state of ``n`` entries, ``drives``
    driven coordinates; ``A``, ``D``: the tableau's): the stages ``K``, the new state, a
    stage's state, the dense polynomial's rows, the programs' stack and the drives'
    values.  Allocated by the caller: ``rk_stretch`` is compiled without reference
    counting."""
    return (np.empty((A.shape[0], n)), np.empty(n), np.empty(n), np.empty((3 + D.shape[0], n)),
            np.empty(STACK), np.empty((drives, 3)))


@njit(**UNCOUNTED)
def rk_stretch(kind, A, B, C, E, E3, D, t, t_end, y, f, h_abs, rtol, atol, max_step,
               max_accept, t_eval, i_eval, samples, ops, consts, starts, nq, slots, quats,
               free_q, free_u, drive_q, drive_u, tree, body, loads, ws, out_t, out_y, out_h,
               out_nfev, out_ieval, out_K, fail, nfev, events, work):
    """Up to ``max_accept`` accepted steps from ``(t, y)`` (``f`` its derivative, ``h_abs``
    the proposed step) towards ``t_end``.  Accepted step ``k``: ``out_t[k]``,
    ``out_y[k]``, its size ``out_h[k]``, the evaluations so far ``out_nfev[k]``, the
    samples so far ``out_ieval[k]``; its stages in ``out_K[k]`` when ``out_K`` has rows
    (the last row when it has fewer: ``out_K`` of one row keeps the last step's stages).
    Output times ``t_eval[i_eval:]`` passed are sampled on the dense output into
    ``samples``.  ``y``, ``f`` end as the last accepted state and its derivative.
    ``events``: the event conditions (``kernels.events``), checked after every step; the
    stretch ends early after a step where one crossed zero or is not finite.  ``work``:
    ``stretch_scratch(A, D, y.size, drive_q.size)`` (the kernel allocates nothing and
    counts no references: about a second less to compile).
    On failure ``fail`` holds the stage's time, then its state.  Returns
    ``(accepted, status, h_abs, i_eval)``.  A tree's ``quats`` are not projected (the drift
    is reported, as with scipy's solvers); a closed mechanism's state is projected onto its
    constraints after every accepted step (``integrators.finish_step``), and its
    derivative evaluated again there."""
    # long: one compiled loop over accepted steps (stages, error norm, step control, dense
    # output, events): split into helpers numba must inline, it compiled 4 s longer cold on
    # the 2-core machine for no speed (measured for issue 23), and not inlined it pays a call
    # per stage.
    n = y.shape[0]
    stages = B.shape[0] + 1
    K, y_new, tmp, F, stack, dv = work
    keep_stages = out_K.shape[0]
    check_events = events[3].shape[0] > 0
    exponent = -1.0 / (5.0 if kind == RK45 else 8.0)
    constrained = closed(loads)    # a closed mechanism (routes)
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
                st = stage(t + C[s] * h, tmp, ops, consts, starts, stack, dv, nq, slots,
                            free_q, free_u, drive_q, drive_u, tree, body, loads, ws, K[s],
                            nfev)
                if st:
                    _failed(t + C[s] * h, tmp, fail)
                    return accepted, st, h_abs, i_eval
            for i in range(n):
                acc = 0.0
                for j in range(stages - 1):
                    acc += B[j] * K[j, i]
                y_new[i] = y[i] + h * acc
            st = stage(t_new, y_new, ops, consts, starts, stack, dv, nq, slots, free_q,
                        free_u, drive_q, drive_u, tree, body, loads, ws, K[stages - 1], nfev)
            if st:
                _failed(t_new, y_new, fail)
                return accepted, st, h_abs, i_eval
            # error norm
            if kind == RK45:
                total = 0.0
                for i in range(n):
                    scale = atol + max(abs(y[i]), abs(y_new[i])) * rtol
                    acc = 0.0
                    for j in range(stages):
                        acc += E[j] * K[j, i]
                    e = h * acc / scale
                    total += e * e
                norm = np.sqrt(total / n)
            else:
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
                    norm = 0.0
                else:
                    norm = h_abs * e5 / np.sqrt((e5 + 0.01 * e3) * n)
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
        if constrained:      # a closed mechanism: back onto the constraint manifold
            if dv.shape[0]:
                drive_values(ops, consts, starts, t_new, stack, dv)
            st = finish_step(y_new, dv, nq, slots, quats, free_q, free_u, drive_q, drive_u,
                             tree, loads, ws)
            if st == 0:
                st = stage(t_new, y_new, ops, consts, starts, stack, dv, nq, slots, free_q,
                            free_u, drive_q, drive_u, tree, body, loads, ws, K[stages - 1],
                            nfev)
            if st:
                _failed(t_new, y_new, fail)
                return accepted, st, h_abs, i_eval
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
        for i in range(n):
            out_y[accepted, i] = y[i]
        out_h[accepted] = h
        out_nfev[accepted] = nfev[0]
        out_ieval[accepted] = i_eval
        accepted += 1
        if check_events and step_ends_stretch(events, t, y, accepted - 1):
            break
    return accepted, 0, h_abs, i_eval


@njit(**CACHED)
def dense_step(A, C, D, stages, t_old, y_old, y_new, h, K_step, ops, consts, starts, nq,
               slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws, nfev):
    """The dense polynomial ``F`` of one accepted step from its stages ``K_step``
    (``out_K[k]`` of ``rk_stretch``); returns ``(F, status)``."""
    n = y_old.shape[0]
    K = np.zeros((A.shape[0], n))
    for s in range(stages):
        for i in range(n):
            K[s, i] = K_step[s, i]
    F = np.empty((3 + D.shape[0], n))
    tmp = np.empty(n)
    fail = np.empty(n + 1)
    st = _dense_coefficients(A, C, D, stages, t_old, y_old, y_new, h, K, F, tmp, ops, consts,
                             starts, np.empty(STACK), np.empty((drive_q.shape[0], 3)), nq,
                             slots, free_q, free_u, drive_q, drive_u, tree, body, loads, ws,
                             fail, nfev)
    return F, st

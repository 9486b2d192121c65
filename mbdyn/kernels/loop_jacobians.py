"""The Jacobians of the frames the loop joints join, for the routes whose kinematics skip
the full Jacobians (the articulated-body layout): ``G``'s rows read them
(``kernels.constraints``).
"""
from numba import njit

from .joints import NU


@njit(cache=True, inline="always")
def jacobian_of(i, parent, kind, ucol, r, S, JR, JT):
    """``JR[i]``, ``JT[i]`` (3 x nu, world axes): frame ``i``'s angular velocity and its
    origin's velocity per free speed, from each ancestor joint's motion subspace ``S[k]``
    (its frame's angular and origin velocity per unit speed) moved to ``O_i``."""
    for a_ in range(3):
        for col in range(JR.shape[2]):
            JR[i, a_, col] = 0.0
            JT[i, a_, col] = 0.0
    k = i
    while k >= 0:
        if ucol[k] >= 0:
            d0, d1, d2 = r[i, 0] - r[k, 0], r[i, 1] - r[k, 1], r[i, 2] - r[k, 2]
            for j in range(NU[kind[k]]):
                col = ucol[k] + j
                w0, w1, w2 = S[k, 0, j], S[k, 1, j], S[k, 2, j]
                JR[i, 0, col], JR[i, 1, col], JR[i, 2, col] = w0, w1, w2
                JT[i, 0, col] = S[k, 3, j] + w1 * d2 - w2 * d1
                JT[i, 1, col] = S[k, 4, j] + w2 * d0 - w0 * d2
                JT[i, 2, col] = S[k, 5, j] + w0 * d1 - w1 * d0
        k = parent[k]


@njit(cache=True, inline="always")
def constrained_jacobians(con_int, parent, kind, ucol, r, S, JR, JT):
    """``jacobian_of`` every frame the primitives ``con_int`` join (after kinematics that
    skipped the full Jacobians: the articulated-body layout), once each (a loop joint's
    primitives join the same two frames)."""
    for k in range(con_int.shape[0]):
        for side in (1, 2):
            f = con_int[k, side]
            if f < 0:
                continue
            done = False
            for j in range(k + 1):
                if (con_int[j, 1] == f and (j < k or side == 2)) or (
                        con_int[j, 2] == f and j < k):
                    done = True
                    break
            if not done:
                jacobian_of(f, parent, kind, ucol, r, S, JR, JT)

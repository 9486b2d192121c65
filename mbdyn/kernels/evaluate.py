"""One-call evaluations of the equations of motion (kinematics + loads + formulation + solve).

Fusing the steps into one compiled call keeps the Python overhead of a right-hand side to a
single dispatch.  The arguments are the compiled model's static arrays (``tree``, ``body``),
the joint-space state with drives filled in, the load values and a workspace.
"""
import numpy as np
from numba import njit

from .dynamics import applied_loads, cholesky_solve, jourdain, newton_euler_system
from .kinematics import forward_kinematics


@njit(cache=True)
def kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                         mass, com, gravity, qfull, ufull, udfull,
                         load_body, load_point, load_force, load_moment, load_in_body,
                         R, r, w, v, alpha, a, JR, JT, F, N):
    forward_kinematics(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                       qfull, ufull, udfull, R, r, w, v, alpha, a, JR, JT)
    applied_loads(mass, com, gravity, R, r, load_body, load_point, load_force, load_moment,
                  load_in_body, F, N)


@njit(cache=True)
def jourdain_accelerations(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                           mass, com, inertia, has_inertia, gravity, qfull, ufull, udfull,
                           load_body, load_point, load_force, load_moment, load_in_body,
                           R, r, w, v, alpha, a, JR, JT, F, N, M, f, L, ud):
    """Kinematics, loads, ``M`` and ``f``, then ``ud = M^-1 f`` by Cholesky.

    Returns -1 on success, the index of the speed where the Cholesky factorisation broke
    down, or -2 when ``ud`` holds NaN or Inf.
    """
    kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                         mass, com, gravity, qfull, ufull, udfull,
                         load_body, load_point, load_force, load_moment, load_in_body,
                         R, r, w, v, alpha, a, JR, JT, F, N)
    jourdain(mass, com, inertia, has_inertia, R, r, w, alpha, a, JR, JT, anc_ptr, anc_idx,
             parent, F, N, M, f)
    pivot = cholesky_solve(M, f, L, ud)
    if pivot >= 0:
        return pivot
    for k in range(ud.shape[0]):
        if not np.isfinite(ud[k]):
            return -2
    return -1


@njit(cache=True)
def newton_euler_solution(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                          mass, com, inertia, gravity, qfull, ufull, udfull,
                          load_body, load_point, load_force, load_moment, load_in_body,
                          react_joint, react_force, react_moment,
                          R, r, w, v, alpha, a, JR, JT, F, N, A, b):
    """Kinematics, loads, the Newton-Euler system with reactions, solved by LU.

    Returns the unknowns ``x = [ud, lambda]`` (a new array).
    """
    kinematics_and_loads(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr, anc_idx,
                         mass, com, gravity, qfull, ufull, udfull,
                         load_body, load_point, load_force, load_moment, load_in_body,
                         R, r, w, v, alpha, a, JR, JT, F, N)
    newton_euler_system(mass, com, inertia, parent, R, r, w, alpha, a, JR, JT, anc_ptr, anc_idx,
                        F, N, react_joint, react_force, react_moment, A, b)
    return np.linalg.solve(A, b)

"""What is wrong where a model is singular or nearly so: the degrees of freedom that carry
no inertia (a singular mass matrix, named), the conditioning of ``M(q)``, and the distance
of Euler-angle joints from their singular configuration.
"""
from __future__ import annotations


import numpy as np

from ..errors import NonFiniteError, SingularMassMatrixError


#: above this many free speeds the mass matrix's condition number is not computed
CONDITION_SPEEDS = 1000


def raise_singular(model, q, t, pivot):
    if pivot is not None and model.nu > CONDITION_SPEEDS:
        _raise_at_pivot(model, q, t, pivot)
    model._jourdain_terms(q, np.zeros(model.nu), t)   # M at q (whatever route failed)
    M = model._M
    if not np.all(np.isfinite(M)):   # a NaN pivot: the input, not the inertia
        model._require_finite(q, model._ufull[model._free_u] if model._time_inputs else
                             model._ufull, t)
        model._check_finite(q, np.zeros(model.nu), t, M.reshape(-1), "the mass matrix",
                           names=[f"M[{i},{j}]" for i in range(model.nu)
                                  for j in range(model.nu)])
    eigval, eigvec = np.linalg.eigh(0.5 * (M + M.T))
    scale = max(abs(eigval).max(), 1e-300)
    null = eigvec[:, eigval <= 1e-12 * scale]
    if null.size:
        weight = np.abs(null).max(axis=1)
        names = [s for s, wgt in zip(model.speeds, weight) if wgt > 0.1]
    else:
        names = [model.speeds[pivot]] if pivot is not None else []
    raise SingularMassMatrixError(
        f"model {model.name!r}, t={t:.6g}: the mass matrix is not positive definite; "
        f"the degrees of freedom {model.describe_speeds(names)} carry no inertia here "
        "(smallest eigenvalue {:.3g}, largest {:.3g}).  Give the bodies they move mass "
        "or inertia, or, for a configuration singularity such as Euler angles at "
        "sin(theta)=0, use a spherical (quaternion) joint.".format(eigval[0], eigval[-1]),
        names)


def _raise_at_pivot(model, q, t, pivot):
    """``raise_singular`` above ``CONDITION_SPEEDS`` free speeds: the degree of freedom
    where the elimination broke down is named without ``M``, whose nu x nu floats and
    O(nu^3) eigenvalues the O(n) routes never need (1.6 GB and minutes at 10,000 speeds)."""
    model._require_finite(q, model._ufull[model._free_u] if model._time_inputs else
                          model._ufull, t)
    names = [model.speeds[pivot]]
    raise SingularMassMatrixError(
        f"model {model.name!r}, t={t:.6g}: the mass matrix is not positive definite; "
        f"the degrees of freedom {model.describe_speeds(names)} carry no inertia here "
        f"(found where the elimination broke down; above {CONDITION_SPEEDS} speeds the "
        "eigenvalues of M, which would name every such degree of freedom, are not "
        "computed).  Give the bodies they move mass or inertia, or, for a configuration "
        "singularity such as Euler angles at sin(theta)=0, use a spherical (quaternion) "
        "joint.", names)


def mass_matrix_condition(model, q, t=0.0):
    """2-norm condition number of ``M(q)`` (inf when singular) and the speeds that
    dominate its weakest direction: ``(condition, [speed names])``; ``(None, [])`` above
    ``CONDITION_SPEEDS`` free speeds, where the eigenvalues would cost O(n^3) (about a
    minute at 5,000 speeds, and more than the run)."""
    if model.nu == 0:
        return 1.0, []
    if model.nu > CONDITION_SPEEDS:
        return None, []
    try:
        M = model._mass_matrix(q, t, model._jourdain_terms)
    except NonFiniteError:
        return float("inf"), []
    ev, vec = np.linalg.eigh(M)
    weak = [s for s, x in zip(model.speeds, np.abs(vec[:, 0])) if x > 0.3]
    cond = float(ev[-1] / ev[0]) if ev[0] > 0 else float("inf")
    return cond, weak


def euler_singularity(model, q):
    """Distance of every Euler-angle joint from its singular configuration:
    ``{joint: |sin(q1)|}`` for proper sequences (``ZXZ``...), ``|cos(q1)|`` for
    Tait-Bryan ones (``XYZ``...).  At 0 the angle rates are undefined."""
    out = {}
    for name, k, proper in model._euler_middle:
        out[name] = abs(np.sin(q[k])) if proper else abs(np.cos(q[k]))
    return out

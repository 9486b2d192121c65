"""Closed loops through flexible bodies, in Python (numpy): the constraint rows, the
constrained forward dynamics and the projection onto the constraints.

A loop joint at a point of a flexible body acts at that point's node frame
(``elements.flexible_nodes``), a frame of the tree, so the tree's kernels give its rows
over the tree's speeds exactly: ``phi``, ``psi = G_x u_x`` (plus the drives' part), ``G_x``
and ``gamma_x`` (``kernels.constraints``).  With ``u_x = P u`` and ``u_x' = P u'``
(``compiled.flexible_states``; ``P`` constant) the model's rows are ``G = G_x P`` and
``gamma = gamma_x``.  The accelerations solve

    A u' = f + G^T lam,     G u' = gamma

(``A``, ``f``: ``flexible_dynamics.terms``).  The rank of ``G`` is decided by its singular
values, as for rigid mechanisms (``RANK_TOLERANCE``; during a run at most the rank held
at its start, and a direction weaker than ``PASSAGE_TOLERANCE`` of the strongest is left
to the projection): with ``G = U S V^T`` and the ``r`` kept directions
``G_r = S_r V_r^T``, ``gamma_r = U_r^T gamma``, the system ``[[A, -G_r^T], [G_r, 0]]``
gives ``u'`` and ``mu``, and ``lam = U_r mu`` is the minimum-norm multiplier vector that
produces them.  The multipliers are the primitives' reactions as on rigid mechanisms.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, NonFiniteError, SingularMassMatrixError
from ..kernels.constrained import PROJECTION_ITERATIONS, PROJECTION_TOLERANCE
from ..kernels.loop_solve import PASSAGE_TOLERANCE, RANK_TOLERANCE
from .constrained import positions_not_closed, speeds_not_closed
from .flexible_dynamics import split, terms

#: a projection whose residual stops falling (by half a Newton step) below this is done:
#: what is left is the mode shapes' round-off (a planar beam's out-of-plane entries,
#: 1e-11 of the largest), which makes redundant rows (a revolute's tilt and the point's
#: out-of-plane row) disagree by ~1e-13, so that no state zeroes both
STALLED = 1e-10

def constraint_terms(model, q, u, t=0.0):
    """``(phi, psi, G, gamma)`` of the loop joints at the model's state (new arrays)."""
    qx, ux = model._extended(*split(model, q, u))
    tree = model.tree
    phi, psi = tree.constraint_residuals(qx[:tree.nq], ux[:tree.nu], t)
    Gx, gamma = tree._con[4], tree._con[5].copy()
    if model._map is None:
        G = np.zeros((Gx.shape[0], model.nu))
        G[:, :tree.nu] = Gx
    else:
        G = Gx @ model._map.P[:tree.nu]
    return phi, psi, G, gamma


def constraint_residuals(model, q, u=None, t=0.0):
    """``(phi, psi)``: the loop constraints' position residuals and their rates."""
    _require_loops(model)
    return constraint_terms(model, q, np.zeros(model.nu) if u is None else u, t)[:2]


def constraint_jacobian(model, q, t=0.0):
    """``G`` (constraint rows x the model's speeds, the modal rates among them)."""
    _require_loops(model)
    return constraint_terms(model, q, np.zeros(model.nu), t)[2]


def _kept(G, model):
    """``(U_r, s_r, Vt_r, ratio)``: the directions of ``G`` kept (module docstring) and
    the weakest kept singular value over the largest."""
    U, s, Vt = np.linalg.svd(G, full_matrices=False)
    if not s.size or s[0] == 0.0:
        return U[:, :0], s[:0], Vt[:0], 1.0
    r = int(np.count_nonzero(s > RANK_TOLERANCE * s[0]))
    held = int(model._con[7][2])
    if held >= 0:                                # a run: its rank, no weak passage
        r = min(r, held, int(np.count_nonzero(s > PASSAGE_TOLERANCE * s[0])))
    return U[:, :r], s[:r], Vt[:r], float(s[r - 1] / s[0]) if r else 1.0


def constrained_accelerations(model, q, u, t=0.0):
    """``(u', lam)`` of the closed mechanism at the state (module docstring)."""
    q, u = split(model, q, u)
    M, f, A = terms(model, q, u, t)
    _, _, G, gamma = constraint_terms(model, q, u, t)
    Ur, sr, Vtr, _ = _kept(G, model)
    r, nu = sr.size, model.nu
    Gr = sr[:, None] * Vtr
    K = np.zeros((nu + r, nu + r))
    K[:nu, :nu], K[:nu, nu:], K[nu:, :nu] = A, -Gr.T, Gr
    rhs = np.concatenate([f, Ur.T @ gamma])
    if not np.all(np.isfinite(K)) or not np.all(np.isfinite(rhs)):
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the equations of motion "
                             "came out non-finite (check the state, masses and stiffness)")
    try:
        x = np.linalg.solve(K, rhs)
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(
            f"model {model.name!r}, t={t:.6g}: the mass matrix is singular on the "
            "motions the loop constraints allow", []) from None
    return x[:nu], Ur @ x[nu:]


def multipliers(model, q, u, t=0.0):
    """``(u', lam)``: the accelerations and the minimum-norm multipliers."""
    _require_loops(model)
    return constrained_accelerations(model, q, u, t)


def _min_norm(G, rhs, model):
    """The minimum-norm ``x`` with ``G x = rhs`` over the kept directions of ``G``."""
    Ur, sr, Vtr, _ = _kept(G, model)
    return Vtr.T @ ((Ur.T @ rhs) / sr)


def project(model, q, u, t=0.0):
    """``(q, u)`` moved onto the constraints: Newton-Raphson on the positions with
    minimum-norm steps ``du = G^+ phi`` applied through ``q' = N(q) u`` (until every
    residual is below ``PROJECTION_TOLERANCE``, or stalls below ``STALLED``), then
    ``u -= G^+ psi``; a run's lowest rank and conditioning are kept as the compiled
    projection keeps them."""
    _require_loops(model)
    q, u = (np.array(x, dtype=float) for x in split(model, q, u))
    zero = np.zeros(model.nu)
    before = np.inf
    for _ in range(PROJECTION_ITERATIONS + 1):
        phi, _, G, _ = constraint_terms(model, q, zero, t)
        size = np.abs(phi).max(initial=0.0)
        if size <= PROJECTION_TOLERANCE or (size <= STALLED and size > 0.5 * before):
            break
        before = size
        q -= model.coordinate_rates(q, _min_norm(G, phi, model))
        model.normalize_quaternions(q)
    if size > max(PROJECTION_TOLERANCE, STALLED):
        raise positions_not_closed(model, t, phi)
    psi = constraint_terms(model, q, u, t)[1]
    u -= _min_norm(G, psi, model)
    psi = constraint_terms(model, q, u, t)[1]
    if np.abs(psi).max(initial=0.0) > 1e-8 * (1.0 + float(np.abs(u).max(initial=0.0))):
        raise speeds_not_closed(model, t, psi)
    info = model._con[7]
    if info[2] >= 0:                            # a run: the lowest rank met at its steps
        _, s, _, ratio = _kept(G, model)
        info[3] = min(info[3], s.size)
        info[4] = min(info[4], ratio)
    return q, u


def _require_loops(model):
    if not model.has_loops:
        raise ModelError(f"model {model.name!r} has no loop joints (no constraints)")

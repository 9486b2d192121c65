"""Closed loops from Python: the constraint residuals and Jacobian at a state, the
constrained forward dynamics (``kernels.constrained``), the multipliers, the projection
onto the constraint manifold, the rank of the constraints and the mobility.

Conventions (``kernels.constraints``): ``phi(q) = 0`` holds on the mechanism, its rate is
``psi = G u`` (plus the drives' part), and the accelerations satisfy ``G u' = gamma``.
The multipliers ``lam`` are the reactions in the primitives' terms: a point's force, a
perpendicularity's moment, as the parent exerts them on the child.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, SimulationError
from ..kernels import constrained as kc
from ..kernels import flexible_entry as kfe
from ..kernels import loop_articulated as kla
from ..kernels import route_entry as kre
from ..kernels.loop_solve import RANK_TOLERANCE
from .inputs import fits, freeze, plain
# LOOP_ARTICULATED_FROM: documented here (docs/api.md); the route's choice lives in route_hook
from .route_hook import LOOP_ARTICULATED_FROM, loop_route, model_quats, python_hook  # noqa: F401


def groups(model):
    """The kernels' argument groups of a loop model's workspace."""
    body = (model._mass, model._com, model._inertia, model._has_inertia, model.gravity)
    state = (model._qfull, model._ufull, model._udfull)
    jourdain = (model._M, model._f, model._L, model._ud)
    return model._tree, body, state, model._loads_arrays, model._kin_out, jourdain


def _evaluate(model, q, u, t):
    """The kinematics and the constraint rows at ``(q, u, t)``: ``phi, psi, G, gamma``
    left in the model's constraint workspace."""
    q, u = model._fill(q, u, t)
    tree, _, state, _, motion, _ = groups(model)
    try:
        kc.constraint_state(tree, state, motion, model._con, model._scratch)
    except ZeroDivisionError:
        raise model._division_by_zero(q, t) from None
    return q, u


def constraint_residuals(model, q, u=None, t=0.0):
    """``(phi, psi)``: the position residuals of the loop constraints and their rates
    (each row labelled by ``Model.constraint_rows``); zero on the mechanism."""
    _require_loops(model)
    _evaluate(model, q, np.zeros(model.nu) if u is None else u, t)
    return model._con[2].copy(), model._con[3].copy()


def constraint_jacobian(model, q, t=0.0):
    """``G`` (constraint rows x free speeds): ``d phi / dt = G u`` (plus the drives')."""
    _require_loops(model)
    _evaluate(model, q, np.zeros(model.nu), t)
    return model._con[4].copy()


def constraint_rank(model, q, t=0.0):
    """``(rank, smallest kept singular value / largest)`` of ``G`` at ``q``: rows above
    ``RANK_TOLERANCE`` of the largest singular value count (docs/constraints.md)."""
    G = model.constraint_jacobian(q, t)
    if not G.size:
        return 0, 1.0
    sv = np.linalg.svd(G, compute_uv=False)
    kept = sv[sv > RANK_TOLERANCE * sv[0]] if sv[0] > 0 else sv[:0]
    return int(kept.size), float(kept[-1] / sv[0]) if kept.size else 1.0


def mobility(model, q, t=0.0):
    """Degrees of freedom the mechanism has at ``q``: free speeds minus the rank of the
    constraints (Grübler's count is ``nu - rows``; redundant rows make the difference)."""
    if model._con is None:
        return model.nu
    return model.nu - model.constraint_rank(q, t)[0]


def constrained_accelerations(model, q, u, t=0.0, route="jourdain"):
    """``u'`` of the closed mechanism, ``M u' = f + G^T lam``, ``G u' = gamma``: by the
    mass matrix (``route="jourdain"``; the minimum-norm multipliers stay in the
    workspace, ``multipliers``) or by the articulated-body algorithm (``"articulated"``,
    O(n) per independent constraint row, multipliers a basic solution; near a singular
    configuration it hands over to the mass matrix).  One compiled call on the packed
    arrays: float64 arrays as they come, anything else converted and checked first.
    After a call that succeeded, a model without inputs written in Python calls the
    kernel's compiled entry from then on (``fast_call``), with no dispatch: for arrays that
    pass ``inputs.fits``; the kernel checks their sizes."""
    kernel = (kla.constrained_articulated_packed if route == "articulated"
              else kc.constrained_accelerations_packed)
    packed = (*model._dynamics_full, *model._con_packed)    # (fb, ib, forces, con_int, cf)
    status = None
    if not model._python_inputs and plain(q, model.nq) and plain(u, model.nu):
        try:
            status = kernel(*packed, q, u)
        except ZeroDivisionError:
            pass
    if status is None:                           # convert, check, say what is wrong
        q, u = model._fill(q, u, t)
        q, u = np.require(q, float, "CW"), np.require(u, float, "CW")  # one compiled type
        try:
            status = kernel(*packed, q, u)
        except ZeroDivisionError:
            raise model._division_by_zero(q, t) from None
    if status == kla.DEPENDENT_ROWS:             # dependent rows: decided with M
        return constrained_accelerations(model, q, u, t)
    _check_status(model, q, u, t, status, model._ud)
    if status == -1 and not model._python_inputs:
        freeze(model, ("closed", route), kernel, packed, (q, u), model._ud)
    return model._ud.copy()


def fast_call(model, q, u, route):
    """``u'`` by the compiled entry of a closed mechanism's ``route`` (``freeze``), or
    ``None`` when there is none yet, the input is not float64 arrays that fit, or the
    call did not succeed (the caller then takes the checked route)."""
    call = model._fast_calls.get(("closed", route))
    if call is None or not (fits(q) and fits(u)):    # no dispatch: inputs.freeze
        return None
    kernel, fb, ib, forces, con_int, cf, ud = call
    try:
        if kernel(fb, ib, forces, con_int, cf, q, u) == -1:
            return ud.copy()
    except ZeroDivisionError:
        pass
    return None


def multipliers(model, q, u, t=0.0):
    """``(u', lam)``: the accelerations and the minimum-norm multipliers, by the mass
    matrix.  Where that is the mechanism's own route (fewer than
    ``LOOP_ARTICULATED_FROM`` free speeds), by its function (``algorithms.route_hook``):
    the reactions and drive efforts of a run's outputs take the code the run compiled,
    with the full Jacobians, not an entry of their own."""
    if loop_route(model, "auto") != "jourdain":
        ud = constrained_accelerations(model, q, u, t)
        return ud, model._con[6].copy()
    model._full_workspace()
    q, u = model._fill(q, u, t)
    ud = np.empty(model.nu)
    try:
        status = kfe.call(python_hook(model), ud, kre.ACCEL)
    except ZeroDivisionError:
        raise model._division_by_zero(q, t) from None
    _check_status(model, q, u, t, status, ud)
    return ud, model._con[6].copy()


def _check_status(model, q, u, t, status, ud):
    """Raise what a closed mechanism's accelerations kernel returned, if it failed: a
    speed's column where the constrained mass matrix is singular, -2 for a non-finite
    ``ud``; return on success (-1)."""
    if status >= 0:
        model._raise_singular(q, t, status)
    if status == -2:
        model._check_finite(q, u, t, ud, "the accelerations")


def project(model, q, u, t=0.0):
    """``(q, u)`` moved onto the constraint manifold (Newton-Raphson on positions with
    minimum-norm steps, then the velocities); raises ``SimulationError`` when the
    positions do not converge (the mechanism cannot close there)."""
    _require_loops(model)
    q, u = model._fill(q, u, t)
    y = np.concatenate([q, u])
    tree, _, state, _, motion, _ = groups(model)
    # the entry the route's function calls, compiled once for both (the same types)
    steps = kc.project_state_call(y, model.nq, model._slots, model_quats(model),
                                  model._free_q, model._free_u, tree, state, motion,
                                  model._con, model._scratch)
    if steps < 0:
        raise positions_not_closed(model, t, model._con[2])
    q, u = y[:model.nq].copy(), y[model.nq:].copy()
    _evaluate(model, q, u, t)
    psi = model._con[3]
    scale = 1.0 + float(np.abs(y[model.nq:]).max(initial=0.0))
    if np.abs(psi).max(initial=0.0) > 1e-8 * scale:
        raise speeds_not_closed(model, t, psi)
    return q, u


def positions_not_closed(model, t, phi):
    """The error of a projection whose Newton-Raphson left the residuals ``phi``."""
    k = int(np.argmax(np.abs(phi)))
    return SimulationError(f"model {model.name!r}, t={t:.6g}: the loops cannot be closed "
                           f"near this state (constraint {model.constraint_rows[k]} "
                           f"residual {phi[k]:.3g} after {kc.PROJECTION_ITERATIONS} Newton "
                           "steps)")


def speeds_not_closed(model, t, psi):
    """The error of a projection whose speeds keep the constraint rates ``psi``."""
    k = int(np.argmax(np.abs(psi)))
    return SimulationError(f"model {model.name!r}, t={t:.6g}: the speeds cannot satisfy the "
                           f"loop joint {model._row_joint[k]!r} (its constraint "
                           f"{model.constraint_rows[k]} moves at {psi[k]:.3g} per second "
                           "whatever the free speeds): the drives move it against its "
                           "constraint -- drive fewer joints of the loop")


def _require_loops(model):
    if model._con is None:
        raise ModelError(f"model {model.name!r} has no loop joints (no constraints)")

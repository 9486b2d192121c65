"""Assembly of a closed mechanism: the coordinates and speeds that close its loops, given
the values the user holds.

Newton-Raphson on the positions: ``phi(q) = 0`` with the held coordinates fixed, each
step the minimum-norm ``du = -G_free^+ phi`` over the speeds that are not held, applied
through ``q' = N(q) u`` (with step halving while the residual grows).  Then the speeds
from the velocity equations ``G u = -(drives' part)``, the held speeds fixed: linear, one
least-squares solve.  The starting values (``guess``) choose the branch: a four-bar
closes in two ways at each crank angle.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..kernels.constrained import PROJECTION_TOLERANCE
from ..kernels.loop_solve import RANK_TOLERANCE

#: Newton steps at most before the assembly is declared impossible
ASSEMBLY_ITERATIONS = 60
#: a residual above this after the iterations is an error (metres, or dimensionless)
ASSEMBLY_TOLERANCE = 1e-10


def held_speeds(model, held_coordinates):
    """Speed indices whose coordinate is held: a 1-DoF or Euler coordinate holds its own
    rate, a quaternion coordinate its joint's rotation, a free joint's x, y, z its
    velocity components, a flexible body's modal coordinate its rate."""
    names, rates = _modal_pairs(model)
    held = {model.speed_index(r) for c, r in zip(names, rates) if c in held_coordinates}
    for code, q0, nq, u0, nu in model._free_joint_slots:
        for k in range(nq):
            if model.coordinates[q0 + k] not in held_coordinates:
                continue
            if nq == nu:
                held.add(u0 + k)
            elif nq == 4:                      # spherical
                held.update(range(u0, u0 + 3))
            elif k < 3:                        # free joint: position
                held.add(u0 + k)
            else:                              # free joint: quaternion
                held.update(range(u0 + 3, u0 + 6))
    return sorted(held)


def assemble(model, initial=None, initial_speeds=None, guess=None, t=0.0):
    """``(q, u)`` that close every loop: ``initial`` (``{coordinate: value}``) and
    ``initial_speeds`` (``{speed: value}``; a 1-DoF coordinate's name stands for its rate)
    are held; the other coordinates start from ``guess`` (``{coordinate: value}``, else
    zero) and are solved for.  A flexible body's modal coordinates and rates are held
    too (at the values given, else zero) unless the coordinate is in ``guess``.  Raises
    ``ModelError`` naming the loop joint and its residual when the loops cannot be
    closed with the values held."""
    initial, initial_speeds, guess = dict(initial or {}), dict(initial_speeds or {}), \
        dict(guess or {})
    both = sorted(set(initial) & set(guess))
    if both:
        raise ModelError(f"model {model.name!r}: {', '.join(both)} given both as initial "
                         "values (held) and as guesses; give each once")
    q = model.q_vector({**guess, **initial})
    u = model.u_vector(initial_speeds)
    model.normalize_quaternions(q)
    if model._con is None:
        return q, u
    # a flexible body's modal coordinates are held (at their values given, else 0) unless
    # guessed: closing a loop by deflecting a body, stiffness unseen, is no assembly
    modal, rates = _modal_pairs(model)
    elastic = {c for c in modal if c not in guess}
    free = np.ones(model.nu, bool)
    free[held_speeds(model, set(initial) | elastic)] = False
    q = _close_positions(model, q, free, t)
    rate_names = dict(zip(*_rate_pairs(model)))
    held_u = {model.speed_index(rate_names.get(k, k)) for k in initial_speeds}
    held_u |= {model.speed_index(r) for c, r in zip(modal, rates) if c in elastic}
    free_u = np.ones(model.nu, bool)
    free_u[sorted(held_u)] = False
    u = _close_speeds(model, q, u, free_u, t)
    return q, u


def _modal_pairs(model):
    """The flexible bodies' modal coordinates and their rates (none on a rigid model)."""
    names = tuple(getattr(model, "modal_coordinates", ()))
    return names, tuple(model.speeds[model.nu - len(names):])


def _rate_pairs(model):
    names, rates = (list(x) for x in _modal_pairs(model))
    for j in model.elements[1]:
        if j.drive is None and j.kind in ("revolute", "prismatic", "euler"):
            names.extend(j.coordinates)
            rates.extend(j.speeds)
    return names, rates


def _close_positions(model, q, free, t):
    zero = np.zeros(model.nu)
    phi = model.constraint_residuals(q, zero, t)[0]
    size = np.abs(phi).max(initial=0.0)
    for _ in range(ASSEMBLY_ITERATIONS):
        if size <= PROJECTION_TOLERANCE:
            break
        G = model.constraint_jacobian(q, t)
        du = np.zeros(model.nu)
        du[free] = np.linalg.lstsq(G[:, free], phi, rcond=RANK_TOLERANCE)[0]
        step = 1.0
        while True:
            trial = q - step * model.coordinate_rates(q, du)
            model.normalize_quaternions(trial)
            trial_phi = model.constraint_residuals(trial, zero, t)[0]
            trial_size = np.abs(trial_phi).max()
            if trial_size < size or step < 1e-3:
                break
            step *= 0.5
        q, phi, size = trial, trial_phi, trial_size
    if size > ASSEMBLY_TOLERANCE:
        k = int(np.argmax(np.abs(phi)))
        joint = model._row_joint[k]
        raise ModelError(
            f"model {model.name!r}: the loop closed by joint {joint!r} cannot be assembled: "
            f"its constraint {model.constraint_rows[k]} keeps a residual of {phi[k]:.3g} "
            f"(after {ASSEMBLY_ITERATIONS} Newton steps).  The values held in [initial] may "
            "not fit the loop (e.g. a four-bar that fails Grashof's condition cannot reach "
            "that crank angle), or the guess is too far: give [guess] values near the "
            "configuration you mean")
    return q


def _close_speeds(model, q, u, free, t):
    psi = model.constraint_residuals(q, u, t)[1]
    if np.abs(psi).max(initial=0.0) > 0.0 and free.any():
        G = model.constraint_jacobian(q, t)
        du = np.zeros(model.nu)
        du[free] = np.linalg.lstsq(G[:, free], psi, rcond=RANK_TOLERANCE)[0]
        u = u - du
        psi = model.constraint_residuals(q, u, t)[1]
    scale = 1.0 + np.abs(u).max(initial=0.0)
    if np.abs(psi).max(initial=0.0) > 1e-9 * scale:
        k = int(np.argmax(np.abs(psi)))
        raise ModelError(
            f"model {model.name!r}: the speeds held in [initial_speeds] do not fit the loop "
            f"closed by joint {model._row_joint[k]!r}: its constraint "
            f"{model.constraint_rows[k]} moves at {psi[k]:.3g} per second.  Hold fewer "
            "speeds (the mechanism has "
            f"{model.mobility(q, t)} degree(s) of freedom) and let the others be solved")
    return u

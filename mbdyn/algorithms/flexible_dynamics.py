"""The Jourdain form ``M u' = f`` of a tree with flexible bodies, in Python (numpy).

The model (``compiled.flexible_model.FlexibleModel``) holds the tree compiled with its
flexible bodies massless (``model.tree``) and, per flexible body, its invariants and
modal matrices (``model._flex``).  Its free speeds are the tree's, then each flexible
body's modal rates ``eta'``.  One evaluation:

1. the tree's kernels give ``M_t``, ``f_t`` without the flexible bodies, and every
   frame's rotation ``R``, Jacobians ``JT`` (origin) and ``JR``, and bias accelerations
   ``a_b``, ``alpha_b`` (the accelerations at ``u' = 0``, drives' included);
2. each flexible body's velocity ``w = (v_0, omega, eta')`` in body components is
   ``B u`` with ``B = [[R^T JT, 0], [R^T JR, 0], [0, I]]`` (its modal columns), and its
   equations (``mbdyn.flexible.invariants``) are
   ``M_b(eta) (B u' + [R^T a_b; R^T alpha_b; 0]) = Q``, with ``Q`` the quadratic velocity
   vector, gravity (``m g``, ``c(eta) x g``, ``C^T g`` in body components), the elastic
   and damping forces ``-K eta - D eta'`` and, with ``geometric_stiffening``, the axial
   force's stiffness ``-((omega_y^2 + omega_z^2) K_c + (a_x - g_x) K_a) eta``;
3. ``M = M_t + B^T M_b B``, ``f = f_t + B^T (Q - M_b [R^T a_b; R^T alpha_b; 0])``.  The
   part of ``a_x`` that depends on ``u'`` (``(R^T JT u')_x K_a eta``) is moved to the
   left: it makes the matrix solved non-symmetric, so ``u'`` comes from an LU solve;
   ``mass_matrix`` is the symmetric inertia alone.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, NonFiniteError, SingularMassMatrixError
from ..flexible.invariants import (cross3, floating_frame_mass_matrix,
                                   quadratic_velocity_vector)
from .flexible_forces import body_map, generalized_forces
from .flexible_forces import energies as _element_energies


def split(model, q, u):
    """``(q, u)`` as float arrays of the model's lengths, checked."""
    try:
        q, u = np.asarray(q, dtype=float), np.asarray(u, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"model {model.name!r}: q and u must be arrays of numbers "
                         f"(q: {model.nq} coordinates, u: {model.nu} speeds)") from None
    if q.shape != (model.nq,) or u.shape != (model.nu,):
        raise ModelError(f"model {model.name!r} expects q of length {model.nq} and u of "
                         f"length {model.nu}, got {q.shape} and {u.shape}")
    return q, u


def body_matrix(fb, eta):
    """The body's ``M_b(eta)`` ((6 + k) square): the invariants' with the modal mass as
    the reduced body gives it (reduced data's own ``M_ee``)."""
    Mb = floating_frame_mass_matrix(fb.invariants, eta)
    Mb[6:, 6:] = fb.mass
    return Mb


def body_forces(model, fb, eta, eta_dot, omega, a_b, Mb):
    """The body's generalized forces ``Q`` (6 + k) at the state, its frame's bias
    accelerations ``a_b = [a_0; alpha]`` (body components) moved to the right."""
    tree, inv = model.tree, fb.invariants
    Q = (quadratic_velocity_vector(inv, eta, eta_dot, omega)   # zero at omega = 0
         if tree.gyroscopic and omega.any() else np.zeros(6 + fb.n))
    g = tree._R[fb.frame].T @ tree.gravity
    Q[:3] += inv.mass * g
    Q[3:6] += cross3(inv.first_moment + inv.modal_first_moment @ eta, g)
    Q[6:] += inv.modal_first_moment.T @ g - fb.stiffness @ eta - fb.damping @ eta_dot
    if fb.spin:                     # a rotor's spin, its frame not spinning
        Q[6:] -= fb.spin * (fb.gyroscopic @ eta_dot)
    if model.stiffening:
        Kg = (omega[1] ** 2 + omega[2] ** 2) * fb.centrifugal + (a_b[0] - g[0]) * fb.axial
        Q[6:] -= Kg @ eta
    Q -= Mb[:, :6] @ a_b
    return Q


def terms(model, q, u, t=0.0):
    """``(M, f, A)`` at the state: the symmetric mass matrix ``M``, the forcing ``f`` and
    the matrix ``A`` that ``u'`` solves (``M`` plus the geometric stiffness's part in
    ``u'``; ``M`` itself without it).  With node frames, those of the extended state
    (``extended_terms``) projected on the model's speeds: ``P^T M_x P``, ``P^T f_x``
    (``compiled.flexible_states``)."""
    q, u = split(model, q, u)
    M, f, A = extended_terms(model, *model._extended(q, u), t)
    P = None if model._map is None else model._map.P
    if P is None:
        return M, f, A
    PT = P.T
    M, f = PT @ M @ P, PT @ f
    return M, f, (M if A is None else PT @ A @ P)


def extended_terms(model, qx, ux, t=0.0):
    """``(M_x, f_x, A_x)`` over the extended speeds (the tree's, then the modal ones):
    the tree's Jourdain terms and each flexible body's (module docstring); ``A_x`` is
    ``M_x`` plus the stiffening's part in the accelerations (the same array without)."""
    tree = model.tree
    nqt, nut, nux = tree.nq, tree.nu, model._nux
    f_elements = None
    if model._flex_elements and not tree.gyroscopic:
        # the elements read the true velocities, which the bias pass below drops
        tree._kinematics_kernel(qx[:nqt], ux[:nut], t)
        f_elements = generalized_forces(model, qx, ux, t)
    tree._jourdain_terms(qx[:nqt], ux[:nut], t)
    M = np.zeros((nux, nux))
    f = np.zeros(nux)
    M[:nut, :nut] = tree._M
    f[:nut] = tree._f
    coupled = []                      # (rows, row-vector): the stiffening's part in u'
    omegas = _angular_velocities(model, qx, ux, t)
    for fb in model._flex:
        eta, eta_dot = qx[fb.q], ux[fb.u]
        B = body_map(tree, fb, nux)
        RT = tree._R[fb.frame].T
        bias = np.concatenate([RT @ tree._a[fb.frame], RT @ tree._alpha[fb.frame]])
        Mb = body_matrix(fb, eta)
        omega = RT @ tree._w[fb.frame] if omegas is None else omegas[fb.frame]
        M += B.T @ Mb @ B
        f += B.T @ body_forces(model, fb, eta, eta_dot, omega, bias, Mb)
        if model.stiffening and fb.axial.any():
            coupled.append((fb.u, np.outer(fb.axial @ eta, B[0])))
    if model._flex_elements:
        f += generalized_forces(model, qx, ux, t) if f_elements is None else f_elements
    A = M
    if coupled:
        A = M.copy()
        for rows, block in coupled:
            A[rows] += block
    return M, f, A


def _angular_velocities(model, q, u, t):
    """With the gyroscopic effect off the tree's kernels leave every frame's angular
    velocity at zero (``drop_velocity_products``); the stiffening needs the true one:
    the frames' body-component angular velocities then, else ``None`` (``q``, ``u``:
    extended)."""
    tree = model.tree
    if tree.gyroscopic or not model.stiffening:
        return None
    kin = tree.kinematics(q[:tree.nq], u[:tree.nu], t=t)
    w = kin.w_body
    tree._jourdain_terms(q[:tree.nq], u[:tree.nu], t)     # the workspace as it was
    return w


def forward_dynamics(model, q, u, t=0.0, method="jourdain"):
    """``u'`` from ``M u' = f`` (see the module's docstring); only the Jourdain route is
    there for flexible bodies (``formulation`` says so for the others)."""
    model.formulation(method)
    M, f, A = terms(model, q, u, t)
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(f))):
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the equations of motion "
                             "came out non-finite (check the state, masses and stiffness)")
    try:
        return np.linalg.solve(A, f)
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(f"model {model.name!r}, t={t:.6g}: the mass matrix "
                                      "is singular", _weak_speeds(model, M)) from None


def state_derivative(model, t, y, method="jourdain"):
    """``[q', u']`` for ``y = [q, u]`` (a new array)."""
    y = np.asarray(y, dtype=float)
    if y.shape != (model.nq + model.nu,):
        raise ModelError(f"model {model.name!r} expects a state of length "
                         f"{model.nq + model.nu} (q then u), got shape {y.shape}")
    q, u = y[:model.nq], y[model.nq:]
    return np.concatenate([coordinate_rates(model, q, u),
                           model.forward_dynamics(q, u, t, method)])


def coordinate_rates(model, q, u):
    """``q' = N(q) u``: the tree's, then ``eta' `` as the modal speeds."""
    q, u = split(model, q, u)
    tree = model.tree
    if model._map is None:
        return np.concatenate([tree.coordinate_rates(q[:tree.nq], u[:tree.nu]),
                               u[tree.nu:]])
    qx, ux = model._extended(q, u)
    rates = tree.coordinate_rates(qx[:tree.nq], ux[:tree.nu])
    return np.concatenate([rates[model._map.keep_q], u[model._map.keep_u.size:]])


def mass_matrix(model, q, t=0.0):
    """The symmetric mass matrix ``M(q)`` (nu x nu) of the tree and its flexible bodies."""
    return terms(model, q, np.zeros(model.nu), t)[0]


def forcing(model, q, u, t=0.0):
    """The right-hand side ``f(q, u, t)`` of ``M u' = f`` (with the geometric stiffness's
    part in ``u'`` on the left: see the module's docstring)."""
    return terms(model, q, u, t)[1]


def _weak_speeds(model, M):
    d = np.abs(np.diag(M))
    return [s for s, x in zip(model.speeds, d) if x <= 1e-12 * max(d.max(), 1e-300)]


def check_at_rest(model, q, t=0.0):
    """Raise ``SingularMassMatrixError`` when ``M(q)`` is not positive definite (the
    compile-time check of every degree of freedom's inertia)."""
    M = mass_matrix(model, q, t)
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(f"model {model.name!r}: the mass matrix is singular",
                                      [s for s in _weak_speeds(model, M)
                                       if s in model.tree.speeds]) from None


def mass_matrix_condition(model, q, t=0.0):
    """``(condition number of M, [speeds of its weakest direction])``."""
    M = mass_matrix(model, q, t)
    ev, vec = np.linalg.eigh(M)
    weak = [s for s, x in zip(model.speeds, np.abs(vec[:, 0])) if x > 0.3]
    return (float(ev[-1] / ev[0]) if ev[0] > 0 else float("inf")), weak


def energy(model, q, u, t=0.0):
    """Kinetic and potential energy ``(T, V)``: the tree's, plus each flexible body's
    ``1/2 w^T M_b(eta) w``, ``-g . (m r_0 + R c(eta))`` and ``1/2 eta^T K eta``."""
    q, u = model._extended(*split(model, q, u))
    tree = model.tree
    T, V = tree.energy(q[:tree.nq], u[:tree.nu], t)     # leaves the tree's kinematics
    for fb in model._flex:
        i, eta, inv = fb.frame, q[fb.q], fb.invariants
        R = tree._R[i]
        w = np.concatenate([R.T @ tree._v[i], R.T @ tree._w[i], u[fb.u]])
        T += 0.5 * w @ body_matrix(fb, eta) @ w
        c = inv.first_moment + inv.modal_first_moment @ eta
        V += -tree.gravity @ (inv.mass * tree._r[i] + R @ c) + 0.5 * eta @ fb.stiffness @ eta
    return float(T), float(V)


def element_energies(model, q, u, t=0.0):
    """``(V, P_nc, P_load)`` of the loads and force elements at points of flexible
    bodies (``flexible_forces``), after a kinematics evaluation of the tree."""
    if not model._flex_elements:
        return 0.0, 0.0, 0.0
    q, u = model._extended(*split(model, q, u))
    model.tree._kinematics_kernel(q[:model.tree.nq], u[:model.tree.nu], t)
    return _element_energies(model, q, u, t)


def momentum(model, q, u, t=0.0):
    """Linear momentum and angular momentum about the world origin ``(p, L)``, world
    components: the tree's plus each flexible body's ``R [M_b w]_t`` and
    ``R [M_b w]_r + r_0 x p`` (its momenta about the frame origin, ``dT/dv_0``,
    ``dT/domega``)."""
    q, u = model._extended(*split(model, q, u))
    tree = model.tree
    p, L = tree.momentum(q[:tree.nq], u[:tree.nu], t)
    tree._kinematics_kernel(q[:tree.nq], u[:tree.nu], t)
    for fb in model._flex:
        i = fb.frame
        R = tree._R[i]
        w = np.concatenate([R.T @ tree._v[i], R.T @ tree._w[i], u[fb.u]])
        P = body_matrix(fb, q[fb.q]) @ w
        p_i = R @ P[:3]
        p = p + p_i
        L = L + R @ P[3:6] + np.cross(tree._r[i], p_i)
    return p, L


def modal_power(model, q, u, t=0.0):
    """The power of the flexible bodies' forces that no potential gives: modal damping
    ``-eta'^T D eta'`` and, with ``geometric_stiffening``, ``-eta'^T K_G eta`` (its
    axial part reads the frame's acceleration, so ``u'`` is computed)."""
    q, u = split(model, q, u)
    ud = model.forward_dynamics(q, u, t) if model.stiffening else None
    q, u = model._extended(q, u)
    P = sum(-u[fb.u] @ fb.damping @ u[fb.u] for fb in model._flex)
    if not model.stiffening:
        return float(P)
    if model._map is not None:
        ud = model._map.P @ ud
    tree = model.tree                  # its workspace: the forward dynamics' at (q, u)
    omegas = _angular_velocities(model, q, u, t)
    for fb in model._flex:
        RT = tree._R[fb.frame].T
        omega = RT @ tree._w[fb.frame] if omegas is None else omegas[fb.frame]
        a_x = (body_map(tree, fb, model._nux)[0] @ ud + (RT @ tree._a[fb.frame])[0]
               - (RT @ tree.gravity)[0])
        Kg = (omega[1] ** 2 + omega[2] ** 2) * fb.centrifugal + a_x * fb.axial
        P -= u[fb.u] @ Kg @ q[fb.q]
    return float(P)

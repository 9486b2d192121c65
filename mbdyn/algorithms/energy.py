"""Energies, momentum and power on a compiled model: kinetic and gravitational energy,
linear and angular momentum, the force elements' stored energy and power, the power of
the loads.
"""
from __future__ import annotations


import numpy as np

from ..kernels import dynamics as kd
from ..kernels import forces as kf


def energy(model, q, u, t=0.0):
    """Kinetic and gravitational potential energy ``(T, V)``; ``V = -sum m g . r_G``."""
    model._kinematics_kernel(q, u, t)
    T, V = kd.energies(model._mass, model._com, model._inertia, model.gravity, model._R,
                       model._r, model._w, model._v)
    return float(T), float(V)


def momentum(model, q, u, t=0.0):
    """Linear momentum ``sum m v_G`` and angular momentum about the world origin
    ``sum (r_G x m v_G + I_G w)`` of all bodies, world components: ``(p, L)``."""
    q, u = model._state(q, u)
    model._require_finite(q, u, t)
    kin = model.kinematics(q, u, t=t)
    p = np.zeros(3)
    L = np.zeros(3)
    for i in range(model.n_frames):
        m = model._mass[i]
        R = kin.R[i]
        IG = R @ model._inertia[i] @ R.T
        p += m * kin.v_com[i]
        L += np.cross(kin.r_com[i], m * kin.v_com[i]) + IG @ kin.w[i]
    return p, L


def element_energy(model, q, u, t=0.0):
    """Force elements' ``(potential energy, non-conservative power)``: the energy stored
    in springs, stops and contacts, and the power dampers, friction, bushings, bearings
    and actuators deliver to the system (negative when they take energy out)."""
    V, P_nc, P_act = element_power(model, q, u, t)
    return V, P_nc + P_act


def element_power(model, q, u, t=0.0):
    """``(potential energy, non-conservative power, actuators' power)`` of the force
    elements: ``element_energy`` with what the actuators put in apart."""
    if not model.forces:
        return 0.0, 0.0, 0.0
    model._kinematics_kernel(q, u, t)
    acc = np.zeros(3)
    kf.force_elements(model._force_int, model._force_data, model._parent, model._axis,
                      model._com, model._qfull, model._ufull, model._R, model._r, model._w,
                      model._v, model._F, model._N, acc, model._scratch, model._force_shapes)
    return float(acc[0]), float(acc[1]), float(acc[2])


def load_power(model, q, u, t=0.0):
    """Power of the loads (``add_load``) on the system: force times the velocity of its
    point plus moment times the body's angular velocity."""
    if not model.loads:
        return 0.0
    model._kinematics_kernel(q, u, t)
    P = 0.0
    for k in range(len(model.loads)):
        i = model._load_body[k]
        f, m = model._load_force[k], model._load_moment[k]
        if model._load_in_body[k]:
            f, m = model._R[i] @ f, model._R[i] @ m
        lever = model._R[i] @ model._load_point[k]
        P += f @ (model._v[i] + np.cross(model._w[i], lever)) + m @ model._w[i]
    return float(P)

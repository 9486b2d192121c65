"""The textbook's three examples built through mbdyn's Python API, with the text's symbols.

Each builder returns an uncompiled ``mb.System``; the tests compile it.  The choices the
text leaves open are documented where they are made.
"""
import numpy as np
import sympy as sp

import mbdyn as mb

G = 9.81


def rotating_pendulum_system(Omega, omega, a, b, c, r, h, l, m, g=G, parameters=None):
    """Example 1 (1.4.1): a particle pendulum on a disk turning on a turning arm.

    Frames as in the text: the arm B1 turns about Z at ``Omega`` (joint ``"Omega"``, at the
    top A of the post, ``I r_OA = [0, 0, a]``); the disk B2 turns relative to the arm about
    its own vertical axis at ``omega`` (joint ``"omega"``; its origin is the disk centre C,
    ``B1 r_AC = B1 r_AB + B2 r_BC = [0, b, c]`` since the disk turns about the vertical
    through B); the pendulum B3 swings about the disk-fixed X2 axis at the pivot D
    (joint ``"beta"``, ``B2 r_CD = [0, r, h]``), and carries the particle E at
    ``B3 r_DE = [0, 0, -l]`` (the hanging rod; the text's ``[0, 0, l]`` lost its minus).

    The arm and the disk are massless frames; the rod is massless, so the only body is the
    particle (mass ``m``, frame ``"pendulum"``).  The reaction of joint ``"beta"`` is then
    the rod/hinge force on E: in B3 components it is the text's ``[R, 0, T]``.
    """
    s = mb.System("rotating pendulum", gravity=(0.0, 0.0, -g), parameters=parameters)
    s.add_frame("arm")
    s.add_joint("Omega", "revolute", parent="ground", child="arm", axis="z",
                position=(0.0, 0.0, a), drive=Omega * mb.t)
    s.add_frame("disk")
    s.add_joint("omega", "revolute", parent="arm", child="disk", axis="z",
                position=(0.0, b, c), drive=omega * mb.t)
    s.add_body("pendulum", mass=m, com=(0.0, 0.0, -l))
    s.add_joint("beta", "revolute", parent="disk", child="pendulum", axis="x",
                position=(0.0, r, h))
    return s


def double_pendulum_system(m1, m2, l1, l2, g=G, parameters=None):
    """Example 2 (1.4.2): two particles on massless rods, gravity along -y.

    ``theta1`` is rod 1's angle from the downward vertical, ``theta2`` rod 2's angle
    relative to rod 1.  The listing's positions are ``x1 = -l1 sin t1``,
    ``y1 = -l1 cos t1``: a positive angle swings the particle towards -x, i.e. the angles
    turn about -z.  The joints therefore use ``axis="-z"`` so that the model's positions
    are the listing's (the equations of motion are the same either way, by symmetry).

    Body ``"link1"`` is rod 1 with particle 1 at its end, body ``"link2"`` rod 2 with
    particle 2; each body frame's -y axis points along its rod, so the rod force (tension
    positive, the listing's ``Tr1``, ``Tr2``) is the +y component, in the child frame, of
    the reaction of joint ``theta1`` resp. ``theta2``.
    """
    s = mb.System("double pendulum", gravity=(0.0, -g, 0.0), parameters=parameters)
    s.add_body("link1", mass=m1, com=(0.0, -l1, 0.0))
    s.add_joint("theta1", "revolute", parent="ground", child="link1", axis="-z")
    s.add_body("link2", mass=m2, com=(0.0, -l2, 0.0))
    s.add_joint("theta2", "revolute", parent="link1", child="link2", axis="-z",
                position=(0.0, -l1, 0.0))
    return s


def with_symbols(builder, values, **fixed):
    """An example with the parameters named in ``values`` as sympy symbols, declared with
    those values as the System's parameters (for the symbolic derivation); ``fixed`` are
    passed to ``builder`` as they are (e.g. the rotating pendulum's drive rates)."""
    symbols = {name: sp.Symbol(name, real=True) for name in values}
    return builder(**symbols, **fixed, parameters=dict(values))


def top_inertia_about_com(m, h, A, C):
    """The top's inertia about its centre of mass (body axes) from the text's data about the
    contact point O (``Ixx = Iyy = A``, ``Izz = C``), G at ``h`` along the spin axis z."""
    return mb.inertia.about_com(np.diag([A, A, C]), m, (0.0, 0.0, -h))


def top_system(m, h, A, C, Mz, joint="euler", g=G):
    """Example 3 (1.4.3): the heavy top on a fixed contact point O.

    ``joint="euler"``: a ``"ZXZ"`` Euler joint at O with coordinates
    ``("psi", "theta", "phi")`` -- precession, nutation, spin, as in the text.
    ``joint="spherical"``: a quaternion joint at O instead (coordinates ``q_w..q_z``,
    speeds = the top's angular velocity in its own axes).  Either way the joint is named
    ``"contact"`` and its reaction force is the floor's contact force on the top.

    The body ``"top"`` has its centre of mass at ``h`` on its z (spin) axis; its inertia
    about the centre of mass comes from the text's data about O (``about_com``).  With the
    listing's data this breaks the triangle inequality (A_G + A_G < C): mbdyn warns with a
    ``ModelWarning`` and the model still runs -- the listing's data are the prototype's.
    ``Mz`` is a moment about the spin axis, applied in body axes (load ``"Mz"``).
    """
    if joint not in ("euler", "spherical"):
        raise ValueError(f"joint must be 'euler' or 'spherical', got {joint!r}")
    s = mb.System("top", gravity=(0.0, 0.0, -g))
    s.add_body("top", mass=m, com=(0.0, 0.0, h), inertia=top_inertia_about_com(m, h, A, C))
    if joint == "euler":
        s.add_joint("contact", "euler", parent="ground", child="top", sequence="ZXZ",
                    coordinates=("psi", "theta", "phi"))
    else:
        s.add_joint("contact", "spherical", parent="ground", child="top",
                    coordinates=("q_w", "q_x", "q_y", "q_z"))
    s.add_load("Mz", "top", moment=(0.0, 0.0, Mz), frame="body")
    return s


#: The listing's data of the top (about the contact point O).
TOP_DATA = dict(m=0.582, h=0.0558, A=0.00209393, C=0.00220580)
#: The listing's data of the double pendulum.
DOUBLE_PENDULUM_DATA = dict(m1=0.00046, m2=0.0046, l1=0.07, l2=0.07)

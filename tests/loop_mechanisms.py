"""Closed mechanisms for the loop tests, built through the public API, and their closed
forms derived here by hand (independently of the engine's constraint kernels).

Four-bar (planar, in the x-y plane, axes along +z): ground pivot A at the origin, crank
``a`` at absolute angle ``th2``, coupler ``b`` at ``th3`` *relative to the crank*, rocker
``c`` from the ground pivot (d, 0) at absolute angle ``th4``; the loop joint ``D`` pins the
coupler's end to the rocker's end.  Slider-crank: crank ``r`` at ``th``, connecting rod
``l`` at ``phi`` relative to the crank, piston on a prismatic joint along x at height
``e`` (offset), the loop closed at the rod-piston pin.
"""
from __future__ import annotations

import numpy as np

import mbdyn as mb

FOUR_BAR = {"a": 0.1, "b": 0.3, "c": 0.25, "d": 0.3}       # Grashof crank-rocker
MASSES = {"crank": 1.0, "coupler": 2.0, "rocker": 1.5}


def _rod(s, name, length, mass):
    """A slender planar link along its body x axis with a small thickness inertia."""
    s.add_body(name, mass=mass, com=(length / 2, 0, 0),
               inertia=(1e-4, mass * length ** 2 / 12, mass * length ** 2 / 12 + 1e-4))


def four_bar(drive=None, closer="revolute", g=9.81, a=0.1, b=0.3, c=0.25, d=0.3,
             compile_=True):
    """The four-bar; ``drive``: the crank's motion (sympy of ``mb.t``) or None (free);
    ``closer``: the kind of loop joint D (revolute, spherical, cylindrical, universal)."""
    s = mb.System("four-bar", gravity=(0, -g, 0))
    _rod(s, "crank", a, MASSES["crank"])
    _rod(s, "coupler", b, MASSES["coupler"])
    _rod(s, "rocker", c, MASSES["rocker"])
    s.add_joint("th2", "revolute", "ground", "crank", axis="z", drive=drive)
    s.add_joint("th3", "revolute", "crank", "coupler", axis="z", position=(a, 0, 0))
    s.add_joint("th4", "revolute", "ground", "rocker", axis="z", position=(d, 0, 0))
    keys = {"axis": "z"} if closer in ("revolute", "cylindrical") else {}
    if closer == "universal":
        keys = {"axis": "z", "axis2": "x"}
    s.add_joint("D", closer, "coupler", "rocker", position=(b, 0, 0),
                child_position=(c, 0, 0), **keys)
    return s.compile() if compile_ else s


def freudenstein(th2, branch, a=0.1, b=0.3, c=0.25, d=0.3):
    """``(th4, th3_absolute)`` of the four-bar at crank angle ``th2``: Freudenstein's
    equation ``K1 cos th4 - K2 cos th2 + K3 = cos(th2 - th4)`` solved by the half-angle
    substitution; ``branch`` +1 or -1 picks the root."""
    K1, K2, K3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    P, S, Q = K1 - np.cos(th2), np.sin(th2), K3 - K2 * np.cos(th2)
    disc = S * S - (Q - P) * (Q + P)
    tt = (S + branch * np.sqrt(disc)) / (Q - P)
    th4 = 2 * np.arctan(tt)
    th3 = np.arctan2(c * np.sin(th4) - a * np.sin(th2), d + c * np.cos(th4) - a * np.cos(th2))
    return th4, th3


def four_bar_rates(th2, w2, al2, th3, th4, a=0.1, b=0.3, c=0.25):
    """Absolute angular velocities and accelerations of coupler and rocker from the loop
    equation ``a e(th2) + b e(th3) - c e(th4) = d ex`` differentiated once and twice (each
    a 2x2 linear system in the unknown rates)."""
    def e(x):
        return np.array([np.cos(x), np.sin(x)])

    def p(x):
        return np.array([-np.sin(x), np.cos(x)])
    A = np.column_stack([b * p(th3), -c * p(th4)])
    w3, w4 = np.linalg.solve(A, -a * w2 * p(th2))
    rhs = (-a * al2 * p(th2) + a * w2 ** 2 * e(th2) + b * w3 ** 2 * e(th3)
           - c * w4 ** 2 * e(th4))
    al3, al4 = np.linalg.solve(A, rhs)
    return w3, w4, al3, al4


def slider_crank(drive=None, r=0.05, l=0.2, e=0.01, g=9.81):
    """Crank, connecting rod and piston (prismatic along x at height ``e``)."""
    s = mb.System("slider-crank", gravity=(0, -g, 0))
    _rod(s, "crank", r, 0.5)
    _rod(s, "rod", l, 0.8)
    s.add_body("piston", mass=0.6, inertia=(1e-4, 1e-4, 1e-4))
    s.add_joint("th", "revolute", "ground", "crank", axis="z", drive=drive)
    s.add_joint("phi", "revolute", "crank", "rod", axis="z", position=(r, 0, 0))
    s.add_joint("x", "prismatic", "ground", "piston", axis="x", position=(0, e, 0))
    s.add_joint("pin", "revolute", "rod", "piston", axis="z", position=(l, 0, 0),
                child_position=(0, 0, 0))
    return s.compile()


def piston(th, w, al, r=0.05, l=0.2, e=0.01):
    """Exact piston position, velocity and acceleration: ``x = r cos th + sqrt(l^2 -
    (r sin th - e)^2)`` and its time derivatives (chain rule, by hand)."""
    s = r * np.sin(th) - e
    root = np.sqrt(l * l - s * s)
    x = r * np.cos(th) + root
    ds = r * np.cos(th)                    # ds/dth
    dds = -r * np.sin(th)
    dx = -r * np.sin(th) - s * ds / root
    ddx = -r * np.cos(th) - (ds * ds + s * dds) / root - (s * ds) ** 2 / root ** 3
    return x, dx * w, ddx * w * w + dx * al

"""Force elements a user adds beside bodies and joints, each validated on creation.

Kinds (``System.add_force(name, kind, ...)``):

* ``spring-damper``  between a point of one body and a point of another (or the ground):
  tension ``T = preload + k (L - free_length) + c L'`` along the line between the points,
  or a tabulated force of the elongation and/or of its rate.
* ``joint-spring-damper``  on the coordinate of a revolute or prismatic joint:
  ``Q = -(preload + k (q - rest) + c q')``, or tabulated.
* ``bushing``  6x6 stiffness and damping between two frames (small relative rotations).
* ``bearing``  radial force of a journal bearing on a shaft point: the eight coefficients
  ``kxx, kxy, kyx, kyy, cxx, cxy, cyx, cyy``, constant or tabulated against the spin speed.
* ``contact``  a sphere (or a disk's rim) of a body against a plane fixed in the world:
  Hunt-Crossley normal force and regularised Coulomb friction.
* ``joint-stop``  a one-sided spring-damper at the bounds of a joint's coordinate.

Actuators (``System.add_actuator``, ``mbdyn.elements.actuators``) are force elements of
kind ``actuator`` too: one namespace, each a named effect.

Tables are interpolated monotonically: ``"pchip"`` (piecewise-cubic Hermite that keeps
monotone data monotone; the default) or ``"linear"``; never a smoothing spline.

Here: the record and ``make_force``; each kind's builder is in ``force_kinds``, the values
they read in ``force_values``, the tables in ``tables``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from .actuators import make_actuator
from ..names import identifier_problem
from .force_kinds import (BEARING_COEFFICIENTS, BUILDERS, hunt_crossley_factor,  # noqa: F401
                          radial_directions)
from .force_values import Given, Law, make_law  # noqa: F401
from .tables import INTERPOLATIONS, Table, make_table  # noqa: F401
from .values import has_symbols

KINDS = tuple(BUILDERS)
#: the effects that are not elements
GLOBAL_EFFECTS = ("gravity", "gyroscopic")


@dataclass(frozen=True)
class ForceElement:
    """A validated force element: ``kind``, the frames it acts on and its numbers
    (``params``; tables as ``Table``).  ``symbolic`` keeps values given as expressions of
    parameters, for the symbolic layer."""
    name: str
    kind: str
    frames: tuple
    params: dict
    symbolic: dict = field(default_factory=dict)

    def describe(self):
        """One line for ``mbdyn info``."""
        p = self.params
        if self.kind == "spring-damper":
            law = ("law " + (str(p["law"].expression) if p["law"].expression is not None
                             else "(a function)") if p["law"] is not None else
                   "force table" if p["force_table"] is not None else
                   f"k = {p['stiffness']:g}, free length {p['free_length']:g}"
                   + (f", preload {p['preload']:g}" if p["preload"] else "")
                   if p["stiffness"] or p["preload"] else "")
            damp = ("damping table" if p["damping_table"] is not None else
                    f"c = {p['damping']:g}" if p["damping"] else "")
            return (f"{self.frames[0]}{tuple(p['point_a'].tolist())} -- "
                    f"{self.frames[1]}{tuple(p['point_b'].tolist())}: "
                    + ", ".join(x for x in (law, damp) if x))
        if self.kind == "joint-spring-damper":
            if p["law"] is not None:
                law = p["law"].expression
                return (f"on joint {p['joint']!r}: law "
                        f"{law if law is not None else '(a function)'} of x = q - "
                        f"{p['rest']:g}, v = q'")
            law = ("table" if p["force_table"] is not None else
                   f"k = {p['stiffness']:g}, rest {p['rest']:g}")
            return f"on joint {p['joint']!r}: {law}, c = {p['damping']:g}"
        if self.kind == "joint-stop":
            return (f"on joint {p['joint']!r}: stops at {p['lower']:g} and {p['upper']:g}, "
                    f"k = {p['stiffness']:g}, c = {p['damping']:g}")
        if self.kind == "actuator":
            return describe_actuator(p)
        if self.kind == "bushing":
            return f"{self.frames[0]} -- {self.frames[1]}: 6x6 stiffness and damping"
        if self.kind == "bearing":
            tab = [c for c in BEARING_COEFFICIENTS if isinstance(p[c], Table)]
            return (f"shaft {self.frames[0]} at {tuple(p['point'].tolist())} in "
                    f"{self.frames[1]}" + (f"; {', '.join(tab)} tabulated against "
                                           f"{p['speed']}" if tab else ""))
        return (f"{p['shape']} of radius {p['radius']:g} on {self.frames[0]} against the "
                f"plane through {tuple(p['plane_point'].tolist())}, normal "
                f"{tuple(np.round(p['plane_normal'], 6).tolist())}; k = {p['stiffness']:g}, "
                f"e = {p['restitution']:g}, mu = {p['friction']:g}")


def check_name(element, name):
    """An element's ``name`` names its effect: an identifier, not a global effect's."""
    problem = identifier_problem(name)
    if problem:
        raise ModelError(f"{element}: the name {problem}; it names the element's effect")
    if name in GLOBAL_EFFECTS:
        raise ModelError(f"{element}: the name is reserved for the {name} effect; choose "
                         "another")


def describe_actuator(p):
    """One line for ``mbdyn info`` of an actuator's parameters ``p``."""
    kind = p["type"]
    sat = "" if p["limit"] == float("inf") else f", limit {p['limit']:g}"
    if kind == "torque":
        what = f"effort {_signal_text(p['value'])}"
    elif kind == "held":
        what = "effort held by a sampled controller"
    elif kind == "motor":
        line = ("torque-speed table" if p["torque_speed"] is not None else
                f"stall torque {p['stall_torque']:g}, no-load speed {p['no_load_speed']:g}")
        what = (f"motor ({line}, gear {p['gear']:g}, command {_signal_text(p['command'])}"
                + (f", rotor inertia {p['rotor_inertia']:g}" if p["rotor_inertia"] else "")
                + ")")
    else:
        what = (f"{kind.upper()} kp = {p['kp']:g}, kd = {p['kd']:g}"
                + (f", ki = {p['ki']:g} at {p['rate']:g} Hz" if kind == "pid" else "")
                + f", setpoint {_signal_text(p['setpoint'])}"
                + (", gravity compensated" if p["gravity_compensation"] else ""))
    return f"on joint {p['joint']!r}: {what}{sat}"


def _signal_text(value):
    return ("a table of t" if isinstance(value, Table) else
            f"{value:g}" if isinstance(value, float) else str(value))


def actuator(name, joint, kind, parameters=None, **kw):
    """Validate and build an actuator (a ``ForceElement`` of kind ``actuator``)."""
    check_name(f"actuator {name!r}", name)
    symbolic = {k: v for k, v in kw.items() if not isinstance(v, str) and has_symbols(v)}
    params = make_actuator(name, joint, kind, parameters, **kw)
    return ForceElement(name, "actuator", (), params, symbolic)


def make_force(name, kind, parameters=None, gravity=(0.0, 0.0, -9.81), **kw):
    """Validate and build a ``ForceElement`` (frames are checked against the tree by
    ``System.add_force``); each kind's keys are read by its builder in ``BUILDERS``."""
    element = f"force {name!r}"
    parameters = parameters or {}
    check_name(element, name)
    if kind not in KINDS:
        raise ModelError(f"{element}: unknown kind {kind!r}; use one of {', '.join(KINDS)}")
    symbolic = {k: v for k, v in kw.items() if not isinstance(v, str) and has_symbols(v)}
    params, frames = BUILDERS[kind](Given(kw, element, parameters, gravity))
    return ForceElement(name, kind, tuple(frames), params, symbolic)

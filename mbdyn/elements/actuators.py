"""Joint actuators and joint stops: efforts on one joint coordinate, equal and opposite on
the joint's child and parent, each validated on creation.  They are force elements (one
namespace with loads and forces, each a named effect), packed for the compiled force kernel
(``compiled.actuator_packing``, ``kernels.actuation``): no Python per step.

Actuator kinds (``System.add_actuator(name, joint, kind, ...)``):

* ``torque``  ``value``: a number, an expression of ``t``, the coordinates, speeds and
  parameters, or a table of ``t`` (``[[t0, tau0], ...]``);
* ``motor``  a DC motor through a gear: motor torque ``tau_m = stall_torque (command -
  w_m / no_load_speed)`` (the torque-speed line at the ``command``, a fraction of the rated
  voltage: a number, an expression of ``t`` or a table of ``t``; default 1), or
  ``command * torque_speed(w_m)`` from a table; ``w_m = gear * u``; the joint gets
  ``gear * tau_m``; ``limit`` bounds ``tau_m`` (the current limit); ``rotor_inertia``
  reflected through the gear (``gear^2 J``) on a joint whose parent is the ground;
* ``pd``, ``pid``  ``tau = kp (s - q) + kd (s' - u) + I + g(q)``: ``setpoint`` ``s`` a
  number, an expression of ``t`` or a table of ``t`` (its rate exact: sympy's derivative
  or the table's slope); ``I`` the integral term of a PID, accumulated at ``rate`` Hz with
  anti-windup and held between samples (``integrate.sampled``); ``gravity_compensation``
  adds the effort that balances gravity on the bodies the joint carries; ``feedforward``
  adds the computed torque, the inverse dynamics of the model without its actuators at
  the setpoints (their positions, rates and accelerations), updated at ``rate`` Hz;
* ``held``  a value a sampled controller writes (``System.add_controller``).

Every kind takes ``limit`` (saturation, default none).  A joint stop
(``System.add_force(name, "joint-stop", joint=..., lower=..., upper=..., stiffness=...,
damping=...)``) is a one-sided spring-damper at a coordinate's ``lower`` and ``upper``
bounds.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from .force_values import Given
from .tables import Table, make_table
from .values import has_symbols

ACTUATOR_KINDS = ("torque", "motor", "pd", "pid", "held")
_KEYS = {"torque": ("value", "limit"),
         "motor": ("stall_torque", "no_load_speed", "torque_speed", "gear", "command",
                   "rotor_inertia", "limit"),
         "pd": ("kp", "kd", "setpoint", "limit", "gravity_compensation", "feedforward",
                "rate"),
         "pid": ("kp", "kd", "ki", "setpoint", "limit", "gravity_compensation", "rate",
                 "anti_windup", "feedforward"),
         "held": ("limit", "value")}
#: the default rate (Hz) at which a PID accumulates its integral term
PID_RATE = 1000.0


def _signal(given, key, default=None):
    """A source: a float, a sympy expression (of ``t``, coordinates, speeds; parameters
    resolved at compile) or a ``Table`` of ``t``."""
    kw = given.kw
    if key not in kw or kw[key] is None:
        return default
    value = kw[key]
    if isinstance(value, Table):
        return value
    if isinstance(value, (list, tuple, dict, np.ndarray)):
        return make_table(value, given.element, key, given.interp)
    if callable(value) and not hasattr(value, "free_symbols"):
        raise ModelError(f"{given.element}: {key} is a Python function; give a number, an "
                         "expression of t (and the coordinates and speeds) or a table of "
                         "t -- or use System.add_controller for a controller in Python")
    if isinstance(value, str):
        raise ModelError(f"{given.element}: {key} = {value!r} is text; in Python give a "
                         "number or a sympy expression (model files read text for you)")
    if has_symbols(value):
        return value
    return given.num(value, key)


def make_actuator(name, joint, kind, parameters, **kw):
    """The validated parameters of an actuator (``ForceElement.params``)."""
    element = f"actuator {name!r}"
    if kind not in ACTUATOR_KINDS:
        raise ModelError(f"{element}: unknown kind {kind!r}; use one of "
                         f"{', '.join(ACTUATOR_KINDS)}")
    if not isinstance(joint, str):
        raise ModelError(f"{element}: joint must be the name of a joint, got {joint!r}")
    g = Given(kw, element, parameters or {}, None)
    extra = sorted(set(kw) - set(_KEYS[kind]) - {"interpolation"})
    if extra:
        raise ModelError(f"{element}: unknown key(s) {', '.join(extra)} for a {kind} "
                         f"actuator; known: {', '.join(_KEYS[kind])}")
    limit = math.inf if kw.get("limit") is None else g.num(kw["limit"], "limit", positive=True)
    p = {"type": kind, "joint": joint, "limit": limit}
    if kind == "torque":
        if "value" not in kw:
            raise ModelError(f"{element}: a torque actuator needs value = (a number, an "
                             "expression of t, q, u or a table of t)")
        p["value"] = _signal(g, "value")
    elif kind == "held":
        p["value"] = g.num(kw.get("value", 0.0), "value")
    elif kind == "motor":
        _motor(g, p)
    else:
        _controller(g, p, kind)
    return p


def _motor(g, p):
    kw, element = g.kw, g.element
    p["torque_speed"] = g.table("torque_speed")
    if p["torque_speed"] is None:
        for key in ("stall_torque", "no_load_speed"):
            if key not in kw:
                raise ModelError(f"{element}: a motor needs stall_torque and no_load_speed "
                                 "(its torque-speed line) or a torque_speed table")
        p["stall_torque"] = g.num(kw["stall_torque"], "stall_torque", positive=True)
        p["no_load_speed"] = g.num(kw["no_load_speed"], "no_load_speed", positive=True)
    else:
        p["stall_torque"] = p["no_load_speed"] = 0.0
    p["gear"] = g.num(kw.get("gear", 1.0), "gear")
    if p["gear"] == 0.0:
        raise ModelError(f"{element}: gear must not be 0 (the motor would not reach the joint)")
    p["rotor_inertia"] = g.num(kw.get("rotor_inertia", 0.0), "rotor_inertia", minimum=0.0)
    p["command"] = _signal(g, "command", 1.0)


def _controller(g, p, kind):
    kw, element = g.kw, g.element
    if "kp" not in kw:
        raise ModelError(f"{element}: a {kind} controller needs kp (and kd"
                         + (", ki" if kind == "pid" else "") + ")")
    p["kp"] = g.num(kw["kp"], "kp", minimum=0.0)
    p["kd"] = g.num(kw.get("kd", 0.0), "kd", minimum=0.0)
    p["ki"] = g.num(kw.get("ki", 0.0), "ki", minimum=0.0) if kind == "pid" else 0.0
    p["setpoint"] = _signal(g, "setpoint", 0.0)
    gc = kw.get("gravity_compensation", False)
    if not isinstance(gc, (bool, np.bool_)):
        raise ModelError(f"{element}: gravity_compensation must be true or false, got {gc!r}")
    p["gravity_compensation"] = bool(gc)
    ff = kw.get("feedforward", False)
    if not isinstance(ff, (bool, np.bool_)):
        raise ModelError(f"{element}: feedforward must be true or false, got {ff!r}")
    p["feedforward"] = bool(ff)
    if ff and gc:
        raise ModelError(f"{element}: feedforward (the computed torque at the setpoints) "
                         "already balances gravity there; give feedforward or "
                         "gravity_compensation, not both")
    if ff and isinstance(p["setpoint"], Table):
        raise ModelError(f"{element}: feedforward needs the setpoint's acceleration; give the "
                         "setpoint as a number or an expression of t, not a table")
    if kind == "pid" or ff:
        p["rate"] = g.num(kw.get("rate", PID_RATE), "rate", positive=True)
        aw = kw.get("anti_windup", True)
        if not isinstance(aw, (bool, np.bool_)):
            raise ModelError(f"{element}: anti_windup must be true or false, got {aw!r}")
        p["anti_windup"] = bool(aw)


def joint_stop(g):
    """A joint stop's parameters (``kind = "joint-stop"``): ``joint``, ``lower`` and/or
    ``upper`` bounds of its coordinate, ``stiffness`` (required), ``damping``."""
    kw, element = g.kw, g.element
    g.check_keys(("joint", "lower", "upper", "stiffness", "damping"), "joint-stop", "joint",
                 "give the joint whose coordinate it bounds")
    if not isinstance(kw["joint"], str):
        raise ModelError(f"{element}: joint must be the name of a joint, got {kw['joint']!r}")
    lo = g.num(kw["lower"], "lower") if kw.get("lower") is not None else -math.inf
    hi = g.num(kw["upper"], "upper") if kw.get("upper") is not None else math.inf
    if math.isinf(lo) and math.isinf(hi):
        raise ModelError(f"{element}: give lower, upper or both (the bounds of the joint's "
                         "coordinate)")
    if not lo < hi:
        raise ModelError(f"{element}: lower ({lo:g}) must be below upper ({hi:g})")
    if kw.get("stiffness") is None:
        raise ModelError(f"{element}: a stop needs stiffness (N/m or N m/rad) -- stiff "
                         "enough that the overshoot is small, e.g. m (2 pi 50 Hz)^2 for a "
                         "joint moving a mass m")
    return {"joint": kw["joint"], "lower": lo, "upper": hi,
            "stiffness": g.num(kw["stiffness"], "stiffness", positive=True),
            "damping": g.num(kw.get("damping", 0.0), "damping", minimum=0.0)}, ()

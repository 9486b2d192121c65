"""Actuators, joint stops and compiled force laws laid out for the force kernel
(``kernels.actuation``); the clock they read; the motors' rotor inertia reflected onto
their joints; the PID integral terms and Python controllers a run updates at its
sampling instants (``integrate.sampled``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy

from ..errors import ModelError
from ..elements.tables import Table
from ..kernels import actuation as ka
from ..kernels import forces as kf
from .programs import program_block


def _time_dependent(value, parameters):
    return isinstance(value, Table) or (isinstance(value, sympy.Basic) and any(
        s.name not in parameters for s in value.free_symbols))


def reads_time(forces, parameters):
    """Whether some actuator may read the time: a table, or an expression of more than
    the ``parameters`` (the clock is given to every such actuator)."""
    for el in forces:
        if el.kind == "actuator":
            p = el.params
            if any(_time_dependent(p.get(k), parameters)
                   for k in ("value", "setpoint", "command")):
                return True
    return False


def reflect_rotors(model, forces):
    """A motor's rotor inertia ``J`` seen through its gear ``G``: ``G^2 J`` about the
    joint's axis, added to the child's inertia (exact for a stator fixed in the world,
    which ``System.add_actuator`` requires: the rotor then turns with ``G u`` about that
    axis alone)."""
    for el in forces:
        if el.kind == "actuator" and el.params.get("rotor_inertia"):
            p = el.params
            i = model._frame_index[model._joint[p["joint"]].child]
            a = model._axis[i]
            model._inertia[i] += p["gear"] ** 2 * p["rotor_inertia"] * np.outer(a, a)
            model._has_inertia[i] = True


def variable_codes(model):
    """``{name: code}`` of what an actuator's expression may read: every joint's
    coordinates (``qfull`` entries) and speeds (``-1 - ufull`` entry)."""
    codes = {}
    for i, j in enumerate(model.elements[1]):
        for k, c in enumerate(j.coordinates):
            codes[c] = int(model._qoff[i]) + k
        for k, s in enumerate(j.speeds):
            codes[s] = -1 - (int(model._uoff[i]) + k)
    return codes


def _numeric(model, value, element, key):
    """``value`` with the parameters' values in; its symbols must be ``t`` or state."""
    expr = value.subs({s: model.parameters[s.name] for s in value.free_symbols
                       if s.name in model.parameters})
    codes = variable_codes(model)
    unknown = sorted(s.name for s in expr.free_symbols if s.name != "t" and s.name not in codes)
    if unknown:
        raise ModelError(f"{element}: {key} uses {', '.join(unknown)}, which are neither t, "
                         "coordinates, speeds nor parameters of the model")
    return expr, codes


def put_source(model, data, value, element, key, time_only=False):
    """``(offset, mode)`` of a source (``kernels.actuation.source_value``)."""
    if isinstance(value, Table):
        return data.put(value.block()), value.mode
    if isinstance(value, sympy.Basic) and value.free_symbols:
        expr, codes = _numeric(model, value, element, key)
        if not expr.free_symbols:                     # parameters only: a constant
            return data.put([float(expr)]), ka.CONSTANT
        if time_only and any(s.name != "t" for s in expr.free_symbols):
            raise ModelError(f"{element}: {key} must be a function of t alone (the "
                             "controller compares the coordinate with it)")
        block = program_block(expr, codes)
        if block is None:
            raise ModelError(f"{element}: {key} = {value} uses a function compiled code "
                             "cannot evaluate (known: + - * / ** sqrt exp log sin cos tan "
                             "asin acos atan atan2 sinh cosh tanh abs sign Min Max); "
                             "rewrite it or give a table of t")
        return data.put(block), ka.PROGRAM
    return data.put([float(value)]), ka.CONSTANT


def _carried(model, joint):
    """``(frame, mass)`` of every body the joint carries (its child's subtree)."""
    i = model._frame_index[joint.child]
    inside = np.zeros(model.n_frames, bool)
    inside[i] = True
    for b in range(i + 1, model.n_frames):          # parents come first
        inside[b] = inside[model._parent[b]] if model._parent[b] >= 0 else False
    return [(b, float(model._mass[b])) for b in np.flatnonzero(inside) if model._mass[b]]


def pack_actuator(model, el, element, row, data, laws):
    """An actuator's row and numbers (``kernels.actuation``)."""
    p = el.params
    j = model._joint[p["joint"]]
    i = model._frame_index[j.child]
    kind = p["type"]
    carried = _carried(model, j) if p.get("gravity_compensation") else []
    clock = model._clock[0] if model._clock is not None else -1
    setpoint = p.get("setpoint", 0.0)
    if isinstance(setpoint, sympy.Basic):          # of parameters only: a constant
        expr = _numeric(model, setpoint, element, "setpoint")[0]
        setpoint = setpoint if expr.free_symbols else float(expr)
    off = data.put([ka.TYPES[kind], 1.0 if j.kind == "prismatic" else 0.0, clock,
                    p["limit"], p.get("kp", p.get("stall_torque", 0.0)),
                    p.get("kd", p.get("no_load_speed", 0.0)), p.get("ki", 0.0),
                    p.get("gear", 1.0), p.get("value", 0.0) if kind == "held" else 0.0,
                    len(carried), *model.gravity,
                    setpoint if isinstance(setpoint, float) else 0.0, 0.0]
                   + [x for pair in carried for x in pair])
    row[:4] = [kf.ACTUATOR, i, int(model._parent[i]), off]
    row[8:10] = [int(model._qoff[i]), int(model._uoff[i])]
    if kind == "torque":
        row[4:6] = put_source(model, data, p["value"], element, "value")
    elif kind == "motor":
        row[4:6] = put_source(model, data, p["command"], element, "command", time_only=True)
        if p["torque_speed"] is not None:
            row[6:8] = data.put(p["torque_speed"].block()), p["torque_speed"].mode
    elif kind in ("pd", "pid"):
        if not isinstance(setpoint, float):
            row[4:6] = put_source(model, data, setpoint, element, "setpoint",
                                  time_only=True)
            if row[5] == ka.PROGRAM:           # the setpoint's rate, exact: its derivative
                expr, codes = _numeric(model, setpoint, element, "setpoint")
                rate = sum((sympy.diff(expr, s) for s in expr.free_symbols if s.name == "t"),
                           sympy.S.Zero)
                block = program_block(rate, codes)
                if block is None:
                    raise ModelError(f"{element}: the rate of setpoint = {setpoint} uses a "
                                     "function compiled code cannot evaluate; give a table")
                row[6:8] = data.put(block), ka.PROGRAM


def pack_joint_stop(model, el, element, row, data, laws):
    p = el.params
    j = model._joint[p["joint"]]
    i = model._frame_index[j.child]
    off = data.put([p["lower"], p["upper"], p["stiffness"], p["damping"],
                    1.0 if j.kind == "prismatic" else 0.0])
    row[:4] = [kf.JOINT_STOP, i, int(model._parent[i]), off]
    row[8:10] = [int(model._qoff[i]), int(model._uoff[i])]


def law_block(law):
    """The program of a force law of ``x`` and ``v`` (``None`` when it is a function or
    uses what compiled code cannot evaluate: it is then evaluated in Python)."""
    if law is None or law.numeric is None:
        return None
    return program_block(law.numeric, {"x": ka.X_VAR, "v": ka.V_VAR})


@dataclass
class Sampler:
    """What a run updates at ``rate`` and holds in the packed numbers at ``slot``: a PID's
    integral term (``kind`` ``"integral"``: ``I += ki e dt``, not past what makes the
    effort saturate) or a PD/PID's computed-torque feed-forward (``"feedforward"``: the
    inverse dynamics at the setpoints)."""
    element: object
    slot: int
    rate: float
    kind: str = "integral"


def samplers(model, controllers):
    """The PIDs' integral terms and the feed-forward terms (their slots in the packed
    data)."""
    out = []
    for e, el in enumerate(model._force_elements):
        p = el.params
        if el.kind != "actuator":
            continue
        off = int(model._force_int[e, 3])
        if p["type"] == "pid" and p["ki"] > 0:
            out.append(Sampler(el, off + ka.A_HELD, p["rate"]))
        if p.get("feedforward"):
            out.append(Sampler(el, off + ka.A_FEEDFORWARD, p["rate"], "feedforward"))
    return out

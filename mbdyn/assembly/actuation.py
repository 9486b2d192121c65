"""Actuators, sampled controllers and force elements added to a ``System``: the checks
across elements (the frames and joint exist, the joint has one free coordinate, names are
free) that their records (``elements.actuators``, ``elements.forces``) cannot make alone.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..elements.forces import actuator
from ..errors import ModelError
from ..names import identifier_problem

GROUND = "ground"
#: joint kinds an actuator or a stop acts on: one coordinate
ONE_COORDINATE = ("revolute", "prismatic")


def check_joint(system, element, joint):
    """The joint named ``joint`` of ``system``, a revolute or prismatic tree joint that is
    not driven (a driven joint's effort is an output, not an input)."""
    if joint not in system._joints:
        raise ModelError(f"{element}: unknown joint {joint!r}; add it first (known: "
                         f"{', '.join(system._joints) or 'none'})")
    j = system._joints[joint]
    if j.kind not in ONE_COORDINATE:
        raise ModelError(f"{element}: joint {joint!r} is {j.kind}; actuators and stops act on "
                         "the coordinate of a revolute or prismatic joint (a universal or "
                         "cylindrical joint's two coordinates are joints of their own: "
                         f"{joint}_1, {joint}_2 or {joint}_slide, {joint}_turn)")
    if j.drive is not None:
        raise ModelError(f"{element}: joint {joint!r} is driven (its motion is prescribed); "
                         "an actuator needs a free coordinate -- remove the drive, or read "
                         "the drive's effort from the results")
    return j


def check_force(system, el):
    """A force element's frames and joint exist in ``system``."""
    name = el.name
    for frame in el.frames:
        if frame != GROUND and frame not in system.graph:
            raise ModelError(f"force {name!r}: unknown body {frame!r}; add it first with "
                             f"add_body or add_frame (known: "
                             f"{', '.join(n for n in system.graph if n != GROUND)}, ground)")
    if el.kind == "joint-spring-damper" and el.params["joint"] not in system._joints:
        raise ModelError(f"force {name!r}: unknown joint {el.params['joint']!r}; add it "
                         f"first (known: {', '.join(system._joints) or 'none'})")
    if el.kind == "joint-stop":
        check_joint(system, f"force {name!r}", el.params["joint"])


def add_actuator(system, name, joint, kind="torque", **params):
    """``System.add_actuator``: see ``mbdyn.elements.actuators``."""
    if name in system._forces or name in system._loads:
        raise ModelError(f"actuator {name!r}: the name is already used by a force element, "
                         "actuator or load (one namespace: their names are the scene's "
                         "effects)")
    el = actuator(name, joint, kind, system.parameters, **params)
    j = check_joint(system, f"actuator {name!r}", joint)
    if el.params.get("rotor_inertia") and j.parent != "ground":
        raise ModelError(f"actuator {name!r}: rotor_inertia is reflected onto the joint's "
                         f"child, exact when the motor's stator is fixed; joint {joint!r} "
                         f"hangs from {j.parent!r}, which moves -- model the rotor as a body "
                         "instead, or give rotor_inertia = 0")
    system._forces[name] = el
    return name


@dataclass(frozen=True)
class Controller:
    """A controller written in Python, ``function(t, q, u)`` returning one effort per
    actuator of ``actuators`` (held actuators it writes), called ``rate`` times a second;
    the efforts are held between calls (zero-order hold)."""
    name: str
    function: object
    rate: float
    actuators: tuple


def add_controller(system, name, function, rate, joints, limit=None):
    """``System.add_controller``: a sampled controller on ``joints`` (one held actuator
    per joint, named ``NAME_JOINT``)."""
    problem = identifier_problem(name)
    if problem:
        raise ModelError(f"controller {name!r}: the name {problem}")
    if name in system._controllers:
        raise ModelError(f"controller {name!r}: the name is already used by a controller")
    if not callable(function):
        raise ModelError(f"controller {name!r}: function must be callable as "
                         "function(t, q, u) -> efforts, one per joint")
    try:
        rate = float(rate)
    except (TypeError, ValueError):
        raise ModelError(f"controller {name!r}: rate must be a number (Hz), got "
                         f"{rate!r}") from None
    if not rate > 0 or rate == float("inf"):
        raise ModelError(f"controller {name!r}: rate must be a positive, finite number of "
                         f"samples per second (Hz), got {rate!r}")
    if isinstance(joints, str):
        joints = [joints]
    joints = list(joints)
    if not joints:
        raise ModelError(f"controller {name!r}: give the joints it acts on")
    held = []
    for joint in joints:
        held.append(add_actuator(system, f"{name}_{joint}", joint, "held",
                                 **({} if limit is None else {"limit": limit})))
    system._controllers[name] = Controller(name, function, rate, tuple(held))
    return name


def attach_plant(system, model, state):
    """A model whose PD/PID actuators feed the computed torque forward gets its plant: the
    same system compiled without its actuators (``model._plant``), whose inverse dynamics
    at the setpoints is that torque (``integrate.sampled``)."""
    if not any(s.kind == "feedforward" for s in model._samplers):
        model._plant = None
        return
    off = {n: False for n, el in system._forces.items() if el.kind == "actuator"}
    model._plant = system.compile(check_inertia=False, effects={**state, **off})

"""What a URDF says beyond rigid bodies, as named effects and loop joints of the ``System``:
``<dynamics damping friction>`` (dampers and regularised Coulomb friction on the joint's
coordinate), ``<limit lower upper>`` (joint stops) and ``<mimic>`` (``coupling`` loop
joints).

A stop is a one-sided spring-damper on the coordinate (a ``joint-stop`` force element,
compiled): zero between the limits and beyond them ``k d + c v`` (``d`` the overshoot,
never pulling the joint back into the stop).  URDF gives no stiffness, so the stop's is scaled
to the joint: ``k = m (2 pi STOP_FREQUENCY)^2`` and ``c = 2 STOP_DAMPING_RATIO sqrt(k m)``,
``m`` the mass matrix's diagonal entry of the joint at the zero configuration (the inertia
the joint moves with the others held): the joint bounces off its stop at about
``STOP_FREQUENCY``, critically damped.
"""
from __future__ import annotations

import math

import sympy

#: slip speed (rad/s or m/s) of the regularised Coulomb friction ``F tanh(v / v_s)``
FRICTION_SLIP_SPEED = 0.01
#: the frequency (Hz) at which a joint rings against its stop
STOP_FREQUENCY = 50.0
#: the stop's damping ratio (1: critically damped, no bounce)
STOP_DAMPING_RATIO = 1.0
X, V = sympy.Symbol("x"), sympy.Symbol("v")


def add_effects(b, order):
    """Dampers, friction, stops and mimic couplings of the joints ``order`` (a
    ``RobotBuilder`` ``b``)."""
    if {"x", "v"} & set(b.system.parameters) and any(
            (j.dynamics or {}).get("friction") or j.limit for j in order):
        raise b.error("", "friction and joint stops are laws of x and v, which the model "
                      "also declares as parameters; rename those parameters")
    stops = []
    for joint in order:
        one_dof = joint.type in ("revolute", "continuous", "prismatic")
        dyn = joint.dynamics or {}
        if dyn and not one_dof and any(dyn.values()):
            b.warnings.append(f"{b.reader.file}: joint {joint.name!r}: <dynamics> of a "
                              f"{joint.type} joint is not used (only 1-DoF joints take it)")
            continue
        if not one_dof:
            continue
        c = b.coordinate[joint.name]
        if dyn.get("damping", 0.0) < 0 or dyn.get("friction", 0.0) < 0:
            raise b.error(f"joint {joint.name!r}", "<dynamics> damping and friction must "
                          "be >= 0")
        if dyn.get("damping"):
            _force(b, "damping", c, joint.name, damping=dyn["damping"])
        if dyn.get("friction"):
            law = dyn["friction"] * sympy.tanh(V / FRICTION_SLIP_SPEED)
            _force(b, "friction", c, joint.name, law=law)
        limit = joint.limit or {}
        if joint.type in ("revolute", "prismatic") and ("lower" in limit or "upper" in limit):
            lower, upper = limit.get("lower", -math.inf), limit.get("upper", math.inf)
            if lower > upper:
                raise b.error(f"joint {joint.name!r}", f"<limit> lower {lower:g} is above "
                              f"upper {upper:g}")
            stops.append((joint, c, lower, upper))
            if not lower <= 0.0 <= upper:
                b.warnings.append(f"{b.reader.file}: joint {joint.name!r}: its coordinate "
                                  f"starts at 0, outside its limits [{lower:g}, {upper:g}]: "
                                  "the stop pushes it in; give an initial value inside")
        elif joint.type == "revolute" and joint.limit is None:
            b.warnings.append(f"{b.reader.file}: joint {joint.name!r}: a revolute joint "
                              "without <limit> (URDF requires one); it turns freely")
    if stops:
        add_stops(b, stops)
    add_mimics(b, order)


def _force(b, what, coordinate, joint, **keys):
    name = f"{what}_{coordinate}"
    b.system.add_force(name, "joint-spring-damper", joint=joint, **keys)
    b.report["effects"].setdefault(what, []).append(name)


def add_stops(b, stops):
    """One stop per ``(joint, coordinate, lower, upper)``, scaled to the joint's inertia
    at the zero configuration."""
    model = b.system.compile(check_inertia=False)
    q = model.default_coordinates()
    # by the kernels a run compiles anyway (the kinematics, Jourdain's terms), not the
    # packed entry point of Model.mass_matrix: the same numbers, no compile of its own
    M = model._mass_matrix(q, 0.0, model._jourdain_terms)
    for joint, c, lower, upper in stops:
        speed = b.system.joints[joint.name].speeds[0]
        m = float(M[model.speeds.index(speed), model.speeds.index(speed)])
        if not m > 0:
            continue                    # no inertia: compile names the joint
        k = m * (2 * math.pi * STOP_FREQUENCY) ** 2
        damping = 2 * STOP_DAMPING_RATIO * math.sqrt(k * m)
        b.system.add_force(f"limit_{c}", "joint-stop", joint=joint.name, lower=lower,
                           upper=upper, stiffness=k, damping=damping)
        b.report["effects"].setdefault("limit", []).append(f"limit_{c}")
        b.report["stops"][f"limit_{c}"] = {"joint": joint.name, "lower": lower,
                                           "upper": upper, "stiffness": k,
                                           "damping": damping}


def add_mimics(b, order):
    """A ``coupling`` loop joint ``mimic_COORD`` for every ``<mimic>``:
    ``q_follower = multiplier q_leader + offset``."""
    for joint in order:
        if not joint.mimic:
            continue
        where = f"joint {joint.name!r}"
        leader = joint.mimic["joint"]
        if leader not in b.robot.joints:
            raise b.error(where, f"<mimic joint={leader!r}>: no such joint")
        for name in (joint.name, leader):
            if b.robot.joints[name].type not in ("revolute", "continuous", "prismatic"):
                raise b.error(where, f"<mimic>: joint {name!r} is "
                              f"{b.robot.joints[name].type}; a mimic couples two revolute, "
                              "continuous or prismatic joints")
        if leader == joint.name:
            raise b.error(where, "<mimic> names the joint itself")
        name = f"mimic_{b.coordinate[joint.name]}"
        b.system.add_joint(name, "coupling", follower=joint.name, leader=leader,
                           ratio=joint.mimic.get("multiplier", 1.0),
                           offset=joint.mimic.get("offset", 0.0))
        b.joints.append(name)
        b.report["effects"].setdefault("mimic", []).append(name)

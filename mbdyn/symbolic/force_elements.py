"""Force elements in closed form, as body wrenches added to the walk's applied loads: a
spring-damper's tension along the line of its points, a joint spring-damper's effort on
its coordinate, a bushing's 6x6 law, a bearing's eight coefficients (tabulated ones as
named functions of the spin speed), a contact's Hunt-Crossley force and regularised
friction.  The same wrenches as ``mbdyn.kernels.forces`` computes numerically.
"""
from __future__ import annotations

import numpy as np
import sympy

from ..elements.tables import Table
from ..errors import ModelError
from .symbols import canonical, exact, exact_vector

Z3 = sympy.zeros(3, 1)


def apply_forces(walk):
    """Every force element of the walk's model, as wrenches on its frames."""
    for el in getattr(walk.model, "_force_elements", ()):
        p = el.params
        tabulated = [k for k in ("force_table", "damping_table", "torque_speed")
                     if p.get(k) is not None]
        if tabulated:
            raise ModelError(f"force {el.name!r}: the symbolic layer writes linear springs "
                             "and dampers in closed form, not tabulated laws; switch it off "
                             f"to derive the rest (--effects=-{el.name})")
        law = p.get("law")
        if law is not None and law.expression is None:
            raise ModelError(f"force {el.name!r}: its law is a Python function; the symbolic "
                             "layer needs it as an expression of x and v (or switch it off: "
                             f"--effects=-{el.name})")
        KINDS[el.kind](walk, el, law)


def _param(walk, el, key):
    value = el.symbolic.get(key, el.params[key])
    if isinstance(value, sympy.Basic):
        return canonical(value, walk.sym.table)
    return exact(value)


def _vector(walk, el, key):
    return exact_vector(el.symbolic.get(key, el.params[key]), walk.sym.table)


def _law(walk, law, x, v):
    """A law's expression with the elongation ``x`` and its rate ``v`` put in."""
    e = law.expression
    e = e.xreplace({s: (x if s.name == "x" else v) for s in e.free_symbols
                    if s.name in ("x", "v")})
    return canonical(e, walk.sym.table)


def spring_damper(walk, el, law):
    k, c, F0 = (_param(walk, el, key) for key in ("stiffness", "damping", "preload"))
    pa, pb = _vector(walk, el, "point_a"), _vector(walk, el, "point_b")
    a, b = el.frames
    d = walk._world_point(b, pb) - walk._world_point(a, pa)
    L = sympy.sqrt((d.T * d)[0])
    x = L - _param(walk, el, "free_length")
    T = (_law(walk, law, x, walk.D(L)) if law is not None
         else F0 + k * x + c * walk.D(L))
    f = d * (T / L)
    walk._add_wrench(el.name, a, f, Z3, pa)
    walk._add_wrench(el.name, b, -f, Z3, pb)


def joint_spring_damper(walk, el, law):
    k, c, F0 = (_param(walk, el, key) for key in ("stiffness", "damping", "preload"))
    joint = next(j for j in walk.joints if j.name == el.params["joint"])
    qj, uj, _, driven = walk.joint_values[joint.name]
    x = qj[0] - _param(walk, el, "rest")
    tau = -(_law(walk, law, x, uj[0]) if law is not None else F0 + k * x + c * uj[0])
    joint_effort(walk, el, joint, tau)


def joint_effort(walk, el, joint, tau):
    """The effort ``tau`` on a revolute or prismatic joint's coordinate, on its child and,
    opposite, its parent."""
    m = walk.by_name[joint.child]
    axis = walk._joint_geometry(joint)[0]
    # the axis in world components: joint frame J0 = child axes along the axis
    axis_w = walk.s(walk._R_world(joint.child) * axis)
    if joint.kind == "revolute":
        walk._add_wrench(el.name, joint.child, Z3, tau * axis_w, Z3)
        walk._add_wrench(el.name, joint.parent, Z3, -tau * axis_w, Z3)
    else:
        walk._add_wrench(el.name, joint.child, tau * axis_w, Z3, Z3)
        if joint.parent != "ground":
            walk._add_wrench(el.name, joint.parent, -tau * axis_w, Z3, m.rho_p)


def bushing(walk, el, law):
    p = el.params
    a, b = el.frames
    pa, pb = _vector(walk, el, "point_a"), _vector(walk, el, "point_b")
    Ra = walk._R_world(a)
    pbw = walk._world_point(b, pb)
    x = walk.s(Ra.T * (pbw - walk._world_point(a, pa)))
    Rrel = walk.s(Ra.T * walk._R_world(b))
    theta = sympy.Matrix([Rrel[2, 1] - Rrel[1, 2], Rrel[0, 2] - Rrel[2, 0],
                          Rrel[1, 0] - Rrel[0, 1]]) / 2
    xd = walk.s(walk.D(x))
    thd = walk.s(Ra.T * (walk._omega_world(b) - walk._omega_world(a)))
    K = sympy.Matrix(6, 6, [exact(v) for v in np.ravel(p["stiffness"])])
    C = sympy.Matrix(6, 6, [exact(v) for v in np.ravel(p["damping"])])
    w6 = -(K * x.col_join(theta) + C * xd.col_join(thd))
    f, mo = walk.s(Ra * w6[:3, 0]), walk.s(Ra * w6[3:, 0])
    walk._add_wrench(el.name, b, f, mo, pb)
    walk._add_wrench(el.name, a, -f, -mo, walk._own_point(a, pbw))


def _spin(walk, name):
    """The speed a bearing's coefficients depend on: a speed symbol, or a driven joint's
    prescribed rate."""
    for j in walk.joints:
        qj, uj, _, driven = walk.joint_values[j.name]
        if j.nu == 1 and (name == j.name or name in j.coordinates or name in j.speeds):
            return uj[0]
    raise ModelError(f"unknown spin speed {name!r}")


def _coefficient(walk, el, key):
    """A bearing coefficient: a number, or a table as a named function of the spin speed
    (``kxx_bearing(spin)``) that evaluates by the table's interpolation."""
    value = el.params[key]
    if hasattr(value, "block"):                     # a Table
        from sympy.utilities.lambdify import implemented_function
        fn = implemented_function(f"{key}_{el.name}", value)
        return fn(_spin(walk, el.params["speed"]))
    return _param(walk, el, key)


def bearing(walk, el, law):
    a, b = el.frames
    Rb = walk._R_world(b)
    e1 = walk.s(Rb * _vector(walk, el, "e1"))
    e2 = walk.s(Rb * _vector(walk, el, "e2"))
    pa = _vector(walk, el, "point")
    paw = walk._world_point(a, pa)
    d = paw - walk._world_point(b, _vector(walk, el, "center"))
    x, y = (e1.T * d)[0], (e2.T * d)[0]
    xd, yd = walk.D(x), walk.D(y)
    kxx, kxy, kyx, kyy, cxx, cxy, cyx, cyy = (
        _coefficient(walk, el, c) for c in ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy",
                                            "cyx", "cyy"))
    fx = -(kxx * x + kxy * y + cxx * xd + cxy * yd)
    fy = -(kyx * x + kyy * y + cyx * xd + cyy * yd)
    f = walk.s(e1 * fx + e2 * fy)
    walk._add_wrench(el.name, a, f, Z3, pa)
    walk._add_wrench(el.name, b, -f, Z3, walk._own_point(b, paw))


def contact(walk, el, law):
    p = el.params
    a = el.frames[0]
    n = _vector(walk, el, "plane_normal")
    radius = _param(walk, el, "radius")
    centre = walk._world_point(a, _vector(walk, el, "center"))
    if p["shape"] == "disk":
        ax = walk._R_world(a) * _vector(walk, el, "axis")
        side = -n + (n.T * ax)[0] * ax
        pc = centre + radius * side / sympy.sqrt((side.T * side)[0])
    else:
        pc = centre - radius * n
    pc = walk.s(pc)
    delta = -((pc - _vector(walk, el, "plane_point")).T * n)[0]
    own = walk._own_point(a, pc)
    vc = walk._world_velocity(a) + walk._omega_world(a).cross(
        pc - walk._world_point(a, Z3))
    vn = (vc.T * n)[0]
    k = _param(walk, el, "stiffness")
    ex = _param(walk, el, "exponent")
    chc = exact(p["damping_factor"])
    fn = sympy.Max(0, k * delta ** ex * (1 - chc * vn))
    vt = vc - vn * n
    ft = -_param(walk, el, "friction") * fn / sympy.sqrt(
        (vt.T * vt)[0] + _param(walk, el, "slip_speed") ** 2)
    f = (fn * n + ft * vt).applyfunc(lambda e: sympy.Piecewise((e, delta > 0), (0, True)))
    walk._add_wrench(el.name, a, f, Z3, own)


def shape_contact(walk, el, law):
    raise ModelError(f"contact {el.name!r}: contact between shapes (a broad phase, nearest "
                     "points, cam profiles) has no closed form in the symbolic layer; switch "
                     f"it off to derive the rest (--effects=-{el.name})")


#: each force-element kind's wrenches
KINDS = {"spring-damper": spring_damper, "joint-spring-damper": joint_spring_damper,
         "bushing": bushing, "bearing": bearing, "contact": contact,
         "joint-stop": lambda walk, el, law: joint_stop(walk, el),
         "actuator": lambda walk, el, law: actuator(walk, el),
         "shape-contact": shape_contact}


def joint_stop(walk, el):
    """``-max(k (q - upper) + c u, 0)`` above the upper bound, ``-min(k (q - lower) + c u,
    0)`` below the lower one, zero between (``kernels.actuation.stop_effort``)."""
    p = el.params
    joint = next(j for j in walk.joints if j.name == p["joint"])
    qj, uj, _, _ = walk.joint_values[joint.name]
    x, v = qj[0], uj[0]
    k, c = exact(p["stiffness"]), exact(p["damping"])
    pieces = []
    if np.isfinite(p["upper"]):
        up = exact(p["upper"])
        pieces.append((sympy.Max(k * (x - up) + c * v, 0), x > up))
    if np.isfinite(p["lower"]):
        lo = exact(p["lower"])
        pieces.append((sympy.Min(k * (x - lo) + c * v, 0), x < lo))
    joint_effort(walk, el, joint, -sympy.Piecewise(*pieces, (0, True)))


def actuator(walk, el):
    """An actuator's effort in closed form: a torque given as a number or an expression,
    a PD law on a setpoint of ``t``, a motor's torque-speed line; a PID, a table, a
    controller in Python or gravity compensation are refused (their state or their data
    are not closed forms)."""
    p = el.params
    kind = p["type"]
    refuse = ("pid", "held")
    if (kind in refuse or p.get("gravity_compensation")
            or any(isinstance(p.get(k), Table) for k in ("value", "setpoint", "command"))):
        raise ModelError(f"actuator {el.name!r}: the symbolic layer writes torques, PD laws "
                         "and motors given by numbers or expressions, not PID integrals, "
                         "sampled controllers, tables or gravity compensation; switch it "
                         f"off to derive the rest (--effects=-{el.name})")
    joint = next(j for j in walk.joints if j.name == p["joint"])
    qj, uj, _, _ = walk.joint_values[joint.name]
    value = (lambda key: canonical(sympy.sympify(p[key]), walk.sym.table))
    if kind == "torque":
        tau = value("value")
    elif kind == "pd":
        s = value("setpoint")
        tau = (exact(p["kp"]) * (s - qj[0])
               + exact(p["kd"]) * (sympy.diff(s, walk.sym.t) - uj[0]))
    else:
        gear = exact(p["gear"])
        tau = gear * (exact(p["stall_torque"]) * (value("command")
                                                 - gear * uj[0] / exact(p["no_load_speed"])))
    if np.isfinite(p["limit"]):
        lim = exact(p["limit"])
        tau = sympy.Min(sympy.Max(tau, -lim), lim)
    joint_effort(walk, el, joint, tau)


def reflected_inertia(model, body):
    """The rotor inertia of the motors whose joint's child is ``body``, seen through their
    gears, ``gear^2 J a a^T`` about the joint axis ``a`` (child axes): what
    ``compiled.actuator_packing.reflect_rotors`` adds to the numeric inertia."""
    out = sympy.zeros(3, 3)
    for el in getattr(model, "_force_elements", ()):
        p = el.params
        if el.kind != "actuator" or not p.get("rotor_inertia"):
            continue
        joint = model._joint[p["joint"]]
        if joint.child == body:
            a = sympy.Matrix([exact(x) for x in joint.axis])
            out += exact(p["gear"]) ** 2 * exact(p["rotor_inertia"]) * (a * a.T)
    return out

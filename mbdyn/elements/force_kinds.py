"""One builder per force-element kind: each reads its keywords (a ``Given``), checks them
and returns ``(params, frames)``; ``BUILDERS`` maps the kind to its builder, in the order
of ``mbdyn.forces.KINDS``.  The physics a kind needs at build time stays beside it: the
bearing's radial directions, the contact's Hunt-Crossley damping from a restitution.
"""
from __future__ import annotations

import functools

import numpy as np

from ..errors import ModelError
from .actuators import joint_stop
from .force_values import make_law, number
from .tables import Table, make_table
from .values import numeric, parse_axis

BEARING_COEFFICIENTS = ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy")


# ---------------------------------------------------------------- springs and dampers
def _check_spring(g, rest):
    """A (joint) spring-damper's force: a law alone, or stiffness and/or damping, each a
    number or a table but not both; ``rest`` names the key of its unstretched state."""
    kw, element = g.kw, g.element
    if kw.get("law") is not None:
        clash = [k for k in ("stiffness", "damping", "force_table", "damping_table", "preload")
                 if kw.get(k) is not None]
        if clash:
            raise ModelError(f"{element}: law gives the whole force; remove "
                             f"{', '.join(clash)} (or drop the law)")
    if all(kw.get(k) is None for k in ("stiffness", "force_table", "damping",
                                        "damping_table", "law")):
        raise ModelError(f"{element}: missing stiffness: give stiffness (and {rest}), a "
                         "force_table, or damping")


def _spring_params(g, rest, rest_minimum):
    """Stiffness, damping, the ``rest`` length or coordinate, preload and the tables of a
    (joint) spring-damper, read in this order."""
    kw = g.kw
    return {
        "stiffness": g.num(kw.get("stiffness") or 0.0, what="stiffness"),
        "damping": g.num(kw.get("damping") or 0.0, what="damping", minimum=0.0),
        rest: g.num(kw.get(rest, 0.0), what=rest, minimum=rest_minimum),
        "preload": g.num(kw.get("preload", 0.0), what="preload"),
        "force_table": g.table("force_table"),
        "damping_table": g.table("damping_table"),
    }


def spring_damper(g):
    kw, element = g.kw, g.element
    g.check_keys(("body_a", "point_a", "body_b", "point_b", "stiffness", "damping",
                  "free_length", "preload", "force_table", "damping_table",
                  "interpolation", "min_length", "law"), "spring-damper",
                 "body_a", "give body_a (and body_b, default the ground)")
    _check_spring(g, "free_length")
    if kw.get("stiffness") is not None and kw.get("force_table") is not None:
        raise ModelError(f"{element}: give either stiffness or force_table, not both")
    if kw.get("damping") is not None and kw.get("damping_table") is not None:
        raise ModelError(f"{element}: give either damping or damping_table, not both")
    params = {
        "point_a": g.vector("point_a"),
        "point_b": g.vector("point_b"),
        **_spring_params(g, "free_length", 0.0),
        "min_length": g.num(kw.get("min_length", 1e-9), what="min_length", positive=True),
        "law": make_law(kw.get("law"), g.parameters, element),
    }
    dt = params["damping_table"]
    if dt is not None and np.any(np.diff(dt.y) < 0):
        raise ModelError(f"{element}: damping_table must not decrease (a damper's force "
                         "grows with the rate of elongation); a falling segment feeds "
                         "energy in")
    return params, g.two_frames("a spring")


def joint_spring_damper(g):
    kw, element = g.kw, g.element
    g.check_keys(("joint", "stiffness", "damping", "rest", "preload", "force_table",
                  "damping_table", "interpolation", "law"), "joint-spring-damper",
                 "joint", "give the joint whose coordinate it acts on")
    if not isinstance(kw["joint"], str):
        raise ModelError(f"{element}: joint must be the name of a joint, got "
                         f"{kw['joint']!r}")
    _check_spring(g, "rest")
    params = {
        "joint": kw["joint"],
        **_spring_params(g, "rest", None),
        "law": make_law(kw.get("law"), g.parameters, element),
    }
    return params, ()


def bushing(g):
    kw, element = g.kw, g.element
    g.check_keys(("body_a", "point_a", "body_b", "point_b", "stiffness", "damping"),
                 "bushing", "body_a", "give body_a (and body_b, default the ground)")
    if kw.get("stiffness") is None:
        raise ModelError(f"{element}: missing stiffness: give six diagonal values or a "
                         "6x6 matrix (translation then rotation, frame a's axes)")
    C = g.matrix6(kw.get("damping", [0] * 6), "damping")
    if np.linalg.eigvalsh(0.5 * (C + C.T))[0] < -1e-12 * max(1.0, np.abs(C).max()):
        raise ModelError(f"{element}: damping must be positive semi-definite (its "
                         "symmetric part has a negative eigenvalue: it feeds energy in)")
    params = {
        "point_a": g.vector("point_a"),
        "point_b": g.vector("point_b"),
        "stiffness": g.matrix6(kw["stiffness"], "stiffness"),
        "damping": C,
    }
    return params, g.two_frames("a bushing")


# ---------------------------------------------------------------- journal bearings
def radial_directions(axis):
    """The bearing's x and y directions across a shaft ``axis``: ``e1 x e2 = axis``, and
    for a coordinate axis the next two in cyclic order (axis x: y, z; axis z: x, y)."""
    i = int(np.argmax(np.abs(axis)))
    helper = np.eye(3)[(i + 1) % 3]
    e1 = helper - (helper @ axis) * axis
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(axis, e1)


def _bearing_speeds(g):
    """The spin speeds of a bearing's tabulated coefficients, or None."""
    speeds = g.kw.get("speeds")
    if speeds is not None:
        try:
            speeds = np.asarray(speeds, dtype=float)
        except (TypeError, ValueError):
            speeds = None
        if speeds is None or speeds.ndim != 1:
            raise ModelError(f"{g.element}: speeds must be a list of spin speeds (rad/s), "
                             f"one per row of the tabulated coefficients, got "
                             f"{g.kw['speeds']!r}")
    return speeds


def _bearing_coefficients(g, speeds):
    """The eight coefficients, each a number or a ``Table`` against the spin speed."""
    element = g.element
    coeffs = {}
    for c in BEARING_COEFFICIENTS:
        val = g.kw.get(c, 0.0)
        if isinstance(val, (list, tuple, np.ndarray)):
            if speeds is None:
                raise ModelError(f"{element}: {c} is tabulated, so give `speeds`, the "
                                 "spin speeds (rad/s) of the table's rows")
            if len(val) != len(speeds):
                raise ModelError(f"{element}: {c} has {len(val)} values but speeds has "
                                 f"{len(speeds)}; give one value per speed")
            coeffs[c] = make_table({"x": speeds, "y": val}, element, c, g.interp, clamp=True)
        else:
            coeffs[c] = g.num(val, what=c)
    tabulated = [c for c in BEARING_COEFFICIENTS if isinstance(coeffs[c], Table)]
    if tabulated and g.kw.get("speed") is None:
        raise ModelError(f"{element}: tabulated coefficients need `speed`: the name of "
                         "the spin speed (a speed, a coordinate or a driven joint)")
    for c in ("cxx", "cyy"):
        vals = coeffs[c].y if isinstance(coeffs[c], Table) else [coeffs[c]]
        if np.min(vals) < 0:
            raise ModelError(f"{element}: {c} must be >= 0 (a negative direct damping "
                             "feeds energy in)")
    return coeffs


def bearing(g):
    kw, element = g.kw, g.element
    g.check_keys(("body", "point", "housing", "center", "axis", "speed", "speeds",
                  "interpolation") + BEARING_COEFFICIENTS, "bearing",
                 "body", "give the shaft body (body = ...)")
    missing = [c for c in ("kxx", "kyy") if kw.get(c) is None]
    if missing:
        raise ModelError(f"{element}: missing stiffness {', '.join(missing)}: a bearing "
                         "needs at least kxx and kyy (kxy, kyx, c.. default to 0)")
    speeds = _bearing_speeds(g)
    params = _bearing_coefficients(g, speeds)
    axis = parse_axis(kw.get("axis", "x"), element)
    e1, e2 = radial_directions(axis)
    params.update({
        "point": g.vector("point"),
        "center": g.vector("center"),
        "axis": axis, "e1": e1, "e2": e2, "speed": kw.get("speed"),
        "speeds": None if speeds is None else np.asarray(speeds, float),
    })
    frames = (kw["body"], kw.get("housing", "ground"))
    for key, frame in zip(("body", "housing"), frames):
        if not isinstance(frame, str):
            raise ModelError(f"{element}: {key} must be the name of a body, got "
                             f"{frame!r}")
    if frames[0] in ("ground", frames[1]):
        raise ModelError(f"{element}: the shaft body is {frames[0]!r} and the housing "
                         f"{frames[1]!r}; a bearing acts between a shaft body and its "
                         "housing (another body, or the ground)")
    return params, frames


# ---------------------------------------------------------------- contacts
def contact(g):
    kw, element = g.kw, g.element
    g.check_keys(("body", "center", "radius", "shape", "axis", "plane_point",
                  "plane_normal", "stiffness", "exponent", "restitution",
                  "impact_speed", "friction", "slip_speed"), "contact",
                 "body", "give the body that touches (body = ...)")
    if kw.get("stiffness") is None:
        raise ModelError(f"{element}: missing stiffness (N/m^exponent) of the contact")
    shape = kw.get("shape", "sphere")
    if shape not in ("sphere", "disk"):
        raise ModelError(f"{element}: shape {shape!r} is not 'sphere' or 'disk'")
    normal = kw.get("plane_normal")
    if normal is None:
        gravity = np.asarray(g.gravity, float)
        normal = -gravity if np.linalg.norm(gravity) > 0 else (0.0, 0.0, 1.0)
    num = g.num
    params = {
        "shape": shape,
        "center": g.vector("center"),
        "radius": num(kw.get("radius", 0.0), what="radius", minimum=0.0),
        "axis": (parse_axis(kw.get("axis", "z"), element) if shape == "disk"
                 else np.array([0.0, 0.0, 1.0])),
        "plane_point": g.vector("plane_point"),
        "plane_normal": parse_axis(numeric(normal, g.parameters, element, "plane_normal"),
                                   element),
        **compliant_law(element, g.parameters, kw),
    }
    return params, (kw["body"],)


def compliant_law(element, parameters, kw):
    """The numbers of a compliant contact's law from its keys ``kw``, read and checked:
    ``stiffness`` (required), ``exponent``, ``restitution`` in (0, 1] at
    ``impact_speed``, ``friction``, ``slip_speed``, and the Hunt-Crossley
    ``damping_factor`` per unit speed they make (the floor contact's and the contacts
    between shapes')."""
    if kw.get("stiffness") is None:
        raise ModelError(f"{element}: missing stiffness (N/m^exponent) of the contact")

    def num(key, default, **check):
        return number(kw.get(key, default), parameters, element, key, **check)
    params = {
        "stiffness": num("stiffness", None, positive=True),
        "exponent": num("exponent", 1.5, positive=True),
        "restitution": num("restitution", 1.0, minimum=0.0),
        "impact_speed": num("impact_speed", 1.0, positive=True),
        "friction": num("friction", 0.0, minimum=0.0),
        "slip_speed": num("slip_speed", 1e-3, positive=True),
    }
    if params["restitution"] > 1.0:
        raise ModelError(f"{element}: restitution must be in (0, 1], got "
                         f"{params['restitution']:g}")
    if params["restitution"] == 0.0:
        raise ModelError(f"{element}: restitution 0 needs infinite damping; give a small "
                         "positive value such as 0.05")
    try:
        factor = hunt_crossley_factor(params["restitution"], params["exponent"])
    except ModelError as exc:
        raise ModelError(f"{element}: {exc}") from None
    params["damping_factor"] = factor / params["impact_speed"]
    return params


@functools.lru_cache(maxsize=64)
def hunt_crossley_factor(restitution, exponent):
    """``z = c v`` such that a Hunt-Crossley contact ``F = k d^n (1 + c d')`` returns an
    impact at speed ``v`` with the coefficient of restitution ``e``.

    In the scaled variables ``d = a x``, ``t = b s`` with ``a/b = v`` the impact is
    ``x'' = -x^n (1 + z x')``, ``x(0) = 0``, ``x'(0) = 1``: the restitution depends on
    ``z = c v`` and ``n`` only, so ``z`` is found once by root finding on that equation.
    The contact releases when the force reaches zero (it never pulls).
    """
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq
    if restitution >= 1.0:
        return 0.0

    def e_of(z):
        def rhs(s, y):
            x, xd = y
            f = max(x, 0.0) ** exponent * (1.0 + z * xd)
            return [xd, -max(f, 0.0)]

        def released(s, y):             # force back to zero: x = 0 or 1 + z x' = 0
            return min(y[0], 1.0 + z * y[1]) if s > 0 else 1.0
        released.terminal, released.direction = True, -1
        with np.errstate(all="ignore"):
            sol = solve_ivp(rhs, (0, 1e3), [0.0, 1.0], events=released, rtol=1e-11,
                            atol=1e-13, method="DOP853", max_step=0.05)
        if sol.y_events is None or not len(sol.y_events[0]):
            raise ModelError(f"exponent {exponent:g}: the impact of a Hunt-Crossley contact "
                             "cannot be computed with it (the force overflows); give a "
                             "moderate exponent such as 1.5 (Hertz)")
        return -sol.y_events[0][0][1]
    lo, hi = 1e-9, 1.0
    while e_of(hi) > restitution:
        hi *= 4.0
        if hi > 1e8:
            raise ModelError(f"restitution {restitution:g} is too small to model with "
                             "Hunt-Crossley damping; give a larger value")
    return brentq(lambda z: e_of(z) - restitution, lo, hi, xtol=1e-14, rtol=1e-12)


#: kind -> builder, in the order the kinds are listed
BUILDERS = {"spring-damper": spring_damper, "joint-spring-damper": joint_spring_damper,
            "bushing": bushing, "bearing": bearing, "contact": contact,
            "joint-stop": joint_stop}

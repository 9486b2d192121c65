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

Tables are interpolated monotonically: ``"pchip"`` (piecewise-cubic Hermite that keeps
monotone data monotone; the default) or ``"linear"``; never a smoothing spline.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..names import identifier_problem
from .values import _vector3, has_symbols, numeric, parse_axis

KINDS = ("spring-damper", "joint-spring-damper", "bushing", "bearing", "contact")
INTERPOLATIONS = ("pchip", "linear")
BEARING_COEFFICIENTS = ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy")
#: the effects that are not elements
GLOBAL_EFFECTS = ("gravity", "gyroscopic")


@dataclass(frozen=True)
class Table:
    """A monotone interpolation table ``y(x)``: strictly increasing knots ``x``."""
    x: np.ndarray
    y: np.ndarray
    interpolation: str = "pchip"
    clamp: bool = False           # hold the end values outside the knots (else extrapolate)

    def block(self):
        """The kernel's table block ``[n, clamp, x, y, slopes, integral]`` (see
        ``kernels.forces``)."""
        x, y = self.x, self.y
        n = len(x)
        h = np.diff(x)
        secant = np.diff(y) / h
        if self.interpolation == "pchip" and n > 2:
            from scipy.interpolate import PchipInterpolator
            d = PchipInterpolator(x, y).derivative()(x)
        else:
            d = np.empty(n)
            d[:-1] = secant
            d[-1] = secant[-1]
            if self.interpolation == "pchip":          # two knots: the line through them
                d[:] = secant[0]
        integral = np.zeros(n)
        for k in range(n - 1):                         # exact integral of each segment
            if self.interpolation == "linear":
                seg = h[k] * 0.5 * (y[k] + y[k + 1])
            else:
                seg = h[k] * (0.5 * (y[k] + y[k + 1]) + h[k] * (d[k] - d[k + 1]) / 12.0)
            integral[k + 1] = integral[k] + seg
        return np.concatenate([[n, 1.0 if self.clamp else 0.0], x, y, d, integral])

    @property
    def mode(self):
        return 1 if self.interpolation == "linear" else 2

    def __call__(self, x):
        """The interpolant at ``x`` (numpy; for reports and tests)."""
        from ..kernels.forces import table_eval
        blk = self.block()
        out = np.empty(3)
        table_eval(blk, 0, self.mode, float(x), out)
        return float(out[0])


def make_table(value, element, what, interpolation="pchip", clamp=False):
    """A ``Table`` from ``[[x0, y0], [x1, y1], ...]`` or ``{"x": [...], "y": [...]}`` or a
    pair of sequences ``(xs, ys)``; refuses unsorted or repeated knots, mismatched lengths,
    fewer than two points and non-finite values, naming the element and key."""
    if interpolation not in INTERPOLATIONS:
        raise ModelError(f"{element}: interpolation {interpolation!r} is not one of "
                         f"{', '.join(INTERPOLATIONS)} (tables are interpolated monotonically; "
                         "a smoothing spline would overshoot)")
    if isinstance(value, dict):
        if set(value) != {"x", "y"}:
            raise ModelError(f"{element}: {what} must have keys 'x' and 'y', got "
                             f"{sorted(value)}")
        xs, ys = value["x"], value["y"]
    elif (isinstance(value, (tuple, list)) and len(value) == 2
          and all(isinstance(v, (tuple, list, np.ndarray)) for v in value)
          and not all(len(v) == 2 for v in value)):
        xs, ys = value
    else:
        try:
            pairs = [tuple(p) for p in value]
        except TypeError:
            raise ModelError(f"{element}: {what} must be a list of [x, y] pairs") from None
        if any(len(p) != 2 for p in pairs):
            raise ModelError(f"{element}: {what} must be a list of [x, y] pairs")
        xs, ys = [p[0] for p in pairs], [p[1] for p in pairs]
    try:
        x = np.asarray(xs, dtype=float).reshape(-1)
        y = np.asarray(ys, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {what} must hold numbers") from None
    if x.size != y.size:
        raise ModelError(f"{element}: {what} has {x.size} abscissae but {y.size} values; "
                         "give one value per abscissa")
    if x.size < 2:
        raise ModelError(f"{element}: {what} needs at least two points")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ModelError(f"{element}: {what} holds non-finite numbers")
    if np.any(np.diff(x) <= 0):
        k = int(np.argmax(np.diff(x) <= 0))
        raise ModelError(f"{element}: {what} is not monotone: its abscissae must increase "
                         f"strictly, but {x[k]:g} is followed by {x[k + 1]:g}; sort the rows "
                         "and remove repeated abscissae")
    return Table(x, y, interpolation, clamp)


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
            law = ("table" if p["force_table"] is not None else
                   f"k = {p['stiffness']:g}, rest {p['rest']:g}")
            return f"on joint {p['joint']!r}: {law}, c = {p['damping']:g}"
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


def radial_directions(axis):
    """The bearing's x and y directions across a shaft ``axis``: ``e1 x e2 = axis``, and
    for a coordinate axis the next two in cyclic order (axis x: y, z; axis z: x, y)."""
    i = int(np.argmax(np.abs(axis)))
    helper = np.eye(3)[(i + 1) % 3]
    e1 = helper - (helper @ axis) * axis
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(axis, e1)


@dataclass(frozen=True)
class Law:
    """A force law ``law(x, v)`` of an elongation (or coordinate offset) ``x`` and its rate
    ``v``: ``function`` for the numbers, ``expression`` (sympy, in the symbols ``x`` and
    ``v`` and the system's parameters) when it was given as one, for the symbolic layer."""
    function: object
    expression: object = None

    def __call__(self, x, v):
        return self.function(x, v)


def make_law(law, parameters, element):
    """A ``Law`` from a callable ``f(x, v)`` or a sympy expression of ``x`` and ``v``."""
    if law is None:
        return None
    if callable(law) and not hasattr(law, "free_symbols"):
        return Law(law)
    import sympy
    if not isinstance(law, sympy.Basic):
        raise ModelError(f"{element}: law must be a function f(x, v) or a sympy expression of "
                         "x (elongation) and v (its rate)")
    named = {s.name: s for s in law.free_symbols}
    extra = sorted(set(named) - {"x", "v"} - set(parameters))
    if extra:
        raise ModelError(f"{element}: law uses {', '.join(extra)}, which are neither x, v nor "
                         "parameters of the system")
    numeric_law = law.subs({named[n]: parameters[n] for n in named if n in parameters})
    xs, vs = sympy.Symbol("x"), sympy.Symbol("v")
    numeric_law = numeric_law.subs({s: (xs if s.name == "x" else vs)
                                    for s in numeric_law.free_symbols})
    fn = sympy.lambdify((xs, vs), numeric_law, "math")
    return Law(lambda x, v: float(fn(x, v)), law)


def _check_law(kw, element):
    if kw.get("law") is not None:
        clash = [k for k in ("stiffness", "damping", "force_table", "damping_table", "preload")
                 if kw.get(k) is not None]
        if clash:
            raise ModelError(f"{element}: law gives the whole force; remove "
                             f"{', '.join(clash)} (or drop the law)")


def _number(value, parameters, element, what, minimum=None, positive=False):
    v = numeric(value, parameters, element, what)
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {what} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ModelError(f"{element}: {what} must be finite, got {value!r}")
    if positive and v <= 0:
        raise ModelError(f"{element}: {what} must be positive, got {v:g}")
    if minimum is not None and v < minimum:
        raise ModelError(f"{element}: {what} must be >= {minimum:g}, got {v:g}"
                         + ("; a negative damping feeds energy in" if "damping" in what else ""))
    return v


def _matrix6(value, parameters, element, what):
    v = numeric(value, parameters, element, what)
    try:
        arr = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {what} must be six diagonal values or a 6x6 "
                         "matrix") from None
    if arr.shape == (6,):
        arr = np.diag(arr)
    if arr.shape != (6, 6):
        raise ModelError(f"{element}: {what} must be six diagonal values or a 6x6 matrix, "
                         f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ModelError(f"{element}: {what} holds non-finite numbers")
    return arr


def _unknown_keys(kw, allowed, element, kind):
    extra = sorted(set(kw) - set(allowed))
    if extra:
        raise ModelError(f"{element}: unknown key(s) {', '.join(extra)} for a {kind}; "
                         f"known: {', '.join(sorted(allowed))}")


def _two_frames(kw, element, what):
    """``(body_a, body_b)`` of an element between two frames (``body_b`` default the
    ground): names, and two different ones."""
    frames = (kw["body_a"], kw.get("body_b", "ground"))
    for key, frame in zip(("body_a", "body_b"), frames):
        if not isinstance(frame, str):
            raise ModelError(f"{element}: {key} must be the name of a body, got {frame!r}")
    if frames[0] == frames[1]:
        raise ModelError(f"{element}: body_a and body_b are both {frames[0]!r}; {what} acts "
                         "between two bodies (or a body and the ground)")
    return frames


def make_force(name, kind, parameters=None, gravity=(0.0, 0.0, -9.81), **kw):
    """Validate and build a ``ForceElement`` (frames are checked against the tree by
    ``System.add_force``)."""
    element = f"force {name!r}"
    parameters = parameters or {}
    problem = identifier_problem(name)
    if problem:
        raise ModelError(f"force {name!r}: the name {problem}; it names the element's "
                         "effect")
    if name in GLOBAL_EFFECTS:
        raise ModelError(f"{element}: the name is reserved for the {name} effect; choose "
                         "another")
    if kind not in KINDS:
        raise ModelError(f"{element}: unknown kind {kind!r}; use one of {', '.join(KINDS)}")
    symbolic = {k: v for k, v in kw.items() if not isinstance(v, str) and has_symbols(v)}
    num = functools.partial(_number, parameters=parameters, element=element)
    interp = kw.get("interpolation", "pchip")

    def table(key, clamp=False):
        return (None if kw.get(key) is None
                else make_table(kw[key], element, key, interp, clamp))

    if kind == "spring-damper":
        _unknown_keys(kw, ("body_a", "point_a", "body_b", "point_b", "stiffness", "damping",
                           "free_length", "preload", "force_table", "damping_table",
                           "interpolation", "min_length", "law"), element, kind)
        if "body_a" not in kw:
            raise ModelError(f"{element}: give body_a (and body_b, default the ground)")
        _check_law(kw, element)
        if all(kw.get(k) is None for k in ("stiffness", "force_table", "damping",
                                            "damping_table", "law")):
            raise ModelError(f"{element}: missing stiffness: give stiffness (and free_length), "
                             "a force_table, or damping")
        if kw.get("stiffness") is not None and kw.get("force_table") is not None:
            raise ModelError(f"{element}: give either stiffness or force_table, not both")
        if kw.get("damping") is not None and kw.get("damping_table") is not None:
            raise ModelError(f"{element}: give either damping or damping_table, not both")
        params = {
            "point_a": _vector3(numeric(kw.get("point_a", (0, 0, 0)), parameters, element,
                                        "point_a"), "point_a", element),
            "point_b": _vector3(numeric(kw.get("point_b", (0, 0, 0)), parameters, element,
                                        "point_b"), "point_b", element),
            "stiffness": num(kw.get("stiffness") or 0.0, what="stiffness"),
            "damping": num(kw.get("damping") or 0.0, what="damping", minimum=0.0),
            "free_length": num(kw.get("free_length", 0.0), what="free_length", minimum=0.0),
            "preload": num(kw.get("preload", 0.0), what="preload"),
            "force_table": table("force_table"),
            "damping_table": table("damping_table"),
            "min_length": num(kw.get("min_length", 1e-9), what="min_length", positive=True),
            "law": make_law(kw.get("law"), parameters, element),
        }
        dt = params["damping_table"]
        if dt is not None and np.any(np.diff(dt.y) < 0):
            raise ModelError(f"{element}: damping_table must not decrease (a damper's force "
                             "grows with the rate of elongation); a falling segment feeds "
                             "energy in")
        frames = _two_frames(kw, element, "a spring")
    elif kind == "joint-spring-damper":
        _unknown_keys(kw, ("joint", "stiffness", "damping", "rest", "preload", "force_table",
                           "damping_table", "interpolation", "law"), element, kind)
        if "joint" not in kw:
            raise ModelError(f"{element}: give the joint whose coordinate it acts on")
        if not isinstance(kw["joint"], str):
            raise ModelError(f"{element}: joint must be the name of a joint, got "
                             f"{kw['joint']!r}")
        _check_law(kw, element)
        if all(kw.get(k) is None for k in ("stiffness", "force_table", "damping",
                                            "damping_table", "law")):
            raise ModelError(f"{element}: missing stiffness: give stiffness (and rest), a "
                             "force_table, or damping")
        params = {
            "joint": kw["joint"],
            "stiffness": num(kw.get("stiffness") or 0.0, what="stiffness"),
            "damping": num(kw.get("damping") or 0.0, what="damping", minimum=0.0),
            "rest": num(kw.get("rest", 0.0), what="rest"),
            "preload": num(kw.get("preload", 0.0), what="preload"),
            "force_table": table("force_table"),
            "damping_table": table("damping_table"),
            "law": make_law(kw.get("law"), parameters, element),
        }
        frames = ()
    elif kind == "bushing":
        _unknown_keys(kw, ("body_a", "point_a", "body_b", "point_b", "stiffness", "damping"),
                      element, kind)
        if "body_a" not in kw:
            raise ModelError(f"{element}: give body_a (and body_b, default the ground)")
        if kw.get("stiffness") is None:
            raise ModelError(f"{element}: missing stiffness: give six diagonal values or a "
                             "6x6 matrix (translation then rotation, frame a's axes)")
        C = _matrix6(kw.get("damping", [0] * 6), parameters, element, "damping")
        if np.linalg.eigvalsh(0.5 * (C + C.T))[0] < -1e-12 * max(1.0, np.abs(C).max()):
            raise ModelError(f"{element}: damping must be positive semi-definite (its "
                             "symmetric part has a negative eigenvalue: it feeds energy in)")
        params = {
            "point_a": _vector3(numeric(kw.get("point_a", (0, 0, 0)), parameters, element,
                                        "point_a"), "point_a", element),
            "point_b": _vector3(numeric(kw.get("point_b", (0, 0, 0)), parameters, element,
                                        "point_b"), "point_b", element),
            "stiffness": _matrix6(kw["stiffness"], parameters, element, "stiffness"),
            "damping": C,
        }
        frames = _two_frames(kw, element, "a bushing")
    elif kind == "bearing":
        _unknown_keys(kw, ("body", "point", "housing", "center", "axis", "speed", "speeds",
                           "interpolation") + BEARING_COEFFICIENTS, element, kind)
        if "body" not in kw:
            raise ModelError(f"{element}: give the shaft body (body = ...)")
        missing = [c for c in ("kxx", "kyy") if kw.get(c) is None]
        if missing:
            raise ModelError(f"{element}: missing stiffness {', '.join(missing)}: a bearing "
                             "needs at least kxx and kyy (kxy, kyx, c.. default to 0)")
        speeds = kw.get("speeds")
        if speeds is not None:
            try:
                speeds = np.asarray(speeds, dtype=float)
            except (TypeError, ValueError):
                speeds = None
            if speeds is None or speeds.ndim != 1:
                raise ModelError(f"{element}: speeds must be a list of spin speeds (rad/s), "
                                 f"one per row of the tabulated coefficients, got "
                                 f"{kw['speeds']!r}")
        coeffs = {}
        for c in BEARING_COEFFICIENTS:
            val = kw.get(c, 0.0)
            if isinstance(val, (list, tuple, np.ndarray)):
                if speeds is None:
                    raise ModelError(f"{element}: {c} is tabulated, so give `speeds`, the "
                                     "spin speeds (rad/s) of the table's rows")
                if len(val) != len(speeds):
                    raise ModelError(f"{element}: {c} has {len(val)} values but speeds has "
                                     f"{len(speeds)}; give one value per speed")
                coeffs[c] = make_table({"x": speeds, "y": val}, element, c, interp,
                                       clamp=True)
            else:
                coeffs[c] = num(val, what=c)
        tabulated = [c for c in BEARING_COEFFICIENTS if isinstance(coeffs[c], Table)]
        if tabulated and kw.get("speed") is None:
            raise ModelError(f"{element}: tabulated coefficients need `speed`: the name of "
                             "the spin speed (a speed, a coordinate or a driven joint)")
        for c in ("cxx", "cyy"):
            vals = coeffs[c].y if isinstance(coeffs[c], Table) else [coeffs[c]]
            if np.min(vals) < 0:
                raise ModelError(f"{element}: {c} must be >= 0 (a negative direct damping "
                                 "feeds energy in)")
        axis = parse_axis(kw.get("axis", "x"), element)
        e1, e2 = radial_directions(axis)
        params = dict(coeffs)
        params.update({
            "point": _vector3(numeric(kw.get("point", (0, 0, 0)), parameters, element,
                                      "point"), "point", element),
            "center": _vector3(numeric(kw.get("center", (0, 0, 0)), parameters, element,
                                       "center"), "center", element),
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
    else:   # contact
        _unknown_keys(kw, ("body", "center", "radius", "shape", "axis", "plane_point",
                           "plane_normal", "stiffness", "exponent", "restitution",
                           "impact_speed", "friction", "slip_speed"), element, kind)
        if "body" not in kw:
            raise ModelError(f"{element}: give the body that touches (body = ...)")
        if kw.get("stiffness") is None:
            raise ModelError(f"{element}: missing stiffness (N/m^exponent) of the contact")
        shape = kw.get("shape", "sphere")
        if shape not in ("sphere", "disk"):
            raise ModelError(f"{element}: shape {shape!r} is not 'sphere' or 'disk'")
        normal = kw.get("plane_normal")
        if normal is None:
            g = np.asarray(gravity, float)
            normal = -g if np.linalg.norm(g) > 0 else (0.0, 0.0, 1.0)
        params = {
            "shape": shape,
            "center": _vector3(numeric(kw.get("center", (0, 0, 0)), parameters, element,
                                       "center"), "center", element),
            "radius": num(kw.get("radius", 0.0), what="radius", minimum=0.0),
            "axis": (parse_axis(kw.get("axis", "z"), element) if shape == "disk"
                     else np.array([0.0, 0.0, 1.0])),
            "plane_point": _vector3(numeric(kw.get("plane_point", (0, 0, 0)), parameters,
                                            element, "plane_point"), "plane_point", element),
            "plane_normal": parse_axis(numeric(normal, parameters, element, "plane_normal"),
                                       element),
            "stiffness": num(kw["stiffness"], what="stiffness", positive=True),
            "exponent": num(kw.get("exponent", 1.5), what="exponent", positive=True),
            "restitution": num(kw.get("restitution", 1.0), what="restitution", minimum=0.0),
            "impact_speed": num(kw.get("impact_speed", 1.0), what="impact_speed",
                                positive=True),
            "friction": num(kw.get("friction", 0.0), what="friction", minimum=0.0),
            "slip_speed": num(kw.get("slip_speed", 1e-3), what="slip_speed", positive=True),
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
        frames = (kw["body"],)
    return ForceElement(name, kind, tuple(frames), params, symbolic)


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

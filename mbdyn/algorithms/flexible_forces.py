"""Loads and force elements at points of flexible bodies, in Python (numpy).

A point of a flexible body is tied to its nearest node (``flexible.points``): world
position ``r_0 + R (x_p + Phi_p eta)``, velocity ``v_0 + omega x R x_p' + R Phi_p eta'``
and the node's small rotation ``Psi_p eta`` (its frame turned by it, for a bushing's
moments).  A point of a rigid frame or of the ground is as in the kernels.  Each element
is evaluated as ``kernels.forces`` evaluates it (the same laws, signs and power), and its
force ``F`` and moment ``N`` (world components) at each of its points enter the
equations as ``J_T^T F + J_R^T N``: for a flexible body ``J_T = R [I, -x~, Phi_p] B`` and
``J_R = R [0, I, Psi_p] B`` on its speeds ``B u = (v_0, omega, eta')`` (body
components), so the modal coordinates receive ``Phi_p^T R^T F + Psi_p^T R^T N``.

Kinds: ``spring-damper`` (stiffness, damping, preload, free and regularising length),
``bushing``, ``bearing`` (constant or tabulated coefficients; its ``speed`` a model's
speed, a parameter or a flexible rotor's name) and loads (constant, functions, or
expressions of ``t``, coordinates and speeds).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..elements.force_kinds import BEARING_COEFFICIENTS
from ..elements.tables import Table
from ..errors import ModelError
from ..flexible.invariants import skew
from ..flexible.points import body_point

#: the force-element kinds that may act at points of flexible bodies
KINDS = ("spring-damper", "bushing", "bearing")


@dataclass(frozen=True, eq=False)
class Side:
    """One point of an element: tree ``frame`` (-1: the ground), the flexible body's
    ``FlexPack`` (or ``None``), the point ``s`` (frame components) and, on a flexible
    body, its ``BodyPoint``."""
    frame: int
    flex: object
    s: np.ndarray
    point: object = None


@dataclass(frozen=True, eq=False)
class Packed:
    """An element or load as evaluated here: ``what`` (``"load"`` or its kind), the
    record, its ``sides`` and ``extra`` numbers (a bearing's coefficients or speed)."""
    what: str
    record: object
    sides: tuple
    extra: object = None


def side(model, frame, point):
    """The ``Side`` of ``point`` (frame components) on ``frame`` (a name)."""
    if frame == "ground":
        return Side(-1, None, np.asarray(point, float))
    flex = {fb.name: fb for fb in model._flex}.get(frame)
    i = model.tree.frame_index(frame)
    if flex is None:
        return Side(i, None, np.asarray(point, float))
    return Side(i, flex, np.asarray(point, float),
                body_point(model.flexible[frame].reduced, point))


def pack(model, loads, forces):
    """The ``Packed`` loads and force elements that act on the model's flexible bodies."""
    out = []
    for ld in loads:
        fn = tuple(_load_part(model, ld, part) for part in (ld.force, ld.moment))
        out.append(Packed("load", ld, (side(model, ld.body, ld.point),), fn))
    for el in forces:
        p, where = el.params, f"force {el.name!r}"
        if el.kind not in KINDS:
            raise ModelError(f"{where}: a {el.kind} at a flexible body is not there yet; "
                             f"{', '.join(KINDS)} and loads are")
        if el.kind == "bearing":
            sides = (side(model, el.frames[0], p["point"]),
                     side(model, el.frames[1], p["center"]))
            out.append(Packed("bearing", el, sides, _bearing_speed(model, el)))
            continue
        if el.kind == "spring-damper" and (p["law"] is not None or p["force_table"]
                                           is not None or p["damping_table"] is not None):
            raise ModelError(f"{where}: laws and tables of a spring-damper at a flexible "
                             "body are not there yet; give stiffness, damping, preload")
        out.append(Packed(el.kind, el, (side(model, el.frames[0], p["point_a"]),
                                        side(model, el.frames[1], p["point_b"]))))
    return tuple(out)


def _load_part(model, ld, part):
    """A load's force or moment as a constant array or a callable ``(t, q, u)``."""
    if isinstance(part, tuple):                 # sympy expressions
        from .inputs import lambdify_load
        return lambdify_load(model, ld.name, part)
    return part


def _bearing_speed(model, el):
    """A bearing's spin speed: ``("value", coefficients)`` at a parameter's or a flexible
    rotor's (constant) spin, ``("speed", k)`` for the model's free speed ``k``."""
    name = el.params["speed"]
    if name is None:
        return ("value", _coefficients(el.params, 0.0))
    if name in model.flexible:
        return ("value", _coefficients(el.params, model.flexible[name].spin))
    if name in model._speed_index:
        return ("speed", model._extended_speed(model._speed_index[name]))
    params = getattr(model.tree, "parameters", None) or {}
    if name in params:
        return ("value", _coefficients(el.params, float(params[name])))
    raise ModelError(f"force {el.name!r}: unknown speed {name!r}; at a flexible body a "
                     f"bearing's speed is a free speed ({', '.join(model.speeds)}), a "
                     "parameter, or a flexible rotor's name (its spin)")


def body_map(tree, fb, nu):
    """``B`` (6 + k, nu): the part of the body's ``(v_0, omega, eta')`` (body components)
    that the extended speeds make (the tree's, then the modal ones: ``nu`` of them), after
    a kinematics evaluation of the tree (the drives' part is in the frame's velocity, not
    here)."""
    i, nut = fb.frame, tree.nu
    RT = tree._R[i].T
    B = np.zeros((6 + fb.n, nu))
    B[:3, :nut] = RT @ tree._JT[i]
    B[3:6, :nut] = RT @ tree._JR[i]
    B[6:, fb.u] = np.eye(fb.n)
    return B


def point_state(model, sd, q, u, jacobians=True):
    """``(p, v, R, w, JT, JR)`` of a side after a tree evaluation at ``(q, u)``: world
    position and velocity of the point, orientation and angular velocity of the frame
    there (a flexible body's node turned by its small rotation), and the Jacobians
    (3, nu) of its velocity and angular velocity over the extended speeds (``None``
    without ``jacobians``); ``q``, ``u``: the extended state."""
    tree, nu = model.tree, model._nux
    if sd.frame < 0:
        z = np.zeros((3, nu)) if jacobians else None
        return sd.s, np.zeros(3), np.eye(3), np.zeros(3), z, z
    i = sd.frame
    R, r, v, w = tree._R[i], tree._r[i], tree._v[i], tree._w[i]
    JT = JR = None
    if sd.flex is None:
        lever = R @ sd.s
        if jacobians:
            JR = np.zeros((3, nu))
            JR[:, :tree.nu] = tree._JR[i]
            JT = -skew(lever) @ JR
            JT[:, :tree.nu] += tree._JT[i]
        return r + lever, v + _cross(w, lever), R, w, JT, JR
    pt, fb = sd.point, sd.flex
    eta, eta_dot = q[fb.q], u[fb.u]
    xb = pt.x + pt.Phi @ eta
    lever = R @ xb
    theta = pt.Psi @ eta
    if jacobians:
        B = body_map(tree, fb, nu)
        JT = R @ (B[:3] - skew(xb) @ B[3:6] + pt.Phi @ B[6:])
        JR = R @ (B[3:6] + pt.Psi @ B[6:])
    return (r + lever, v + _cross(w, lever) + R @ (pt.Phi @ eta_dot),
            R @ _rotation(theta), w + R @ (pt.Psi @ eta_dot), JT, JR)


def _cross(a, b):
    """``a x b`` of two 3-vectors (``np.cross`` costs ten times more on these)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _rotation(theta):
    """The rotation of the vector ``theta`` (Rodrigues)."""
    a = float(np.linalg.norm(theta))
    K = skew(theta)
    if a < 1e-12:
        return np.eye(3) + K
    return np.eye(3) + np.sin(a) / a * K + (1 - np.cos(a)) / a ** 2 * K @ K


def wrenches(model, pk, q, u, t, jacobians=True):
    """The element's ``[(side state, F, N)]`` (world components, at each side's point)
    and its ``(V, P_nc, P_load)``: potential, non-conservative power, a load's power."""
    states = [point_state(model, sd, q, u, jacobians) for sd in pk.sides]
    return _LAWS[pk.what](model, pk, states, q, u, t)


def _load(model, pk, states, q, u, t):
    (_, v, _, w, _, _), ld = states[0], pk.record
    outer = model._model_state(q, u) if any(callable(p) for p in pk.extra) else None
    F, N = (np.asarray(part(t, *outer) if callable(part) else part, float)
            for part in pk.extra)
    if ld.in_body:
        frame = model.tree._R[pk.sides[0].frame] if pk.sides[0].frame >= 0 else np.eye(3)
        F, N = frame @ F, frame @ N
    return [(states[0], F, N)], (0.0, 0.0, float(F @ v + N @ w))


def _spring_damper(model, pk, states, q, u, t):
    p = pk.record.params
    (pa, va, *_), (pb, vb, *_) = states
    d = pb - pa
    L = float(np.linalg.norm(d))
    e = d / np.sqrt(L * L + p["min_length"] ** 2)
    x, xd = L - p["free_length"], float(e @ (vb - va))
    fs = p["preload"] + p["stiffness"] * x
    fd = p["damping"] * xd
    F = (fs + fd) * e
    zero = np.zeros(3)
    return ([(states[0], F, zero), (states[1], -F, zero)],
            (p["preload"] * x + 0.5 * p["stiffness"] * x * x, -fd * xd, 0.0))


def _bushing(model, pk, states, q, u, t):
    p = pk.record.params
    (pa, va, Ra, wa, *_), (pb, vb, Rb, wb, *_) = states
    x6 = np.concatenate([Ra.T @ (pb - pa), _axial(Ra.T @ Rb)])
    va_b = va + _cross(wa, pb - pa)           # a's material velocity at b's point
    xd6 = np.concatenate([Ra.T @ (vb - va) - _cross(Ra.T @ wa, Ra.T @ (pb - pa)),
                          Ra.T @ (wb - wa)])
    w6 = -(p["stiffness"] @ x6 + p["damping"] @ xd6)
    F, N = Ra @ w6[:3], Ra @ w6[3:]
    JTa, JRa = states[0][4], states[0][5]            # a's material point at b's point
    at_b = (pb, va_b, Ra, wa, None if JTa is None else JTa - skew(pb - pa) @ JRa, JRa)
    return ([(states[1], F, N), (at_b, -F, -N)],
            (0.0, float(F @ (vb - va_b) + N @ (wb - wa)), 0.0))


def _axial(Rrel):
    """The axial vector of the skew part of ``Rrel`` (a small rotation's angles)."""
    return 0.5 * np.array([Rrel[2, 1] - Rrel[1, 2], Rrel[0, 2] - Rrel[2, 0],
                           Rrel[1, 0] - Rrel[0, 1]])


def _coefficients(p, spin):
    """A bearing's eight coefficients at the spin speed ``spin``."""
    return [p[c](spin) if isinstance(p[c], Table) else p[c] for c in BEARING_COEFFICIENTS]


def bearing_coefficients(pk, u):
    """The eight coefficients at the bearing's spin speed."""
    how, what = pk.extra
    return what if how == "value" else _coefficients(pk.record.params, u[what])


def _bearing(model, pk, states, q, u, t):
    p = pk.record.params
    (pa, va, *_), (pb, _, Rh, wh, JTh, JRh) = states
    vh = states[1][1] + _cross(wh, pa - pb)   # the housing's material velocity at pa
    e1, e2 = Rh @ p["e1"], Rh @ p["e2"]
    kxx, kxy, kyx, kyy, cxx, cxy, cyx, cyy = bearing_coefficients(pk, u)
    d, dv = pa - pb, va - vh
    x, y, xd, yd = e1 @ d, e2 @ d, e1 @ dv, e2 @ dv
    F = (-(kxx * x + kxy * y + cxx * xd + cxy * yd) * e1
         - (kyx * x + kyy * y + cyx * xd + cyy * yd) * e2)
    zero = np.zeros(3)
    housing = (pa, vh, Rh, wh, None if JTh is None else JTh - skew(pa - pb) @ JRh, JRh)
    return [(states[0], F, zero), (housing, -F, zero)], (0.0, float(F @ dv), 0.0)


_LAWS = {"load": _load, "spring-damper": _spring_damper, "bushing": _bushing,
         "bearing": _bearing}


def generalized_forces(model, q, u, t):
    """The sum of ``J_T^T F + J_R^T N`` over the packed elements (the extended speeds),
    after a tree evaluation at the extended state ``(q, u, t)``."""
    f = np.zeros(model._nux)
    for pk in model._flex_elements:
        for (_, _, _, _, JT, JR), F, N in wrenches(model, pk, q, u, t)[0]:
            f += JT.T @ F + JR.T @ N
    return f


def energies(model, q, u, t):
    """``(V, P_nc, P_load)`` of the packed elements, after a tree kinematics evaluation."""
    total = np.zeros(3)
    for pk in model._flex_elements:
        total += wrenches(model, pk, q, u, t, jacobians=False)[1]
    return tuple(float(x) for x in total)

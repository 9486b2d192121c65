"""Linearisation about an operating point: ``M x'' + (D + G) x' + (K + N) x = 0``.

With ``u' = g(q, u, t)`` the model's accelerations (``M(q)^-1 f(q, u, t)``) and ``x`` the
tangent coordinates about ``q0`` (``analysis.tangent``), the first-order motion is

    x' = du + B x,        du' = G_x x + G_u du,

``B`` coupling a rotation vector's rate to the operating angular velocity (zero for
ordinary coordinates).  In second-order form, multiplied by ``M = M(q0)``:

    M x'' + C x' + Kt x = 0,     C = -M (G_u + B),     Kt = -M (G_x - G_u B),

split into ``D`` (symmetric part of ``C``: damping), ``G`` (skew part: gyroscopic),
``K`` (symmetric part of ``Kt``: stiffness) and ``N`` (skew part: circulatory).  The state
matrix ``A`` acts on ``[x, x']``.  At an equilibrium with ``u0 = 0``, ``M G_x = df/dq`` and
``M G_u = df/du``: the textbook's ``K = -df/dq``, ``D + G = -df/du``.

Two routes: ``"numeric"`` differentiates the compiled model by central differences, the
step chosen per coordinate, and reports an error estimate (the difference to the
derivative with twice the step, over three: the leading truncation error of the central
formula); ``"symbolic"`` differentiates the closed-form equations of ``mb.derive`` exactly.

A closed mechanism (loop joints) is linearised in independent coordinates
(``analysis.reduction``): ``x`` above becomes the independent tangent coordinates ``z``,
the dependent ones following on the constraints, ``u`` the independent speeds ``w``, ``g``
the constrained accelerations' independent part (``M u' = f + G^T lam``, ``G u' = gamma``)
and ``M`` the reduced mass matrix ``S^T M S``.  Differentiating on the constraints keeps the
geometric stiffness of the constraint forces, which ``S^T (df/dq) S`` would miss.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, SingularMassMatrixError
from . import arguments
from .tangent import Tangent

ROUTES = ("numeric", "symbolic")


@dataclass
class Linearization:
    """A model linearised about ``(q0, u0, t)``; rows and columns in ``names`` order."""
    model: object
    names: tuple
    q0: np.ndarray
    u0: np.ndarray
    t: float
    M: np.ndarray
    D: np.ndarray
    G: np.ndarray
    K: np.ndarray
    N: np.ndarray
    A: np.ndarray
    route: str = "numeric"
    error: float | None = None
    details: dict = field(default_factory=dict)
    #: closed loops: every tangent coordinate's name, and ``basis`` (all x independent):
    #: how each moves with the independent ones ``names``, ``dx = basis @ dz`` to first
    #: order.  A tree has no dependent coordinates: ``coordinates == names``, no basis.
    coordinates: tuple = ()
    basis: np.ndarray | None = None

    def __post_init__(self):
        self.coordinates = tuple(self.coordinates) or tuple(self.names)

    @property
    def C(self):
        """The whole velocity matrix ``D + G``."""
        return self.D + self.G

    @property
    def stiffness(self):
        """The whole displacement matrix ``K + N``."""
        return self.K + self.N

    @property
    def n(self):
        return len(self.names)

    def to_dict(self):
        """Plain data: operating point, matrices with their row names."""
        m = self.model
        return {"coordinates": list(self.names),
                "operating_point": {"t": self.t,
                                    "q": dict(zip(m.coordinates, self.q0.tolist())),
                                    "u": dict(zip(m.speeds, self.u0.tolist()))},
                "route": self.route, "error_estimate": self.error,
                **{k: getattr(self, k).tolist() for k in ("M", "D", "G", "K", "N")},
                **({} if self.basis is None else {
                    "all_coordinates": list(self.coordinates),
                    "basis": {nm: row.tolist() for nm, row in zip(self.coordinates,
                                                                   self.basis)}})}


def _split(C, Kt, M, names, model, q0, u0, t, route, error, details, reduction=None):
    D, G = 0.5 * (C + C.T), 0.5 * (C - C.T)
    K, N = 0.5 * (Kt + Kt.T), 0.5 * (Kt - Kt.T)
    n = len(names)
    try:
        Minv = np.linalg.inv(M)
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(f"model {model.name!r}: the mass matrix is singular at "
                                      "the operating point; it cannot be linearised there") \
            from None
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ Kt, -Minv @ C]])
    lin = Linearization(model, tuple(names), q0, u0, float(t), M, D, G, K, N, A, route,
                        error, details)
    if reduction is not None:
        lin.coordinates, lin.basis = tuple(reduction.tangent.names), reduction.S
    return lin


def _operating_point(model, q0, u0):
    q0 = model.q_vector(q0).copy() if q0 is None or isinstance(q0, dict) else \
        np.array(q0, dtype=float)
    u0 = model.u_vector(u0).copy() if u0 is None or isinstance(u0, dict) else \
        np.array(u0, dtype=float)
    if q0.shape != (model.nq,) or u0.shape != (model.nu,):
        raise ModelError(f"model {model.name!r}: an operating point needs {model.nq} "
                         f"coordinates and {model.nu} speeds, got {q0.size} and {u0.size}")
    if not (np.all(np.isfinite(q0)) and np.all(np.isfinite(u0))):
        raise ModelError("the operating point holds non-finite values")
    model.normalize_quaternions(q0)
    return q0, u0


def linearize(model, q0=None, u0=None, t=0.0, route="numeric", step=None,
              independent=None):
    """Linearise ``model`` about the coordinates ``q0`` and speeds ``u0`` (arrays or
    ``{name: value}``; default the model's zero state) at time ``t``.

    ``route``: ``"numeric"`` (central differences of the compiled model; ``step`` scales
    the per-coordinate step, default the cube root of the machine epsilon) or
    ``"symbolic"`` (exact derivatives of the closed-form equations).  Returns a
    ``Linearization``.

    A closed mechanism is linearised in independent coordinates, chosen by pivoted QR of
    the constraint Jacobian unless ``independent`` names them (coordinates or joints); the
    operating point is first moved onto the constraints (``Model.project``).
    """
    where = "linearize"
    model = arguments.model(model, where)
    t = arguments.number(t, where, "t")
    if step is not None:
        step = arguments.number(step, where, "step", positive=True)
    if not isinstance(route, str) or route not in ROUTES:
        raise ModelError(f"unknown route {route!r}; use one of {', '.join(ROUTES)}")
    q0, u0 = _operating_point(model, arguments.state(q0, where, "q0"),
                              arguments.state(u0, where, "u0"))
    if model.nu == 0:
        raise ModelError(f"model {model.name!r} has no degrees of freedom to linearise")
    if model.has_loops:
        if route != "numeric":
            raise ModelError(f"model {model.name!r} has closed loops: linearise it by the "
                             "numeric route (the symbolic equations are the tree's)")
        independent = arguments.names(independent or (), where, "independent")
        return _loop_linearization(model, q0, u0, t, step, independent)
    if independent:
        raise ModelError(f"linearize: model {model.name!r} has no closed loops; its "
                         "coordinates are all independent (leave out independent)")
    tangent = Tangent(model, q0)
    M = model.mass_matrix(q0, t)
    B = tangent.rate_coupling(u0)
    if route == "numeric":
        Gx, Gu, error = _numeric_jacobians(model, tangent, u0, t, step)
        details = {}
    else:
        Gx, Gu = _symbolic_jacobians(model, tangent, q0, u0, t)
        error, details = 0.0, {}
    C = -M @ (Gu + B)
    Kt = -M @ (Gx - Gu @ B)
    if not (np.all(np.isfinite(C)) and np.all(np.isfinite(Kt))):
        raise ModelError(f"linearize: the derivatives of model {model.name!r} are not finite "
                         f"at the operating point (t = {t:g}"
                         + (f", step = {step:g}: try a smaller step)" if step else ")"))
    return _split(C, Kt, M, tangent.names, model, q0, u0, t, route, error, details)


def _accelerations(model, q, u, t):
    return model.forward_dynamics(q, u, t)


def _loop_linearization(model, q0, u0, t, step, independent):
    """``linearize`` of a closed mechanism, in the independent coordinates of
    ``analysis.reduction`` (the module's docstring)."""
    from .reduction import Reduction, speed_indices
    q0, u0 = model.project(q0, u0, t)
    chosen = speed_indices(model, Tangent(model, q0), independent, "linearize")
    red = Reduction(model, q0, t, independent=chosen)
    if red.n == 0:
        raise ModelError(f"model {model.name!r} has no degrees of freedom to linearise: "
                         "its loops fix every coordinate")
    w0 = u0[red.independent]
    u0 = red.speeds(q0, w0)

    def on_constraints(z, w):
        q = red.configuration(z)
        if q is None:
            raise ModelError(f"linearize: the loops of model {model.name!r} cannot be "
                             "closed next to the operating point (a singular configuration?)")
        return _accelerations(model, q, red.speeds(q, w), t)[red.independent]

    eps = np.finfo(float).eps
    base = eps ** (1 / 3) if step is None else float(step)
    hz = base / np.maximum(1.0, np.abs(red.S).max(axis=0))   # no coordinate moves more
    hw = base * np.maximum(1.0, np.abs(w0))
    Gz, Gz2 = _central(lambda z: on_constraints(z, w0), np.zeros(red.n), hz)
    Gw, Gw2 = _central(lambda w: on_constraints(np.zeros(red.n), w), w0, hw)
    scale = max(np.abs(Gz).max(initial=0.0), np.abs(Gw).max(initial=0.0), 1e-300)
    error = max(np.abs(Gz - Gz2).max(initial=0.0), np.abs(Gw - Gw2).max(initial=0.0)) / 3
    S = red.S
    M = S.T @ model.mass_matrix(q0, t) @ S
    B = (red.tangent.rate_coupling(u0) @ S)[red.independent]
    C = -M @ (Gw + B)
    Kt = -M @ (Gz - Gw @ B)
    details = {"independent": red.names, "constraint_rank": red.rank,
               "partition_condition": red.condition}
    return _split(C, Kt, M, red.names, model, q0, u0, t, "numeric", float(error / scale),
                  details, red)


def _central(fn, x0, steps):
    """Columns ``(fn(x0 + h e_j) - fn(x0 - h e_j)) / 2h`` and the same with ``2h``."""
    cols, cols2 = [], []
    for j, h in enumerate(steps):
        e = np.zeros_like(x0)
        e[j] = h
        cols.append((fn(x0 + e) - fn(x0 - e)) / (2 * h))
        cols2.append((fn(x0 + 2 * e) - fn(x0 - 2 * e)) / (4 * h))
    return np.array(cols).T, np.array(cols2).T


def _numeric_jacobians(model, tangent, u0, t, step):
    eps = np.finfo(float).eps
    base = eps ** (1 / 3) if step is None else float(step)
    x0 = np.zeros(tangent.n)
    hx = base * np.ones(tangent.n)
    # scalar coordinates: scale the step with the coordinate's size (angles and lengths)
    q0 = tangent.q0
    for k, xs in enumerate(tangent._scalar_x):
        hx[xs] = base * max(1.0, abs(q0[tangent._scalar_q[k]]))
    hu = base * np.maximum(1.0, np.abs(u0))
    Gx, Gx2 = _central(lambda x: _accelerations(model, tangent.retract(x), u0, t), x0, hx)
    Gu, Gu2 = _central(lambda u: _accelerations(model, tangent.q0, u, t), u0, hu)
    scale = max(np.abs(Gx).max(initial=0.0), np.abs(Gu).max(initial=0.0), 1e-300)
    # the central formula's error is c h^2: D(h) - D(2h) = -3 c h^2
    error = max(np.abs(Gx - Gx2).max(initial=0.0), np.abs(Gu - Gu2).max(initial=0.0)) / 3
    return Gx, Gu, float(error / scale)


def _symbolic_jacobians(model, tangent, q0, u0, t):
    """Exact derivatives of the closed-form ``M`` and ``f``: the chain rule applied to the
    expressions of ``mb.derive`` node by node (``symbolic.evaluate.evaluate_derivative``),
    at the operating point, for each coordinate and speed."""
    from ..symbolic.derive import derive
    from ..symbolic.evaluate import evaluate_derivative
    d = derive(model, "jourdain", measure=False)
    sym = d.walk.sym
    q, u = list(sym.q), list(sym.u)
    values = dict(zip(q, q0))
    values.update(zip(u, u0))
    values[sym.t] = float(t)
    values.update({s: model.parameters[n] for n, s in sym.params.items()})
    exprs = list(d.mass_matrix) + list(d.forcing)
    nu = len(u)

    def derivative(var):
        v, dv = evaluate_derivative(exprs, values, var)
        return (np.array(v[:nu * nu]).reshape(nu, nu), np.array(v[nu * nu:]),
                np.array(dv[:nu * nu]).reshape(nu, nu), np.array(dv[nu * nu:]))

    Fq = np.empty((nu, len(q)))
    dMud = np.empty((nu, len(q)))
    M0 = ud0 = None
    for k, var in enumerate(q):
        M_, f_, dM, df = derivative(var)
        if ud0 is None:
            M0, ud0 = M_, np.linalg.solve(M_, f_)
        Fq[:, k] = df
        dMud[:, k] = dM @ ud0
    Fu = np.empty((nu, nu))
    for k, var in enumerate(u):
        M_, f_, _, df = derivative(var)
        if ud0 is None:
            M0, ud0 = M_, np.linalg.solve(M_, f_)
        Fu[:, k] = df
    Bq = tangent.basis()                      # dq/dx
    Gx = np.linalg.solve(M0, (Fq - dMud) @ Bq)
    Gu = np.linalg.solve(M0, Fu)
    return Gx, Gu

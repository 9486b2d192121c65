"""Sampled-data control: a run with controllers in Python (``System.add_controller``) or
PID integral terms is integrated in stretches between sampling instants.  At each instant
the controllers are called with the state there and their efforts, like the PIDs'
integral terms, are written into the held actuators' numbers; between instants they stay
constant (zero-order hold) and the integrator runs as it would without them -- compiled,
when the model allows -- restarting at each instant, where the efforts jump.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import sympy

from ..elements.tables import Table
from ..errors import ModelError, NonFiniteError
from ..kernels import actuation as ka
from .plan import Outcome

#: the most sampling instants a run may take (each restarts the integrator)
MAX_INSTANTS = 1_000_000
#: the counters of a route's ``info`` that add up over the stretches
_COUNTERS = ("steps", "njev", "nlu", "rejected", "nfev", "solver_rhs_evaluations")


def is_sampled(model):
    return bool(getattr(model, "_controllers", ()) or getattr(model, "_samplers", ()))


def instants(model, t0, t_end):
    """The sampling instants in ``[t0, t_end)``: ``t0 + k / rate`` of every controller and
    PID, merged (instants closer than 1e-12 of the span are one)."""
    rates = [c.rate for c in model._controllers] + [s.rate for s in model._samplers]
    count = sum(math.floor((t_end - t0) * r) + 1 for r in rates)
    if count > MAX_INSTANTS:
        raise ModelError(f"the controllers' rates ({', '.join(f'{r:g} Hz' for r in rates)}) "
                         f"make {count} sampling instants over {t_end - t0:g} s, more than "
                         f"{MAX_INSTANTS}; lower a rate or shorten the run")
    times = np.concatenate([t0 + np.arange(math.floor((t_end - t0) * r) + 1) / r
                            for r in rates])
    times = np.unique(times[times < t_end - 1e-12 * max(1.0, abs(t_end))])
    keep = np.concatenate([[True], np.diff(times) > 1e-12 * max(1.0, t_end - t0)])
    return times[keep]


class Updates:
    """What changes at the sampling instants: each controller's efforts and each PID's
    integral term, written into the packed numbers the force kernel reads."""

    def __init__(self, model, t0):
        self.model = model
        data, index = model._force_data, {el.name: e for e, el in
                                          enumerate(model._force_elements)}
        self.held = [(c, [int(model._force_int[index[a], 3]) + ka.A_HELD
                          if a in index else -1 for a in c.actuators])
                     for c in model._controllers]
        self.next = {id(x): t0 for x in list(model._controllers) + list(model._samplers)}
        #: how close to its next instant a sampler counts as due (round-off of t0 + k/rate)
        self.tol = 1e-9 / max([1.0] + [x.rate for x in list(model._controllers)
                                       + list(model._samplers)])
        self.setpoints = {id(s): _function_of_t(s.element.params["setpoint"])
                          for s in model._samplers}
        self.desired = _desired_motions(model) if any(
            s.kind == "feedforward" for s in model._samplers) else None
        for s in model._samplers:            # a run starts with no integral
            data[s.slot] = 0.0
        for _, slots in self.held:
            for k in slots:
                if k >= 0:
                    data[k] = 0.0

    def at(self, t, y):
        """Call what is due at ``t`` with the state ``y``."""
        model, tol = self.model, self.tol
        q, u = y[:model.nq], y[model.nq:]
        for c, slots in self.held:
            if t >= self.next[id(c)] - tol:
                self.next[id(c)] += 1.0 / c.rate
                efforts = _call(c, t, q, u, len(slots))
                for k, val in zip(slots, efforts):
                    if k >= 0:
                        model._force_data[k] = val
        torques = None
        for s in model._samplers:
            if t >= self.next[id(s)] - tol:
                self.next[id(s)] += 1.0 / s.rate
                if s.kind == "integral":
                    self._integrate(s, t, q, u)
                    continue
                if torques is None:
                    torques = self._computed_torque(t, q, u)
                j = model._joint[s.element.params["joint"]]
                model._force_data[s.slot] = torques[j.speeds[0]]

    def _computed_torque(self, t, q, u):
        """The plant's inverse dynamics at the setpoints: the PD/PID joints at their
        setpoints' positions, rates and accelerations, the others where they are, at zero
        acceleration."""
        model = self.model
        qd, ud, udd = q.copy(), u.copy(), np.zeros(model.nu)
        for kq, ku, (s, sd, sdd) in self.desired:
            qd[kq], ud[ku], udd[ku] = s(t), sd(t), sdd(t)
        efforts, _ = model._plant.inverse_dynamics(qd, ud, udd, t)
        return efforts

    def _integrate(self, s, t, q, u):
        """One sample of a PID's integral: ``I += ki e / rate`` (the error at the
        instant), held unless the effort saturates in the error's direction (with
        ``anti_windup``)."""
        model, p = self.model, s.element.params
        j = model._joint[p["joint"]]        # a free joint: actuators refuse driven ones
        error = self.setpoints[id(s)](t) - q[model.coordinate_index(j.coordinates[0])]
        data = model._force_data
        grown = data[s.slot] + p["ki"] * error / s.rate
        if p["anti_windup"] and math.isfinite(p["limit"]):
            if abs(grown) > p["limit"] and grown * error > 0:
                return                      # saturated: integrating would wind up
            grown = min(max(grown, -p["limit"]), p["limit"])
        data[s.slot] = grown


def _desired_motions(model):
    """``[(index of the joint's coordinate, of its speed, (s, s', s''))]`` of every
    PD/PID actuator: its setpoint and the setpoint's derivatives, functions of ``t``."""
    out = []
    t = sympy.Symbol("t")
    for el in model._force_elements:
        p = el.params
        if el.kind != "actuator" or p["type"] not in ("pd", "pid"):
            continue
        j = model._joint[p["joint"]]
        expr = p["setpoint"]
        expr = (sympy.Float(expr) if not isinstance(expr, sympy.Basic) else
                expr.subs({s: model.parameters[s.name] for s in expr.free_symbols
                           if s.name in model.parameters}))
        expr = expr.subs({s: t for s in expr.free_symbols if s.name == "t"})
        parts = [sympy.lambdify(t, e, "math") for e in (expr, expr.diff(t), expr.diff(t, 2))]
        out.append((model.coordinate_index(j.coordinates[0]), model.speed_index(j.speeds[0]),
                    tuple(lambda x, f=f: float(f(x)) for f in parts)))
    return out


def _function_of_t(value):
    if isinstance(value, Table):
        return value
    if isinstance(value, sympy.Basic) and value.free_symbols:
        tsyms = [s for s in value.free_symbols if s.name == "t"]
        return sympy.lambdify(tsyms[:1], value, "math")
    return lambda t, v=float(value): v


def _call(controller, t, q, u, n):
    """The controller's efforts at ``t``, checked: ``n`` finite numbers."""
    try:
        out = controller.function(t, q.copy(), u.copy())
        out = np.asarray(out, dtype=float).reshape(-1)
    except (ModelError, NonFiniteError):
        raise
    except Exception as exc:
        raise ModelError(f"controller {controller.name!r}: its function raised "
                         f"{type(exc).__name__}: {exc} (at t={t:.6g})") from exc
    if out.shape != (n,):
        raise ModelError(f"controller {controller.name!r}: its function returned {out.size} "
                         f"values at t={t:.6g}; it must return {n}, one effort per joint")
    if not np.all(np.isfinite(out)):
        raise NonFiniteError(f"controller {controller.name!r}: its function returned "
                             f"non-finite efforts {out.tolist()} at t={t:.6g}")
    return out


def run(plan, integrate):
    """Integrate ``plan`` stretch by stretch between the sampling instants, each with
    ``integrate(sub_plan)`` (the route ``simulate`` chose); the outcomes joined."""
    model = plan.model
    times = instants(model, plan.t0, plan.t_end)
    updates = Updates(model, plan.t0)
    ts, ys, found, info = [], [], [], {"sampling_instants": 0}
    y = np.array(plan.y0, float)
    steps_left = plan.budget["max_steps"]
    for k, tk in enumerate(times):
        t_next = times[k + 1] if k + 1 < len(times) else plan.t_end
        updates.at(tk, y)
        info["sampling_instants"] += 1
        sub_eval = None
        if plan.t_eval is not None:
            inside = plan.t_eval[(plan.t_eval > tk) & (plan.t_eval < t_next)]
            sub_eval = np.concatenate([[tk], inside, [t_next]])
        budget = dict(plan.budget, max_steps=max(1, steps_left))
        sub = dataclasses.replace(plan, t0=float(tk), t_end=float(t_next), y0=y,
                                  t_eval=sub_eval, budget=budget)
        out = integrate(sub)
        steps_left -= out.info.get("steps", 0)
        _join(plan, out, k == 0, tk, t_next, ts, ys)
        found.extend(out.found)
        for key, val in out.info.items():
            info[key] = info.get(key, 0) + val if key in _COUNTERS else val
        y = np.array(out.ys[-1], float)
        stopped = out.ts[-1] < t_next - 1e-12 * max(1.0, abs(t_next))
        if "failure" in out.info:
            info["failure"] = (f"{out.info['failure']} -- in the stretch {tk:.6g} .. "
                               f"{t_next:.6g} s between two sampling instants of the run "
                               f"to {plan.t_end:.6g} s; a controller sampled too slowly for "
                               "its gains makes the loop unstable: raise its rate")
        if "failure" in out.info or stopped:
            break
    return Outcome(np.concatenate(ts), np.vstack(ys), found, info)


def _join(plan, out, first, tk, t_next, ts, ys):
    """Keep a stretch's samples: without ``t_eval`` all but its first (the previous
    stretch's last); with ``t_eval``, the requested ones."""
    t, y = np.asarray(out.ts), np.asarray(out.ys)
    if plan.t_eval is None:
        keep = np.ones(len(t), bool)
        keep[0] = first
    else:
        wanted = set(plan.t_eval.tolist())
        keep = np.array([tt in wanted and (first or tt != tk) for tt in t.tolist()])
    ts.append(t[keep])
    ys.append(y[keep])

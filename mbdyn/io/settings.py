"""The run a model file asks for: ``[simulation]`` (integrator, method, tolerances, steps,
sampling and budgets, with ``DEFAULT_SIMULATION`` where the file is silent) and
``[outputs]`` (reactions, energy, points); ``METHODS``, the formulations a run can use.
"""
from __future__ import annotations

import warnings

from ..algorithms.forward_dynamics import METHODS as _METHODS
from ..errors import ModelWarning
from ..integrate.settings import DEFAULTS as SIMULATE_DEFAULTS
from ..integrate.settings import FIXED_STEP, INTEGRATORS
from .wording import suggest

#: The formulations a run can use -- the one list behind ``[simulation] method`` and
#: ``mbdyn run --method``.  Extend it here when a formulation is added.
METHODS = ("auto",) + tuple(_METHODS) + ("symbolic",)

#: ``[simulation]`` defaults.
DEFAULT_SIMULATION = dict(SIMULATE_DEFAULTS)     # one set of defaults (mbdyn.integrate.settings)
SIMULATE_KEYWORDS = ("t_end", "integrator", "method", "rtol", "atol", "dt", "max_step",
                     "output_dt", "progress", "events", "outputs", "points", "max_steps",
                     "max_samples", "max_wall_time", "error_estimate")
BUDGETS = ("max_steps", "max_samples", "max_wall_time")


def read_simulation(b):
    """The ``[simulation]`` settings of the builder ``b``'s document."""
    sim = b.doc.get("simulation", {})
    s = dict(DEFAULT_SIMULATION)
    s["t_end"] = None
    path = ("simulation",)
    if "t_end" in sim:
        s["t_end"] = b.number(sim["t_end"], path + ("t_end",), positive=True)
    for key, options in (("integrator", INTEGRATORS), ("method", METHODS)):
        if key in sim:
            if sim[key] not in options:
                raise b.error(path + (key,), f"unknown {key} {sim[key]!r}; "
                              f"{suggest(sim[key], options)}use one of: "
                              f"{', '.join(options)}")
            s[key] = sim[key]
    for key in ("rtol", "atol", "dt", "max_step", "output_dt", "max_wall_time"):
        if key in sim:
            s[key] = b.number(sim[key], path + (key,), positive=True)
    for key in ("max_steps", "max_samples"):
        if key in sim:
            v = b.number(sim[key], path + (key,), positive=True)
            if v != int(v):
                raise b.error(path + (key,), f"must be a whole number, got {v:g}")
            s[key] = int(v)
    if s["integrator"] in FIXED_STEP and not s.get("dt"):
        raise b.error(path + ("integrator",), f"{s['integrator']!r} is a fixed-step "
                      "integrator: add dt = ... to [simulation] (or pass --dt)")
    if s["integrator"] in FIXED_STEP:
        _warn_fixed_step(sim, s)
    return s


def _warn_fixed_step(sim, s):
    """What a fixed-step run of settings ``s`` does not do as ``[simulation]`` may expect."""
    ignored = [k for k in ("rtol", "atol", "max_step") if k in sim]
    if ignored:
        warnings.warn(f"simulation.{', simulation.'.join(ignored)} ignored: the "
                      f"fixed-step integrator {s['integrator']} takes steps of dt",
                      ModelWarning)
    if s.get("t_end") and s["dt"] > s["t_end"]:
        warnings.warn(f"simulation.dt = {s['dt']:g} is longer than t_end = "
                      f"{s['t_end']:g}: the run is one shortened step", ModelWarning)
    ratio = s["output_dt"] / s["dt"] if s.get("output_dt") else 1.0
    if ratio >= 1 and abs(ratio - round(ratio)) > 1e-6 * ratio:
        warnings.warn(f"simulation.output_dt = {s['output_dt']:g} is not a multiple of "
                      f"dt = {s['dt']:g}: every {round(ratio)}-th step is kept "
                      f"(every {round(ratio) * s['dt']:g} s)", ModelWarning)
    if s.get("output_dt") and s["output_dt"] < s["dt"] * (1 - 1e-9):
        warnings.warn(f"simulation.output_dt = {s['output_dt']:g} is smaller than dt = "
                      f"{s['dt']:g}: a fixed-step run keeps its own steps, so every step "
                      "is stored", ModelWarning)


def read_outputs(b):
    """The ``[outputs]`` of the builder ``b``'s document, checked against ``b.model``."""
    out = b.doc.get("outputs", {})
    model = b.model
    path = ("outputs",)
    reactions = out.get("reactions", False)
    if reactions is True:
        reactions = list(model.reaction_joints)
    elif reactions is False:
        reactions = []
    else:
        for k, jn in enumerate(reactions):
            if jn not in model.reaction_joints:
                raise b.error(path + ("reactions", k), f"{jn!r} is not a joint; "
                              f"{suggest(jn, model.reaction_joints)}the joints are: "
                              f"{', '.join(model.reaction_joints)}")
    points = {}
    for pname, p in out.get("points", {}).items():
        ppath = path + ("points", pname)
        if p["frame"] not in model.frames:
            raise b.error(ppath + ("frame",), f"{p['frame']!r} is not a frame; "
                          f"{suggest(p['frame'], model.frames)}the frames are: "
                          f"{', '.join(model.frames)}")
        if pname in model.coordinates or pname in model.speeds:
            raise b.error(ppath, f"{pname!r} is also a coordinate or speed name; "
                          "rename the point")
        offset = b.numbers(p.get("offset", [0, 0, 0]), ppath + ("offset",))
        points[pname] = (p["frame"], tuple(offset))
    return {"reactions": reactions, "reactions_frame": out.get("reactions_frame", "world"),
            "energy": bool(out.get("energy", False)), "points": points}

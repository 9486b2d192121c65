"""Flexible bodies: a body whose frame is the floating frame of a modally reduced elastic
body (``mbdyn.flexible``), with its modal coordinates named ``BODY_m1 ... BODY_mk``.

The description (``System.add_body(..., flexible={...})`` or a model file's
``[[bodies]] flexible = {...}``), every key checked and named in errors:

* ``beam = {...}``: a beam along the body's x axis from the frame origin
  (``mbdyn.flexible.spec``: ``length``, ``elements``, ``E``, ``rho``, ``nu``, a section
  ``circle = d`` / ``tube = [d_out, d_in]`` / ``rect = [b, h]`` or ``section = {...}``,
  ``theory``, ``segments``, ``masses``, ``nodes``); or ``data = "blade.npz"`` (reduced
  data from another program, ``mbdyn.flexible.data``);
* ``modes`` (how many modes to keep) and/or ``f_max`` (a cut-off in Hz): a beam needs
  one of them; ``reduction``: ``"craig-bampton"`` (the default: the beam clamped at the
  frame, the cantilever's modes) or ``"free-interface"``;
* ``damping``: a modal damping ratio, or one per mode (default 0, or the data's);
* ``spin``: a rotor's spin speed about its x axis (rad/s; a number or a parameter's
  name), in a frame that does not spin: ``Omega G_ee eta'`` on the modal equations
  (``reduction = "lateral"``, ``mbdyn.flexible.rotor``; the body fixed to the ground).

The body frame is the beam's root (the clamped frame of the reduction).  Mass, centre of
mass and inertia come from the inertia invariants at ``eta = 0``, plus a rigid part
given as ``mass``, ``com`` and ``inertia`` (about its centre of mass) of ``add_body``.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..flexible import (ReducedBody, beam_from_spec, craig_bampton, free_interface,
                        load_reduced_body, modal_damping)
from ..flexible.invariants import Invariants
from ..flexible.rotor import lateral_modes
from ..names import identifier_problem
from .bodies import Body, make_body, make_shape

KEYS = ("beam", "data", "modes", "f_max", "reduction", "damping", "spin")
REDUCTIONS = {"craig-bampton": craig_bampton, "free-interface": free_interface,
              "lateral": None}


@dataclass(frozen=True, eq=False)
class FlexibleBody:
    """A flexible body: its ``reduced`` model (``ReducedBody``), the ``invariants`` of the
    whole body (the elastic part's plus the rigid part given with it), ``rigid``: the
    ``Body`` with the same mass properties at ``eta = 0`` (what the body is with its
    flexibility off), and the names of its modal ``coordinates`` and ``speeds``."""
    name: str
    reduced: ReducedBody
    invariants: Invariants
    rigid: Body
    coordinates: tuple
    speeds: tuple
    spec: dict
    spin: float = 0.0

    @property
    def n_modes(self):
        return self.reduced.n_modes


def make_flexible_body(name, spec, lumped, base=None, parameters=None):
    """The ``FlexibleBody`` ``name`` described by ``spec`` (this module's docstring);
    ``lumped``: the rigid part (a ``Body``: mass, com, inertia about its com) carried at
    the frame; ``base``: the directory a relative ``data`` path starts from;
    ``parameters``: the values a ``spin`` given by name reads."""
    where = f"body {name!r}: flexible"
    problem = identifier_problem(name)
    if problem:
        raise ModelError(f"body {name!r}: a flexible body's name names its modal "
                         f"coordinates ({name}_m1 ...), so it must be an identifier: it "
                         f"{problem}")
    if not isinstance(spec, dict):
        raise ModelError(f"{where}: must be a table, e.g. {{ beam = {{...}}, modes = 4 }} "
                         "or { data = \"blade.npz\" }")
    for key in spec:
        if key not in KEYS:
            raise ModelError(f"{where}.{key}: unknown key; known: {', '.join(KEYS)}")
    if ("beam" in spec) == ("data" in spec):
        raise ModelError(f"{where}: give exactly one of beam = {{...}} and data = \"file\"")
    reduced = _from_beam(spec, where) if "beam" in spec else _from_data(spec, where, base)
    spin = _spin(spec, where, reduced, parameters or {})
    inv = _with_rigid_part(reduced.invariants, lumped)
    k = reduced.n_modes
    coords = tuple(f"{name}_m{i + 1}" for i in range(k))
    shape = lumped.shape
    if shape is None:                   # drawn as a rod along its nodes
        ends = reduced.nodes[[0, -1]]
        if np.any(ends[0] != ends[1]):
            shape = make_shape({"type": "rod", "start": list(ends[0]), "end": list(ends[1])},
                               f"body {name!r}")
    rigid = dataclasses.replace(rigid_body(name, inv), shape=shape)
    return FlexibleBody(name, reduced, inv, rigid, coords, tuple(f"{c}_dot" for c in coords),
                        dict(spec), spin)


def _spin(spec, where, reduced, parameters):
    """The spin speed (rad/s): a number, or the value of the parameter it names (a name
    only: the text is never evaluated); only with a gyroscopic matrix (``lateral``)."""
    value = spec.get("spin")
    if value is None:
        return 0.0
    if reduced.gyroscopic is None:
        raise ModelError(f"{where}.spin: a spinning rotor needs reduction = \"lateral\" "
                         "(the free-free lateral modes with their gyroscopic matrix, in a "
                         "frame that does not spin)")
    if isinstance(value, str):
        if value not in parameters:
            raise ModelError(f"{where}.spin: {value!r} is not a parameter; give a number "
                             "(rad/s) or a parameter's name"
                             + (f" ({', '.join(parameters)})" if parameters else ""))
        value = parameters[value]
    try:
        value = float(value)
    except (TypeError, ValueError):
        value = float("nan")
    if isinstance(spec["spin"], bool) or not math.isfinite(value):
        raise ModelError(f"{where}.spin: must be a finite spin speed in rad/s or a "
                         f"parameter's name, got {spec['spin']!r}")
    return value


def _count(spec, key, where):
    value = spec.get(key)
    if value is None:
        return None
    if key == "modes" and (isinstance(value, bool) or not isinstance(value, numbers.Integral)
                           or value < 1):
        raise ModelError(f"{where}.modes: must be a whole number >= 1, got {value!r}")
    if key == "f_max" and (isinstance(value, bool) or not isinstance(value, numbers.Real)
                           or not math.isfinite(value) or value <= 0):
        raise ModelError(f"{where}.f_max: must be a positive frequency in Hz, got {value!r}")
    return int(value) if key == "modes" else float(value)


def _from_beam(spec, where):
    reduction = spec.get("reduction", "craig-bampton")
    if reduction not in REDUCTIONS:
        raise ModelError(f"{where}.reduction: {reduction!r} is not one of "
                         f"{', '.join(REDUCTIONS)}")
    n_modes, f_max = _count(spec, "modes", where), _count(spec, "f_max", where)
    if n_modes is None and f_max is None:
        raise ModelError(f"{where}: give modes = N (how many modes to keep), f_max (a "
                         "cut-off in Hz) or both")
    beam = beam_from_spec(spec["beam"], key=f"{where}.beam")
    try:
        if reduction == "lateral":
            return lateral_modes(beam, n_modes=n_modes, f_max=f_max,
                                 damping=spec.get("damping", 0.0))
        return REDUCTIONS[reduction](beam, interface=("root",), n_modes=n_modes, f_max=f_max,
                                     damping=spec.get("damping", 0.0))
    except ModelError as exc:
        raise ModelError(f"{where}: {exc}") from None


def _from_data(spec, where, base):
    for key in ("modes", "f_max", "reduction"):
        if key in spec:
            raise ModelError(f"{where}.{key}: reduced data come with their modes; "
                             f"{key} applies to a beam only")
    path = spec["data"]
    if not isinstance(path, str) or not path:
        raise ModelError(f"{where}.data: must be a file name (.npz or .toml), got {path!r}")
    path = Path(path)
    if not path.is_absolute() and base is not None:
        path = Path(base) / path
    if not path.is_file():
        raise ModelError(f"{where}.data: no file {str(path)!r}")
    try:
        reduced = load_reduced_body(path)
    except ModelError as exc:
        raise ModelError(f"{where}.data: {exc}") from None
    if "damping" in spec:
        ratios = np.asarray(spec["damping"], dtype=float)
        if ratios.ndim > 1 or not np.all(np.isfinite(ratios)) or np.any(ratios < 0) or (
                ratios.ndim == 1 and len(ratios) != reduced.n_modes):
            raise ModelError(f"{where}.damping: one ratio >= 0 or {reduced.n_modes} (one "
                             f"per mode), got {spec['damping']!r}")
        C = modal_damping(reduced.stiffness_matrix, reduced.mass_matrix, ratios)
        reduced = dataclasses.replace(reduced, damping_matrix=C)
    return reduced


def _with_rigid_part(inv, lumped):
    """The invariants with a rigid part (mass ``m``, centre of mass ``s``, inertia ``I``
    about it) fixed to the frame: ``m``, ``m s`` and ``I + m (|s|^2 E - s s^T)`` added."""
    if not lumped.has_inertia:
        return inv
    m, s = lumped.mass, lumped.com
    return dataclasses.replace(
        inv, mass=inv.mass + m, first_moment=inv.first_moment + m * s,
        inertia=inv.inertia + lumped.inertia + m * ((s @ s) * np.eye(3) - np.outer(s, s)))


def rigid_body(name, inv):
    """The rigid ``Body`` with the invariants' mass properties at ``eta = 0``: mass ``m``,
    centre of mass ``c / m``, inertia about it ``J0 - m (|s|^2 E - s s^T)``."""
    m = inv.mass
    s = inv.first_moment / m
    I_G = inv.inertia - m * ((s @ s) * np.eye(3) - np.outer(s, s))
    I_G = 0.5 * (I_G + I_G.T)
    return make_body(name, m, s, I_G)

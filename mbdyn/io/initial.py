"""The initial state of a model file: ``[initial]`` coordinates and ``[initial_speeds]``
speeds (or, where ``u = q'``, the rates of coordinates) by name, the rest zero; the
quaternions of spherical and free joints checked and normalised.
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import ModelWarning
from .wording import suggest


def read_initial(b):
    """``(q0, u0, initial)`` of the compiled ``b.model``: the two vectors, and the values
    the file gives by name."""
    driven, rates = _driven_and_rates(b.system)
    q = _coordinates(b, driven)
    u = _speeds(b, driven, rates)
    q0 = b.model.q_vector(dict(q)).copy()
    u0 = b.model.u_vector(dict(u)).copy()
    _normalise_quaternions(b, q0)
    if b.model.has_loops:             # hold what the file gives, solve the rest
        guess = _guess(b, driven, q)
        with b.engine(("initial",)):
            q0, u0 = b.model.assemble(dict(q), dict(u), guess)
    elif b.doc.get("guess"):
        raise b.error(("guess",), "a [guess] table starts the assembly of closed loops; "
                      "this model has no loop joints -- remove it or use [initial]")
    initial = dict(q)
    initial.update(u)
    return q0, u0, initial


def _driven_and_rates(system):
    """``{coordinate or speed of a driven joint: the joint}`` and ``{coordinate: its
    speed}`` where the speed is the coordinate's rate (``u = q'``)."""
    driven = {}
    for j in system.joints.values():
        if j.drive is not None:
            for n in j.coordinates + j.speeds:
                driven[n] = j.name
    rates = {}                      # coordinate -> its speed, where u = q'
    for j in system.joints.values():
        if j.drive is None and j.kind in ("revolute", "prismatic", "euler"):
            rates.update(zip(j.coordinates, j.speeds))
    for body in system._flexible.values():      # modal coordinates: u = q'
        rates.update(zip(body.coordinates, body.speeds))
    return driven, rates


def _modal_off(b, name, path):
    """True (with a warning) for a modal coordinate or speed of a flexible body whose
    flexibility the scene switched off: the body is rigid, its value is not used."""
    for body in b.system._flexible.values():
        if name in body.coordinates + body.speeds and \
                body.coordinates[0] not in b.model.coordinates:
            warnings.warn(f"{'.'.join(map(str, path))}: body {body.name!r} is rigid in this "
                          "scene (flexibility_" f"{body.name} is off); {name} is ignored",
                          ModelWarning, stacklevel=4)
            return True
    return False


def _coordinates(b, driven):
    model = b.model
    q = {}
    for k, v in b.doc.get("initial", {}).items():
        path = ("initial", k)
        if k not in model.coordinates:
            if _modal_off(b, k, path):
                continue
            if k in driven:
                raise b.error(path, f"is the coordinate of driven joint "
                              f"{driven[k]!r}; its motion comes from the drive -- "
                              "remove it here")
            raise b.error(path, f"{k!r} is not a coordinate of the model; "
                          f"{suggest(k, model.coordinates)}the coordinates are: "
                          f"{', '.join(model.coordinates) or '(none)'}")
        q[k] = b.number(v, path)
    return q


def _speeds(b, driven, rates):
    model = b.model
    u = {}
    for k, v in b.doc.get("initial_speeds", {}).items():
        path = ("initial_speeds", k)
        if k in model.speeds:
            target = k
        elif _modal_off(b, k, path):
            continue
        elif k in rates:
            target = rates[k]
        else:
            if k in driven:
                raise b.error(path, f"belongs to driven joint {driven[k]!r}; its "
                              "speed comes from the drive -- remove it here")
            raise b.error(path, f"{k!r} is not a speed of the model; "
                          f"{suggest(k, model.speeds + tuple(rates))}the speeds are: "
                          f"{', '.join(model.speeds) or '(none)'}"
                          + (f" (or, for their rates, the coordinates "
                             f"{', '.join(rates)})" if rates else ""))
        if target in u:
            raise b.error(path, f"sets the speed {target!r} a second time; keep "
                          "one of the two keys")
        u[target] = b.number(v, path)
    return u


def _normalise_quaternions(b, q0):
    """Refuses a zero quaternion of a spherical or free joint; normalises one of another
    length than 1, with a warning."""
    model = b.model
    for j in b.system.joints.values():
        if j.drive is None and j.kind in ("spherical", "free"):
            names = j.coordinates[-4:]
            idx = [model.coordinate_index(n) for n in names]
            norm = float(np.linalg.norm(q0[idx]))
            if norm < 1e-12:
                raise b.error(("initial", names[0]), f"the quaternion of joint "
                              f"{j.name!r} ({', '.join(names)}) is zero; give a unit "
                              "quaternion, e.g. [cos(a/2), sin(a/2), 0, 0]")
            if abs(norm - 1.0) > 1e-9:
                warnings.warn(f"{b.file}: initial: the quaternion of joint {j.name!r} "
                              f"({', '.join(names)}) has length {norm:.6g}; it is "
                              "normalised to unit length", ModelWarning)
                q0[idx] = q0[idx] / norm


def _guess(b, driven, held):
    """``[guess]``: starting values of the coordinates the assembly solves for."""
    model = b.model
    out = {}
    for k, v in b.doc.get("guess", {}).items():
        path = ("guess", k)
        if k not in model.coordinates:
            if _modal_off(b, k, path):
                continue
            if k in driven:
                raise b.error(path, f"is the coordinate of driven joint {driven[k]!r}; the "
                              "drive gives it -- remove it here")
            raise b.error(path, f"{k!r} is not a coordinate of the model; "
                          f"{suggest(k, model.coordinates)}the coordinates are: "
                          f"{', '.join(model.coordinates) or '(none)'}")
        if k in held:
            raise b.error(path, f"{k!r} is also in [initial], which holds it; a guess is "
                          "for the coordinates the assembly solves -- keep one of the two")
        out[k] = b.number(v, path)
    return out

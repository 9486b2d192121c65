"""States by name on a compiled model: coordinate and speed vectors from arrays or
``{name: value}``, the default coordinates (identity quaternions), and the unit-quaternion
projection and drift; a frame's index by name, as the packers need it.
"""
from __future__ import annotations


import numpy as np

from ..errors import ModelError, NonFiniteError


def frame_slot(model, name, element):
    """The index of the frame ``name`` (-1: the ground), or a ``ModelError`` naming
    ``element`` and the frames there are."""
    if name == "ground":
        return -1
    if name not in model._frame_index:
        raise ModelError(f"{element}: unknown body {name!r}; the model's bodies and frames "
                         f"are {', '.join(model.frames)}, or 'ground'")
    return model._frame_index[name]


def default_coordinates(model):
    """Zero coordinates with identity quaternions."""
    q = np.zeros(model.nq)
    for s in model._quaternions:
        q[s.start] = 1.0
    return q


def q_vector(model, values=None):
    """Coordinates as an array from an array, or a mapping ``{name: value}`` over the
    defaults (unknown names are refused)."""
    return model._vector(values, model.default_coordinates(), model._coordinate_index,
                        "coordinate")


def u_vector(model, values=None):
    """Speeds as an array from an array, or a mapping ``{name: value}`` over zeros; as
    in model files, a revolute, prismatic or Euler-angle coordinate's name stands for
    its rate (``{"theta": 1}`` sets ``theta_dot``)."""
    if isinstance(values, dict):
        rates = {}
        for j in model.elements[1]:
            if j.drive is None and j.kind in ("revolute", "prismatic", "euler"):
                rates.update(zip(j.coordinates, j.speeds))
        mapped = {}
        for k, v in values.items():
            target = k if k in model._speed_index else rates.get(k, k)
            if target in mapped:
                raise ModelError(f"speed {target!r} is given twice ({k!r} stands for it); "
                                 "keep one of the two")
            mapped[target] = v
        values = mapped
    return model._vector(values, np.zeros(model.nu), model._speed_index, "speed")


def vector(model, values, default, index, what):
    try:
        return model._vector_of(values, default, index, what)
    except ModelError:
        raise
    except (TypeError, ValueError):
        raise ModelError(f"the {what}s must be numbers, given as an array or as "
                         f"{{name: value}}; got {values!r}") from None


def vector_of(model, values, default, index, what):
    if values is None:
        return default
    if isinstance(values, dict):
        for k, val in values.items():
            if k not in index and k in model._joint and np.ndim(val) == 1:
                # a joint's name: all its coordinates (or speeds) at once, e.g. a
                # spherical joint's quaternion from mbdyn.rotations
                joint = model._joint[k]
                names = joint.coordinates if what == "coordinate" else joint.speeds
                if len(val) != len(names) or any(n not in index for n in names):
                    raise ModelError(f"joint {k!r}: give its {len(names)} {what}s "
                                     f"({', '.join(names)}), got {len(val)} values")
                for n, v in zip(names, val):
                    default[index[n]] = float(v)
                continue
            if k not in index:
                raise ModelError(f"unknown {what} {k!r}; the model's {what}s are "
                                 f"{', '.join(index) or '(none)'}")
            default[index[k]] = float(val)
        return default
    arr = np.array(values, dtype=float).reshape(-1)
    if arr.shape != default.shape:
        raise ModelError(f"expected {default.size} {what}s ({', '.join(index)}), "
                         f"got {arr.size} values")
    return arr


def normalize_quaternions(model, q):
    """Project every joint quaternion in ``q`` back onto the unit sphere (in place);
    returns the largest ``| |quat| - 1 |`` found before projection."""
    drift = 0.0
    for s in model._quaternions:
        n = np.linalg.norm(q[s])
        if not (np.isfinite(n) and n > 0):
            raise NonFiniteError(f"model {model.name!r}: the quaternion "
                                 f"{', '.join(model.coordinates[s])} is {q[s].tolist()}, "
                                 "which has no direction; give a finite, non-zero one")
        drift = max(drift, abs(n - 1.0))
        q[s] /= n
    return drift


def quaternion_drift(model, q):
    """Largest ``| |quat| - 1 |`` over the joint quaternions in ``q`` (0 if none); ``q``
    one state or an array of states (one per row)."""
    q = np.asarray(q, dtype=float)
    if not model._quaternions or not q.size:
        return 0.0
    return float(max(np.abs(np.linalg.norm(q[..., s], axis=-1) - 1.0).max()
                     for s in model._quaternions))

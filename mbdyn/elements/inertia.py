"""Inertia tensors of common shapes about their centre of mass, and the parallel-axis theorem.

Each shape's symmetry axis is the body ``z`` axis unless an argument says otherwise;
results are 3x3 tensors in body axes (kg m^2).
"""
import numbers

import numpy as np

from ..errors import ModelError
from ..limits import magnitude_problem


def _nonnegative(shape, **values):
    """Refuse a mass or dimension of a shape helper that is not a number, negative,
    non-finite or beyond the magnitudes mbdyn accepts; sympy expressions pass (their sign is
    the user's to keep)."""
    for name, v in values.items():
        if getattr(v, "free_symbols", None):
            continue
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            raise ModelError(f"inertia.{shape}: {name} must be a number (or a sympy "
                             f"expression of parameters), got {v!r}")
        if not (np.isfinite(v) and v >= 0):
            raise ModelError(f"inertia.{shape}: {name} must be a finite number >= 0, got {v!r}")
        problem = magnitude_problem(float(v))
        if problem:
            raise ModelError(f"inertia.{shape}: {name} {problem}")


def _axis_index(axis, shape="disk"):
    if not isinstance(axis, str) or axis not in ("x", "y", "z"):
        raise ModelError(f"inertia.{shape}: axis must be 'x', 'y' or 'z', got {axis!r}")
    return {"x": 0, "y": 1, "z": 2}[axis]


def _symmetric(mass, axial, transverse, axis, shape):
    index = _axis_index(axis, shape)
    moments = np.full(3, float(transverse))
    moments[index] = axial
    return np.diag(moments)


def disk(mass, radius, axis="z"):
    """Thin uniform disk: ``m r^2/2`` about its axis, ``m r^2/4`` across."""
    _nonnegative('disk', mass=mass, radius=radius)
    return _symmetric(mass, mass * radius**2 / 2, mass * radius**2 / 4, axis, "disk")


def cylinder(mass, radius, length, axis="z"):
    """Solid uniform cylinder: ``m r^2/2`` about its axis, ``m (3 r^2 + L^2)/12`` across."""
    _nonnegative('cylinder', mass=mass, radius=radius, length=length)
    return _symmetric(mass, mass * radius**2 / 2, mass * (3 * radius**2 + length**2) / 12, axis,
                      "cylinder")


def rod(mass, length, axis="z"):
    """Slender uniform rod along ``axis``: 0 about it, ``m L^2/12`` across."""
    _nonnegative('rod', mass=mass, length=length)
    return _symmetric(mass, 0.0, mass * length**2 / 12, axis, "rod")


def sphere(mass, radius):
    """Solid uniform sphere: ``2 m r^2/5`` about any axis."""
    _nonnegative('sphere', mass=mass, radius=radius)
    return np.eye(3) * (2 * mass * radius**2 / 5)


def box(mass, a, b, c):
    """Solid uniform box with edges ``a, b, c`` along body x, y, z."""
    _nonnegative('box', mass=mass, a=a, b=b, c=c)
    return np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * (mass / 12)


def _shift(helper, inertia, mass, offset):
    """The tensor, mass and offset of ``parallel_axis``/``about_com``, checked: a 3x3 tensor
    (or three principal moments), a mass and three coordinates, all finite numbers."""
    _nonnegative(helper, mass=mass)
    try:
        I = np.array(inertia, dtype=float)
        d = np.array(offset, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"inertia.{helper}: give the inertia as a 3x3 tensor (or three "
                         f"principal moments) and the offset as three numbers, got "
                         f"{inertia!r} and {offset!r}") from None
    if I.shape == (3,):
        I = np.diag(I)
    if I.shape != (3, 3) or d.shape != (3,):
        raise ModelError(f"inertia.{helper}: give the inertia as a 3x3 tensor (or three "
                         f"principal moments) and the offset as three numbers, got shapes "
                         f"{I.shape} and {d.shape}")
    for name, arr in (("inertia", I), ("offset", d)):
        for v in arr.ravel():
            problem = f"{v:g} is not a finite number" if not np.isfinite(v) else \
                magnitude_problem(float(v))
            if problem:
                raise ModelError(f"inertia.{helper}: {name}: {problem}")
    return I, float(mass), d


def parallel_axis(inertia_com, mass, offset):
    """Inertia about a point at ``offset`` from the centre of mass (same axes):
    ``I_P = I_G + m (|d|^2 E - d d^T)``."""
    I, mass, d = _shift("parallel_axis", inertia_com, mass, offset)
    return I + mass * (d @ d * np.eye(3) - np.outer(d, d))


def about_com(inertia_point, mass, offset):
    """Inverse of ``parallel_axis``: the inertia about the centre of mass from the inertia
    about a point at ``offset`` from it (e.g. a top's data given about its contact point)."""
    I, mass, d = _shift("about_com", inertia_point, mass, offset)
    return I - mass * (d @ d * np.eye(3) - np.outer(d, d))

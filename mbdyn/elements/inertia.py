"""Inertia tensors of common shapes about their centre of mass, and the parallel-axis theorem.

Each shape's symmetry axis is the body ``z`` axis unless an argument says otherwise;
results are 3x3 tensors in body axes (kg m^2).
"""
import numpy as np

from ..errors import ModelError


def _nonnegative(shape, **values):
    """Refuse a negative (or non-finite) mass or dimension of a shape helper; sympy symbols
    pass (their sign is the user's to keep)."""
    for name, v in values.items():
        if isinstance(v, (int, float, np.number)) and not (np.isfinite(v) and v >= 0):
            raise ModelError(f"inertia.{shape}: {name} must be a finite number >= 0, got {v!r}")


def _axis_index(axis):
    return {"x": 0, "y": 1, "z": 2}[axis]


def _symmetric(mass, axial, transverse, axis):
    moments = np.full(3, float(transverse))
    moments[_axis_index(axis)] = axial
    return np.diag(moments)


def disk(mass, radius, axis="z"):
    """Thin uniform disk: ``m r^2/2`` about its axis, ``m r^2/4`` across."""
    _nonnegative('disk', mass=mass, radius=radius)
    return _symmetric(mass, mass * radius**2 / 2, mass * radius**2 / 4, axis)


def cylinder(mass, radius, length, axis="z"):
    """Solid uniform cylinder: ``m r^2/2`` about its axis, ``m (3 r^2 + L^2)/12`` across."""
    _nonnegative('cylinder', mass=mass, radius=radius, length=length)
    return _symmetric(mass, mass * radius**2 / 2, mass * (3 * radius**2 + length**2) / 12, axis)


def rod(mass, length, axis="z"):
    """Slender uniform rod along ``axis``: 0 about it, ``m L^2/12`` across."""
    _nonnegative('rod', mass=mass, length=length)
    return _symmetric(mass, 0.0, mass * length**2 / 12, axis)


def sphere(mass, radius):
    """Solid uniform sphere: ``2 m r^2/5`` about any axis."""
    _nonnegative('sphere', mass=mass, radius=radius)
    return np.eye(3) * (2 * mass * radius**2 / 5)


def box(mass, a, b, c):
    """Solid uniform box with edges ``a, b, c`` along body x, y, z."""
    _nonnegative('box', mass=mass, a=a, b=b, c=c)
    return np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * (mass / 12)


def parallel_axis(inertia_com, mass, offset):
    """Inertia about a point at ``offset`` from the centre of mass (same axes):
    ``I_P = I_G + m (|d|^2 E - d d^T)``."""
    d = np.asarray(offset, dtype=float)
    return np.asarray(inertia_com, dtype=float) + mass * (d @ d * np.eye(3) - np.outer(d, d))


def about_com(inertia_point, mass, offset):
    """Inverse of ``parallel_axis``: the inertia about the centre of mass from the inertia
    about a point at ``offset`` from it (e.g. a top's data given about its contact point)."""
    d = np.asarray(offset, dtype=float)
    return np.asarray(inertia_point, dtype=float) - mass * (d @ d * np.eye(3) - np.outer(d, d))

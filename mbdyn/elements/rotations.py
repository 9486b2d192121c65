"""Orientations for initial states: unit quaternions ``(w, x, y, z)`` of spherical and
free joints from an axis and angle, Euler angles or a rotation matrix, and angular
velocities between world and body axes.

Conventions as the engine's: a joint quaternion maps child components to parent
components (``P s = R(q) B s``); a spherical or free joint's speeds are the angular velocity
of the child relative to the parent in the child's own axes.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .values import parse_axis, parse_sequence


def _numbers(value, shape, where, what):
    """``value`` as a float array of ``shape``, every entry finite; else a ModelError."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.shape != shape or not np.all(np.isfinite(arr)):
        size = f"{' x '.join(map(str, shape))} finite numbers" if shape else "a finite number"
        raise ModelError(f"{where}: {what} must be {size}, got {value!r}")
    return arr


def from_axis_angle(axis, angle):
    """The quaternion of a rotation by ``angle`` (rad) about ``axis`` (a vector or
    ``"x"``/``"y"``/``"z"``)."""
    a = parse_axis(axis, "rotation")
    angle = float(_numbers(angle, (), "from_axis_angle", "angle"))
    return np.array([np.cos(angle / 2), *(np.sin(angle / 2) * a)])


def product(a, b):
    """The quaternion product ``a (x) b`` (rotation ``b`` then ``a``, in the fixed frame)."""
    w1, x1, y1, z1 = _numbers(a, (4,), "product", "a quaternion")
    w2, x2, y2, z2 = _numbers(b, (4,), "product", "a quaternion")
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def from_euler(angles, sequence="ZXZ"):
    """The quaternion of three successive rotations about moving axes (``sequence`` as an
    euler joint's: ``"ZXZ"`` is the textbook's precession, nutation, spin)."""
    seq = parse_sequence(sequence, "rotation")
    angles = _numbers(angles, (3,), "from_euler", "angles")
    q = np.array([1.0, 0.0, 0.0, 0.0])
    for k, angle in zip(seq, angles):
        q = product(q, from_axis_angle(np.eye(3)[k], angle))
    return q


def to_matrix(q):
    """The rotation matrix of a unit quaternion (child to parent components)."""
    try:
        q = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"to_matrix: {q!r} is not a quaternion (four finite numbers, not "
                         "all zero)") from None
    n = np.linalg.norm(q)
    if q.shape != (4,) or not (np.isfinite(n) and n > 0):
        raise ModelError(f"to_matrix: {q.tolist()} is not a quaternion (four finite numbers, "
                         "not all zero)")
    w, x, y, z = q / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def from_matrix(R):
    """The unit quaternion (``w >= 0``) of a proper rotation matrix."""
    R = _numbers(R, (3, 3), "from_matrix", "R")
    if R.shape != (3, 3) or np.abs(R.T @ R - np.eye(3)).max() > 1e-8 or \
            np.linalg.det(R) < 0:
        raise ModelError("from_matrix: not a proper rotation matrix (needs R^T R = I and "
                         "det R = +1)")
    tr = np.trace(R)
    if tr > 0:
        s = 2 * np.sqrt(tr + 1)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2 * np.sqrt(1 + R[i, i] - R[j, j] - R[k, k])
        v = np.empty(3)
        v[i] = 0.25 * s
        v[j] = (R[j, i] + R[i, j]) / s
        v[k] = (R[k, i] + R[i, k]) / s
        q = [(R[k, j] - R[j, k]) / s, *v]
    q = np.array(q)
    return q if q[0] >= 0 else -q


def body_rates(q, omega):
    """The angular velocity ``omega`` given in the parent's (for a joint on the ground:
    the world's) axes, in the child's own axes -- what a spherical or free joint's speeds
    are."""
    return to_matrix(q).T @ _numbers(omega, (3,), "body_rates", "omega")


def parent_rates(q, omega_body):
    """The inverse of ``body_rates``."""
    return to_matrix(q) @ _numbers(omega_body, (3,), "parent_rates", "omega_body")

"""Steps 1-6 of the textbook on a compiled model: the motion of every frame and centre of
mass, the Jacobians of rotation and translation, points fixed on frames, and the kinematic
equations ``q' = N(q) u``.  Vectors in world components unless said otherwise.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..kernels import evaluate as ke
from ..kernels import joints as kj
from ..kernels.kinematics import point_jacobian


@dataclass(frozen=True)
class Kinematics:
    """Motion of every frame (rows in ``Model.frames`` order).

    World components: ``R`` (``I s = R . B s``), ``r, v, a`` of frame origins, ``w, alpha``
    angular velocity and acceleration, ``r_com, v_com, a_com`` of centres of mass.
    Own-frame components (as the textbook writes them): ``w_body``, ``alpha_body``.
    """
    frames: tuple
    R: np.ndarray
    r: np.ndarray
    v: np.ndarray
    a: np.ndarray
    w: np.ndarray
    alpha: np.ndarray
    r_com: np.ndarray
    v_com: np.ndarray
    a_com: np.ndarray

    @property
    def T(self):
        """The textbook's transformation matrices ``B s = T . I s`` (``R`` transposed)."""
        return np.transpose(self.R, (0, 2, 1))

    @property
    def w_body(self):
        return np.einsum("nji,nj->ni", self.R, self.w)

    @property
    def alpha_body(self):
        return np.einsum("nji,nj->ni", self.R, self.alpha)

    def frame(self, name):
        """Index of a frame by name."""
        return self.frames.index(name)


def kinematics_kernel(model, q, u, t, ud=None):
    q, u = model._fill(q, u, t)
    if ud is not None:
        model._udfull[model._free_u] = ud
    try:
        ke.kinematics_and_loads(*model._tree, model._mass, model._com, model.gravity,
                                model._qfull, model._ufull, model._udfull,
                                *model._loads_arrays, *model._kin_out, model._scratch)
    except ZeroDivisionError:
        raise model._division_by_zero(q, t) from None
    return q, u


def drop_velocity_products(model):
    """With the gyroscopic effect off: bias accelerations without velocity products."""
    if not model.gyroscopic:
        ke.drop_velocity_products(*model._tree, model._qfull, model._ufull, model._udfull,
                                  *model._kin_out[:9], model._scratch)


def kinematics(model, q, u=None, ud=None, t=0.0):
    """Positions, velocities and accelerations of every frame and centre of mass.

    With ``ud=None`` the accelerations are those at zero free speed rates (the
    velocity-product part); pass ``ud`` for the full accelerations.
    """
    u = np.zeros(model.nu) if u is None else u
    model._kinematics_kernel(q, u, t, ud)
    R = model._R.copy()
    c = np.einsum("nij,nj->ni", R, model._com)
    w, al = model._w.copy(), model._alpha.copy()
    return Kinematics(model.frames, R, model._r.copy(), model._v.copy(), model._a.copy(), w, al,
                      model._r + c, model._v + np.cross(w, c),
                      model._a + np.cross(al, c) + np.cross(w, np.cross(w, c)))


def jacobian_rotation(model, q, frame, t=0.0):
    """``dw/du`` of a frame (3 x nu, world components)."""
    i = model.frame_index(frame)
    model._full_workspace()
    model._kinematics_kernel(q, np.zeros(model.nu), t)
    return model._JR[i].copy()


def jacobian_translation(model, q, frame, point=None, t=0.0):
    """``dv/du`` of a point fixed on a frame (3 x nu, world components).

    ``point`` is in the frame's own components from its origin; default the centre of
    mass of a body (the origin of a massless frame).
    """
    i = model.frame_index(frame)
    model._full_workspace()
    model._kinematics_kernel(q, np.zeros(model.nu), t)
    p = model._com[i] if point is None else np.asarray(point, dtype=float)
    out = np.empty((3, model.nu))
    point_jacobian(model._JT[i], model._JR[i], model._R[i] @ p, out)
    return out


def point_positions(model, q, points, t=0.0):
    """World positions of points fixed on frames: ``points`` is a list of
    ``(frame, offset in the frame's components)``; returns an array (len(points), 3)."""
    try:
        specs = [(frame, np.asarray(offset, dtype=float).reshape(3))
                 for frame, offset in points]
    except (TypeError, ValueError):
        raise ModelError("point_positions: points must be a list of (frame, offset) with "
                         f"offset three numbers, got {points!r}") from None
    model._kinematics_kernel(q, np.zeros(model.nu), t)
    out = np.empty((len(specs), 3))
    for k, (frame, offset) in enumerate(specs):
        i = model.frame_index(frame)
        out[k] = model._r[i] + model._R[i] @ offset
    return out


def coordinate_rates(model, q, u):
    """Kinematic equations ``q' = N(q) u``; quaternion rates use the normalised
    quaternion, so that ``|q|`` is an invariant of the exact flow."""
    u = np.asarray(u, dtype=float)
    if not model._quaternions:
        return u.copy()
    qd = np.empty(model.nq)
    try:
        kj.coordinate_rates(np.asarray(q, dtype=float), u, model._slots, qd)
    except ZeroDivisionError:
        raise model._division_by_zero(q) from None
    return qd

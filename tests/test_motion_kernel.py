"""``kernels.motion.turned``: a revolute joint's rotation ``J Rot(a, q)`` and axis ``J a``,
with the axes along ``x``, ``y``, ``z`` (either sign) written out, against the general
product ``mm(J, rodrigues(...))`` and against ``joints.rotation_about_axis`` through numpy
(``walk``'s route), for every signed coordinate axis and a skew one."""
import numpy as np
import pytest
from numba import njit
from numba.core import config

from mbdyn.kernels.joints import rotation_about_axis
from mbdyn.kernels.motion import mm, mv, rodrigues, turned

compiled_only = pytest.mark.skipif(config.DISABLE_JIT,
                                   reason="internal kernels are called from compiled code")


@njit
def _both(J, a, angle):
    Jt = (J[0, 0], J[0, 1], J[0, 2], J[1, 0], J[1, 1], J[1, 2], J[2, 0], J[2, 1], J[2, 2])
    Ri, e = turned(Jt, a[0], a[1], a[2], angle)
    general = mm(Jt, rodrigues(a[0], a[1], a[2], angle))
    axis = mv(Jt, a[0], a[1], a[2])
    out = np.empty((5, 3, 3))
    rotation_about_axis(a, angle, out[4])
    for k in range(9):
        out[0, k // 3, k % 3] = Ri[k]
        out[1, k // 3, k % 3] = general[k]
    for k in range(3):
        out[2, 0, k] = e[k]
        out[3, 0, k] = axis[k]
    return out


AXES = [(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 0.0),
        (0.0, 0.0, 1.0), (0.0, 0.0, -1.0), tuple(np.array([0.3, -0.5, 0.8]) / np.sqrt(0.98))]


@compiled_only
@pytest.mark.parametrize("axis", AXES)
def test_turned_agrees_with_the_general_rotation(axis):
    rng = np.random.default_rng(5)
    J, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    a = np.array(axis)
    for angle in (0.0, 0.7, -2.9, 3.1):
        out = _both(J, a, angle)
        Rrel = out[4]
        assert np.abs(out[0] - out[1]).max() < 1e-15
        assert np.abs(out[0] - J @ Rrel).max() < 1e-15
        assert np.abs(out[2, 0] - J @ a).max() < 1e-15
        assert np.array_equal(out[2, 0], out[3, 0])

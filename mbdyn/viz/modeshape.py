"""A mode shape oscillating about its operating point, as an animation.

The motion ``x(t) = amplitude Re(phi e^{s t})`` of a mode (``mbdyn.analysis.modes``) in
the tangent coordinates of the linearisation is mapped back to coordinates
(``analysis.tangent``) and drawn like a run: two periods, slowed or sped up so that one
period lasts ``period_seconds`` of playback.  The growth or decay of the mode is shown
too (its real part), unless ``steady=True``.  A closed mechanism's mode moves every
coordinate (``Mode.motion``), and each frame is put back on the constraints
(``Model.project``: the linear motion leaves them at second order).
"""
from __future__ import annotations

import numpy as np

from ..analysis.tangent import Tangent
from ..errors import ModelError
from ..integrate.result import Result
from .animate import animate


def mode_motion(lin, mode, amplitude=0.1, periods=2.0, samples=200, steady=False):
    """A ``Result`` holding the mode's motion about ``lin``'s operating point."""
    if mode.damped_frequency <= 0:
        raise ModelError("this mode does not oscillate (a real eigenvalue or a rigid-body "
                         "mode); pick an oscillating one")
    model = lin.model
    T = 2 * np.pi / mode.damped_frequency
    t = np.linspace(0.0, periods * T, samples)
    s = complex(0.0 if steady else mode.eigenvalue.real, mode.damped_frequency)
    tangent = Tangent(model, lin.q0)
    x = amplitude * np.real(np.outer(np.exp(s * t), mode.motion))
    xd = amplitude * np.real(np.outer(s * np.exp(s * t), mode.motion))
    q = np.array([tangent.retract(row) for row in x])
    u = lin.u0 + xd
    if model.has_loops:
        for k in range(len(t)):
            q[k], u[k] = model.project(q[k], u[k], lin.t)
    return Result(model, t, q, u, [], {"mode_frequency_hz": mode.frequency_hz})


def animate_mode(lin, mode, out, amplitude=0.1, period_seconds=2.0, fps=30.0, title=None):
    """Write the mode's animation to ``out`` (.gif, .mp4, .html); returns the frame count."""
    res = mode_motion(lin, mode, amplitude)
    T = 2 * np.pi / mode.damped_frequency
    speed = T / period_seconds
    title = title or (f"{lin.model.name}: mode at {mode.frequency_hz:.4g} Hz "
                      f"(zeta {mode.damping_ratio:.3g})")
    return animate(res, out, speed=speed, fps=fps, title=title)

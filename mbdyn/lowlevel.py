"""The low-level entry: the compiled kernels of one model, for users who drive their own
loops (``Model.lowlevel()``).

Each call is one compiled call on the model's packed buffers after the essential checks
(the inputs are float64 numpy arrays of the right sizes: anything else would make numba
compile anew or write past the buffers): no conversion, no copy of the result.
What it returns is a view into the model's workspace, overwritten by the next evaluation
of the same model (copy it, or pass ``out=``, to keep it).  Failures raise the same errors
as ``Model.forward_dynamics`` (a degree of freedom without inertia, NaN or Inf), found
after the fact; drives and loads written as Python functions are evaluated at ``t`` as in
the ``Model`` methods.  Not thread-safe (one workspace per model).
"""
from __future__ import annotations

import numpy as np

from .errors import ModelError
from .kernels import packed as kp

_ARRAY, _F64 = np.ndarray, np.dtype(np.float64)

#: per-call formulations of the low-level entry
ROUTES = {"jourdain": (kp.jourdain_accelerations_packed, kp.state_derivative_packed),
          "articulated": (kp.articulated_accelerations_packed,
                          kp.state_derivative_articulated_packed)}


class LowLevel:
    """``forward_dynamics(q, u, t=0.0, out=None)`` and ``state_derivative(y, t=0.0,
    out=None)`` of one model by one route (``"jourdain"`` or ``"articulated"``)."""

    def __init__(self, model, method):
        if method not in ROUTES:
            raise ModelError(f"lowlevel: unknown method {method!r}; use one of "
                             f"{', '.join(ROUTES)} (or 'auto')")
        self.model = model
        self.method = method
        self._fd, self._sd = ROUTES[method]
        self._fb, self._ib, self._t = model._packed
        self._ud = model._ud
        self._inputs = model._python_inputs
        self._nq, self._nu = model.nq, model.nu
        self._ydot = np.empty(model.nq + model.nu)
        self._q_shape, self._u_shape = (model.nq,), (model.nu,)
        self._y_shape = (model.nq + model.nu,)
        self.forward_dynamics = self._bind_forward_dynamics()

    def _bind_forward_dynamics(self):
        """``forward_dynamics`` as a closure over locals: attribute look-ups cost a tenth
        of a small model's call."""
        array, f64, fill, fail = _ARRAY, _F64, self.model._fill_inputs, self._fail
        fd, fb, ib, table, ud = self._fd, self._fb, self._ib, self._t, self._ud
        q_shape, u_shape, inputs, refuse = self._q_shape, self._u_shape, self._inputs, self._refuse

        def forward_dynamics(q, u, t=0.0, out=None):
            """Speed rates ``u'`` (a workspace view unless ``out`` is given)."""
            if not (q.__class__ is array and u.__class__ is array and q.dtype is f64
                    and u.dtype is f64 and q.shape == q_shape and u.shape == u_shape):
                refuse(q=q, u=u)
            if inputs:
                fill(q, u, t)
            if fd(fb, ib, table, q, u) != -1:
                fail(q, u, t)
            if out is None:
                return ud
            out[:] = ud
            return out
        return forward_dynamics

    def __repr__(self):
        return f"<LowLevel {self.model.name!r} {self.method}: nq={self._nq}, nu={self._nu}>"

    def state_derivative(self, y, t=0.0, out=None):
        """``[q', u']`` of ``y = [q, u]`` (a workspace array unless ``out`` is given)."""
        if not (type(y) is _ARRAY and y.dtype is _F64 and y.shape == self._y_shape):
            self._refuse(y=y)
        if self._inputs:
            self.model._fill_inputs(y[:self._nq], y[self._nq:], t)
        ydot = self._ydot if out is None else out
        status = self._sd(self._fb, self._ib, self._t, y, ydot)
        if status != -1:
            self.model.state_derivative(t, y, self.method)   # raises the precise error
        return ydot

    def _refuse(self, **arrays):
        sizes = {"q": self._nq, "u": self._nu, "y": self._nq + self._nu}
        for name, a in arrays.items():
            if not (isinstance(a, np.ndarray) and a.dtype == np.float64
                    and a.shape == (sizes[name],)):
                got = (f"{a.dtype} array of shape {a.shape}" if isinstance(a, np.ndarray)
                       else type(a).__name__)
                raise ModelError(f"lowlevel: {name} must be a float64 numpy array of shape "
                                 f"({sizes[name]},), got {got}; convert it once with "
                                 "np.asarray(..., dtype=float) outside the loop")
        raise ModelError("lowlevel: the inputs must be plain float64 numpy arrays")

    def _fail(self, q, u, t):
        """Raise what went wrong, found by the checked call."""
        self.model.forward_dynamics(q, u, t, self.method)    # raises the precise error
        raise ModelError("lowlevel: the compiled evaluation failed where the checked call "
                         "did not")

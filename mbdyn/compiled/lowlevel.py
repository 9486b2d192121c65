"""The low-level entry: the compiled kernels of one model, for users who drive their own
loops (``Model.lowlevel()``).

Each call is one compiled call on the model's packed buffers, with the essential checks
made there: the entry points are compiled for contiguous, writable float64 arrays only
(numba refuses any other type at the call instead of compiling for it), and check the
sizes before they touch the buffers.  No conversion, no copy of the result.
What it returns is a view into the model's workspace, overwritten by the next evaluation
of the same model (copy it, or pass ``out=``, to keep it).  Failures raise the same errors
as ``Model.forward_dynamics`` (a degree of freedom without inertia, NaN or Inf), found
after the fact; drives and loads written as Python functions are evaluated at ``t`` as in
the ``Model`` methods.  Not thread-safe (one workspace per model).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..errors import ModelError
from ..kernels import entries
from ..kernels import packed as kp
from ..kernels.entries import FORWARD_SIGNATURE as SIGNATURE
from ..kernels.entries import WRONG_SIZE
from ..kernels.entries import articulated_forward as _articulated_forward
from ..kernels.entries import jourdain_forward as _jourdain_forward
from ..kernels.entries import entry as _entry
from ..kernels.views import UNCOUNTED, c_view

_ARRAY, _F64 = np.ndarray, np.dtype(np.float64)

# The integer buffer ``ib`` starts with the offset table (``packed.pack``) and stands for it:
# one array less for numba to type and unbox at every call.

@njit(inline="always", **UNCOUNTED)
def _state(derivative, fb, ib, y, ydot):
    """``derivative`` (a packed kernel) of ``y`` into ``ydot``, after the sizes."""
    if y.shape[0] != ib[7] + ib[1] or ydot.shape[0] != y.shape[0]:
        return WRONG_SIZE
    return derivative(fb, ib, ib, kp.force_table(ib, ib), y, ydot)


def _jourdain_state(fb, ib, y, ydot):
    return _state(kp.state_derivative_packed, fb, ib, y, ydot)


@njit(inline="always", **UNCOUNTED)
def _articulated_derivative(fb, ib, t, forces, y, ydot):
    return kp.state_derivative_articulated_packed(fb, ib, forces, y, ydot)


def _articulated_state(fb, ib, y, ydot):
    return _state(_articulated_derivative, fb, ib, y, ydot)


def _tree_reactions(fb, ib, q, u, out):
    """The joint wrenches ``out`` (frames x 6: force, moment; world components, about
    each child's origin) and ``u'`` by the Newton-Euler equations in tree order."""
    n = ib[0]
    if q.shape[0] != ib[7] or u.shape[0] != ib[1] or out.shape[0] != n or out.shape[1] != 6:
        return WRONG_SIZE
    status = kp.newton_euler_tree_packed(fb, ib, ib, kp.force_table(ib, ib), q, u)
    wrench = c_view(fb, ib[kp.WRENCH], (n, 6))
    for i in range(n):
        for k in range(6):
            out[i, k] = wrench[i, k]
    return status


#: the signature of the reactions' entry point
REACTIONS_SIGNATURE = ("int64(float64[::1], int64[::1], float64[::1], float64[::1], "
                       "float64[:, ::1])")
#: per-call formulations of the low-level entry: (forward dynamics, state derivative)
ROUTES = {"jourdain": (_jourdain_forward, _jourdain_state),
          "articulated": (_articulated_forward, _articulated_state)}
#: the signatures of the two entry points
SIGNATURES = (SIGNATURE, "int64(float64[::1], int64[::1], float64[::1], float64[::1])")


class LowLevel:
    """``forward_dynamics(q, u, t=0.0, out=None)`` and ``state_derivative(y, t=0.0,
    out=None)`` of one model by one route (``"jourdain"`` or ``"articulated"``)."""

    def __init__(self, model, method):
        if method not in ROUTES:
            raise ModelError(f"lowlevel: unknown method {method!r}; use one of "
                             f"{', '.join(ROUTES)} (or 'auto')")
        self.model = model
        self.method = method
        if method == "jourdain":
            model._full_workspace()
        self._fd, self._sd = (_entry(f, sig) for f, sig in zip(ROUTES[method], SIGNATURES))
        # the full tree's buffers (the reactions, the Jourdain route), the merged tree's
        # integer buffer (the articulated bodies, inverse dynamics, the mass matrix:
        # compiled.merging); the float buffer is the same
        self._fb, self._ib_full = model._packed[:2]
        self._ib_merged = model._dynamics[1]
        self._ib, self._ud = ((self._ib_full, model._ud) if method == "jourdain"
                              else (self._ib_merged, model._dynamics_ud))
        self._inputs = model._python_inputs
        self._nq, self._nu = model.nq, model.nu
        self._ydot = np.empty(model.nq + model.nu)
        self._wrenches = np.empty((model.n_frames, 6))
        self._tau, self._M = np.empty(model.nu), np.empty((model.nu, model.nu))
        self.forward_dynamics = self._bind_forward_dynamics()

    def _bind_forward_dynamics(self):
        """``forward_dynamics`` as a closure over locals: attribute look-ups cost a tenth
        of a small model's call.  The types and sizes are checked by the compiled entry
        (numba refuses any other type; the entry returns ``WRONG_SIZE``)."""
        fill, fail, refuse = self.model._fill_inputs, self._fail, self._refuse
        fd, fb, ib, ud, inputs = self._fd, self._fb, self._ib, self._ud, self._inputs

        def forward_dynamics(q, u, t=0.0, out=None):
            """Speed rates ``u'`` (a workspace view unless ``out`` is given)."""
            if inputs:
                refuse(q=q, u=u)          # (only when the inputs are good: nothing raised)
                fill(q, u, t)
            if out is None:
                out = ud
            try:
                status = fd(fb, ib, q, u, out)
            except TypeError:
                status = WRONG_SIZE
            if status != -1:
                if status == WRONG_SIZE:
                    refuse(q=q, u=u, out=out)
                fail(q, u, t)
            return out
        return forward_dynamics

    def __repr__(self):
        return f"<LowLevel {self.model.name!r} {self.method}: nq={self._nq}, nu={self._nu}>"

    def state_derivative(self, y, t=0.0, out=None):
        """``[q', u']`` of ``y = [q, u]`` (a workspace array unless ``out`` is given)."""
        if self._inputs:
            self._refuse(y=y)
            self.model._fill_inputs(y[:self._nq], y[self._nq:], t)
        ydot = self._ydot if out is None else out
        try:
            status = self._sd(self._fb, self._ib, y, ydot)
        except TypeError:
            status = WRONG_SIZE
        if status != -1:
            if status == WRONG_SIZE:
                self._refuse(y=y, out=ydot)
            self.model.state_derivative(t, y, self.method)   # raises the precise error
        return ydot

    def reactions(self, q, u, t=0.0, out=None):
        """The joint wrenches, one row per joint in ``Model.joints`` order: the force and
        the moment the parent exerts on the child about the joint origin, world
        components (``Model.reaction_array``), by the Newton-Euler equations in tree
        order (whatever the entry's route); a workspace array unless ``out`` is given."""
        model = self.model
        if model._con is not None:
            raise ModelError(f"model {model.name!r} has closed loops: use "
                             "model.reaction_array(q, u, t)")
        if self._inputs:
            self._refuse(q=q, u=u)
            model._fill_inputs(q, u, t)
        if out is None:
            out = self._wrenches
        try:
            status = _entry(_tree_reactions, REACTIONS_SIGNATURE)(self._fb, self._ib_full,
                                                                   q, u, out)
        except TypeError:
            status = WRONG_SIZE
        if status != -1:
            if status == WRONG_SIZE:
                self._refuse(q=q, u=u)
                raise ModelError(f"lowlevel: out must be a contiguous, writable float64 "
                                 f"array of shape ({model.n_frames}, 6)")
            model.reaction_array(q, u, t)          # raises the precise error
        return out

    def inverse_dynamics(self, q, u, u_dot, t=0.0, out=None):
        """The generalized forces ``M u' - f`` on the free speeds that make the motion
        ``(q, u, u')`` (``Model.effort_array``), by the recursive Newton-Euler algorithm in
        one compiled call; a workspace array unless ``out`` is given."""
        model = self.model
        if model._con is not None:
            raise ModelError(f"model {model.name!r} has closed loops: use "
                             "model.inverse_dynamics(q, u, u_dot, t)")
        if self._inputs:
            self._refuse(q=q, u=u)
            model._fill_inputs(q, u, t)
        if out is None:
            out = self._tau
        try:
            status = _entry(entries.inverse_dynamics, entries.INVERSE_SIGNATURE)(
                self._fb, self._ib_merged, q, u, u_dot, out)
        except TypeError:
            status = WRONG_SIZE
        if status != -1:
            self._refuse(q=q, u=u, u_dot=u_dot, out=out)
            model.effort_array(q, u, u_dot, t)           # raises the precise error
        return out

    def mass_matrix(self, q, t=0.0, out=None):
        """The mass matrix ``M(q)`` (nu x nu) by composite rigid bodies in one compiled
        call; a workspace array unless ``out`` is given."""
        model = self.model
        if self._inputs:
            self._refuse(q=q)
            model._fill_inputs(q, np.zeros(self._nu), t)
        if out is None:
            out = self._M
        try:
            status = _entry(entries.mass_matrix, entries.MASS_MATRIX_SIGNATURE)(
                self._fb, self._ib_merged, q, out)
        except TypeError:
            status = WRONG_SIZE
        if status != -1:
            self._refuse(square=True, q=q, out=out)
            model.mass_matrix(q, t)                       # raises the precise error
        return out

    def _refuse(self, square=False, **arrays):
        """Raise, naming the first of ``arrays`` that is not a C-contiguous float64 array of
        the model's size (``out`` nu x nu with ``square``); return if they all are."""
        nq, nu = self._nq, self._nu
        sizes = {"q": (nq,), "u": (nu,), "y": (nq + nu,), "u_dot": (nu,),
                 "out": (nu, nu) if square else ((nq + nu,) if "y" in arrays else (nu,))}
        for name, a in arrays.items():
            if not (isinstance(a, np.ndarray) and a.dtype == np.float64
                    and a.shape == sizes[name] and a.flags.c_contiguous
                    and a.flags.writeable):
                got = type(a).__name__
                if isinstance(a, np.ndarray):
                    kind = ("" if a.flags.c_contiguous else "non-contiguous ") + (
                        "" if a.flags.writeable else "read-only ")
                    got = f"{kind}{a.dtype} array of shape {a.shape}"
                shape = sizes[name] if len(sizes[name]) > 1 else f"({sizes[name][0]},)"
                raise ModelError(f"lowlevel: {name} must be a contiguous, writable float64 "
                                 f"numpy array of shape {shape}, got {got}; convert "
                                 "it once with np.array(..., dtype=float) outside the loop")

    def _fail(self, q, u, t):
        """Raise what went wrong, found by the checked call."""
        self.model.forward_dynamics(q, u, t, self.method)    # raises the precise error
        raise ModelError("lowlevel: the compiled evaluation failed where the checked call "
                         "did not")

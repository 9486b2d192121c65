"""A model with flexible bodies laid out for the compiled kernels (``kernels.flexible``,
``kernels.flexible_loops``): each body's invariants and modal matrices in one float array,
the node frames' chains, the map ``P`` as compressed rows, the loads and force elements at
the bodies' points (``kernels.flexible_forces``), and the joint space extended by the
modal coordinates, with the arrays the compiled loops take (``FlexibleModel.
loop_arguments``).

The extended joint space holds the tree's ``qfull``, ``ufull``, ``udfull`` and then each
flexible body's ``eta`` and ``eta'`` (rates zero): the model's free coordinates and speeds
are scattered there as the tree's are (``free_q``, ``free_u``), and a modal coordinate's
``q' = u`` is written as a prismatic joint's (``slots``).  The tree's kinematic arrays
(``R``, ``r``, ..., ``M``, ``f``) are shared with ``model.tree``.
"""
from __future__ import annotations

import numpy as np

from ..elements.force_kinds import BEARING_COEFFICIENTS as _COEFFICIENTS
from ..elements.tables import Table
from ..kernels import evaluate as ke
from ..kernels import flexible as kx
from ..kernels import flexible_entry as kfe
from ..kernels import flexible_views as kfv
from ..kernels import flexible_forces as kff
from ..kernels.constrained import loop_work
from ..kernels.flexible_body import body_layout, body_work
from ..kernels.flexible_loops import loops_work
from ..kernels.joints import PRISMATIC
from ..kernels.tables import NO_TABLE


class FlexibleKernels:
    """The arrays the kernels take for ``model`` (a ``FlexibleModel``): the extended joint
    space (``qfull``, ``ufull``, ``udfull``), ``free_q``, ``free_u``, ``slots``,
    ``quats``, the ``flex`` arrays, with loops the model's ``G`` and the loops' scratch;
    the *hook* (``kernels.flexible_entry``: the compiled function's address and every
    array's) and ``ws``, the Jourdain layout of the tree's workspace over the extended
    joint space; ``load_functions``: ``(offset in edata, load's callable)`` of the loads
    at flexible bodies given as Python functions (written before each evaluation, as the
    tree's are)."""

    def __init__(self, model):
        tree = model.tree
        smap = model._map
        self.nqf, self.nuf = tree._nq_full, tree._nu_full
        modal = model._nux - tree.nu
        keep_q = np.arange(tree.nq) if smap is None else smap.keep_q
        keep_u = np.arange(tree.nu) if smap is None else smap.keep_u
        self.free_q = np.concatenate([tree._free_q[keep_q],
                                      self.nqf + np.arange(modal)]).astype(np.int64)
        self.free_u = np.concatenate([tree._free_u[keep_u],
                                      self.nuf + np.arange(modal)]).astype(np.int64)
        kept = len(keep_q)
        slots = list(model._free_joint_slots) + [
            (PRISMATIC, kept + k, 1, len(keep_u) + k, 1) for k in range(modal)]
        self.slots = np.array(slots, np.int64).reshape(-1, 5)
        self.quats = np.array([s.start for s in model._quaternions], np.int64)
        self.drive_q = np.array([d[1] for d in tree._time_inputs], np.int64)
        self.drive_u = np.array([d[2] for d in tree._time_inputs], np.int64)
        self.qfull = np.concatenate([tree._qfull, np.zeros(modal)])
        self.ufull = np.zeros(self.nuf + modal)
        self.udfull = np.zeros(self.nuf + modal)
        self.load_functions = []
        self.flex = _flex_arrays(model, self)
        con = tree._con
        m = 0 if con is None else con[4].shape[0]
        self.scratch = np.zeros(max(tree._scratch.size,
                                    ke.scratch_size(tree.n_frames, tree.nu, self.ufull.size),
                                    loop_work(tree.n_frames, tree.nu, m) if m else 0))
        self.G = np.zeros((m, model.nu))
        self.lw = np.zeros(loops_work(model.nq, model.nu, m) if m else 0)
        con_int, cf = (tree._con_packed if m else
                       (np.zeros((0, 2), np.int64), np.zeros(0)))
        arrays = {"qfull": self.qfull, "ufull": self.ufull, "udfull": self.udfull,
                  "scratch": self.scratch, "slots": self.slots, "quats": self.quats,
                  "free_q": self.free_q, "free_u": self.free_u, "con_int": con_int,
                  "cf": cf, "G": self.G, "lw": self.lw,
                  **dict(zip(FLEX_NAMES, self.flex))}
        fbuf, ibuf = tree._packed[:2]
        #: False where the compiled route cannot take the model (contacts between shapes)
        self.takes = tree._force_shapes is None
        #: set by ``FlexibleModel.compiled_terms`` (opt-in: its first use compiles 20-30 s)
        self.opted = False
        self._kind = (tree._force_int.shape[0] > 0, len(self.flex[7]) > 0, m > 0)
        self.function = None            # compiled on first use (``ready``)
        hook = [int(tree._switches[0]), 0, fbuf.ctypes.data, fbuf.size, ibuf.ctypes.data,
                ibuf.size, model.nq, model.nu, tree.nu]
        self._keep = []
        for name, integer, ndim in kfv.ARRAYS:
            arr = arrays[name]
            dtype = np.int64 if integer else np.float64
            if not (arr.dtype == dtype and arr.flags.c_contiguous and arr.ndim == ndim):
                raise TypeError(f"flexible kernels: {name} must be a C-contiguous "
                                f"{dtype.__name__} array of {ndim} dimensions")
            self._keep.append(arr)
            shape = tuple(arr.shape) + (0,) * (2 - ndim)
            hook += [arr.ctypes.data, *shape]
        # last: whether routes.finish_step projects onto the loops (by this function)
        self.hook = np.array(hook + [int(m > 0)], np.int64)
        self.ws = (self.qfull, self.ufull, self.udfull, *tree._kin_out[:8], tree._S,
                   tree._F, tree._N, tree._M, tree._f, tree._L, self.scratch)

    @property
    def supported(self):
        """True when the evaluations take the compiled function: asked for
        (``FlexibleModel.compiled_terms``) and possible (no contacts between shapes)."""
        return self.opted and self.takes

    def ready(self):
        """The hook, its function compiled (or loaded from numba's cache) on first use."""
        if self.function is None:
            self.function = kfe.entry(*self._kind)
            self.hook[kfv.FUNCTION] = self.function.address
        return self.hook

    def loop_arguments(self, model):
        """``(nq, slots, quats, free_q, free_u, drive_q, drive_u, tree, body, loads, ws)``
        as ``Model.loop_arguments``: the tree's loads with the hook for ``switches``."""
        tree = model.tree
        body = (tree._mass, tree._com, tree._inertia, tree._has_inertia, tree.gravity)
        loads = tree._loads_arrays[:7] + (self.ready(),)
        return (model.nq, self.slots, self.quats, self.free_q, self.free_u, self.drive_q,
                self.drive_u, tree._tree, body, loads, self.ws)


#: the ``flex`` arrays' names (``kernels.flexible``), in order
FLEX_NAMES = ("fint", "fdata", "chain", "D", "pptr", "pidx", "pval", "eint", "edata",
              "flags", "Mx", "Ax", "fx", "M", "A", "f", "fwork")


def _flex_arrays(model, kern):
    """The ``flex`` tuple of ``kernels.flexible`` (its module docstring)."""
    tree, packs = model.tree, model._flex
    nux, nu = model._nux, model.nu
    rows, data, qe_at = [], [], 0
    for fb in packs:
        rows.append([fb.frame, fb.n, kern.nqf + fb.q.start - tree.nq,
                     kern.nuf + fb.u.start - tree.nu, fb.u.start, len(data), qe_at])
        data.extend(_body_numbers(fb))
        qe_at += 6 + fb.n
    fint = np.array(rows, np.int64).reshape(len(rows), kff.FROW)
    fdata = np.array(data, float)
    smap = model._map
    if smap is None:
        chain = np.zeros((0, 2), np.int64)
        D = np.zeros((0, nux - tree.nu))
        P = np.eye(nux, nu)
    else:
        chain = np.stack([tree._free_q[smap.chain_q],
                          tree._free_u[smap.chain_u]], axis=1).astype(np.int64)
        D, P = np.ascontiguousarray(smap.D, float), smap.P
    pptr = np.zeros(nux + 1, np.int64)
    pidx, pval = [], []
    for e in range(nux):
        nz = np.flatnonzero(P[e])
        pidx.extend(nz)
        pval.extend(P[e, nz])
        pptr[e + 1] = len(pidx)
    eint, edata = _element_arrays(model, kern)
    nmax = max(fb.n for fb in packs)
    anc = tree._anc_ptr
    na = max(int(anc[fb.frame + 1] - anc[fb.frame]) for fb in packs)
    sizes = [(6 + nmax) ** 2, 6 + nmax, body_work(nmax), qe_at, 3 * len(packs), nux,
             kff.ELEMENT_WORK, max(nux * nu, nu * nu), (12 + nmax) * max(na, 1), nmax, 12]
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    coupled = model.stiffening and any(fb.axial.any() for fb in packs)
    flags = np.zeros(kx.FLAGS_SIZE, np.int64)
    flags[:kx.W_MB] = [int(model.stiffening), tree.nu, kern.nqf, kern.nuf, int(coupled),
                       int(smap is not None), nux - tree.nu]
    flags[kx.W_MB:] = offsets[:-1]
    return (fint, fdata, chain, np.ascontiguousarray(D, float), pptr,
            np.array(pidx, np.int64), np.array(pval, float), eint, edata, flags,
            np.zeros((nux, nux)), np.zeros((nux, nux)), np.zeros(nux),
            np.zeros((nu, nu)), np.zeros((nu, nu)), np.zeros(nu), np.zeros(offsets[-1]))


def _body_numbers(fb):
    """A body's numbers in the order of ``kernels.flexible_body.body_layout``."""
    inv, n = fb.invariants, fb.n
    spin_G = fb.spin * fb.gyroscopic if fb.spin else np.zeros((n, n))
    parts = [[inv.mass], inv.first_moment, inv.modal_first_moment, inv.inertia,
             inv.inertia_1, inv.inertia_2 + inv.inertia_2.swapaxes(0, 1), inv.coupling,
             inv.coupling_1, fb.mass,
             fb.stiffness, fb.damping, fb.centrifugal, fb.axial, spin_G]
    out = np.concatenate([np.asarray(p, float).reshape(-1) for p in parts])
    assert out.size == body_layout(n)[-1]
    return out


def _element_arrays(model, kern):
    """``(eint, edata)`` of the loads and force elements at flexible bodies' points."""
    tree = model.tree
    body_row = {fb.name: b for b, fb in enumerate(model._flex)}
    rows, data = [], []

    def put(values):
        at = len(data)
        data.extend(float(x) for x in np.asarray(values, float).reshape(-1))
        return at

    def side(sd):
        if sd.flex is None:
            return [sd.frame, -1, put(sd.s)]
        pt = sd.point
        return [sd.frame, body_row[sd.flex.name], put(np.concatenate(
            [pt.x, pt.Phi.reshape(-1), pt.Psi.reshape(-1)]))]
    for pk in model._flex_elements:
        a = side(pk.sides[0])
        b = side(pk.sides[1]) if len(pk.sides) > 1 else [-1, -1, 0]
        mode, slot, in_body = NO_TABLE, -1, 0
        p = pk.record.params if pk.what != "load" else None
        if pk.what == "load":
            kind = kff.LOAD
            at = put(np.zeros(6))
            for k, part in enumerate(pk.extra):
                if callable(part):
                    kern.load_functions.append((at + 3 * k, part))
                else:
                    data[at + 3 * k:at + 3 * k + 3] = np.asarray(part, float).reshape(3)
            in_body = int(bool(pk.record.in_body))
        elif pk.what == "spring-damper":
            kind = kff.SPRING_DAMPER
            at = put([p["stiffness"], p["damping"], p["free_length"], p["preload"],
                      p["min_length"]])
        elif pk.what == "bushing":
            kind = kff.BUSHING
            at = put(np.concatenate([p["stiffness"].ravel(), p["damping"].ravel()]))
        else:
            kind = kff.BEARING
            how, what = pk.extra
            consts = list(what) if how == "value" else [
                0.0 if isinstance(p[c], Table) else p[c] for c in _COEFFICIENTS]
            at = put(np.concatenate([p["e1"], p["e2"], consts, -np.ones(8)]))
            if how == "speed":
                k = what
                slot = int(tree._free_u[k]) if k < tree.nu else kern.nuf + k - tree.nu
                for c8, c in enumerate(_COEFFICIENTS):
                    if isinstance(p[c], Table):
                        data[at + 14 + c8] = float(put(p[c].block()))
                        mode = p[c].mode
        rows.append([kind, *a, *b, at, mode, slot, in_body])
    eint = np.array(rows, np.int64).reshape(len(rows), kff.EROW)
    return eint, np.array(data, float)


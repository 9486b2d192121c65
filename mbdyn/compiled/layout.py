"""The compiled model's data: the element records laid out as flat arrays in topological
order, and the workspace every evaluation writes into.

Each function lays out one part and sets it on the ``Model`` (its private ``_``
attributes, which the algorithms and kernels read): the tree, the coordinates, the bodies,
the reaction directions, the loads, the workspace.  ``Model.__init__`` calls them in this
order; ``pack`` then moves the arrays the fused kernels read into two flat buffers.  What
only the Jourdain and dense Newton-Euler routes read (the full Jacobians, ``M``, the
ancestor-column lists: O(n nu) and O(nu^2)) is laid out by ``full_workspace`` on the first
use of such a route.
"""
from __future__ import annotations

import numpy as np

from ..kernels import evaluate as ke
from ..kernels import force_function as kff
from ..kernels import joints as kj
from ..kernels import constrained as kc
from ..kernels import packed as kp
from ..kernels.constraints import DATA, constraint_count
from ..kernels.contact import CONTACT_SHAPES
from ..elements.joints import make_drive
from ..elements.values import t as TIME
from .constraint_packing import pack_constraints
from . import merging

#: the clock: a drive whose value is the time
CLOCK = make_drive(TIME, "the clock")


def tree(model, joints):
    """Each frame's joint: parent index, kind code, axis, Euler sequence, placement
    (position and orientation ``C`` in the parent)."""
    n = len(joints)
    model._parent = np.array([model._frame_index.get(j.parent, -1) for j in joints], np.int64)
    model._kind = np.array([j.code for j in joints], np.int64)
    model._axis = np.array([j.axis for j in joints], float).reshape(n, 3)
    model._seq = np.array([j.sequence for j in joints], np.int64).reshape(n, 3)
    model._pos = np.array([j.position for j in joints], float).reshape(n, 3)
    model._C = np.array([j.orientation for j in joints], float).reshape(n, 3, 3)


def coordinates(model, joints, clock=False):
    """Where each joint's coordinates and speeds sit: offsets into the joint-space vectors
    (every joint) and columns of the free ``u`` (free joints only); the free coordinates'
    and speeds' names and indices; the driven joints, quaternion slices, the free joints'
    slots for ``q' = N(q) u`` and the Euler joints' middle angles.  With ``clock`` (force
    elements that read the time) the joint-space vectors end with the clock's entry,
    filled like a drive's with ``t``, 1, 0: ``model._time_inputs`` lists the drives and
    the clock, whatever writes into joint space at each evaluation's time."""
    n = len(joints)
    qoff = np.zeros(n, np.int64)
    uoff = np.zeros(n, np.int64)
    ucol = -np.ones(n, np.int64)
    free_q, free_u, coords, speeds = [], [], [], []
    model._driven = []                 # (joint, qfull index, ufull index, drive)
    model._quaternions = []            # slices of q holding a quaternion
    nqf = nuf = 0
    for i, j in enumerate(joints):
        qoff[i], uoff[i] = nqf, nuf
        if j.drive is not None:
            model._driven.append((j.name, nqf, nuf, j.drive))
        elif j.nu:
            ucol[i] = len(free_u)
            start = len(free_q)
            if j.kind == "spherical":
                model._quaternions.append(slice(start, start + 4))
            elif j.kind == "free":
                model._quaternions.append(slice(start + 3, start + 7))
            free_q.extend(range(nqf, nqf + j.nq))
            free_u.extend(range(nuf, nuf + j.nu))
            coords.extend(j.coordinates)
            speeds.extend(j.speeds)
        nqf += j.nq
        nuf += j.nu
    model._clock = None
    model._time_inputs = list(model._driven)
    if clock:
        model._clock = (nqf, nuf)
        model._time_inputs.append(("t", nqf, nuf, CLOCK))
        nqf += 1
        nuf += 1
    model._nq_full, model._nu_full = nqf, nuf
    model._qoff, model._uoff, model._ucol = qoff, uoff, ucol
    model._free_q = np.array(free_q, np.int64)
    model._free_u = np.array(free_u, np.int64)
    model.coordinates = tuple(coords)
    model.speeds = tuple(speeds)
    model.nq, model.nu = len(coords), len(speeds)
    model._coordinate_index = {c: k for k, c in enumerate(coords)}
    model._speed_index = {c: k for k, c in enumerate(speeds)}
    model._speed_joint = []            # joint name of each speed
    model._free_joint_slots = []       # (kind code, q start, nq, u start, nu)
    model._euler_middle = []           # (joint, q index of middle angle, proper sequence?)
    qi = ui = 0
    for j in joints:
        if j.drive is None and j.nu:
            model._free_joint_slots.append((j.code, qi, j.nq, ui, j.nu))
            if j.kind == "euler":
                model._euler_middle.append((j.name, qi + 1, j.sequence[0] == j.sequence[2]))
            model._speed_joint.extend([j.name] * j.nu)
            qi += j.nq
            ui += j.nu


def columns(model):
    """The columns of ``u`` each frame's motion depends on, its own joint's and its
    ancestors' (the Jacobians' sparsity), as compressed rows ``(ptr, idx)``: O(n depth)
    entries (50 million for a 10,000-body chain), built by ``full_workspace`` only."""
    ucol, parent, kind = model._ucol, model._parent, model._kind
    counts = np.zeros(model.n_frames, np.int64)
    for i in range(model.n_frames):
        own = kj.NU[kind[i]] if ucol[i] >= 0 else 0
        counts[i] = own + (counts[parent[i]] if parent[i] >= 0 else 0)
    ptr = np.zeros(model.n_frames + 1, np.int64)
    np.cumsum(counts, out=ptr[1:])
    idx = np.empty(ptr[-1], np.int64)
    for i in range(model.n_frames):
        at, p = ptr[i], parent[i]
        if p >= 0:                      # the parent's columns come first: all smaller
            idx[at:at + counts[p]] = idx[ptr[p]:ptr[p + 1]]
            at += counts[p]
        idx[at:ptr[i + 1]] = np.arange(ucol[i], ucol[i] + ptr[i + 1] - at)
    return ptr, idx


def bodies(model, records):
    """Mass, centre of mass (body components) and inertia about it (body axes) per frame."""
    n = len(records)
    model._mass = np.array([b.mass for b in records], float)
    model._com = np.array([b.com for b in records], float).reshape(n, 3)
    model._inertia = np.array([b.inertia for b in records], float).reshape(n, 3, 3)
    model._has_inertia = np.array([b.has_inertia for b in records], np.bool_)


def _perpendicular_pair(a):
    """Two unit vectors completing ``a`` to a right-handed orthonormal basis."""
    helper = np.eye(3)[np.argmin(np.abs(a))]
    n1 = np.cross(a, helper)
    n1 /= np.linalg.norm(n1)
    return n1, np.cross(a, n1)


def reaction_basis(joint):
    """Directions (child-frame components) of the reaction components a joint transmits:
    ``[(force, moment), ...]`` -- six minus its degrees of freedom, plus the drive's."""
    e = np.eye(3)
    z = np.zeros(3)
    kind = joint.kind
    forces = [(e[k], z) for k in range(3)]
    moments = [(z, e[k]) for k in range(3)]
    if kind == "fixed":
        basis = forces + moments
    elif kind in ("spherical", "euler"):
        basis = forces
    elif kind == "free":
        basis = []
    elif kind == "revolute":
        n1, n2 = _perpendicular_pair(joint.axis)
        basis = forces + [(z, n1), (z, n2)]
        if joint.drive is not None:
            basis.append((z, joint.axis.copy()))
    else:  # prismatic
        n1, n2 = _perpendicular_pair(joint.axis)
        basis = [(n1, z), (n2, z)] + moments
        if joint.drive is not None:
            basis.append((joint.axis.copy(), z))
    return basis


def reactions(model, joints):
    """The reaction unknowns of the Newton-Euler system: for each component its joint and
    its force and moment directions (child components); each joint's slice of them."""
    rj, rf, rm, model._reaction_slices = [], [], [], {}
    for i, j in enumerate(joints):
        basis = reaction_basis(j)
        model._reaction_slices[j.name] = slice(len(rj), len(rj) + len(basis))
        for fo, mo in basis:
            rj.append(i)
            rf.append(fo)
            rm.append(mo)
    model._react_joint = np.array(rj, np.int64)
    model._react_force = np.array(rf, float).reshape(-1, 3)
    model._react_moment = np.array(rm, float).reshape(-1, 3)


def loads(model, records):
    """Point loads: body index, point, components (world or body), and the constant
    values; returns the loads given as functions, ``[(load, array name, row, callable)]``
    (sympy expressions are turned into functions here)."""
    model.loads = tuple(ld.name for ld in records)
    nl = len(records)
    model._load_body = np.array([model._frame_index[ld.body] for ld in records], np.int64)
    model._load_point = np.array([ld.point for ld in records], float).reshape(nl, 3)
    model._load_in_body = np.array([ld.in_body for ld in records], np.bool_)
    model._load_force = np.zeros((nl, 3))
    model._load_moment = np.zeros((nl, 3))
    functions = []
    for k, ld in enumerate(records):
        for target, val in (("_load_force", ld.force), ("_load_moment", ld.moment)):
            if isinstance(val, tuple):
                val = model._lambdify_load(ld.name, val)
            if callable(val):
                functions.append((ld.name, target, k, val))
            else:
                getattr(model, target)[k] = val
    return functions


def workspace(model, joints, loop_joints=0):
    """The arrays every evaluation writes into: joint-space state, frame motion, the
    joints' motion subspaces, applied loads, ``f``, the articulated inertias, the reaction
    unknowns, and one scratch array for the kernels' temporaries
    (``kernels.evaluate.scratch_size``): O(n + nu) floats.  The full Jacobians, ``M`` and
    its factor are empty here, allocated with the ancestor lists on the first use of a
    route that reads them (``full_workspace``), and the dense Newton-Euler system
    (6n x 6n) on the first use of its route (``Model._dense_system``): a 5,000-body model
    would otherwise hold 7 GB for it, a 10,000-body chain 6.4 GB for the others.
    ``loop_joints``: how many loop joints close the tree (their constraint rows and
    solves take the scratch after the tree's kernels, ``kernels.constrained.loop_work``)."""
    n, nu = model.n_frames, model.nu
    model._qfull = np.zeros(model._nq_full)
    model._ufull = np.zeros(model._nu_full)
    model._udfull = np.zeros(model._nu_full)
    for i, j in enumerate(joints):    # identity quaternions where nothing else is set
        if j.kind == "spherical":
            model._qfull[model._qoff[i]] = 1.0
        elif j.kind == "free":
            model._qfull[model._qoff[i] + 3] = 1.0
    model._R = np.zeros((n, 3, 3))
    model._r, model._w, model._v = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    model._alpha, model._a = np.zeros((n, 3)), np.zeros((n, 3))
    model._JR, model._JT = np.zeros((0, 3, nu)), np.zeros((0, 3, nu))
    model._anc_ptr, model._anc_idx = np.zeros(0, np.int64), np.zeros(0, np.int64)
    model._S = np.zeros((n, 6, 6))
    model._F, model._N = np.zeros((n, 3)), np.zeros((n, 3))
    model._M, model._L = np.zeros((0, 0)), np.zeros((0, 0))
    model._f = np.zeros(nu)
    model._ud = np.zeros(nu)
    # articulated bodies (kernels.articulated): per frame 6x6 inertias, biases, the
    # joint's U = IA S and Cholesky factor of D, accelerations, joint wrenches
    model._IA, model._U = np.zeros((n, 6, 6)), np.zeros((n, 6, 6))
    model._pA, model._cb, model._acc = np.zeros((n, 6)), np.zeros((n, 6)), np.zeros((n, 6))
    model._Dl, model._W = np.zeros((n, 6, 7)), np.zeros((n, 6))
    model._lam = np.zeros(len(model._react_joint))
    # contacts' broad phase; a closed mechanism's rows and solves (at most 6 rows a loop
    # joint: a fixed joint's)
    model._scratch = np.zeros(max(ke.scratch_size(n, nu, model._nu_full),
                                  getattr(model, "_force_work", 0),
                                  kc.loop_work(n, nu, 6 * loop_joints) if loop_joints else 0))
    model._slots = np.array(model._free_joint_slots, np.int64).reshape(-1, 5)


def pack(model, loop_joints=0):
    """Move every array the fused kernels use into two flat buffers (``kernels.packed``):
    the attributes become views of them, and a kernel call passes three arrays instead of
    38.  The (empty) arrays of ``full_workspace`` stay where they are, entered in the
    offset table by address.

    The merged tree of the per-call dynamics (``compiled.merging``: rigidly attached
    frames merged into their carriers) is laid out with them: ``model._dynamics`` holds
    its packed arguments ``(fbuf, ibuf, forces)`` for the per-call entries (articulated
    bodies, inverse dynamics, mass matrix) and ``model._dynamics_ud`` its ``u'``; without
    one (nothing to merge), the full tree's (``model._dynamics_full``)."""
    attr = {name: "gravity" if name == "gravity" else "_" + name
            for name in kp.FLOATS + kp.INTS + kp.FAR}
    merged = merging.plan(model, loop_joints)
    fbuf, ibuf, table, views, ibuf2, views2 = kp.pack(
        {k: getattr(model, attr[k]) for k in kp.FLOATS},
        {k: getattr(model, attr[k]) for k in kp.INTS},
        {k: getattr(model, attr[k]) for k in kp.FAR}, merged)
    for name, view in views.items():
        setattr(model, attr[name], view)
    # the force elements as the kernels take them (kernels.force_function): the table and
    # the address of the compiled function that applies it (none, without contacts between
    # shapes, with them), an integer for every model: no kernel is compiled again for them
    model._force_shapes = (True if (model._force_int[:, 0] == CONTACT_SHAPES).any()
                           else None)
    kind = (kff.NONE if not model._force_int.shape[0] else
            kff.SHAPES if model._force_shapes else kff.PLAIN)
    forces = (model._force_int, kff.address(kind))
    model._packed = (fbuf, ibuf, table, forces)
    # the per-call entries' arguments (the integer buffer stands for its table): the full
    # tree's, and the merged tree's
    model._dynamics_full = (fbuf, ibuf, forces)
    model._dynamics, model._dynamics_ud = model._dynamics_full, model._ud
    model._merged_frames = 0
    if merged is not None:
        model._dynamics = (fbuf, ibuf2, (views2["force_int"], forces[1]))
        model._dynamics_ud = views2["ud"]
        model._merged_frames = model.n_frames - merged["n"]


def full_workspace(model):
    """Allocate, on the first use of a route that reads them, the arrays no O(n) route
    needs: the full Jacobians ``JR``, ``JT`` (n x 3 x nu each), ``M`` and its Cholesky
    factor ``L`` (nu x nu each) and the ancestor-column lists (``columns``); enter them
    in the packed table (``kernels.packed.place``) and in the argument groups, and set
    the model's Jourdain kernels (``Model._jourdain_kernel``, ``_jourdain_rates``: ``None``
    before, so that a call checks one attribute).  The packed buffers, and every view of
    them, stay as they are.  Kept from then on; a no-op when done."""
    if model._jourdain_kernel is not None:
        return
    n, nu = model.n_frames, model.nu
    model._anc_ptr, model._anc_idx = columns(model)
    model._JR, model._JT = np.zeros((n, 3, nu)), np.zeros((n, 3, nu))
    model._M, model._L = np.zeros((nu, nu)), np.zeros((nu, nu))
    kp.place(model._packed[2], {k: getattr(model, "_" + k) for k in kp.FAR})
    argument_groups(model)
    model._jourdain_kernel = kp.jourdain_accelerations_packed
    model._jourdain_rates = kp.state_derivative_packed


def argument_groups(model):
    """The groups of arrays the kernels take together: the tree, the loads (with the
    force elements' table and function, ``kernels.force_function``), and the kinematics'
    outputs."""
    model._tree = (model._parent, model._kind, model._axis, model._seq, model._pos, model._C,
                   model._qoff, model._uoff, model._ucol, model._anc_ptr, model._anc_idx)
    model._loads_arrays = (model._load_body, model._load_point, model._load_force,
                           model._load_moment, model._load_in_body, model._packed[3],
                           model._force_data, model._switches)
    model._kin_out = (model._R, model._r, model._w, model._v, model._alpha, model._a,
                      model._JR, model._JT, model._S, model._F, model._N)


def constraints(model, loop_joints):
    """The loop joints' primitive constraints (``compiled.constraint_packing``) and their
    workspace: ``model._con = (con_int, con_data, phi, psi, G, gamma, lam, info)``, or
    None for a tree.  ``info``: rank, conditioning, the rank a run holds (-1: none), the
    lowest rank and conditioning a run met at its steps, then how many rows the last
    projection chose (-1: none), those rows and that factorisation's conditioning
    (``kernels.loop_solve.ROWS``)."""
    model.loop_joints = tuple(j.name for j in loop_joints)
    model._loop_joint = {j.name: j for j in loop_joints}
    if not loop_joints:
        model._con = None
        model.constraint_rows = ()
        model._row_joint = model._prim_joint = ()
        return
    full_workspace(model)          # the constraints' Jacobian reads the full JR, JT
    con_int, con_data, labels, owners, prim_owner = pack_constraints(model, loop_joints)
    m = constraint_count(con_int)
    if model._scratch.size < kc.loop_work(model.n_frames, model.nu, m):
        raise RuntimeError(f"model {model.name!r}: the scratch holds {model._scratch.size} "
                           f"floats, the loops need {kc.loop_work(model.n_frames, model.nu, m)}")
    model.constraint_rows = labels
    model._row_joint, model._prim_joint = owners, prim_owner
    con_int = np.ascontiguousarray(con_int, np.int64)
    # the float arrays are views of one buffer, in the order of kernels.constrained's
    # con_views, so that the packed entry point (constrained_accelerations_packed) takes
    # two arrays, not eight
    nprim, nu = con_int.shape[0], model.nu
    cf = np.zeros(kc.con_floats(nprim, m, nu))
    ends = np.cumsum([0, nprim * DATA, m, m, m * nu, m, m, m + 7])
    views = [cf[a:b] for a, b in zip(ends[:-1], ends[1:])]
    views[0], views[3] = views[0].reshape(nprim, DATA), views[3].reshape(m, nu)
    views[0][...] = con_data
    views[6][:6] = [0.0, 1.0, -1.0, np.inf, 1.0, -1.0]
    model._con = (con_int, *views)
    model._con_packed = (con_int, cf)

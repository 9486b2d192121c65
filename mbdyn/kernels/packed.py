"""The compiled model's arrays packed into two flat buffers, for cheap calls.

numba checks the type of every argument of a compiled function at each call from Python
(about 0.1 us per array), so a kernel with 38 array arguments spends more time there than
computing a small model.  ``pack`` lays all the model's float arrays (data, state and
workspace) in one buffer and its integer arrays in another and returns a view of each; the
``*_packed`` kernels take the two buffers and an offset table and cut the same views
inside compiled code.  Writing into a view (the state, the loads) is writing into the
buffer, so the Python side keeps using its arrays as before.

The Jourdain entry points also scatter the free coordinates and speeds into the joint-space
state (what ``Model._fill`` does in Python for the other evaluations); drives and loads
given as Python functions are still written by the caller first.

Every packed kernel takes, after the offset table, the model's force elements ``forces``:
``(force_int, address)``, the force table (a view of the integer buffer) and the address of
the compiled function that applies it (``force_function``: one type for every model, so
that no kernel is compiled again for a model with force elements); the low-level entries
pass ``force_table`` instead.  ``Model._packed`` holds the four, so that a call reads
``kernel(*model._packed, q, u)``.

The arrays only the Jourdain and dense Newton-Euler routes read, O(n nu) and O(nu^2),
are not in the buffers (``FAR``): allocated on the first use of such a route, they are
entered into the offset table by address (``place``), so that the buffers, and every view
of them held anywhere, stay as they are.
"""
import numpy as np
from numba import njit

from .articulated import articulated_body
from .evaluate import (jourdain_accelerations, motion_and_loads, newton_euler_solution,
                       newton_euler_tree, outcome)
from .forces import ROW
from .joints import coordinate_rates
from .views import CACHED, UNCOUNTED, c_view, far_view, untracked

#: what a packed entry returns for an argument of the wrong size, or not contiguous
#: (before it reads it)
WRONG_SIZE = -3


@njit(inline="always", **UNCOUNTED)
def contiguous(x, n):
    """Whether the 1-d float64 argument ``x`` holds ``n`` values side by side.  Its type
    says contiguous, but the ordinary methods call the entries with no dispatch
    (``entries.direct``), which hands over the caller's array unchecked: its strides are
    read as they are (a 1-d array of stride 16 or -8 would otherwise be misread)."""
    return x.shape[0] == n and (n < 2 or x.strides[0] == 8)

#: float arrays in buffer order, with their shapes in terms of the sizes below
FLOATS = ("gravity", "axis", "pos", "C", "mass", "com", "inertia", "load_point", "load_force",
          "load_moment", "react_force", "react_moment", "qfull", "ufull", "udfull", "R", "r",
          "w", "v", "alpha", "a", "S", "F", "N", "f", "ud",
          "force_data", "IA", "pA", "cb", "U", "Dl", "acc", "W", "lam", "scratch")
#: integer arrays in buffer order (the two flags, has_inertia and load_in_body, as 0/1)
INTS = ("parent", "kind", "seq", "qoff", "uoff", "ucol", "has_inertia",
        "load_body", "load_in_body", "react_joint", "free_q", "free_u", "slots", "force_int",
        "switches")
#: arrays kept outside the two buffers, whose table entries are addresses (``place``):
#: those only the Jourdain and dense Newton-Euler routes read -- the full Jacobians
#: (n x 3 x nu each), ``M`` and its factor ``L`` (nu x nu each), the ancestor-column
#: lists (O(n depth)) --, of size zero until a route first needs them
#: (``compiled.layout.full_workspace``): a 10,000-body chain would otherwise hold 6.4 GB
FAR = ("JR", "JT", "M", "L", "anc_ptr", "anc_idx")
#: sizes, first entries of the offset table: frames, free speeds, loads, joint-space
#: coordinates and speeds, ancestor-column entries, reaction components, free coordinates,
#: free joints, force elements, force-element numbers, scratch floats; then the sizes of
#: the ``FAR`` arrays: frames with full Jacobians (n or 0), rows of ``M`` (nu or 0),
#: entries of ``anc_ptr`` (n + 1 or 0)
SIZES = ("n", "nu", "nl", "nqf", "nuf", "nanc", "nreact", "nq", "nslots", "ne", "nfd",
         "nscratch", "nj", "nm", "nptr")
NANC, NJ, NM, NPTR = 5, 12, 13, 14

(GRAVITY, AXIS, POS, C, MASS, COM, INERTIA, LOAD_POINT, LOAD_FORCE, LOAD_MOMENT, REACT_FORCE,
 REACT_MOMENT, QFULL, UFULL, UDFULL, R, RR, W, V, ALPHA, A, S, F, N, FF,
 UD, FORCE_DATA, IA, PA, CB, U, DL, ACC, WRENCH, LAM, SCRATCH) = range(len(SIZES),
                                                                len(SIZES) + len(FLOATS))
(PARENT, KIND, SEQ, QOFF, UOFF, UCOL, HAS_INERTIA, LOAD_BODY, LOAD_IN_BODY,
 REACT_JOINT, FREE_Q, FREE_U, SLOTS, FORCE_INT, SWITCHES) = range(len(SIZES) + len(FLOATS),
                                                                 len(SIZES) + len(FLOATS)
                                                                 + len(INTS))
(JR, JT, M, L, ANC_PTR, ANC_IDX) = range(len(SIZES) + len(FLOATS) + len(INTS),
                                         len(SIZES) + len(FLOATS) + len(INTS) + len(FAR))


#: arrays a merged tree (``compiled.merging``: rigidly attached frames merged into their
#: carriers) has of its own, in the same buffers: its tree and bodies, and the workspace
#: sized by its frames (so that its evaluations leave the full tree's as they were);
#: every other entry of its table is the full tree's (the state, loads, force data,
#: scratch: what Python writes between calls is seen by both)
MERGED_FLOATS = ("axis", "pos", "C", "mass", "com", "inertia", "R", "r", "w", "v", "alpha",
                 "a", "S", "F", "N", "f", "ud", "IA", "pA", "cb", "U", "Dl", "acc", "W")
MERGED_INTS = ("parent", "kind", "seq", "qoff", "uoff", "ucol", "has_inertia", "load_body",
               "force_int")


def pack(floats, ints, far, merged=None):
    """Copy the arrays of ``floats`` and ``ints`` (dicts by the names in ``FLOATS``,
    ``INTS``) into two buffers, and ``place`` the arrays of ``far``.  Returns ``(fbuf,
    ibuf, table, views)``: ``table`` holds the sizes (``SIZES``), then each array's
    offset, then the ``FAR`` arrays' addresses; ``views[name]`` is the array's view.
    The table is also the head of ``ibuf`` (``table`` is that view): ``ibuf`` can stand for
    the table, so that an entry point takes one array less (``mbdyn.compiled.lowlevel``).

    ``merged`` (``compiled.merging.plan``: its frame count ``n`` and the arrays of
    ``MERGED_FLOATS``, ``MERGED_INTS`` it has) adds a merged tree in the same float
    buffer; it returns, after the rest, ``(ibuf2, views2)``: a copy of ``ibuf`` (whose
    numbers are all fixed at compile) holding the merged tree's integer arrays, its head
    the merged tree's table, and the views of its arrays by name; else ``(None, None)``.
    """
    sizes = {"n": floats["mass"].shape[0], "nu": floats["ud"].shape[0],
             "nl": floats["load_force"].shape[0], "nqf": floats["qfull"].shape[0],
             "nuf": floats["ufull"].shape[0], "nreact": ints["react_joint"].shape[0],
             "nq": ints["free_q"].shape[0], "nslots": ints["slots"].shape[0],
             "ne": ints["force_int"].shape[0], "nfd": floats["force_data"].shape[0],
             "nscratch": floats["scratch"].shape[0]}
    table = np.zeros(len(SIZES) + len(FLOATS) + len(INTS) + len(FAR), np.int64)
    table[:len(SIZES)] = [sizes.get(s, 0) for s in SIZES]
    extra = {FLOATS: [], INTS: []}
    if merged is not None:
        extra[FLOATS] = [(name, _merged_array(name, floats[name], merged))
                         for name in MERGED_FLOATS]
        extra[INTS] = [(name, merged[name]) for name in MERGED_INTS]
    views, views2, offsets2 = {}, {}, {}
    for names, source, dtype in ((FLOATS, floats, np.float64), (INTS, ints, np.int64)):
        first = len(SIZES) + (0 if names is FLOATS else len(FLOATS))
        head = 0 if names is FLOATS else table.shape[0]
        arrays = [(name, np.asarray(source[name])) for name in names] + extra[names]
        buf = np.zeros(head + sum(arr.size for _, arr in arrays), dtype)
        at = head
        for k, (name, arr) in enumerate(arrays):
            if k < len(names):
                table[first + k] = at
            else:
                offsets2[first + names.index(name)] = at
            view = buf[at:at + arr.size].reshape(arr.shape)
            view[...] = arr
            (views if k < len(names) else views2)[name] = view
            at += arr.size
        if names is FLOATS:
            fbuf = buf
        else:
            ibuf = buf
    ibuf[:table.shape[0]] = table
    table = ibuf[:table.shape[0]]
    place(table, far)
    if merged is None:
        return fbuf, ibuf, table, views, None, None
    ibuf2 = ibuf.copy()
    table2 = ibuf2[:table.shape[0]]
    for k, at in offsets2.items():
        table2[k] = at
    for name in MERGED_INTS:                   # its integer arrays as views of its buffer
        at, arr = table2[len(SIZES) + len(FLOATS) + INTS.index(name)], views2[name]
        views2[name] = ibuf2[at:at + arr.size].reshape(arr.shape)
    table2[0] = merged["n"]
    for k in (NANC, 6, NJ, NM, NPTR):          # no full Jacobians, no reaction components
        table2[k] = 0
    return fbuf, ibuf, table, views, ibuf2, views2


def _merged_array(name, full, merged):
    """The merged tree's float array ``name``: its own data, or a workspace array shaped
    as the full tree's with its frame count first (``f`` and ``ud`` have the speeds')."""
    if name in merged:
        return np.asarray(merged[name], float)
    shape = full.shape if name in ("f", "ud") else (merged["n"],) + full.shape[1:]
    return np.zeros(shape)


def place(table, far):
    """Enter the arrays of ``far`` (a dict by the names in ``FAR``: float64 and int64,
    C-contiguous) into ``table``: their sizes and addresses.  The caller keeps them alive
    as long as the table is used, and calls no kernel on the table while it changes."""
    for k, name in enumerate(FAR):
        arr = far[name]
        dtype = np.int64 if name.startswith("anc") else np.float64
        if not (isinstance(arr, np.ndarray) and arr.flags.c_contiguous and arr.dtype == dtype):
            raise TypeError(f"packed.place: {name} must be a C-contiguous {dtype.__name__} "
                            "array")
        table[JR + k] = arr.ctypes.data
    table[NJ], table[NM] = far["JR"].shape[0], far["M"].shape[0]
    table[NPTR], table[NANC] = far["anc_ptr"].shape[0], far["anc_idx"].shape[0]


@njit(inline="always", **UNCOUNTED)
def force_table(ib, t):
    """The ``forces`` argument of a model with force elements of any kind, the table a view
    of the integer buffer (for a caller that has only the buffers, e.g.
    ``compiled.lowlevel``)."""
    return c_view(ib, t[FORCE_INT], (t[9], ROW)), True


@njit(inline="always", **UNCOUNTED)
def _views(fb, ib, t, forces):
    """Every packed array as a view, in the order of the unpacked kernels' arguments:
    tree (11), body (mass, com, inertia, has_inertia, gravity), joint-space state (3),
    loads (5, then force elements and effect switches: 3), reactions (3), motion (11),
    Jourdain (M, f, L, ud), articulated bodies (empty ancestor lists, which end the
    tree of that route: ``evaluate.articulated_accelerations``; then the workspace of
    ``articulated.articulated_body`` and the joint wrenches and reaction components), and
    the evaluations' scratch.  Offsets and addresses are read from ``t`` at run time:
    literal constants as arguments would make numba compile a slicing helper per
    constant.  ``forces`` is the loads' force elements as given (see the module's
    docstring)."""
    n, nu, nl, nqf, nuf, nanc, nreact = t[0], t[1], t[2], t[3], t[4], t[5], t[6]
    nj, nm = t[NJ], t[NM]
    fb, ib = untracked(fb), untracked(ib)       # slices of them are untracked too
    tree = (ib[t[PARENT]:t[PARENT] + n], ib[t[KIND]:t[KIND] + n],
            c_view(fb, t[AXIS], (n, 3)),
            c_view(ib, t[SEQ], (n, 3)),
            c_view(fb, t[POS], (n, 3)),
            c_view(fb, t[C], (n, 3, 3)),
            ib[t[QOFF]:t[QOFF] + n], ib[t[UOFF]:t[UOFF] + n], ib[t[UCOL]:t[UCOL] + n],
            far_view(ib, t[ANC_PTR], (t[NPTR],)), far_view(ib, t[ANC_IDX], (nanc,)))
    body = (fb[t[MASS]:t[MASS] + n], c_view(fb, t[COM], (n, 3)),
            c_view(fb, t[INERTIA], (n, 3, 3)),
            ib[t[HAS_INERTIA]:t[HAS_INERTIA] + n], fb[t[GRAVITY]:t[GRAVITY] + 3])
    state = (fb[t[QFULL]:t[QFULL] + nqf], fb[t[UFULL]:t[UFULL] + nuf],
             fb[t[UDFULL]:t[UDFULL] + nuf])
    loads = (ib[t[LOAD_BODY]:t[LOAD_BODY] + nl],
             c_view(fb, t[LOAD_POINT], (nl, 3)),
             c_view(fb, t[LOAD_FORCE], (nl, 3)),
             c_view(fb, t[LOAD_MOMENT], (nl, 3)),
             ib[t[LOAD_IN_BODY]:t[LOAD_IN_BODY] + nl], forces,
             fb[t[FORCE_DATA]:t[FORCE_DATA] + t[10]], ib[t[SWITCHES]:t[SWITCHES] + 1])
    reactions = (ib[t[REACT_JOINT]:t[REACT_JOINT] + nreact],
                 c_view(fb, t[REACT_FORCE], (nreact, 3)),
                 c_view(fb, t[REACT_MOMENT], (nreact, 3)))
    motion = (c_view(fb, t[R], (n, 3, 3)),
              c_view(fb, t[RR], (n, 3)), c_view(fb, t[W], (n, 3)),
              c_view(fb, t[V], (n, 3)),
              c_view(fb, t[ALPHA], (n, 3)),
              c_view(fb, t[A], (n, 3)),
              far_view(fb, t[JR], (nj, 3, nu)),
              far_view(fb, t[JT], (nj, 3, nu)),
              c_view(fb, t[S], (n, 6, 6)),
              c_view(fb, t[F], (n, 3)), c_view(fb, t[N], (n, 3)))
    jourdain = (far_view(fb, t[M], (nm, nm)), fb[t[FF]:t[FF] + nu],
                far_view(fb, t[L], (nm, nm)), fb[t[UD]:t[UD] + nu])
    articulated = (far_view(ib, t[ANC_PTR], (0,)), far_view(ib, t[ANC_IDX], (0,)),
                   c_view(fb, t[IA], (n, 6, 6)),
                   c_view(fb, t[PA], (n, 6)),
                   c_view(fb, t[CB], (n, 6)),
                   c_view(fb, t[U], (n, 6, 6)),
                   c_view(fb, t[DL], (n, 6, 7)),
                   c_view(fb, t[ACC], (n, 6)),
                   c_view(fb, t[WRENCH], (n, 6)),
                   fb[t[LAM]:t[LAM] + nreact])
    scratch = fb[t[SCRATCH]:t[SCRATCH] + t[11]]
    return tree, body, state, loads, reactions, motion, jourdain, articulated, scratch


@njit(inline="always", **UNCOUNTED)
def _scatter(fb, ib, t, q, u):
    """Free coordinates and speeds into the joint-space state; their rates ``u'`` to zero
    (the Jourdain terms are evaluated at ``u' = 0``; driven entries are the caller's)."""
    qfull, ufull, udfull = fb[t[QFULL]:], fb[t[UFULL]:], fb[t[UDFULL]:]
    free_q, free_u = ib[t[FREE_Q]:], ib[t[FREE_U]:]
    for k in range(q.shape[0]):
        qfull[free_q[k]] = q[k]
    for k in range(u.shape[0]):
        ufull[free_u[k]] = u[k]
        udfull[free_u[k]] = 0.0


@njit(**UNCOUNTED)
def jourdain_accelerations_packed(fb, ib, forces, q, u):
    """Scatter ``q``, ``u``, then ``evaluate.jourdain_accelerations`` on packed arrays (same
    return value, or ``WRONG_SIZE`` for ``q`` or ``u`` of another size; ``u'`` is left in
    the ``ud`` view).  The integer buffer stands for the offset table, as in
    ``articulated_accelerations_packed``."""
    t = ib
    if not (contiguous(q, t[7]) and contiguous(u, t[1])):
        return WRONG_SIZE
    _scatter(fb, ib, t, q, u)
    tree, body, state, loads, _, motion, jourdain, _, scratch = _views(fb, ib, t, forces)
    return jourdain_accelerations(tree, body, state, loads, motion, jourdain, scratch)


@njit(**UNCOUNTED)
def state_derivative_packed(fb, ib, t, forces, y, ydot):
    """``ydot = [N(q) u, u']`` for ``y = [q, u]``.  Returns -1, the pivot where the
    Cholesky factorization of ``M`` broke down, or -2 when ``ydot`` holds NaN or Inf."""
    nq = t[7]
    _scatter(fb, ib, t, y[:nq], y[nq:])
    tree, body, state, loads, _, motion, jourdain, _, scratch = _views(fb, ib, t, forces)
    pivot = jourdain_accelerations(tree, body, state, loads, motion, jourdain, scratch)
    if pivot >= 0:
        return pivot
    return _state_rates(fb, ib, t, y, ydot)


@njit(cache=True, inline="always")
def _state_rates(fb, ib, t, y, ydot):
    """After an evaluation left ``u'`` in the ``ud`` view: ``ydot = [N(q) u, u']``;
    returns -1, or -2 when ``ydot`` holds NaN or Inf."""
    nq, nu = t[7], t[1]
    ud = c_view(fb, t[UD], (nu,))
    for k in range(nu):
        ydot[nq + k] = ud[k]
    coordinate_rates(y[:nq], y[nq:], c_view(ib, t[SLOTS], (t[8], 5)), ydot[:nq])
    for k in range(ydot.shape[0]):
        if not np.isfinite(ydot[k]):
            return -2
    return -1


@njit(**CACHED)
def newton_euler_solution_packed(fb, ib, t, forces, q, u, A, b):
    """Scatter ``q``, ``u``, then ``evaluate.newton_euler_solution`` on packed arrays, the
    dense system in ``A`` (6n x 6n) and ``b`` (6n): they are not in the packed buffers,
    being O(n^2) and needed by this route only (``Model._dense_system``).  Returns the
    unknowns ``x = [ud, lambda]`` (a new array) and whether all are finite."""
    _scatter(fb, ib, t, q, u)
    tree, body, state, loads, reactions, motion, _, _, scratch = _views(fb, ib, t, forces)
    mass, com, inertia, _, gravity = body
    x = newton_euler_solution(*tree, mass, com, inertia, gravity, *state, *loads,
                              *reactions, *motion, A, b, scratch)
    finite = True
    for k in range(x.shape[0]):
        finite = finite and np.isfinite(x[k])
    return x, finite


@njit(**UNCOUNTED)
def articulated_accelerations_packed(fb, ib, forces, q, u):
    """Scatter ``q``, ``u``, then ``evaluate.articulated_accelerations`` on packed arrays,
    its kinematics by ``motion`` (``evaluate.motion_and_loads``): the same return value,
    or ``WRONG_SIZE`` for ``q`` or ``u`` of another size; ``u'`` is left in the ``ud``
    view.  The integer buffer stands for the offset table (its head, ``pack``): an
    argument less for numba to check at each call from Python."""
    t = ib
    if not (contiguous(q, t[7]) and contiguous(u, t[1])):
        return WRONG_SIZE
    _scatter(fb, ib, t, q, u)
    tree, body, state, loads, _, kin, jourdain, art, scratch = _views(fb, ib, t, forces)
    mass, com, inertia, _, gravity = body
    motion_and_loads(tree, body, state, loads, kin, scratch)
    parent, kind, ucol = tree[0], tree[1], tree[8]
    R, r, w, v, alpha, a, _, _, S, F, N = kin
    IA, pA, cb, U, Dl, acc = art[2:8]
    ud = jourdain[3]
    pivot = articulated_body(mass, com, inertia, parent, kind, ucol, R, r, w, alpha, a, S, F,
                             N, IA, pA, cb, U, Dl, acc, ud, scratch)
    return outcome(pivot, ud)


@njit(**UNCOUNTED)
def state_derivative_articulated_packed(fb, ib, forces, y, ydot):
    """``state_derivative_packed`` with ``u'`` by the articulated-body algorithm (the
    integer buffer standing for the table, as ``articulated_accelerations_packed``)."""
    nq = ib[7]
    pivot = articulated_accelerations_packed(fb, ib, forces, y[:nq], y[nq:])
    if pivot >= 0:
        return pivot
    return _state_rates(fb, ib, ib, y, ydot)


@njit(**UNCOUNTED)
def newton_euler_tree_packed(fb, ib, t, forces, q, u):
    """Scatter ``q``, ``u``, then ``evaluate.newton_euler_tree`` on packed arrays: ``u'``
    in the ``ud`` view, the reaction components in ``lam``; same return value."""
    _scatter(fb, ib, t, q, u)
    tree, body, state, loads, reactions, motion, jourdain, art, scratch = _views(fb, ib, t,
                                                                                 forces)
    mass, com, inertia, _, gravity = body
    return newton_euler_tree(*tree[:9], *art[:2], mass, com, inertia, gravity, *state, *loads,
                             *reactions, *motion, *art[2:9], jourdain[3], art[9], scratch)


"""The arrays of a model with flexible bodies as its compiled function sees them: one
integer array, the *hook*, holds the function's address and the address and shape of
every array (``compiled.flexible_packing``), and each step of the evaluation takes its
views of them here (``far_view``: no copy, no reference counting).

Layout of the hook: ``[gyroscopic switch, function address, the tree's packed float
buffer (address, size), its integer buffer (address, size; the offset table at its
head), the model's coordinates, speeds, the tree's speeds]``, then ``(address, rows,
columns)`` for each array of ``ARRAYS``.  Its first entry is the tree's ``switches``
(``kernels.packed``): a rigid model's is that one entry, so the hook's length tells the
compiled loops a model with flexible bodies (``kernels.routes``); its last entry, after
the arrays, says whether the loops project onto loop constraints after each step.
"""
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array

from . import packed as kp
from .views import UNCOUNTED, c_view, far_view

SWITCH, FUNCTION, TREE_F, TREE_F_SIZE, TREE_I, TREE_I_SIZE, NQ, NU, NUT = range(9)
HEAD = 9
#: the arrays the hook points to, in order: (name, integer?, dimensions)
ARRAYS = (("qfull", 0, 1), ("ufull", 0, 1), ("udfull", 0, 1), ("scratch", 0, 1),
          ("fint", 1, 2), ("fdata", 0, 1), ("chain", 1, 2), ("D", 0, 2), ("pptr", 1, 1),
          ("pidx", 1, 1), ("pval", 0, 1), ("eint", 1, 2), ("edata", 0, 1), ("flags", 1, 1),
          ("Mx", 0, 2), ("Ax", 0, 2), ("fx", 0, 1), ("M", 0, 2), ("A", 0, 2), ("f", 0, 1),
          ("fwork", 0, 1), ("slots", 1, 2), ("quats", 1, 1), ("free_q", 1, 1),
          ("free_u", 1, 1), ("con_int", 1, 2), ("cf", 0, 1), ("G", 0, 2), ("lw", 0, 1))
(QFULL, UFULL, UDFULL, SCRATCH, FINT, FDATA, CHAIN, DMAP, PPTR, PIDX, PVAL, EINT, EDATA,
 FLAGS, MX, AX, FX, MM, AA, FF, FWORK, SLOTS, QUATS, FREE_Q, FREE_U, CON_INT, CF, GM,
 LW) = range(len(ARRAYS))
HOOK = HEAD + 3 * len(ARRAYS)
#: what a function reached by a hook returns when its kernels raised (a division by zero):
#: a C function cannot raise -- numba's wrapper prints the exception and returns 0 --, so
#: its callers (``flexible_entry.call``, ``routes``) raise ``ZeroDivisionError`` again
FAILED = -3


@intrinsic
def call_address(typingctx, address, hook, io, mode):
    """``f(hook, io, mode)`` for the C function at ``address``
    (``int64(int64*, double*, int64)``): the arrays' data pointers are passed."""
    sig = types.int64(address, hook, io, mode)

    def codegen(context, builder, sig, args):
        addr, h, x, m = args
        h_arr = context.make_array(sig.args[1])(context, builder, h)
        x_arr = context.make_array(sig.args[2])(context, builder, x)
        fnty = ir.FunctionType(ir.IntType(64), [ir.IntType(64).as_pointer(),
                                                ir.DoubleType().as_pointer(), ir.IntType(64)])
        fn = builder.inttoptr(addr, fnty.as_pointer())
        return builder.call(fn, [h_arr.data, x_arr.data, m])
    return sig, codegen


@intrinsic
def pointer_view(typingctx, pointer, size):
    """The 1-d C-contiguous array of ``size`` elements at ``pointer`` (a ``CPointer``
    argument of a C function), untracked as ``views.c_view``'s views."""
    if not (isinstance(pointer, types.CPointer) and isinstance(size, types.Integer)):
        return None
    view_type = types.Array(pointer.dtype, 1, "C")

    def codegen(context, builder, sig, args):
        ptr, n = args
        n = context.cast(builder, n, sig.args[1], types.intp)
        itemsize = context.get_constant(
            types.intp, context.get_abi_sizeof(context.get_data_type(pointer.dtype)))
        out = make_array(view_type)(context, builder)
        populate_array(out, data=ptr, shape=[n], strides=[itemsize], itemsize=itemsize,
                       meminfo=cgutils.get_null_value(out.meminfo.type),
                       parent=cgutils.get_null_value(out.parent.type))
        return out._getvalue()
    return view_type(pointer, size), codegen


@njit(inline="always", **UNCOUNTED)
def one(h, k, like):
    """Array ``k`` of ``ARRAYS`` (1-d), with ``like``'s element type."""
    at = HEAD + 3 * k
    return far_view(like, h[at], (h[at + 1],))


@njit(inline="always", **UNCOUNTED)
def two(h, k, like):
    """Array ``k`` of ``ARRAYS`` (2-d), with ``like``'s element type."""
    at = HEAD + 3 * k
    return far_view(like, h[at], (h[at + 1], h[at + 2]))


@njit(inline="always", **UNCOUNTED)
def buffers(h, like):
    """The tree's packed buffers ``(fb, ib)`` (``ib`` begins with the offset table)."""
    return (far_view(like, h[TREE_F], (h[TREE_F_SIZE],)),
            far_view(h, h[TREE_I], (h[TREE_I_SIZE],)))


@njit(inline="always", **UNCOUNTED)
def tree_views(fb, ib):
    """The tree's ``(parent, kind, axis, seq, pos, C, qoff, uoff, ucol, anc_ptr,
    anc_idx)`` (``kernels.packed``)."""
    n = ib[0]
    return (ib[ib[kp.PARENT]:ib[kp.PARENT] + n], ib[ib[kp.KIND]:ib[kp.KIND] + n],
            c_view(fb, ib[kp.AXIS], (n, 3)), c_view(ib, ib[kp.SEQ], (n, 3)),
            c_view(fb, ib[kp.POS], (n, 3)), c_view(fb, ib[kp.C], (n, 3, 3)),
            ib[ib[kp.QOFF]:ib[kp.QOFF] + n], ib[ib[kp.UOFF]:ib[kp.UOFF] + n],
            ib[ib[kp.UCOL]:ib[kp.UCOL] + n], far_view(ib, ib[kp.ANC_PTR], (ib[kp.NPTR],)),
            far_view(ib, ib[kp.ANC_IDX], (ib[kp.NANC],)))


@njit(inline="always", **UNCOUNTED)
def motion_views(fb, ib):
    """The tree's ``(R, r, w, v, alpha, a, JR, JT, S, F, N)``."""
    n, nu, nj = ib[0], ib[1], ib[kp.NJ]
    return (c_view(fb, ib[kp.R], (n, 3, 3)), c_view(fb, ib[kp.RR], (n, 3)),
            c_view(fb, ib[kp.W], (n, 3)), c_view(fb, ib[kp.V], (n, 3)),
            c_view(fb, ib[kp.ALPHA], (n, 3)), c_view(fb, ib[kp.A], (n, 3)),
            far_view(fb, ib[kp.JR], (nj, 3, nu)), far_view(fb, ib[kp.JT], (nj, 3, nu)),
            c_view(fb, ib[kp.S], (n, 6, 6)), c_view(fb, ib[kp.F], (n, 3)),
            c_view(fb, ib[kp.N], (n, 3)))


@njit(inline="always", **UNCOUNTED)
def body_views(fb, ib):
    """The tree's ``(mass, com, inertia, has_inertia, gravity)``."""
    n = ib[0]
    return (fb[ib[kp.MASS]:ib[kp.MASS] + n], c_view(fb, ib[kp.COM], (n, 3)),
            c_view(fb, ib[kp.INERTIA], (n, 3, 3)),
            ib[ib[kp.HAS_INERTIA]:ib[kp.HAS_INERTIA] + n],
            fb[ib[kp.GRAVITY]:ib[kp.GRAVITY] + 3])


@njit(inline="always", **UNCOUNTED)
def loads_views(fb, ib, forces):
    """The tree's loads ``(load_body, ..., forces, force_data, switches)``; ``forces``:
    None, or True for the force table (without contacts between shapes)."""
    nl = ib[2]
    rows = (
        ib[ib[kp.LOAD_BODY]:ib[kp.LOAD_BODY] + nl], c_view(fb, ib[kp.LOAD_POINT], (nl, 3)),
        c_view(fb, ib[kp.LOAD_FORCE], (nl, 3)), c_view(fb, ib[kp.LOAD_MOMENT], (nl, 3)),
        ib[ib[kp.LOAD_IN_BODY]:ib[kp.LOAD_IN_BODY] + nl])
    data = fb[ib[kp.FORCE_DATA]:ib[kp.FORCE_DATA] + ib[10]]
    switches = ib[ib[kp.SWITCHES]:ib[kp.SWITCHES] + 1]
    if forces is None:
        return rows + (None, data, switches)
    return rows + ((c_view(ib, ib[kp.FORCE_INT], (ib[9], kp.ROW)), None), data, switches)


@njit(inline="always", **UNCOUNTED)
def jourdain_views(fb, ib):
    """The tree's ``(M, f, L)`` (the Jourdain terms without the flexible bodies)."""
    nm = ib[kp.NM]
    return (far_view(fb, ib[kp.M], (nm, nm)), fb[ib[kp.FF]:ib[kp.FF] + ib[1]],
            far_view(fb, ib[kp.L], (nm, nm)))

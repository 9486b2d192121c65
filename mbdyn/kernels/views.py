"""Views into flat buffers without the costs of numba's ``reshape`` and slices.

A small model's evaluation creates some hundred array views (the packed model's arrays,
per-frame scratch); built by numba's ``reshape`` each costs a call to a C helper, and every
view also costs two reference-count calls.  ``c_view`` builds the view's array structure
directly and leaves it untracked.
"""
from numba import types
from numba.core import cgutils
from numba.core.imputils import impl_ret_untracked
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array

#: ``njit`` options of every kernel: cached on disk, and without the wrapper numba adds
#: for calls from C (no kernel is used as a first-class function; ``cfunc`` entries, as
#: ``flexible_entry``'s, make their own).  The kernels only compiled code calls have no
#: Python wrapper either (``internal``).
CACHED = {"cache": True, "no_cfunc_wrapper": True}
#: ``njit`` options of the kernels an evaluation runs through: compiled without numba's
#: reference counting (its ``_nrt=False``).  Every array a compiled function holds --
#: argument, view, tuple member -- otherwise costs a call to increment its count and one to
#: decrement it, even when the array is untracked: some 700 calls, half the time of a
#: double pendulum's evaluation.  Such a kernel must not allocate (``np.empty``, ``copy``,
#: ``np.linalg``) and must not return an array: it works in the arrays and scratch it is
#: given, and may call counted kernels that allocate and free inside themselves.
UNCOUNTED = dict(CACHED, _nrt=False)
#: ``UNCOUNTED`` for the per-call dynamics' arithmetic (``motion``, ``spatial``, the
#: articulated bodies, inverse dynamics, composite rigid bodies): a product and a sum may
#: be fused into one rounding (``a * b + c`` as an FMA where the processor has it), the
#: only licence of fast-math taken -- NaN and Inf keep their meaning, sums their order
FUSED = dict(UNCOUNTED, fastmath={"contract"})


def _view(context, builder, view_type, src, data, shape):
    """The untracked C-contiguous array structure of ``view_type`` on ``data`` (a pointer
    of ``src``'s element type) with the dimensions ``shape`` (a tuple value)."""
    shapes = cgutils.unpack_tuple(builder, shape, view_type.ndim)
    strides = [None] * view_type.ndim
    stride = src.itemsize
    for k in range(view_type.ndim - 1, -1, -1):           # C order
        strides[k] = stride
        stride = builder.mul(stride, shapes[k])
    out = make_array(view_type)(context, builder)
    populate_array(out, data=data, shape=shapes, strides=strides, itemsize=src.itemsize,
                   meminfo=cgutils.get_null_value(src.meminfo.type),
                   parent=cgutils.get_null_value(src.parent.type))
    return impl_ret_untracked(context, builder, view_type, out._getvalue())


@intrinsic
def c_view(typingctx, buf, start, shape):
    """``buf[start:start + prod(shape)].reshape(shape)`` for a 1-d C-contiguous ``buf``,
    built directly (numba's ``reshape`` calls a C helper, about 25 ns: a tenth of a small
    model's evaluation over the 60 views of ``_views``).  No bounds check: the offsets
    come from the caller.  The view shares ``buf``'s memory but holds no reference to it
    (no reference counting either, which costs as much again): it must not outlive
    ``buf``'s owner -- use it only inside a function that received ``buf`` as an
    argument (an argument stays alive for the whole call; a local array may be freed
    after its last direct use)."""
    if not (isinstance(buf, types.Array) and buf.ndim == 1 and buf.layout == "C"
            and isinstance(shape, types.UniTuple) and isinstance(start, types.Integer)):
        return None
    view_type = types.Array(buf.dtype, shape.count, "C")

    def codegen(context, builder, sig, args):
        src = make_array(sig.args[0])(context, builder, args[0])
        first = context.cast(builder, args[1], sig.args[1], types.intp)
        return _view(context, builder, view_type, src, builder.gep(src.data, [first]),
                     args[2])
    return view_type(buf, start, shape), codegen


def _untracked_value(context, builder, typ, value):
    """``value`` of numba type ``typ`` with its array structures' reference-count handle
    (meminfo) and parent cleared; other values unchanged; tuples member by member."""
    if isinstance(typ, types.Array):
        arr = make_array(typ)(context, builder, value)
        out = make_array(typ)(context, builder)
        populate_array(out, data=arr.data, shape=cgutils.unpack_tuple(builder, arr.shape),
                       strides=cgutils.unpack_tuple(builder, arr.strides),
                       itemsize=arr.itemsize,
                       meminfo=cgutils.get_null_value(arr.meminfo.type),
                       parent=cgutils.get_null_value(arr.parent.type))
        return out._getvalue()
    if isinstance(typ, types.BaseTuple):
        members = [_untracked_value(context, builder, t, builder.extract_value(value, k))
                   for k, t in enumerate(typ)]
        return context.make_tuple(builder, typ, members)
    return value


@intrinsic
def untracked(typingctx, value):
    """The same array (or tuple of arrays, nested; other members as they are) without
    reference counting: the views a kernel then takes of it cost no reference-count
    calls.  As with ``c_view``, use it only on a function's arguments, inside that
    function (they stay alive for the whole call)."""
    def codegen(context, builder, sig, args):
        return impl_ret_untracked(context, builder, sig.return_type,
                                  _untracked_value(context, builder, sig.args[0], args[0]))
    return value(value), codegen


@intrinsic
def far_view(typingctx, like, address, shape):
    """A C-contiguous view of ``shape`` with ``like``'s element type on the memory at
    ``address`` (an integer: ``ndarray.ctypes.data`` of an array kept elsewhere), built as
    ``c_view`` builds its views: for the arrays of a packed model that live outside its
    two buffers, allocated on first use (``packed.FAR``), whose addresses the offset table
    holds.  The owner of that memory must outlive every use of the view; a view of size
    zero is never read, whatever the address."""
    if not (isinstance(like, types.Array) and isinstance(address, types.Integer)
            and isinstance(shape, types.UniTuple)):
        return None
    view_type = types.Array(like.dtype, shape.count, "C")

    def codegen(context, builder, sig, args):
        src = make_array(sig.args[0])(context, builder, args[0])
        at = context.cast(builder, args[1], sig.args[1], types.intp)
        return _view(context, builder, view_type, src, builder.inttoptr(at, src.data.type),
                     args[2])
    return view_type(like, address, shape), codegen

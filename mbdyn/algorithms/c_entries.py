"""The C entries of the hottest per-call methods (``kernels.fastcall``), made once a method
is called often.

A C entry's function compiles in 1-2 s on a machine that has not cached it yet (then it
loads in milliseconds).  A model whose mass matrix is asked for a few times (``mbdyn
info``, a script's one call) would pay that for nothing, so a method's first ``WARM`` calls
after its checked call take the Python fast path, counted by a ``Pending`` in the entry's
place; the next one makes the entry and puts it there.
"""
from __future__ import annotations

import warnings
import weakref

from ..kernels import fastcall
from .recycling import FREE

#: calls of a method on its Python fast path before its C entry is made
WARM = 200


def off(*arrays):
    """What stands for a C entry that could not be made: never taken (None)."""
    return None


class Pending:
    """Stands for the C entry of ``key`` on a model until the method has been called
    ``WARM`` times: returns None (the caller's Python fast path answers), then makes the
    entry, stores it with ``store(model, entry)`` and calls it.  It holds the model by a
    weak reference: a model let go of is freed at once, as without it."""

    __slots__ = ("key", "arguments", "store", "model", "calls")

    def __init__(self, model, key, arguments, store):
        self.key, self.arguments, self.store = key, arguments, store
        self.model, self.calls = weakref.ref(model), 0

    def __call__(self, *arrays):
        self.calls += 1
        if self.calls <= WARM:
            return None
        return self.make()(*arrays)

    def make(self):
        """The entry, stored in this one's place: ``off`` where it cannot be made (said
        once, as a warning; the methods keep their Python route)."""
        try:
            entry = fastcall.entry(self.key, *self.arguments)
        except Exception as error:           # a cfunc that fails to compile, a stale build
            warnings.warn(f"mbdyn: the C entry of the {self.key} could not be made "
                          f"({type(error).__name__}: {error}); the Python route is used "
                          "(MBDYN_FASTCALL=0 says so without this warning)", RuntimeWarning,
                          stacklevel=3)
            entry = None
        entry = off if entry is None else entry
        model = self.model()
        if model is not None:
            self.store(model, entry)
        return entry


def pending(model, key, packed, store):
    """What stands for ``key``'s C entry on ``packed`` (``(fb, ib)`` or ``(fb, ib,
    forces)``), to be stored by ``store(model, entry)``: a ``Pending``, or None where the
    extension is not built or switched off."""
    if not fastcall.enabled():
        return None
    forces = packed[2][1] if len(packed) > 2 else 0
    return Pending(model, key, (packed[0], packed[1], forces, model.nq, model.nu, FREE != -1),
                   store)
